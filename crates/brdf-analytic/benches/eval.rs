//! Evaluations per second per model, f32, batched over 2^20 random upper-hemisphere pairs, on
//! the rayon pool (all cores) and single-threaded.
//!
//! Run: `cargo bench -p brdf-analytic --bench eval`. Criterion prints "thrpt" in elements/s,
//! one element being one BRDF evaluation (RGB).

mod common;

use brdf_analytic::albedo::cosine_sample;
use brdf_analytic::*;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use stdx::rng::SplitMix64;

const N: usize = 1 << 20;

fn directions(seed: u64) -> Vec<[f32; 3]> {
    let mut rng = SplitMix64::new(seed);
    (0..N).map(|_| cosine_sample(rng.next_f64(), rng.next_f64()).map(|x| x as f32)).collect()
}

fn models() -> Vec<(&'static str, Box<dyn Brdf<f32>>)> {
    let all_lobes = common::disney_all_lobes();
    vec![
        ("lambert", Box::new(Lambert::new(LambertParams::default()))),
        ("realistic-phong", Box::new(RealisticPhong::new(RealisticPhongParams::default()))),
        ("torrance-sparrow", Box::new(TorranceSparrow::new(TorranceSparrowParams::default()))),
        ("disney-default", Box::new(Disney::new(DisneyParams::default()))),
        ("disney-all-lobes", Box::new(Disney::new(all_lobes))),
    ]
}

/// Monomorphized (not boxed) evaluation: what a renderer using one concrete model gets.
fn bench_concrete<B: Brdf<f32>>(
    c: &mut Criterion,
    name: &str,
    m: &B,
    l: &[[f32; 3]],
    v: &[[f32; 3]],
) {
    let mut out = vec![[0.0_f32; 3]; N];
    let mut g = c.benchmark_group("brdf-eval-f32");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(20);
    g.bench_function(format!("{name}/parallel"), |b| {
        b.iter(|| par_eval_batch(black_box(m), black_box(l), black_box(v), &mut out))
    });
    g.bench_function(format!("{name}/single-thread"), |b| {
        b.iter(|| eval_batch(black_box(m), black_box(l), black_box(v), &mut out))
    });
    g.finish();
}

fn bench_fmbrdf(c: &mut Criterion, l: &[[f32; 3]], v: &[[f32; 3]]) {
    let m = Fmbrdf::new(FmbrdfParams::default());
    let mut out = vec![[0.0_f32; 3]; l.len()];
    let mut g = c.benchmark_group("brdf-eval-f32");
    g.throughput(Throughput::Elements(l.len() as u64));
    g.sample_size(10);
    g.bench_function("fmbrdf/parallel", |b| {
        b.iter(|| par_eval_batch(black_box(&m), black_box(l), black_box(v), &mut out))
    });
    g.bench_function("fmbrdf/single-thread", |b| {
        b.iter(|| eval_batch(black_box(&m), black_box(l), black_box(v), &mut out))
    });
    g.finish();
}

fn bench(c: &mut Criterion) {
    let (l, v) = (directions(1), directions(2));
    bench_concrete(c, "lambert", &Lambert::new(LambertParams::default()), &l, &v);
    bench_concrete(
        c,
        "realistic-phong",
        &RealisticPhong::new(RealisticPhongParams::default()),
        &l,
        &v,
    );
    bench_concrete(
        c,
        "torrance-sparrow",
        &TorranceSparrow::new(TorranceSparrowParams::default()),
        &l,
        &v,
    );
    bench_concrete(c, "disney-default", &Disney::new(DisneyParams::default()), &l, &v);
    // FMBRDF evaluates two small MLPs per call: a smaller batch keeps the bench short.
    let k = N / 64;
    bench_fmbrdf(c, &l[..k], &v[..k]);
    let (_, all) = models().into_iter().nth(4).unwrap();
    let mut out = vec![[0.0_f32; 3]; N];
    let mut g = c.benchmark_group("brdf-eval-f32");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(20);
    g.bench_function("disney-all-lobes/parallel-dyn", |b| {
        b.iter(|| par_eval_batch(black_box(all.as_ref()), black_box(&l), black_box(&v), &mut out))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
