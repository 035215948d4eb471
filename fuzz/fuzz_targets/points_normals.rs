//! Arbitrary finite point sets (`crease_fuzz::points`) into the `crease normals` paths: fused
//! PCA (the default), PCA over stored kNN lists, Delaunay 1-ring normals, and PCA with the
//! Hoppe orientation (`--orient`). The variant byte picks the method and k (20, the CLI
//! default, or 1, 2, 6).

#![no_main]

use crease::estimate::{self, PcaParams};
use crease_fuzz::Bytes;

libfuzzer_sys::fuzz_target!(|data: &[u8]| crease_fuzz::guarded(|| run(data)));

fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let variant = b.u8();
    let points = crease_fuzz::points(&mut b);
    let k = [20, 1, 2, 6][usize::from(variant >> 2) % 4];
    let pca = PcaParams {
        k,
        ..Default::default()
    };
    match variant % 4 {
        0 => {
            let _ = estimate::normals::pca_normals_direct(&points, &pca);
        }
        method => {
            let Ok(nbrs) = crease::spatial::knn(&points, k) else {
                return;
            };
            let normals = if method == 2 {
                let rings = crease::spatial::delaunay_rings(
                    &points,
                    &nbrs,
                    &crease::spatial::RingParams { k },
                );
                match rings {
                    Ok(rings) => estimate::ring_normals(&points, &rings),
                    Err(_) => return,
                }
            } else {
                match estimate::pca_normals(&points, &nbrs, &pca) {
                    Ok(r) => r.normals,
                    Err(_) => return,
                }
            };
            if method == 3 {
                let _ = estimate::orient_normals(&points, &normals, &nbrs);
            }
        }
    }
}
