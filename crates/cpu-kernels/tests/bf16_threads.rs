//! A bf16 product's bits do not depend on how many threads run it: the weight gradients' split
//! over k is a function of k alone (`split_k::bf16_parts`), on the AVX512-BF16 kernel, on the
//! AMX tiles and in the emulation alike, so a fit gives the same weights in a `--jobs` child, a
//! Slurm task with one CPU and on a workstation.

use cpu_kernels::{MatRef, Precision};

/// `xᵀ dy` for x of k x m and dy of k x n (a weight gradient over a batch of k), on `threads`.
fn weight_gradient(threads: usize, amx: bool, (m, n, k): (usize, usize, usize)) -> Vec<f32> {
    let x: Vec<f32> = (0..k * m).map(|i| ((i * 37 % 101) as f32 - 50.0) / 50.0).collect();
    let dy: Vec<f32> = (0..k * n).map(|i| ((i * 53 % 89) as f32 - 44.0) / 440.0).collect();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let mut out = vec![f32::NAN; m * n];
    // xᵀ: m x k with element (i, p) at x[p m + i].
    let lhs = MatRef { ptr: x.as_ptr(), rs: 1, cs: m as isize };
    let rhs = MatRef { ptr: dy.as_ptr(), rs: n as isize, cs: 1 };
    let precision = Precision::Bf16 { amx };
    let dst = &mut out;
    // SAFETY: the operands address k x m and k x n floats, `out` m x n.
    pool.install(|| unsafe {
        cpu_kernels::matmul(
            m,
            n,
            k,
            lhs,
            rhs,
            dst.as_mut_ptr(),
            cpu_kernels::Epilogue::NONE,
            precision,
        )
    });
    assert!(out.iter().all(|v| v.is_finite()));
    out
}

#[test]
fn bf16_weight_gradients_have_the_same_bits_on_any_thread_count() {
    for amx in [false, true] {
        for shape in [(128, 128, 8_192), (64, 48, 2_048), (32, 96, 5_000)] {
            let one = weight_gradient(1, amx, shape);
            for threads in [2, 3, 5] {
                let other = weight_gradient(threads, amx, shape);
                let same = one.iter().zip(&other).all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "amx {amx}, {shape:?}: 1 thread against {threads}");
            }
        }
    }
}
