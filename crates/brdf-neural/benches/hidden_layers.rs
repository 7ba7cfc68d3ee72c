//! A stack of hidden layers, `relu(x W + b)` four times at width 128, with the bias and the ReLU
//! inside the product (`brdf_neural::linear_op::linear_relu`) against the product followed by
//! the ReLU's own pass (`relu(linear(..))`, how every hidden layer ran before): the forward
//! pass alone (evaluation) and a training pass (forward, a loss, backward).
//!
//! `cargo bench -p brdf-neural --bench hidden_layers` runs the criterion groups, then a paired
//! summary: the two forms alternate, one pass each, `BRDF_BENCH_PAIRS` times (default 41), and
//! the summary prints each form's median and the median of the per-pair ratios, which a busy or
//! throttled machine moves far less than the times themselves (a shared 2-core cloud host
//! varied 2x in its gemm rate between runs of a few seconds).
//!
//! Environment: `BRDF_BENCH_BATCH` (default 8192, the default profile's batch);
//! `BRDF_BENCH_PRECISION=f32,bf16` (default `f32`; bf16 only where the CPU has it natively);
//! `BRDF_BENCH_QUICK=1` skips the criterion groups.

use brdf_neural::device;
use brdf_neural::linear_op::{linear, linear_relu, relu};
use brdf_neural::precision::{MatmulPrecision, PrecisionSupport};
use brdf_neural::products::Products;
use burn::tensor::{Device, Distribution, Tensor};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Instant;

const WIDTH: usize = 128;
const LAYERS: usize = 4;

struct Stack {
    x: Tensor<2>,
    weights: Vec<(Tensor<2>, Tensor<1>)>,
    r: Tensor<2>,
}

impl Stack {
    fn new(batch: usize, device: &Device, train: bool) -> Stack {
        let normal = Distribution::Normal(0.0, 0.1);
        let param = |t: Tensor<2>| if train { t.require_grad() } else { t };
        let weights = (0..LAYERS)
            .map(|_| {
                let w = param(Tensor::<2>::random([WIDTH, WIDTH], normal, device));
                let b = Tensor::<1>::random([WIDTH], normal, device);
                (w, if train { b.require_grad() } else { b })
            })
            .collect();
        let x = Tensor::<2>::random([batch, WIDTH], Distribution::Normal(0.0, 1.0), device);
        let r = Tensor::<2>::random([batch, WIDTH], Distribution::Normal(0.0, 1.0), device);
        Stack { x, weights, r }
    }

    fn forward(&self, fused: bool, p: Products) -> Tensor<2> {
        self.weights.iter().fold(self.x.clone(), |h, (w, b)| {
            if fused {
                linear_relu(h, w.clone(), b.clone(), p)
            } else {
                relu(linear(h, w.clone(), Some(b.clone()), p))
            }
        })
    }

    /// One pass: the forward alone, or forward, loss and backward; the result is consumed.
    fn pass(&self, fused: bool, train: bool, p: Products) {
        let y = self.forward(fused, p);
        if train {
            black_box((y * self.r.clone()).sum().backward());
        } else {
            black_box(y.into_data());
        }
    }
}

fn batch() -> usize {
    std::env::var("BRDF_BENCH_BATCH").ok().and_then(|v| v.parse().ok()).unwrap_or(8192)
}

fn precisions() -> Vec<(&'static str, Products)> {
    let names = std::env::var("BRDF_BENCH_PRECISION").unwrap_or_else(|_| "f32".into());
    let mut out = Vec::new();
    for name in names.split(',').map(str::trim) {
        match name {
            "f32" => out.push(("f32", Products::F32)),
            "bf16" if MatmulPrecision::bf16_native() => {
                let p = Products { precision: MatmulPrecision::Bf16, ..Products::F32 };
                out.push(("bf16", p.with_bf16_amx(true)));
            }
            "bf16" => eprintln!("bf16: not native on this CPU, skipped"),
            "f16" if MatmulPrecision::f16_native() => {
                out.push(("f16", Products { precision: MatmulPrecision::F16, ..Products::F32 }))
            }
            "f16" => eprintln!("f16: not native on this CPU, skipped"),
            other => panic!("BRDF_BENCH_PRECISION: unknown precision {other:?}"),
        }
    }
    out
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The paired summary (see the module docs).
fn summary() {
    let pairs: usize =
        std::env::var("BRDF_BENCH_PAIRS").ok().and_then(|v| v.parse().ok()).unwrap_or(41);
    let batch = batch();
    println!("\n{LAYERS} hidden layers of width {WIDTH}, batch {batch}, {pairs} pairs");
    println!("| precision | pass | fused ms | unfused ms | fused / unfused (median of pairs) |");
    println!("| --- | --- | ---: | ---: | ---: |");
    for (name, p) in precisions() {
        for train in [false, true] {
            let device = if train { device::cpu_training() } else { device::cpu() };
            let stack = Stack::new(batch, &device, train);
            stack.pass(true, train, p);
            stack.pass(false, train, p);
            let (mut fused, mut plain, mut ratio) = (vec![], vec![], vec![]);
            for i in 0..pairs {
                let time = |f: bool| {
                    let t = Instant::now();
                    stack.pass(f, train, p);
                    t.elapsed().as_secs_f64() * 1e3
                };
                // Alternate which form goes first, so neither always follows the other.
                let (a, b) = if i % 2 == 0 {
                    let a = time(true);
                    (a, time(false))
                } else {
                    let b = time(false);
                    (time(true), b)
                };
                fused.push(a);
                plain.push(b);
                ratio.push(a / b);
            }
            let pass = if train { "forward + backward" } else { "forward" };
            let (f, u, r) = (median(&mut fused), median(&mut plain), median(&mut ratio));
            println!("| {name} | {pass} | {f:.2} | {u:.2} | {r:.3} |");
        }
    }
}

fn bench(c: &mut Criterion) {
    if std::env::var("BRDF_BENCH_QUICK").as_deref() != Ok("1") {
        let batch = batch();
        for (name, p) in precisions() {
            for train in [false, true] {
                let device = if train { device::cpu_training() } else { device::cpu() };
                let stack = Stack::new(batch, &device, train);
                let pass = if train { "train" } else { "forward" };
                let mut g = c.benchmark_group(format!("hidden_layers_{name}_{pass}"));
                g.sample_size(20);
                g.bench_function("fused", |b| b.iter(|| stack.pass(true, train, p)));
                g.bench_function("unfused", |b| b.iter(|| stack.pass(false, train, p)));
                g.finish();
            }
        }
    }
    summary();
}

criterion_group!(benches, bench);
criterion_main!(benches);
