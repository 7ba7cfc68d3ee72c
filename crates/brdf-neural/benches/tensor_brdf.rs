//! The parametric models' analytic half alone: from the parameter MLP's raw outputs (a leaf
//! `[batch, outputs]` tensor) through the output nonlinearities and the tensor BRDF to a
//! squared-error loss, forward and backward, for RP, TS, Disney and FMBRDF. The difference
//! between a parametric model's training step and its MLP's is this (issue 16: Disney's step
//! was 16 % longer than the Single MLP's with 4 % fewer multiply-adds).
//!
//! `cargo bench -p brdf-neural --bench tensor_brdf` (flex on the CPU). Environment:
//! - `BRDF_BENCH_BATCH` (default 8192, the default run's batch);
//! - `BRDF_BENCH_MODELS=disney,ts` times these models only (default: `rp,ts,disney,fmbrdf`);
//! - `BRDF_BENCH_QUICK=1` skips the criterion groups and prints the medians of 31 passes
//!   (`BRDF_BENCH_PASSES`, for a profiler).
//!
//! Each model also gets a line with the time of `Geometry::new` for its pairs (the batch's
//! direction-only terms, computed on the CPU in the training step's encode phase). Each model's
//! timing line also prints the loss and a hash of the gradient of the raw outputs, so
//! that a rewrite meant to keep the values to the bit can be checked against the build before.
//!
//! Measured 2026-11-27 on the 2-core Intel Xeon (no AVX512-BF16), batch 8,192, medians of 31:
//! Disney 9.26 and 9.94 ms at the start of the session, 5.13 to 5.46 ms after the changes of
//! `benches/README.md` ("Disney's analytic half in fewer passes"); TS 3.26 -> 2.87 ms, RP 3.34
//! -> 3.08 ms; FMBRDF 44 to 51 ms (its two helper networks run per sample).

use brdf_neural::device;
use brdf_neural::products::Products;
use brdf_neural::tensor_brdf::Geometry;
use brdf_neural::{BrdfModel, ModelConfig, ModelKind, ParametricModel};
use burn::tensor::{Device, Tensor, TensorData};
use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Instant;

fn batch_size() -> usize {
    std::env::var("BRDF_BENCH_BATCH").ok().and_then(|s| s.parse().ok()).unwrap_or(8192)
}

/// One model's fixed inputs: the model, raw outputs, the pairs' geometry and a target.
struct Case {
    name: &'static str,
    model: ParametricModel,
    z: Vec<f32>,
    outputs: usize,
    geometry: Geometry,
    pairs: (Vec<[f32; 3]>, Vec<[f32; 3]>),
    target: Tensor<2>,
    device: Device,
}

impl Case {
    fn new(name: &'static str, kind: ModelKind, n: usize, device: &Device) -> Self {
        let c = ModelConfig::new(kind);
        let BrdfModel::Parametric(model) = BrdfModel::init(&c, device).expect("model") else {
            panic!("{kind:?} is not parametric")
        };
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut dir = || {
            let z = uniform().max(1e-3);
            let p = uniform() * std::f32::consts::TAU;
            let s = (1.0 - z * z).sqrt();
            [s * p.cos(), s * p.sin(), z]
        };
        let l: Vec<_> = (0..n).map(|_| dir()).collect();
        let v: Vec<_> = (0..n).map(|_| dir()).collect();
        let outputs = model.analytic().outputs();
        let z = (0..n * outputs).map(|_| 4.0 * uniform() - 2.0).collect();
        let geometry = Geometry::new(&l, &v, kind == ModelKind::Fmbrdf, device);
        let t: Vec<f32> = (0..n * 3).map(|_| uniform()).collect();
        let target = Tensor::from_data(TensorData::new(t, [n, 3]), device);
        let pairs = (l, v);
        Self { name, model, z, outputs, geometry, pairs, target, device: device.clone() }
    }

    /// Forward and backward once; returns the loss and a hash of the raw outputs' gradient.
    fn step(&self) -> (f32, u64) {
        let n = self.z.len() / self.outputs;
        let z = Tensor::<2>::from_data(
            TensorData::new(self.z.clone(), [n, self.outputs]),
            &self.device,
        )
        .require_grad();
        let f = self.model.brdf_of_outputs(z.clone(), &self.geometry, Products::F32);
        let loss = (f - self.target.clone()).square().mean();
        let grads = loss.backward();
        let g = z.grad(&grads).expect("gradient of the raw outputs");
        let g = g.into_data().try_to_vec::<f32>().expect("f32 gradient");
        let fnv = |h: u64, x: f32| (h ^ u64::from(x.to_bits())).wrapping_mul(0x100_0000_01b3);
        let loss = loss.into_scalar();
        (loss, g.iter().fold(fnv(0xcbf2_9ce4_8422_2325, loss), |h, &x| fnv(h, x)))
    }
}

fn cases() -> Vec<Case> {
    let device = device::cpu_training();
    let n = batch_size();
    [
        ("rp", ModelKind::Rp),
        ("ts", ModelKind::Ts),
        ("disney", ModelKind::Disney),
        ("fmbrdf", ModelKind::Fmbrdf),
    ]
    .into_iter()
    .filter(|(name, _)| std::env::var("BRDF_BENCH_MODELS").map_or(true, |m| m.contains(name)))
    .map(|(name, kind)| Case::new(name, kind, n, &device))
    .collect()
}

fn bench(c: &mut Criterion) {
    let cases = cases();
    println!("tensor BRDF forward + backward at batch {}, median (ms):", batch_size());
    for case in &cases {
        for _ in 0..5 {
            case.step();
        }
        let passes = std::env::var("BRDF_BENCH_PASSES").ok().and_then(|s| s.parse().ok());
        let mut t: Vec<f64> = (0..passes.unwrap_or(31))
            .map(|_| {
                let t0 = Instant::now();
                case.step();
                t0.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        t.sort_by(f64::total_cmp);
        let fm = case.name == "fmbrdf";
        let mut tg: Vec<f64> = (0..31)
            .map(|_| {
                let t0 = Instant::now();
                std::hint::black_box(Geometry::new(&case.pairs.0, &case.pairs.1, fm, &case.device));
                t0.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        tg.sort_by(f64::total_cmp);
        println!("  {:<8} geometry {:>6.3} ms", case.name, tg[tg.len() / 2]);
        let (loss, hash) = case.step();
        println!(
            "  {:<8} {:>7.2}   loss {loss:e}, gradient hash {hash:016x}",
            case.name,
            t[t.len() / 2]
        );
    }
    if std::env::var("BRDF_BENCH_QUICK").is_ok_and(|v| v == "1") {
        return;
    }
    let mut group = c.benchmark_group("tensor_brdf");
    group.sample_size(20);
    for case in &cases {
        group.bench_function(case.name, |b| b.iter(|| case.step()));
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
