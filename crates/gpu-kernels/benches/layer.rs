//! One 128-wide hidden layer of a training step on the first device of a runtime: the forward
//! product (bias and ReLU fused), the input gradient and the weight gradient (split-K), on each
//! variant back to back in the same run: the default (64-wide tiles, launched unchecked), the
//! same launched checked (CubeCL's index checks and wgpu's loop counters, see
//! `gpu_kernels::checks`), 128-wide tiles, 64- and 128-wide tiles read from shared memory four
//! floats at a time, and, where the device has bf16 tensor cores, the bf16 products. Every
//! timed call ends by waiting for the device.
//!
//! `cargo bench -p gpu-kernels --features wgpu --bench layer`. Environment:
//! `GPU_KERNELS_BENCH_ROWS` (default 8192: Mesa's lavapipe runs on the CPU; 32768 is the
//! training step's batch on a GPU); `GPU_KERNELS_RUNTIME=cuda` (built with `--features
//! wgpu,cuda`) for CubeCL's CUDA runtime instead of wgpu. A summary line per operation and
//! variant gives GFLOP/s (2 m n k) and the time as a ratio of the default's.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use cubecl::prelude::*;
use gpu_kernels::checks;
use gpu_kernels::linear::{self, Matrix};
use gpu_kernels::plan::Precision::{self, F32};
use gpu_kernels::plan::{Tiling, Tuning};
use std::time::Instant;

const WIDTH: u32 = 128;

fn rows() -> u32 {
    std::env::var("GPU_KERNELS_BENCH_ROWS").ok().and_then(|s| s.parse().ok()).unwrap_or(8_192)
}

fn values(len: usize, salt: usize) -> Vec<f32> {
    (0..len).map(|i| ((i * 37 + salt) % 101) as f32 / 50.0 - 1.0).collect()
}

fn wait(client: &Client) {
    cubecl::future::block_on(client.sync()).expect("the device is lost");
}

type Op = fn(&Client, &Matrix, &Matrix, &Matrix, &Handle, (Precision, Tuning)) -> Matrix;
type Handle = cubecl::server::Handle;

const OPS: [(&str, Op); 3] = [
    ("forward", |c, x, w, _, b, (p, t)| linear::forward(c, x, w, Some(b), true, p, t).unwrap()),
    ("input gradient", |c, _, w, dy, _, (p, t)| linear::x_backward(c, w, dy, p, t).unwrap()),
    ("weight gradient", |c, x, _, dy, _, (p, t)| linear::weight_backward(c, x, dy, p, t).unwrap()),
];

/// The runtime: `GPU_KERNELS_RUNTIME=cuda` (with the `cuda` feature), else wgpu.
fn client() -> Client {
    match std::env::var("GPU_KERNELS_RUNTIME").as_deref() {
        Ok("cuda") if cfg!(feature = "cuda") => cubecl::Device::Cuda(Default::default()).client(),
        Ok("wgpu") | Err(_) => cubecl::Device::Wgpu(Default::default()).client(),
        Ok(other) => {
            panic!("GPU_KERNELS_RUNTIME={other:?}: expected wgpu, or cuda when built with it")
        }
    }
}

fn layer(c: &mut Criterion) {
    let client = client();
    let rows = rows();
    let x = Matrix::upload(&client, &values((rows * WIDTH) as usize, 1), rows, WIDTH).unwrap();
    let w = Matrix::upload(&client, &values((WIDTH * WIDTH) as usize, 2), WIDTH, WIDTH).unwrap();
    let b = Matrix::upload(&client, &values(WIDTH as usize, 3), 1, WIDTH).unwrap();
    let dy = Matrix::upload(&client, &values((rows * WIDTH) as usize, 4), rows, WIDTH).unwrap();
    let flop = 2.0 * rows as f64 * WIDTH as f64 * WIDTH as f64;
    let mut group = c.benchmark_group(format!("layer_{rows}x{WIDTH}x{WIDTH}"));
    group.sample_size(10);
    let mut variants = vec![
        ("64", Tiling::T64, false, F32),
        ("64 checked", Tiling::T64, true, F32),
        ("128", Tiling::T128, false, F32),
        ("64v", Tiling::T64V, false, F32),
        ("128v", Tiling::T128V, false, F32),
    ];
    if linear::bf16_supported(&client) {
        variants.push(("bf16", Tiling::T64, false, Precision::Bf16));
    } else {
        eprintln!("no bf16 tensor cores on this device: the bf16 variant is left out");
    }
    let mut summary = Vec::new();
    for (name, op) in OPS {
        let mut default_seconds = None;
        for &(label, tiling, checked, precision) in &variants {
            checks::set_checked(checked);
            let precision = (precision, Tuning { tiling, split_len: None });
            // Compiles the kernel outside the timing.
            op(&client, &x, &w, &dy, &b.handle, precision);
            wait(&client);
            group.bench_function(BenchmarkId::new(name, label), |bench| {
                bench.iter(|| {
                    op(&client, &x, &w, &dy, &b.handle, precision);
                    wait(&client);
                })
            });
            let reps = 5;
            let t = Instant::now();
            for _ in 0..reps {
                op(&client, &x, &w, &dy, &b.handle, precision);
            }
            wait(&client);
            let seconds = t.elapsed().as_secs_f64() / reps as f64;
            let base = *default_seconds.get_or_insert(seconds);
            summary.push(format!(
                "{name}, {label}: {:.3} ms, {:.1} GFLOP/s, {:.2} x the default's time",
                1e3 * seconds,
                flop / seconds / 1e9,
                seconds / base,
            ));
        }
    }
    checks::set_checked(false);
    group.finish();
    for line in summary {
        eprintln!("{line}");
    }
}

criterion_group!(benches, layer);
criterion_main!(benches);
