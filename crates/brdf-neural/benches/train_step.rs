//! One training step (upload excluded: forward, MSE loss on the rendered radiance, backward,
//! Adam) at batch 32768 for Single MLP (Rusinkiewicz + mapping), Enhanced Additive Shared and
//! Disney, with the machine's FP32 matrix-multiply rate measured in the same run.
//!
//! `cargo bench -p brdf-neural --bench train_step` (default backend: flex);
//! `cargo bench -p brdf-neural --features ndarray --bench train_step -- ndarray` for ndarray.
//! Environment: `BRDF_BENCH_BATCH` (default 32768), `BRDF_BENCH_BACKENDS` (default: every
//! backend compiled in, e.g. `flex,ndarray`).
//!
//! Criterion's filter (e.g. `-- single_mlp`) selects the criterion groups only; the summary
//! always times every model. After the criterion groups a summary prints samples/s and the achieved GFLOP/s of each step
//! (matrix-multiply FLOPs of the model: 2 m n k per product, forward 1x and backward 2x),
//! against the matmul rate of a [32768, 128] x [128, 128] product on the same backend.
//!
//! Measured (2-core AMD EPYC with AVX-512, burn 0.22.1, `x86-v4` on; the machine was NOT quiet:
//! load average 4 to 7 from other builds and benches, so absolute figures are 2 to 4 times
//! slower than on a quiet machine and vary by +-30 % between runs). Step time in ms:
//!
//! | model | flex | ndarray | PyTorch 2.15 CPU, 2 threads (same runs) |
//! | --- | ---: | ---: | ---: |
//! | Single MLP (mapping, 114,691 params) | 540-785 | 1,064-1,137 | 833-2,229 (median of 10 steps, 4 runs) |
//! | Enh. Add. Shared | 748-1,533 | 1,658-2,667 | |
//! | Disney | 342-580 | 1,253-1,539 | |
//!
//! flex beat ndarray by 1.4x to 3.7x in every pair of runs. The Single MLP step time over
//! PyTorch's, measured back to back, ranged from 0.3 to 1.4 (mostly below 1) as the load
//! changed: a ratio taken under such load is not a reliable figure. The "matmul GFLOP/s" column is not a peak: under contention the isolated product
//! runs slower than the products inside a step (fractions above 1).

use brdf_neural::device::Backend;
use brdf_neural::mlp::MlpConfig;
use brdf_neural::{BrdfBatch, BrdfModel, ModelConfig, ModelKind, Reciprocity, Samples};
use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use burn::tensor::{Device, Distribution, Tensor};
use criterion::{Criterion, criterion_group, criterion_main};
use std::time::{Duration, Instant};

fn batch_size() -> usize {
    std::env::var("BRDF_BENCH_BATCH").ok().and_then(|s| s.parse().ok()).unwrap_or(32768)
}

fn backends() -> Vec<Backend> {
    match std::env::var("BRDF_BENCH_BACKENDS") {
        Ok(s) => s.split(',').map(|b| Backend::parse(b).expect("backend")).collect(),
        Err(_) => Backend::available().into_iter().filter(|b| *b != Backend::Wgpu).collect(),
    }
}

fn configs() -> Vec<(&'static str, ModelConfig)> {
    let mut single = ModelConfig::new(ModelKind::SingleMlp);
    single.angles.reciprocity = Reciprocity::Mapping;
    let mut shared = ModelConfig::new(ModelKind::AdditiveSharedEnhanced);
    shared.angles.reciprocity = Reciprocity::Mapping;
    vec![
        ("single_mlp", single),
        ("additive_shared_enhanced", shared),
        ("disney", ModelConfig::new(ModelKind::Disney)),
    ]
}

/// Matrix-multiply FLOPs of one training step (forward + backward = 3x forward).
fn step_flops(c: &ModelConfig, batch: usize) -> f64 {
    let mlp_macs = |m: &MlpConfig| m.param_count() as f64; // one MAC per weight (biases ~0.5 %)
    3.0 * 2.0 * batch as f64 * c.mlp_configs().iter().map(mlp_macs).sum::<f64>()
}

