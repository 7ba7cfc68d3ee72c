//! The weight-gradient products of a Single MLP training step, `Xᵀ dY` with the batch as the
//! inner dimension, through [`cpu_kernels::matmul`] (split over k, see `split_k`) against the
//! same product with gemm's own parallelism over the output ([`cpu_kernels::gemm_f32::gemm`]),
//! in the same run.
//!
//! `cargo bench -p cpu-kernels --bench weight_gradient`; `RAYON_NUM_THREADS=1` gives one
//! thread's rate, the rate a block of the split reaches on every core of a many-core machine
//! (each block is one single-threaded gemm). Environment: `CPU_KERNELS_BENCH_BATCH` (default
//! 32768 and 8192). A summary line per shape gives GFLOP/s (2 m n k per product), and a second
//! line the rates of the product cut into 8, 16, 32 and 64 blocks of k (4,096- to 512-long at
//! 2^15), whatever the kernels' own choice. Before them, the input gradients `dY Wᵀ` of the
//! same layers through gemm's own threading against blocks of rows (the kernels' path).

use cpu_kernels::{Epilogue, MatRef, Precision};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Instant;

/// The Single MLP's weight-gradient shapes (rows of Wᵀ = the layer's inputs, columns = its
/// outputs): 188 inputs, width 128, the input joined again at layer 3, 3 outputs.
const LAYERS: [(usize, usize); 4] = [(188, 128), (128, 128), (316, 128), (128, 3)];

fn batches() -> Vec<usize> {
    match std::env::var("CPU_KERNELS_BENCH_BATCH") {
        Ok(s) => s.split(',').filter_map(|b| b.trim().parse().ok()).collect(),
        Err(_) => vec![32_768, 8_192],
    }
}

/// X (k x m, row-major) and dY (k x n), deterministic values in [-1, 1].
fn operands(m: usize, n: usize, k: usize) -> (Vec<f32>, Vec<f32>) {
    let x = (0..k * m).map(|i| ((i * 37 % 101) as f32 - 50.0) / 50.0).collect();
    let dy = (0..k * n).map(|i| ((i * 53 % 89) as f32 - 44.0) / 44.0).collect();
    (x, dy)
}

/// `out = Xᵀ dY`: the left operand is X read transposed (row stride 1, column stride m).
fn product(m: usize, n: usize, k: usize, x: &[f32], dy: &[f32], out: &mut [f32], split: bool) {
    let lhs = MatRef { ptr: x.as_ptr(), rs: 1, cs: m as isize };
    let rhs = MatRef { ptr: dy.as_ptr(), rs: n as isize, cs: 1 };
    // SAFETY: x holds k m floats, dy k n, out m n.
    unsafe {
        if split {
            cpu_kernels::matmul(
                m,
                n,
                k,
                lhs,
                rhs,
                out.as_mut_ptr(),
                Epilogue::NONE,
                Precision::F32,
            );
        } else {
            cpu_kernels::gemm_f32::gemm(m, n, k, lhs, rhs, out.as_mut_ptr());
        }
    }
}

/// `out = Xᵀ dY` summed in `blocks` blocks of k.
fn in_blocks(m: usize, n: usize, k: usize, blocks: usize, x: &[f32], dy: &[f32], out: &mut [f32]) {
    let lhs = MatRef { ptr: x.as_ptr(), rs: 1, cs: m as isize };
    let rhs = MatRef { ptr: dy.as_ptr(), rs: n as isize, cs: 1 };
    // SAFETY: x holds k m floats, dy k n, out m n; 1 <= blocks <= k.
    unsafe { cpu_kernels::split_k::matmul_in_blocks(m, n, k, blocks, lhs, rhs, out.as_mut_ptr()) }
}

fn median_seconds(mut f: impl FnMut()) -> f64 {
    f();
    let mut t: Vec<f64> = (0..15)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn bench(c: &mut Criterion) {
    let threads = rayon::current_num_threads();
    for k in batches() {
        let mut group = c.benchmark_group(format!("weight_gradient_batch_{k}"));
        for (m, n) in LAYERS {
            let (x, dy) = operands(m, n, k);
            let mut out = vec![0f32; m * n];
            let flop = 2.0 * (m * n * k) as f64;
            let split = median_seconds(|| product(m, n, k, &x, &dy, &mut out, true));
            let plain = median_seconds(|| product(m, n, k, &x, &dy, &mut out, false));
            println!(
                "weight gradient [{m}, {k}] x [{k}, {n}], {threads} threads: matmul {:.1} GFLOP/s \
                 ({:.3} ms), gemm over the output {:.1} GFLOP/s ({:.3} ms), ratio {:.2}",
                flop / split * 1e-9,
                split * 1e3,
                flop / plain * 1e-9,
                plain * 1e3,
                split / plain
            );
            let rates: Vec<String> = [8, 16, 32, 64]
                .into_iter()
                .filter(|&b| b <= k)
                .map(|blocks| {
                    let t = median_seconds(|| in_blocks(m, n, k, blocks, &x, &dy, &mut out));
                    format!("{blocks} blocks ({} long) {:.1}", k / blocks, flop / t * 1e-9)
                })
                .collect();
            println!("  GFLOP/s by blocks of k: {}", rates.join(", "));
            group.bench_function(BenchmarkId::new("matmul", format!("{m}x{n}")), |b| {
                b.iter(|| product(m, n, k, black_box(&x), black_box(&dy), &mut out, true))
            });
        }
        group.finish();
    }
}

/// The input gradients `dY Wᵀ` (and the bias-free skip products) of the same layers: a tall
/// [k, n] x [n, m] product, through gemm's own parallelism against blocks of rows (each a
/// single-threaded gemm, the blocks on every thread), which give the same bits.
fn input_gradients() {
    let threads = rayon::current_num_threads();
    for k in batches() {
        for (m, n) in [(128, 128), (316, 128), (188, 128)] {
            // dY: k x n; W: n x m, the first n m of the second k x m operand (row-major).
            let (dy, w) = operands(n, m, k);
            let mut a = vec![0f32; k * m];
            let mut b = vec![0f32; k * m];
            let lhs = MatRef { ptr: dy.as_ptr(), rs: n as isize, cs: 1 };
            let rhs = MatRef { ptr: w.as_ptr(), rs: m as isize, cs: 1 };
            let flop = 2.0 * (m * n * k) as f64;
            // SAFETY: dy holds k n floats, w at least n m, a and b k m.
            let plain = median_seconds(|| unsafe {
                cpu_kernels::gemm_f32::gemm(k, m, n, lhs, rhs, a.as_mut_ptr())
            });
            let rows = median_seconds(|| unsafe {
                cpu_kernels::gemm_f32::gemm_by_rows(
                    k,
                    m,
                    n,
                    lhs,
                    rhs,
                    Epilogue::NONE,
                    b.as_mut_ptr(),
                )
            });
            assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()), "same bits");
            println!(
                "input gradient [{k}, {n}] x [{n}, {m}], {threads} threads: gemm over the output \
                 {:.1} GFLOP/s, blocks of rows {:.1} GFLOP/s, ratio {:.2}",
                flop / plain * 1e-9,
                flop / rows * 1e-9,
                rows / plain
            );
        }
    }
}

fn products(c: &mut Criterion) {
    input_gradients();
    bench(c);
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = products
}
criterion_main!(benches);
