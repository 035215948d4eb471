//! Arbitrary finite point sets (`crease_fuzz::points`) into `crease fillets` and `crease
//! network` (`crease::fillets::extract_fillets`, Demarsin 2008, then `curve_network`) with the
//! CLI's default parameters; the variant byte picks fillets or network and toggles
//! `--one-run`, `--coarse-retry` and `--smoothing 2`.

#![no_main]

use crease::fillets::{curve_network, extract_fillets, FilletParams, Search};
use crease_fuzz::Bytes;

libfuzzer_sys::fuzz_target!(|data: &[u8]| crease_fuzz::guarded(|| run(data)));

fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let variant = b.u8();
    let points = crease_fuzz::points(&mut b);
    let network = variant & 1 != 0;
    let params = FilletParams {
        search: if variant & 2 != 0 {
            Search::OneRun
        } else {
            Search::Full
        },
        coarse_retry: variant & 4 != 0,
        smoothing_iterations: if variant & 8 != 0 { 2 } else { 0 },
        ..Default::default()
    };
    if params.validate().is_err() {
        return;
    }
    if let Ok(f) = extract_fillets(&points, &params, network) {
        let _ = (
            f.lines.closed_loops(),
            f.lines.junctions(),
            f.lines.endpoints(),
        );
        if network {
            let _ = curve_network(&f);
        }
    }
}
