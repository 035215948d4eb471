//! The B-rep of segmented meshes (`crease::brep`): topology invariants that any valid closed
//! shell satisfies, checked without a CAD kernel (the command-line tests check the STEP files
//! with OpenCASCADE).

use crease::brep::{reconstruct_mesh, to_step, Brep, LengthUnit};
use crease::segment::SegmentParams;
use crease::synth::{self, MeshParams, Shape};

fn brep_of(name: &str) -> (Brep, crease::brep::BrepReport) {
    let m = synth::mesh(
        &Shape::from_name(name).expect("shape"),
        &MeshParams::default(),
    )
    .expect("mesh");
    let rec = reconstruct_mesh(&m.mesh, &SegmentParams::default()).expect("B-rep");
    (rec.brep, rec.report)
}

/// Every edge walked once forwards and once backwards; consecutive edges of a loop share a
/// vertex; V − E + F − (L − F) = 2 (S − G) (Euler–Poincaré) with one shell.
fn check_closed_shell(b: &Brep, genus: i64, name: &str) {
    assert!(b.closed, "{name}");
    let mut walked = vec![[0usize; 2]; b.edges.len()];
    let mut loops = 0i64;
    for f in &b.faces {
        for l in &f.loops {
            loops += 1;
            for (i, &(e, fwd)) in l.iter().enumerate() {
                walked[e][usize::from(!fwd)] += 1;
                let end = if fwd {
                    b.edges[e].end
                } else {
                    b.edges[e].start
                };
                let (n, nfwd) = l[(i + 1) % l.len()];
                let start = if nfwd {
                    b.edges[n].start
                } else {
                    b.edges[n].end
                };
                assert_eq!(end, start, "{name}: loop not closed at edge {e}");
            }
        }
    }
    assert!(walked.iter().all(|w| *w == [1, 1]), "{name}: {walked:?}");
    let (v, e, f) = (
        b.vertices.len() as i64,
        b.edges.len() as i64,
        b.faces.len() as i64,
    );
    assert_eq!(
        v - e + f - (loops - f),
        2 * (1 - genus),
        "{name}: V {v} E {e} F {f} L {loops}"
    );
}

#[test]
fn synthetic_parts_give_closed_shells_of_the_right_genus() {
    for (name, genus, faces) in [
        ("cube", 0, 6),
        ("box-hole", 1, 7),
        ("two-cylinders", 0, 7),
        ("rounded-cube", 0, 26),
        ("fillet-chamfer-cone", 0, 10),
        ("sphere", 0, 2),
        ("torus", 1, 2),
    ] {
        let (b, report) = brep_of(name);
        check_closed_shell(&b, genus, name);
        assert_eq!(b.faces.len(), faces, "{name}");
        // Exact input: the vertices and analytic edges lie on their surfaces to round-off, the
        // interpolated ones within a thousandth of the mesh spacing.
        assert!(
            report.max_gap < 1e-3 * 0.05,
            "{name}: gap {}",
            report.max_gap
        );
        assert_eq!(report.segmentation, "mesh");
        // Each face's loops bound it on the left: a same_sense face's surface normal agrees
        // with the part's outside (checked on the cube, whose normals are known).
        if name == "cube" {
            for f in &b.faces {
                let crease::geometry::SurfaceParams::Plane { normal, offset } = f.surface else {
                    panic!("planes only");
                };
                // The outward normal of a face of the unit cube about the origin points away
                // from the centre: offset · normal > 0 outside.
                assert_eq!(f.same_sense, offset > 0.0, "{name}: {normal:?} {offset}");
            }
        }
    }
}

#[test]
fn the_step_file_is_the_same_whatever_the_thread_count() {
    let m = synth::mesh(
        &Shape::from_name("two-cylinders").expect("shape"),
        &MeshParams::default(),
    )
    .expect("mesh");
    let text = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let rec = reconstruct_mesh(&m.mesh, &SegmentParams::default()).expect("B-rep");
            to_step(&rec.brep, "part", LengthUnit::Millimetre, 1e-7)
        })
    };
    let one = text(1);
    assert!(one.contains("MANIFOLD_SOLID_BREP") && one.contains("CYLINDRICAL_SURFACE"));
    assert_eq!(one, text(2));
    assert_eq!(one, text(3));
}

#[test]
fn a_mesh_with_a_border_gives_an_open_shell() {
    let (b, report) = brep_of("cylinder");
    assert!(!b.closed && !report.closed);
    assert_eq!(report.warnings.len(), 1);
    assert!(report.warnings[0].contains("open shell"));
    let text = to_step(&b, "tube", LengthUnit::Metre, 1e-7);
    assert!(text.contains("OPEN_SHELL") && text.contains("SHELL_BASED_SURFACE_MODEL"));
    assert!(!text.contains("MANIFOLD_SOLID_BREP"));
}
