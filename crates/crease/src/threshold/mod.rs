//! Automatic thresholds on per-point scores: Otsu's method on a histogram (tran section 3.2,
//! equation 4). The multi-resolution histograms and hysteresis of the later papers live here too.

pub mod otsu;

pub use otsu::{histogram, otsu, otsu_of_histogram, Otsu, OtsuParams};
