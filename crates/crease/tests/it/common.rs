//! Helpers shared by the integration tests.

use std::path::PathBuf;

/// `../shared/data` beside the repository. When it is missing, tests fail under `CI=true` and
/// otherwise return `None` so a developer without the data can still run the rest.
pub fn data_dir() -> Option<PathBuf> {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data");
    if d.is_dir() {
        return Some(d);
    }
    if std::env::var("CI").map(|v| v == "true").unwrap_or(false) {
        panic!(
            "CI=true but the shared test data is missing at {}: clone ../shared beside the repository",
            d.display()
        );
    }
    eprintln!("skipping: shared data not found at {}", d.display());
    None
}

/// A fresh temporary directory, removed when dropped.
pub fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().expect("temporary directory")
}

/// A synthetic part of `n` points with Gaussian noise along the normal of `noise` × the
/// expected spacing (none for 0).
pub fn noisy_part(name: &str, n: usize, noise: f64) -> crease::synth::SyntheticPart {
    use crease::synth::{Noise, NoiseScale, SampleParams, Shape};
    crease::synth::sample_points(
        &Shape::from_name(name).expect("known shape"),
        &SampleParams {
            n,
            noise: if noise > 0.0 {
                Noise::AlongNormal(noise)
            } else {
                Noise::None
            },
            noise_scale: NoiseScale::Spacing,
            ..Default::default()
        },
    )
    .expect("sampling works")
}

/// The ABC model of `dir/abc` (`dir` = [`data_dir`]): its mesh and the vertex pairs of its
/// sharp feature curves (`crease::meshfeat::read_abc_sharp_edges`).
pub fn abc_model(dir: &std::path::Path) -> (crease::geometry::TriMesh, Vec<[u32; 2]>) {
    let abc = dir.join("abc");
    let (g, _) = crease::io::read(
        abc.join("00000006_d4fe04f0f5f84b52bd4f10e4_trimesh_001.obj"),
        &Default::default(),
    )
    .expect("ABC mesh");
    let pairs = crease::meshfeat::read_abc_sharp_edges(
        &abc.join("00000006_d4fe04f0f5f84b52bd4f10e4_features_001.yml"),
    )
    .expect("ABC features");
    (g.into_mesh().expect("ABC faces"), pairs)
}
