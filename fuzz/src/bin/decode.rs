//! The geometry a fuzz input decodes to, as a file crease reads: a crash input of a geometry
//! target becomes a plain PLY that a regression test in `crates/` (or `crease` itself) can load.
//!
//! ```text
//! decode points|mesh INPUT OUT.ply
//! ```
//!
//! `points` for the `points_*` targets (the variant byte, then [`crease_fuzz::points`]; stored
//! normals are not written), `mesh` for the `mesh_*` targets ([`crease_fuzz::mesh`]). Prints the
//! variant byte, which picks the target's options (see each target).

use crease::io::{Geometry, WriteOptions};
use crease_fuzz::Bytes;

// As in seedgen: the instrumented crates need a test function; this one never runs.
libfuzzer_sys::fuzz_target!(|_data: &[u8]| {});

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 || !matches!(args[1].as_str(), "points" | "mesh") {
        eprintln!("usage: decode points|mesh INPUT OUT.ply");
        std::process::exit(2);
    }
    let data = match std::fs::read(&args[2]) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("decode: {}: {e}", args[2]);
            std::process::exit(1);
        }
    };
    let mut b = Bytes::new(&data);
    let variant = b.u8();
    let geom = if args[1] == "points" {
        let mut g = Geometry::default();
        g.points.positions = crease_fuzz::points(&mut b);
        g
    } else {
        let Some(mesh) = crease_fuzz::mesh(&mut b) else {
            eprintln!("decode: {}: no mesh (the target returns early)", args[2]);
            std::process::exit(1);
        };
        let mut g = Geometry::from_cloud(mesh.vertices);
        g.faces = mesh.faces;
        g
    };
    if let Err(e) = crease::io::write(&args[3], &geom, &WriteOptions::default()) {
        eprintln!("decode: {}: {e}", args[3]);
        std::process::exit(1);
    }
    println!(
        "variant {variant}: {} points, {} faces -> {}",
        geom.points.positions.len(),
        geom.faces.len(),
        args[3]
    );
}
