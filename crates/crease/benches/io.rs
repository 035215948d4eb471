//! I/O benchmarks (to be written).
fn main() {}
