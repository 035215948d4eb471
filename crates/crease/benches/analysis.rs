//! The whole cloud job from one shared analysis, as `crease run` does it
//! (`pipeline::run_cloud`): a `CloudAnalysis` (Morton order, one kNN query at k = 40, normals,
//! noise, segmentation), the sharp points, the B-rep and the curve network anchored on it, on
//! the synthetic fillet-chamfer-cone part with 10k, 100k and 1M points in sampling (random)
//! order; clean (group `run_clean`) and with Gaussian noise of half a spacing along the normal
//! (group `run_noisy`). File reading and writing are not included.
//!
//! Run with `cargo bench -p crease --bench analysis`.

use std::hint::black_box;

use crease::analysis::{AnalysisParams, CloudAnalysis};
use crease::geometry::Point3;
use crease::pipeline::run_cloud;
use crease::synth::{self, Noise, NoiseScale, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

fn part(n: usize, noise: Noise) -> Vec<Point3> {
    let shape = Shape::from_name("fillet-chamfer-cone").expect("shape");
    synth::sample_points(
        &shape,
        &SampleParams {
            n,
            noise,
            noise_scale: NoiseScale::Spacing,
            ..Default::default()
        },
    )
    .expect("synthetic part")
    .cloud
    .positions
}

/// Everything `crease run` computes on a cloud.
fn whole_job(points: &[Point3]) -> usize {
    let a = CloudAnalysis::new(points, AnalysisParams::default()).expect("analysis");
    let run = run_cloud(&a, |_| {}).expect("run");
    run.surfaces.len() + run.sharp.num_sharp() + run.network.polylines.len()
}

fn run(c: &mut Criterion) {
    for (group, noise) in [
        ("run_clean", Noise::None),
        ("run_noisy", Noise::AlongNormal(0.5)),
    ] {
        let mut g = c.benchmark_group(group);
        g.sample_size(10);
        for n in [10_000usize, 100_000, 1_000_000] {
            let pts = part(n, noise);
            g.bench_function(format!("{n}"), |b| b.iter(|| black_box(whole_job(&pts))));
        }
        g.finish();
    }
}

criterion_group!(benches, run);
criterion_main!(benches);