struct Step {
    model: Option<BrdfModel>,
    optim: ModuleOptimizer,
    batch: BrdfBatch,
    weight: Tensor<2>,
    target: Tensor<2>,
    device: Device,
}

impl Step {
    fn new(c: &ModelConfig, device: &Device, n: usize) -> Self {
        device.seed(1);
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
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
        let spatial: Vec<f32> = (0..n * c.spatial_dim).map(|_| 2.0 * uniform() - 1.0).collect();
        let batch = c.batch(&Samples { spatial: &spatial, l: &l, v: &v }, None, device).unwrap();
        let weight = Tensor::random([n, 1], Distribution::Uniform(0.0, 3.0), device);
        let target = Tensor::random([n, 3], Distribution::Uniform(0.0, 1.0), device);
        Self {
            model: Some(c.init(device).unwrap()),
            optim: AdamConfig::new().init(),
            batch,
            weight,
            target,
            device: device.clone(),
        }
    }

    /// Forward, radiance L = f * (E shadow cos), MSE, backward, Adam; waits for the device.
    fn run(&mut self) {
        let model = self.model.take().expect("model");
        let out = model.forward(&self.batch);
        let loss = (out.f * self.weight.clone() - self.target.clone()).square().mean();
        let grads = GradientsParams::from_grads(loss.backward(), &model);
        let model = self.optim.step(1e-4, model, grads);
        self.device.sync().expect("sync");
        self.model = Some(model);
    }
}

/// FP32 matmul rate (GFLOP/s) of [n, 128] x [128, 128] on `device`.
fn matmul_gflops(device: &Device, n: usize) -> f64 {
    let a = Tensor::<2>::random([n, 128], Distribution::Uniform(-1.0, 1.0), device);
    let b = Tensor::<2>::random([128, 128], Distribution::Uniform(-1.0, 1.0), device);
    let run = || {
        let c = a.clone().matmul(b.clone());
        device.sync().expect("sync");
        drop(c);
    };
    run();
    let reps = 20;
    let t = Instant::now();
    for _ in 0..reps {
        run();
    }
    let secs = t.elapsed().as_secs_f64() / reps as f64;
    2.0 * n as f64 * 128.0 * 128.0 / secs / 1e9
}

fn bench(cr: &mut Criterion) {
    let n = batch_size();
    let mut summary = Vec::new();
    for backend in backends() {
        let device = backend.training_device().expect("backend built");
        let peak = matmul_gflops(&device.clone().inner(), n);
        let mut group = cr.benchmark_group(format!("train_step_{backend:?}").to_lowercase());
        group.sample_size(10).measurement_time(Duration::from_secs(20));
        for (name, c) in configs() {
            let mut step = Step::new(&c, &device, n);
            step.run();
            group.bench_function(name, |b| b.iter(|| step.run()));
            // A direct timing for the summary (criterion's estimate is in its report).
            let reps = 5;
            let t = Instant::now();
            for _ in 0..reps {
                step.run();
            }
            let secs = t.elapsed().as_secs_f64() / reps as f64;
            summary.push((backend, name, secs, step_flops(&c, n) / secs / 1e9, peak));
        }
        group.finish();
    }
    println!(
        "\nbatch {n}, threads: {} ({:?})",
        rayon_threads(),
        std::env::var("RAYON_NUM_THREADS").ok()
    );
    println!("| backend | model | step ms | samples/s | GFLOP/s | matmul GFLOP/s | fraction |");
    println!("| --- | --- | ---: | ---: | ---: | ---: | ---: |");
    for (b, name, secs, gf, peak) in summary {
        println!(
            "| {b:?} | {name} | {:.1} | {:.0} | {gf:.1} | {peak:.1} | {:.2} |",
            secs * 1e3,
            n as f64 / secs,
            gf / peak
        );
    }
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

criterion_group!(benches, bench);
criterion_main!(benches);
