//! One training step (upload excluded: forward, MSE loss on the rendered radiance, backward,
//! Adam) at batch 32768 for Single MLP (Rusinkiewicz + mapping), Enhanced Additive Shared and
//! Disney, with the machine's FP32 matrix-multiply rate measured in the same run.
//!
//! `cargo bench -p brdf-neural --bench train_step` (default backend: flex);
//! `cargo bench -p brdf-neural --features ndarray --bench train_step` adds ndarray.
//! Environment:
//! - `BRDF_BENCH_BATCH` (default 32768);
//! - `BRDF_BENCH_BACKENDS` (default: every CPU backend compiled in, e.g. `flex,ndarray`);
//! - `BRDF_BENCH_QUICK=1` skips the criterion groups (summary only, about a minute);
//! - `BRDF_BENCH_ALL_MODELS=1` adds the six other model kinds to the summary (their default
//!   configurations; `docs/reproduce.md` sizes the `full` profile from these step times);
//! - `BRDF_BENCH_PYTORCH=python3` (a Python with torch) also runs `benches/pytorch_step.py`,
//!   the same step in PyTorch for every model timed (`--kind`, the model rebuilt from
//!   `neural_brdfs.reference_torch` in the same default configuration) on the same number of
//!   threads (on CUDA for the GPU backends), back to back with ours: three rounds of 10 steps
//!   each side after warm-up (`BRDF_BENCH_PYTORCH_ROUNDS` sets another count), and prints the
//!   ratios;
//! - `BRDF_BENCH_MODELS=single_mlp,disney` times only these models (names as in the summary:
//!   each kind's `config_name`);
//!   `BRDF_BENCH_RATES=0` skips the gemm and product rates and prints nothing (for `perf`);
//! - `BRDF_KEEP_MALLOC=0` turns the host-memory policy off (`brdf_neural::host_memory`), and
//!   `CPU_KERNELS_AMX=0` keeps the bf16 products off the AMX tiles, as on the command line;
//! - `BRDF_BENCH_PRECISION=f32,bf16` (default `f32`) also times every step with bf16 matrix
//!   products ([`brdf_neural::precision`], flex and cuda: tensor cores), with the PyTorch
//!   comparison under bf16 autocast, and the flex products themselves in both precisions;
//! - `BRDF_BENCH_SPLIT=1,64` times every step with its linear layers' batch split into these
//!   numbers of parts ([`brdf_neural::batch_split`]; default: what the trainer uses, 1 on the
//!   CPU and [`brdf_neural::products::gpu_parts`] on a GPU), and, on a GPU backend, prints
//!   the times of one 128-wide layer's three products alone (forward, input gradient, weight
//!   gradient plain and split).
//!
//! Criterion's filter (e.g. `-- single_mlp`) selects the criterion groups only; the summary
//! always times every model: median step time of 7, samples/s, and the achieved GFLOP/s
//! (matrix-multiply FLOPs of the model: 2 m n k per product, forward 1x and backward 2x)
//! against the machine's FP32 gemm rate (the `gemm` crate flex uses, all threads, into
//! preallocated buffers, best of 11): 2048^3, and the step's dominant [n, 128] x [128, 128].
//!
//! Dated figures, the first (2026-11-21, 2-core AMD EPYC) included, are in benches/README.md.

use brdf_neural::device::Backend;
use brdf_neural::device::BackendDevice;
use brdf_neural::gpu_linear::{GpuLinear, GpuTuning};
use brdf_neural::mlp::MlpConfig;
use brdf_neural::precision::MatmulPrecision;
use brdf_neural::precision::PrecisionSupport;
use brdf_neural::products::Products;
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
        Ok(s) => {
            s.split(',').map(|b| brdf_neural::device::parse_backend(b).expect("backend")).collect()
        }
        Err(_) => brdf_neural::device::available().into_iter().filter(|b| !b.is_gpu()).collect(),
    }
}

