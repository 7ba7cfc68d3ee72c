//! Importance samples per second per model, f32, one thread: `sample(v, u)` (direction, pdf
//! and weight, which includes one BRDF evaluation) over 2^16 precomputed view directions
//! (cosine-distributed) and uniform pairs; beside each, the baseline of the same run: `eval`
//! on as many cosine-distributed (l, v) pairs.
//!
//! Run: `cargo bench -p brdf-analytic --bench sample`. Criterion prints "thrpt" in elements/s,
//! one element being one call of `sample` (`<model>/sample`) or of `eval` (`<model>/eval`).

mod common;

use brdf_analytic::albedo::cosine_sample;
use brdf_analytic::*;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use stdx::rng::SplitMix64;

const N: usize = 1 << 16;

fn inputs(seed: u64) -> (Vec<[f32; 3]>, Vec<[f32; 2]>) {
    let mut rng = SplitMix64::new(seed);
    let v =
        (0..N).map(|_| cosine_sample(rng.next_f64(), rng.next_f64()).map(|x| x as f32)).collect();
    let u = (0..N).map(|_| [rng.next_f32(), rng.next_f32()]).collect();
    (v, u)
}

/// Sums every field of every successful sample (direction, weight and pdf), so that nothing
/// is optimised away (Lambert's weight alone does not depend on the direction).
#[inline(never)]
fn sample_all<B: Brdf<f32>>(m: &B, v: &[[f32; 3]], u: &[[f32; 2]]) -> f32 {
    let mut acc = 0.0;
    for (&v, &u) in v.iter().zip(u) {
        if let Some(s) = m.sample(v, u) {
            let w = s.weight[0] + s.weight[1] + s.weight[2];
            acc += w + s.l[0] + s.l[1] + s.l[2] + s.pdf;
        }
    }
    acc
}

/// Sums every evaluation (the baseline).
#[inline(never)]
fn eval_all<B: Brdf<f32>>(m: &B, l: &[[f32; 3]], v: &[[f32; 3]]) -> f32 {
    l.iter().zip(v).map(|(&l, &v)| m.eval(l, v).iter().sum::<f32>()).sum()
}

fn bench_model<B: Brdf<f32>>(c: &mut Criterion, name: &str, m: &B, n: usize) {
    let (v, u) = inputs(7);
    let (l, _) = inputs(8);
    let mut g = c.benchmark_group("brdf-sample-f32");
    g.throughput(Throughput::Elements(n as u64));
    g.sample_size(20);
    g.bench_function(format!("{name}/sample"), |b| {
        b.iter(|| sample_all(black_box(m), black_box(&v[..n]), black_box(&u[..n])))
    });
    g.bench_function(format!("{name}/eval"), |b| {
        b.iter(|| eval_all(black_box(m), black_box(&l[..n]), black_box(&v[..n])))
    });
    g.finish();
}

fn bench(c: &mut Criterion) {
    let all_lobes = common::disney_all_lobes();
    bench_model(c, "lambert", &Lambert::new(LambertParams::default()), N);
    bench_model(c, "realistic-phong", &RealisticPhong::new(RealisticPhongParams::default()), N);
    bench_model(c, "torrance-sparrow", &TorranceSparrow::new(TorranceSparrowParams::default()), N);
    bench_model(c, "disney-default", &Disney::new(DisneyParams::default()), N);
    bench_model(c, "disney-all-lobes", &Disney::new(all_lobes), N);
    // FMBRDF evaluates two small MLPs per sample (for the weight): a smaller batch.
    bench_model(c, "fmbrdf", &Fmbrdf::new(FmbrdfParams::default()), N / 16);
}

criterion_group!(benches, bench);
criterion_main!(benches);
