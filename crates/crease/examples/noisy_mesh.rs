//! Adds the noise of vidal2011 section 6.1 to a mesh: isotropic Gaussian noise of `REL` × the
//! bounding box's largest side on every vertex coordinate (default 0.005), seeded; faces and
//! vertex order unchanged, so per-edge labels carry over.
//!
//! `cargo run --release -p crease --example noisy_mesh -- IN OUT [REL] [SEED]`, e.g. the
//! README's noisy fandisk:
//! `cargo run --release -p crease --example noisy_mesh -- ../shared/data/meshes/fandisk.off
//! fandisk-noisy.ply`, then `crease edges fandisk-noisy.ply -o e.ply --lines tangent.obj` and
//! `crease render fandisk-noisy.ply --lines tangent.obj -o tangent.png` (and the same with
//! `--method dihedral`).

use crease::geometry::TriMesh;
use crease::io::{Geometry, ReadOptions, WriteOptions};
use crease::meshfeat::truth::add_noise;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err("usage: noisy_mesh IN OUT [REL] [SEED]".into());
    }
    let rel: f64 = args.get(3).map_or(Ok(0.005), |s| s.parse())?;
    let seed: u64 = args.get(4).map_or(Ok(1), |s| s.parse())?;
    let (mut geom, _) = crease::io::read(&args[1], &ReadOptions::default())?;
    if std::path::Path::new(&args[1]) == std::path::Path::new(&args[2]) {
        return Err("refusing to overwrite the input".into());
    }
    let mesh = TriMesh {
        vertices: std::mem::take(&mut geom.points),
        faces: std::mem::take(&mut geom.faces),
        face_attributes: std::mem::take(&mut geom.face_attributes),
    };
    let noisy = add_noise(&mesh, rel, seed)?;
    crease::io::write(
        &args[2],
        &Geometry::from_mesh(noisy),
        &WriteOptions::default(),
    )?;
    Ok(())
}
