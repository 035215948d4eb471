//! Wall time of the sharp-point detector (all eight scales) on a synthetic cube of N points in
//! Morton order, best of R runs, with and without the one-face neighbourhoods.
//!
//! `cargo run --release -p crease --example sharp_timing -- [N=1000000] [R=3] [one_face=1]`
//! (run under `/usr/bin/time -v` for the peak memory).

use crease::sharp::{detect_points, SharpParams};
use crease::synth::{self, SampleParams, Shape};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut n = 1_000_000usize;
    let mut runs = 3usize;
    let mut params = SharpParams::default();
    for a in std::env::args().skip(1) {
        if let Some(v) = a.strip_prefix("N=") {
            n = v.parse()?;
        } else if let Some(v) = a.strip_prefix("R=") {
            runs = v.parse()?;
        } else if let Some(v) = a.strip_prefix("one_face=") {
            params.one_face = v == "1";
        }
    }
    let shape = Shape::from_name("cube").ok_or("shape")?;
    let part = synth::sample_points(
        &shape,
        &SampleParams {
            n,
            ..Default::default()
        },
    )?;
    let pts = part.cloud.positions;
    let order = crease::spatial::morton_order(&pts);
    let pts: Vec<_> = order.iter().map(|&i| pts[i as usize]).collect();
    let mut best = f64::INFINITY;
    let mut sharp = 0;
    for _ in 0..runs {
        let t = std::time::Instant::now();
        let r = detect_points(&pts, &params)?;
        best = best.min(t.elapsed().as_secs_f64());
        sharp = r.num_sharp();
    }
    println!(
        "n={n} one_face={} best of {runs}: {best:.3} s, {sharp} sharp",
        params.one_face
    );
    Ok(())
}