fn configs() -> Vec<(&'static str, ModelConfig)> {
    let mut single = ModelConfig::new(ModelKind::SingleMlp);
    single.angles.reciprocity = Reciprocity::Mapping;
    let mut shared = ModelConfig::new(ModelKind::AdditiveSharedEnhanced);
    shared.angles.reciprocity = Reciprocity::Mapping;
    let mut out = vec![
        ("single_mlp", single),
        ("additive_shared_enhanced", shared),
        ("disney", ModelConfig::new(ModelKind::Disney)),
    ];
    if std::env::var("BRDF_BENCH_ALL_MODELS").is_ok_and(|v| v == "1") {
        // Every other kind in its default configuration (what a sweep trains).
        for kind in ModelKind::ALL {
            if ![ModelKind::SingleMlp, ModelKind::AdditiveSharedEnhanced, ModelKind::Disney]
                .contains(&kind)
            {
                out.push((kind.config_name(), ModelConfig::new(kind)));
            }
        }
    }
    if let Ok(only) = std::env::var("BRDF_BENCH_MODELS") {
        out.retain(|(name, _)| only.split(',').any(|m| m.trim() == *name));
    }
    out
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
    fn new(
        c: &ModelConfig,
        backend: Backend,
        (precision, split): (MatmulPrecision, usize),
        n: usize,
    ) -> Self {
        let device = &backend.training_device().expect("backend built");
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
        precision.check(backend).expect("precision on this backend");
        let batch =
            BrdfBatch::new(c, &Samples { spatial: &spatial, l: &l, v: &v }, None, device).unwrap();
        let products = Products { precision, parts: split, ..Products::F32 };
        let products = products.with_bf16_amx(bench_bf16_amx()).with_gpu(bench_gpu_tuning());
        let batch = batch.with_products(products);
        let weight = Tensor::random([n, 1], Distribution::Uniform(0.0, 3.0), device);
        let target = Tensor::random([n, 3], Distribution::Uniform(0.0, 1.0), device);
        Self {
            model: Some(BrdfModel::init(c, device).unwrap()),
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

/// The machine's FP32 matrix-multiply rates in GFLOP/s: the `gemm` crate (flex's kernels) into
/// preallocated buffers, so allocation and copies are not part of it; best of 11.
struct GemmRates {
    /// 2048 x 2048 x 2048, all threads.
    square: f64,
    /// The step's forward product [n, 128] x [128, 128], all threads.
    forward: f64,
    /// The weight gradient X^T dY, [128, n] (transposed view) x [n, 128], all threads: the
    /// reduction runs over the batch.
    weight_grad: f64,
    /// The same product split over the batch in two halves, one thread each, then summed.
    weight_grad_split: f64,
}

/// `c = a b` for `a` [m, k] with strides (`a_rs`, `a_cs`), `b` [k, p] row-major.
///
/// # Safety
/// The buffers must hold the elements the strides address.
#[allow(clippy::too_many_arguments)]
unsafe fn gemm_into(
    c: &mut [f32],
    a: &[f32],
    b: &[f32],
    (m, k, p): (usize, usize, usize),
    (a_rs, a_cs): (isize, isize),
    threads: gemm::Parallelism,
) {
    // SAFETY: the caller's contract.
    unsafe {
        gemm::gemm(
            m,
            p,
            k,
            c.as_mut_ptr(),
            1,
            p as isize,
            false,
            a.as_ptr(),
            a_cs,
            a_rs,
            b.as_ptr(),
            1,
            p as isize,
            0.0,
            1.0,
            false,
            false,
            false,
            threads,
        );
    }
}

fn machine_gemm_rates(n: usize) -> GemmRates {
    let fill = |len: usize, s: usize| -> Vec<f32> {
        (0..len).map(|i| ((i * s % 13) as f32 - 6.0) / 7.0).collect()
    };
    let best_of = |flops: f64, f: &mut dyn FnMut()| {
        let mut best = f64::INFINITY;
        for _ in 0..11 {
            let t = Instant::now();
            f();
            best = best.min(t.elapsed().as_secs_f64());
        }
        flops / best / 1e9
    };
    let all = gemm::Parallelism::Rayon(0);
    let plain = |m: usize, k: usize, p: usize| {
        let (a, b, mut c) = (fill(m * k, 7), fill(k * p, 5), vec![0f32; m * p]);
        // SAFETY: row-major buffers of exactly m x k, k x p and m x p elements.
        best_of(2.0 * (m * k * p) as f64, &mut || unsafe {
            gemm_into(&mut c, &a, &b, (m, k, p), (k as isize, 1), all)
        })
    };
    // X [n, 128] row-major, dY [n, 128]: dW = X^T dY, X^T read through strides (1, 128).
    let (x, dy) = (fill(n * 128, 7), fill(n * 128, 5));
    let mut dw = vec![0f32; 128 * 128];
    let flops = 2.0 * (128 * n * 128) as f64;
    // SAFETY: x and dy hold n x 128 elements each, dw 128 x 128.
    let weight_grad = best_of(flops, &mut || unsafe {
        gemm_into(&mut dw, &x, &dy, (128, n, 128), (1, 128), all)
    });
    let half = n / 2;
    let mut other = vec![0f32; 128 * 128];
    let weight_grad_split = best_of(flops, &mut || {
        let (x0, x1) = x.split_at(half * 128);
        let (d0, d1) = dy.split_at(half * 128);
        let none = gemm::Parallelism::None;
        rayon::join(
            // SAFETY: each half holds its rows x 128 elements.
            || unsafe { gemm_into(&mut dw, x0, d0, (128, half, 128), (1, 128), none) },
            || unsafe { gemm_into(&mut other, x1, d1, (128, n - half, 128), (1, 128), none) },
        );
        for (a, b) in dw.iter_mut().zip(&other) {
            *a += b;
        }
    });
    std::hint::black_box((&dw, &other));
    GemmRates {
        square: plain(2048, 2048, 2048),
        forward: plain(n, 128, 128),
        weight_grad,
        weight_grad_split,
    }
}

/// Median step time in seconds over `reps` steps.
fn median_step(step: &mut Step, reps: usize) -> f64 {
    let mut times: Vec<f64> = (0..reps)
        .map(|_| {
            let t = Instant::now();
            step.run();
            t.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[reps / 2]
}

/// Median step time (seconds) of `benches/pytorch_step.py` run by `python`, or why not. A GPU
/// backend is compared with PyTorch on CUDA (f32, no TF32), a CPU backend with PyTorch on the
/// CPU on as many threads.
fn pytorch_step(
    python: &str,
    (backend, kind): (Backend, &str),
    n: usize,
    reps: usize,
    bf16: bool,
) -> Result<f64, String> {
    // The script beside the sources this bench was built from, else (a bench binary carried to
    // another machine and run from a checkout's root) the checkout's own.
    let built = concat!(env!("CARGO_MANIFEST_DIR"), "/../../benches/pytorch_step.py");
    let script =
        if std::path::Path::new(built).exists() { built } else { "benches/pytorch_step.py" };
    let threads = rayon_threads().to_string();
    let device = match backend {
        Backend::Wgpu | Backend::Cuda => "cuda",
        Backend::Flex | Backend::NdArray => "cpu",
    };
    let out = std::process::Command::new(python)
        .args([script, "--kind", kind, "--batch", &n.to_string(), "--threads", &threads])
        .args(["--reps", &reps.to_string(), "--machine", "--device", device])
        .args(if bf16 { &["--bf16"][..] } else { &[] })
        .output()
        .map_err(|e| format!("{python}: {e}"))?;
    let text = String::from_utf8_lossy(&out.stdout);
    text.lines()
        .find_map(|l| l.strip_prefix("median_ms "))
        .and_then(|v| v.trim().parse::<f64>().ok())
        .map(|ms| ms / 1e3)
        .ok_or_else(|| format!("{script}: {}", String::from_utf8_lossy(&out.stderr).trim()))
}

/// `CPU_KERNELS_AMX=0` keeps the bf16 products off the AMX tiles (as the command line's
/// setting does, run-format's `ComputeSettings::bf16_amx`).
fn bench_bf16_amx() -> bool {
    std::env::var("CPU_KERNELS_AMX").map_or(true, |v| v.trim() != "0")
}

/// The GPU's linear layers as `NEURAL_BRDF_GPU_LINEAR`, `_SPLIT_LEN`, `_TILE` and `_CHECKED`
/// say (model-spec's `GpuTuning`, as on the command line).
fn bench_gpu_tuning() -> GpuTuning {
    let mut tuning = GpuTuning::default();
    for (var, _) in GpuTuning::VARIABLES {
        if let Ok(value) = std::env::var(var) {
            tuning = tuning.with_override(var, &value).expect("a GPU setting");
        }
    }
    tuning
}

fn bench(cr: &mut Criterion) {
    if std::env::var("BRDF_KEEP_MALLOC").is_ok_and(|v| v.trim() == "0") {
        brdf_neural::host_memory::leave_allocator_alone();
    }
    brdf_neural::gpu_linear::launch_checked(bench_gpu_tuning().checked);
    let n = batch_size();
    let quick = std::env::var("BRDF_BENCH_QUICK").is_ok_and(|v| v != "0");
    let mut summary = Vec::new();
    let mut versus_pytorch = Vec::new();
    for (backend, precision, split) in backends_and_precisions(n) {
        let label = format!("train_step_{backend:?}_{}", precision.name()).to_lowercase();
        let label = if split > 1 { format!("{label}_split{split}") } else { label };
        let mut group = cr.benchmark_group(label);
        group.sample_size(10).measurement_time(Duration::from_secs(20));
        for (name, c) in configs() {
            let mut step = Step::new(&c, backend, (precision, split), n);
            step.run();
            if !quick {
                group.bench_function(name, |b| b.iter(|| step.run()));
            }
            // A direct timing for the summary (criterion's estimate is in its report).
            let secs = median_step(&mut step, 7);
            let gflops = step_flops(&c, n) / secs / 1e9;
            summary.push((backend, precision, split, name, secs, gflops));
            if split == default_split(backend, n)
                && let Ok(python) = std::env::var("BRDF_BENCH_PYTORCH")
            {
                // Back to back, three rounds: ours then PyTorch's, medians of 10 steps each.
                // Each side warms up first (PyTorch's script runs 3 untimed steps); bf16 is
                // compared with PyTorch's bf16 autocast.
                let bf16 = precision == MatmulPrecision::Bf16;
                let rounds = std::env::var("BRDF_BENCH_PYTORCH_ROUNDS")
                    .ok()
                    .map(|r| r.parse::<usize>().expect("BRDF_BENCH_PYTORCH_ROUNDS: a number"))
                    .unwrap_or(3);
                for _ in 0..rounds {
                    median_step(&mut step, 3);
                    let ours = median_step(&mut step, 10);
                    // A bf16 round also times PyTorch's f32 step right after its autocast one:
                    // the target compares our step with PyTorch's f32 step.
                    let side = (backend, name);
                    let theirs = pytorch_step(&python, side, n, 10, bf16).and_then(|t| {
                        let f32_step =
                            if bf16 { pytorch_step(&python, side, n, 10, false)? } else { t };
                        Ok((t, f32_step))
                    });
                    match theirs {
                        Ok((theirs, theirs_f32)) => versus_pytorch
                            .push((backend, precision, split, name, ours, theirs, theirs_f32)),
                        Err(e) => {
                            eprintln!("PyTorch baseline not run: {e}");
                            break;
                        }
                    }
                }
            }
        }
        group.finish();
    }
    for backend in backends().into_iter().filter(|b| b.is_gpu()) {
        layer_products(backend, n);
    }
    if std::env::var("BRDF_BENCH_RATES").is_ok_and(|v| v == "0") {
        // Steps only (a profile of the steps without the rate measurements).
        return;
    }
    let rates = machine_gemm_rates(n);
    let square = rates.square;
    println!(
        "\nbatch {n}, threads: {} (RAYON_NUM_THREADS {:?}), host-memory policy active: {}",
        rayon_threads(),
        std::env::var("RAYON_NUM_THREADS").ok(),
        brdf_neural::host_memory::is_active()
    );
    println!(
        "machine FP32 gemm (gemm crate, preallocated): 2048^3 {square:.1} GFLOP/s, \
         [{n}, 128] x [128, 128] {:.1} GFLOP/s, weight gradient [128, {n}]^T x [{n}, 128] \
         {:.1} GFLOP/s (split over the batch, one thread a half: {:.1} GFLOP/s)",
        rates.forward, rates.weight_grad, rates.weight_grad_split
    );
    if precisions().contains(&MatmulPrecision::Bf16) && backends().contains(&Backend::Flex) {
        let r = flex_product_rates(n, bench_bf16_amx());
        println!(
            "flex products through burn (allocation included), f32 -> bf16 GFLOP/s: \
             [{n}, 128] x [128, 128] {:.1} -> {:.1} ({:.2}x); weight gradient {:.1} -> {:.1} \
             ({:.2}x); input gradient [{n}, 128] x [128, 128]^T {:.1} -> {:.1} ({:.2}x) \
             (bf16 native: {}, on AMX tiles: {})",
            r[0].0,
            r[0].1,
            r[0].1 / r[0].0,
            r[1].0,
            r[1].1,
            r[1].1 / r[1].0,
            r[2].0,
            r[2].1,
            r[2].1 / r[2].0,
            MatmulPrecision::bf16_native(),
            MatmulPrecision::bf16_on_amx()
        );
        if MatmulPrecision::bf16_on_amx() {
            let r = flex_product_rates(n, false);
            println!(
                "the same bf16 products on the AVX-512 kernel instead of AMX, GFLOP/s: forward \
                 {:.1}, weight gradient {:.1}, input gradient {:.1}",
                r[0].1, r[1].1, r[2].1
            );
        }
    }
    println!(
        "| backend | precision | split | model | step ms | samples/s | GFLOP/s | fraction of the \
         CPU's 2048^3 gemm |"
    );
    println!("| --- | --- | ---: | --- | ---: | ---: | ---: | ---: |");
    for (b, p, split, name, secs, gf) in summary {
        println!(
            "| {b:?} | {} | {split} | {name} | {:.1} | {:.0} | {gf:.1} | {:.2} |",
            p.name(),
            secs * 1e3,
            n as f64 / secs,
            gf / square
        );
    }
    if backends().into_iter().any(|b| b.is_gpu()) {
        // On a GPU whose layers run on gpu-kernels, `batch_split` leaves the layers whole.
        let layers = match bench_gpu_tuning().linear {
            GpuLinear::Ours => {
                "on gpu-kernels, whose weight gradients split inside their kernel: the GPU \
                 rows' split column does not apply"
            }
            GpuLinear::Burn => "on burn's kernels, split by the trainer as the column says",
        };
        println!("(the GPU rows' linear layers ran {layers})");
    }
    if !versus_pytorch.is_empty() {
        println!("\nThe step, back to back with PyTorch (medians of 10 steps; bf16 against");
        println!("PyTorch's bf16 autocast, then against PyTorch's f32 step timed right after it):");
        println!(
            "| backend | precision | split | model | ours ms | PyTorch ms | ours / PyTorch | \
             PyTorch f32 ms | ours / PyTorch f32 |"
        );
        println!("| --- | --- | ---: | --- | ---: | ---: | ---: | ---: | ---: |");
        for (b, p, split, name, ours, theirs, theirs_f32) in versus_pytorch {
            let (o, t, t32) = (ours * 1e3, theirs * 1e3, theirs_f32 * 1e3);
            let (ratio, ratio32) = (ours / theirs, ours / theirs_f32);
            println!(
                "| {b:?} | {} | {split} | {name} | {o:.1} | {t:.1} | {ratio:.3} | {t32:.1} | \
                 {ratio32:.3} |",
                p.name()
            );
        }
    }
}

fn precisions() -> Vec<MatmulPrecision> {
    let spec = std::env::var("BRDF_BENCH_PRECISION").unwrap_or_else(|_| "f32".into());
    spec.split(',')
        .map(|p| match p.trim() {
            "f32" => MatmulPrecision::F32,
            "bf16" => MatmulPrecision::Bf16,
            "f16" => MatmulPrecision::F16,
            other => panic!("BRDF_BENCH_PRECISION: unknown precision {other:?} (f32, bf16, f16)"),
        })
        .collect()
}

/// Every backend with every precision it implements (bf16: flex and cuda) and every split.
fn backends_and_precisions(n: usize) -> Vec<(Backend, MatmulPrecision, usize)> {
    let mut out = Vec::new();
    for b in backends() {
        for p in precisions() {
            if p.check(b).is_ok() {
                out.extend(splits(b, n).into_iter().map(|s| (b, p, s)));
            }
        }
    }
    out
}

/// The batch splits to time on `backend` (`BRDF_BENCH_SPLIT`, else the trainer's).
fn splits(backend: Backend, n: usize) -> Vec<usize> {
    match std::env::var("BRDF_BENCH_SPLIT") {
        Ok(s) => {
            s.split(',').map(|p| p.trim().parse().expect("BRDF_BENCH_SPLIT: a number")).collect()
        }
        Err(_) => vec![default_split(backend, n)],
    }
}

/// The split the trainer uses on `backend` for a batch of `n`.
fn default_split(backend: Backend, n: usize) -> usize {
    if backend.is_gpu() { brdf_neural::products::gpu_parts(n) } else { 1 }
}

/// Prints the times of one 128-wide layer's products at batch `n` on `backend` (a GPU):
/// forward X W, input gradient dY Wᵀ, weight gradient Xᵀ dY plain and split over the batch
/// into parts (batched products, then the sum over the parts); medians of 11 after 3 warm-up
/// runs (autotune), each run waited for.
fn layer_products(backend: Backend, n: usize) {
    let device = backend.device().expect("backend built");
    let x: Tensor<2> = Tensor::random([n, 128], Distribution::Uniform(-1.0, 1.0), &device);
    let dy: Tensor<2> = Tensor::random([n, 128], Distribution::Uniform(-1.0, 1.0), &device);
    let w: Tensor<2> = Tensor::random([128, 128], Distribution::Uniform(-1.0, 1.0), &device);
    let time = |f: &dyn Fn() -> Tensor<2>| time_on(&device, f);
    let flops = 2.0 * (n * 128 * 128) as f64;
    let mut rows = vec![
        ("forward X W".to_string(), time(&|| x.clone().matmul(w.clone()))),
        ("input gradient dY W^T".into(), time(&|| dy.clone().matmul(w.clone().transpose()))),
        ("weight gradient X^T dY".into(), time(&|| x.clone().transpose().matmul(dy.clone()))),
    ];
    for parts in [16, 64, 256].into_iter().filter(|p| n.is_multiple_of(*p)) {
        let split = |t: &Tensor<2>| t.clone().reshape([parts, n / parts, 128]);
        let f = || split(&x).swap_dims(1, 2).matmul(split(&dy)).sum_dim(0).reshape([128, 128]);
        rows.push((format!("weight gradient, {parts} parts"), time(&f)));
    }
    // One whole layer as the models run it (`linear_op`: burn's kernels or gpu-kernels, as
    // NEURAL_BRDF_GPU_LINEAR says), forward alone, then forward and backward (dX, dW, db: the
    // three products' FLOPs, so its GFLOP/s counts 3 products).
    let train = backend.training_device().expect("backend built");
    let random = |shape: [usize; 2]| {
        Tensor::<2>::random(shape, Distribution::Uniform(-1.0, 1.0), &train).require_grad()
    };
    let (xt, wt) = (random([n, 128]), random([128, 128]));
    let bt = Tensor::<1>::random([128], Distribution::Uniform(-1.0, 1.0), &train).require_grad();
    let layer = || {
        let f32 = Products::F32.with_gpu(bench_gpu_tuning());
        brdf_neural::linear_op::linear(xt.clone(), wt.clone(), Some(bt.clone()), f32)
    };
    let ours = brdf_neural::linear_op::uses_gpu_kernels(&xt, bench_gpu_tuning().linear);
    let which = if ours { "gpu-kernels" } else { "burn" };
    rows.push((format!("layer x W + b ({which})"), time_on(&train, &layer)));
    let backward = || {
        let grads = layer().sum().backward();
        let (dx, dw) = (xt.grad(&grads).expect("dX"), wt.grad(&grads).expect("dW"));
        let db = bt.grad(&grads).expect("db");
        // One output that needs all three (so none is skipped), broadcast over dW's rows.
        dw + db.unsqueeze::<2>() + dx.slice([0..1, 0..128])
    };
    let layer_fb = time_on(&train, &backward);
    println!("\n{backend:?}: one layer's products at batch {n}, 128 x 128 (medians of 11)");
    println!("| product | ms | GFLOP/s |");
    println!("| --- | ---: | ---: |");
    for (name, secs) in rows {
        println!("| {name} | {:.3} | {:.0} |", secs * 1e3, flops / secs / 1e9);
    }
    println!(
        "| layer forward + backward ({which}) | {:.3} | {:.0} |",
        layer_fb * 1e3,
        3.0 * flops / layer_fb / 1e9
    );
}

/// The median of 11 timed calls of `f` (after 3 untimed), each waited for on `device`.
fn time_on(device: &Device, f: &dyn Fn() -> Tensor<2>) -> f64 {
    let mut times: Vec<f64> = (0..14)
        .map(|_| {
            let t = Instant::now();
            let out = f();
            device.sync().expect("sync");
            std::hint::black_box(out);
            t.elapsed().as_secs_f64()
        })
        .skip(3)
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// GFLOP/s (f32, bf16) of flex's products through burn tensors, best of 11: the forward
/// [n, 128] x [128, 128], the weight gradient X^T dY and the input gradient dY W^T.
fn flex_product_rates(n: usize, bf16_amx: bool) -> [(f64, f64); 3] {
    let device = Backend::Flex.training_device().expect("flex");
    let x: Tensor<2> = Tensor::random([n, 128], Distribution::Uniform(-1.0, 1.0), &device);
    let dy: Tensor<2> = Tensor::random([n, 128], Distribution::Uniform(-1.0, 1.0), &device);
    let w: Tensor<2> = Tensor::random([128, 128], Distribution::Uniform(-1.0, 1.0), &device);
    let flops = 2.0 * (n * 128 * 128) as f64;
    let rate = |precision: MatmulPrecision, (a, b): (&Tensor<2>, &Tensor<2>)| {
        precision.check(Backend::Flex).expect("flex");
        let p = Products { precision, ..Products::F32 }.with_bf16_amx(bf16_amx);
        let mut best = f64::INFINITY;
        for _ in 0..11 {
            let t = Instant::now();
            std::hint::black_box(brdf_neural::linear_op::linear(a.clone(), b.clone(), None, p));
            best = best.min(t.elapsed().as_secs_f64());
        }
        flops / best / 1e9
    };
    let (xt, wt) = (x.clone().transpose(), w.clone().transpose());
    let products = [(&x, &w), (&xt, &dy), (&dy, &wt)];
    products.map(|ab| (rate(MatmulPrecision::F32, ab), rate(MatmulPrecision::Bf16, ab)))
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

criterion_group!(benches, bench);
criterion_main!(benches);
