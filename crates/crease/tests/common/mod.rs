//! Helpers shared by the integration tests.
#![allow(dead_code)]

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
