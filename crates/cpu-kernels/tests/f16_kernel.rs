//! The AVX512-FP16 kernel against the f16 precision's emulation, to the bit, on the shapes and
//! strides of a training step (forward, input gradient through a transposed weight, weight
//! gradient through transposed activations), with wide magnitude ranges and the epilogue.
//! On a CPU without AVX512-FP16 both sides are the emulation and the test says so. And which
//! products `matmul` sends there: the weight gradients' shapes stay f32.

use cpu_kernels::{Epilogue, MatRef, Precision, f16dot};

/// Deterministic values: a uniform in [-1, 1) times a per-row magnitude from 2^-30 to 2^10.
fn values(rows: usize, cols: usize, seed: u64, spread: bool) -> Vec<f32> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..rows * cols)
        .map(|x| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let u = (s >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0;
            let row = x / cols;
            let mag = if spread { 2f32.powi((row * 7 % 41) as i32 - 30) } else { 1.0 };
            if row % 13 == 5 { 0.0 } else { u * mag }
        })
        .collect()
}

fn transpose(v: &[f32], rows: usize, cols: usize) -> Vec<f32> {
    (0..rows * cols).map(|x| v[(x % rows) * cols + x / rows]).collect()
}

/// `a` m x k and `b` k x n, each given row-major or as the transpose of a stored matrix.
fn check(m: usize, n: usize, k: usize, a_t: bool, b_t: bool, spread: bool, with_epilogue: bool) {
    let a = values(m, k, 1 + m as u64, spread);
    let b = values(k, n, 2 + n as u64, !spread);
    let bias: Vec<f32> = (0..n).map(|j| (j as f32 - 3.0) * 0.01).collect();
    let epilogue =
        if with_epilogue { Epilogue { bias: Some(&bias), relu: true } } else { Epilogue::NONE };
    // Stored transposed where asked: the view then has rs 1.
    let a_store = if a_t { transpose(&a, m, k) } else { a.clone() };
    let b_store = if b_t { transpose(&b, k, n) } else { b.clone() };
    let lhs = if a_t {
        MatRef { ptr: a_store.as_ptr(), rs: 1, cs: m as isize }
    } else {
        MatRef { ptr: a_store.as_ptr(), rs: k as isize, cs: 1 }
    };
    let rhs = if b_t {
        MatRef { ptr: b_store.as_ptr(), rs: 1, cs: k as isize }
    } else {
        MatRef { ptr: b_store.as_ptr(), rs: n as isize, cs: 1 }
    };
    let mut got = vec![f32::NAN; m * n];
    // SAFETY: the views address the stored vectors with their shapes.
    unsafe { f16dot::matmul_f16(m, n, k, lhs, rhs, got.as_mut_ptr(), epilogue) };
    let mut want = f16dot::emulated_row_major(m, n, k, &a, &b);
    // SAFETY: `want` holds m n floats.
    unsafe { epilogue.apply_rows(m, n, want.as_mut_ptr()) };
    let differ = got.iter().zip(&want).filter(|(g, w)| g.to_bits() != w.to_bits()).count();
    assert_eq!(differ, 0, "{m} x {k} x {n} (a_t {a_t}, b_t {b_t}): {differ} elements differ");
}

#[test]
fn kernel_equals_emulation_to_the_bit() {
    if !f16dot::f16_native() {
        eprintln!("no AVX512-FP16 here: the f16 precision is the emulation on both sides");
    }
    // Forward and input gradient (a row-major batch, k up to a few blocks).
    check(300, 70, 130, false, false, true, true);
    check(64, 128, 128, false, true, false, true);
    check(37, 33, 600, false, false, false, false);
    // Weight gradient: transposed activations, a long k split in parts.
    check(24, 40, 4100, true, false, true, false);
    check(17, 16, 2112, true, true, false, true);
}

#[test]
fn matmul_keeps_weight_gradients_f32() {
    let (m, n, k) = (32, 32, 4096);
    let a = values(m, k, 3, false);
    let b = values(k, n, 4, false);
    let f16 = cpu_kernels::matmul_row_major(m, n, k, &a, &b, Epilogue::NONE, Precision::F16);
    let f32 = cpu_kernels::matmul_row_major(m, n, k, &a, &b, Epilogue::NONE, Precision::F32);
    assert_eq!(f16, f32, "a long k into a small output is f32 under Precision::F16");
    let (m, k) = (256, 64);
    let a = values(m, k, 5, false);
    let b = values(k, n, 6, false);
    let got = cpu_kernels::matmul_row_major(m, n, k, &a, &b, Epilogue::NONE, Precision::F16);
    assert_eq!(got, f16dot::emulated_row_major(m, n, k, &a, &b), "a forward product is f16");
}

#[test]
fn values_are_close_to_f64() {
    let (m, n, k) = (64, 48, 3000);
    let a = values(m, k, 7, false);
    let b = values(k, n, 8, false);
    let lhs = MatRef { ptr: a.as_ptr(), rs: k as isize, cs: 1 };
    let rhs = MatRef { ptr: b.as_ptr(), rs: n as isize, cs: 1 };
    let mut got = vec![0f32; m * n];
    // SAFETY: the views address the vectors with their shapes.
    unsafe { f16dot::matmul_f16(m, n, k, lhs, rhs, got.as_mut_ptr(), Epilogue::NONE) };
    for i in 0..m {
        for j in 0..n {
            let (mut exact, mut mag) = (0f64, 0f64);
            for kk in 0..k {
                let p = a[i * k + kk] as f64 * b[kk * n + j] as f64;
                exact += p;
                mag += p.abs();
            }
            let err = (got[i * n + j] as f64 - exact).abs();
            assert!(
                err <= mag * 1e-3,
                "({i}, {j}): {} against {exact} (sum |ab| {mag})",
                got[i * n + j]
            );
        }
    }
}
