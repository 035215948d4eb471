//! Arbitrary finite point sets (`crease_fuzz::points`) into `crease lines`
//! (`crease::lines::extract_lines`, Demarsin 2007) with the CLI's default parameters; the
//! variant byte toggles `--no-smooth`, `--no-boundary`, `--no-denoise` and picks k (20, the
//! default, or 3, 6, 12).

#![no_main]

use crease::lines::{extract_lines, LinesParams};
use crease_fuzz::Bytes;

libfuzzer_sys::fuzz_target!(|data: &[u8]| crease_fuzz::guarded(|| run(data)));

fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let variant = b.u8();
    let points = crease_fuzz::points(&mut b);
    let params = LinesParams {
        k: [20, 3, 6, 12][usize::from(variant >> 3) % 4],
        smooth: variant & 1 == 0,
        boundary: variant & 2 == 0,
        denoise_normals: variant & 4 == 0,
        ..Default::default()
    };
    if params.validate().is_err() {
        return;
    }
    if let Ok(net) = extract_lines(&points, &params) {
        let _ = (net.closed_loops(), net.junctions(), net.endpoints());
    }
}
