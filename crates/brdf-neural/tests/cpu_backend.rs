//! The CPU backend as this workspace builds it: flex with the patches in `vendor/burn-flex`
//! (`vendor/patches/burn-flex-0.22.1.patch`), the host-memory policy, and the linear layers'
//! products in the `cpu-kernels` crate.
//!
//! Matrix products and their gradients are compared with f64 references for output sizes on
//! both sides of the alignment patch (byte sizes that are and are not multiples of 16), for
//! plain and transposed (strided) operands, and across repeated allocate-and-free cycles as a
//! training step makes them. Weight-gradient products split over k (`cpu_kernels::split_k`,
//! through `brdf_neural::linear_op`) and element-wise ops spread over the threads (patch 5) are
//! checked against f64 and scalar references and for giving the same
//! bits on 1, 2 and 3 threads.

use brdf_neural::device;
use burn::tensor::{Tensor, TensorData};
use test_support::assert_close;

/// Deterministic values in [-1, 1).
fn values(n: usize, seed: u64) -> Vec<f32> {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 23) as f32 - 1.0
        })
        .collect()
}

/// Row-major [m, k] x [k, n] in f64.
fn reference(a: &[f32], b: &[f32], m: usize, k: usize, n: usize) -> Vec<f64> {
    let mut c = vec![0.0; m * n];
    for i in 0..m {
        for p in 0..k {
            let x = f64::from(a[i * k + p]);
            for j in 0..n {
                c[i * n + j] += x * f64::from(b[p * n + j]);
            }
        }
    }
    c
}

#[test]
fn matrix_products_match_f64_on_both_sides_of_the_alignment_patch() {
    let d = device::cpu();
    // Output bytes: 9 x 4 (not a multiple of 16), 4 x 4 x 4 = 64, 513 x 3 x 4, 300 x 128 x 4.
    for (m, k, n) in [(3, 5, 3), (4, 7, 4), (513, 33, 3), (300, 188, 128), (1, 1, 1)] {
        for round in 0..3 {
            let a = values(m * k, (m * 31 + k * 7 + n + round) as u64);
            let b = values(k * n, (m + k * 13 + n * 3 + round) as u64);
            let want = reference(&a, &b, m, k, n);
            let ta = Tensor::<2>::from_data(TensorData::new(a.clone(), [m, k]), &d);
            let tb = Tensor::<2>::from_data(TensorData::new(b.clone(), [k, n]), &d);
            let got = ta.clone().matmul(tb.clone()).into_data().try_to_vec::<f32>().unwrap();
            assert_close(&format!("[{m}, {k}] x [{k}, {n}]"), &got, &want, 1e-4);
            // The transposed (strided) operand path: (B^T A^T)^T = A B.
            let t = tb.transpose().matmul(ta.transpose()).transpose();
            let got = t.into_data().try_to_vec::<f32>().unwrap();
            assert_close(&format!("transposed [{m}, {k}] x [{k}, {n}]"), &got, &want, 1e-4);
        }
    }
}

#[test]
fn matrix_product_gradients_match_f64() {
    let d = device::cpu_training();
    let (m, k, n) = (37, 12, 8); // 37 x 8 x 4 bytes: a multiple of 16; 37 x 12 x 4 too
    let a = values(m * k, 1);
    let b = values(k * n, 2);
    let ta = Tensor::<2>::from_data(TensorData::new(a.clone(), [m, k]), &d).require_grad();
    let tb = Tensor::<2>::from_data(TensorData::new(b.clone(), [k, n]), &d).require_grad();
    // L = sum(A B); dL/dA = 1 B^T (row sums of B), dL/dB = A^T 1 (column sums of A).
    let grads = ta.clone().matmul(tb.clone()).sum().backward();
    let ga = ta.grad(&grads).unwrap().into_data().try_to_vec::<f32>().unwrap();
    let gb = tb.grad(&grads).unwrap().into_data().try_to_vec::<f32>().unwrap();
    let want_a: Vec<f64> =
        (0..m * k).map(|i| (0..n).map(|j| f64::from(b[(i % k) * n + j])).sum()).collect();
    let want_b: Vec<f64> =
        (0..k * n).map(|i| (0..m).map(|r| f64::from(a[r * k + i / n])).sum()).collect();
    assert_close("dL/dA", &ga, &want_a, 1e-4);
    assert_close("dL/dB", &gb, &want_b, 1e-4);
}

#[test]
fn host_memory_policy_is_active_after_making_a_cpu_device() {
    let _ = device::cpu();
    let glibc = cfg!(all(target_os = "linux", target_env = "gnu"));
    assert_eq!(brdf_neural::host_memory::is_active(), glibc);
}

/// `f` run on a rayon pool of `threads` threads (flex's products and element-wise ops use the
/// pool they are called from).
fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

#[test]
fn long_products_split_over_k_match_f64_and_not_the_thread_count() {
    // A weight gradient's shape, Xᵀ dY summed over a batch of k rows, as a linear layer
    // computes it: `cpu_kernels::split_k` sums k in blocks (2 at 9,000, 4 at 16,411), on both
    // sides of the block threshold.
    let d = device::cpu();
    for (k, m, n) in [(8_191, 5, 16), (9_000, 7, 19), (16_411, 33, 128)] {
        let x = values(k * m, k as u64);
        let dy = values(k * n, 3 * k as u64);
        let xt: Vec<f32> = (0..m * k).map(|i| x[(i % k) * m + i / k]).collect();
        let want = reference(&xt, &dy, m, k, n);
        let product = || {
            let tx = Tensor::<2>::from_data(TensorData::new(x.clone(), [k, m]), &d);
            let tdy = Tensor::<2>::from_data(TensorData::new(dy.clone(), [k, n]), &d);
            let f32 = brdf_neural::products::Products::F32;
            let y = brdf_neural::linear_op::linear(tx.transpose(), tdy, None, f32);
            y.into_data().try_to_vec::<f32>().unwrap()
        };
        let one = on_threads(1, product);
        assert_close(&format!("[{k}, {m}]ᵀ x [{k}, {n}]"), &one, &want, 1e-4);
        for threads in [2, 3] {
            assert_eq!(on_threads(threads, product), one, "k = {k}, {threads} threads");
        }
    }
}

#[test]
fn element_wise_ops_on_every_thread_equal_the_scalar_ops() {
    // Large enough to run on every thread (2^17 elements and more): a linear layer's bias add,
    // ReLU and its backward (`brdf_neural::linear_op::relu`, the mask in place), and the bias
    // gradient (`cpu_kernels::elementwise::sum_rows`, blocks of rows). W is the identity, so
    // the layer is z + b exactly.
    use brdf_neural::linear_op;
    let d = device::cpu_training();
    let (rows, cols) = (9_001, 37);
    let z = values(rows * cols, 11);
    let b = values(cols, 12);
    let g = values(rows * cols, 13);
    let eye: Vec<f32> =
        (0..cols * cols).map(|i| if i % (cols + 1) == 0 { 1.0 } else { 0.0 }).collect();
    let step = || {
        let tz = Tensor::<2>::from_data(TensorData::new(z.clone(), [rows, cols]), &d);
        let tw = Tensor::<2>::from_data(TensorData::new(eye.clone(), [cols, cols]), &d);
        let tb = Tensor::<1>::from_data(TensorData::new(b.clone(), [cols]), &d).require_grad();
        let tg = Tensor::<2>::from_data(TensorData::new(g.clone(), [rows, cols]), &d);
        let layer =
            linear_op::linear(tz, tw, Some(tb.clone()), brdf_neural::products::Products::F32);
        let y = linear_op::relu(layer);
        let grads = (y.clone() * tg).sum().backward();
        let gb = tb.grad(&grads).unwrap().into_data().try_to_vec::<f32>().unwrap();
        (y.into_data().try_to_vec::<f32>().unwrap(), gb)
    };
    let (y, gb) = on_threads(1, step);
    for (i, yi) in y.iter().enumerate() {
        assert_eq!(*yi, (z[i] + b[i % cols]).max(0.0), "relu(z + b)[{i}]");
    }
    let want: Vec<f64> = (0..cols)
        .map(|c| {
            (0..rows)
                .filter(|r| z[r * cols + c] + b[c] > 0.0)
                .map(|r| f64::from(g[r * cols + c]))
                .sum()
        })
        .collect();
    assert_close("bias gradient", &gb, &want, 1e-4);
    for threads in [2, 3] {
        assert_eq!(on_threads(threads, step), (y.clone(), gb.clone()), "{threads} threads");
    }
}

#[test]
fn row_broadcasts_of_empty_and_thin_matrices_add_correctly() {
    // flex's bias add (vendor patch 5) takes dense [rows, cols] + [1, cols]; empty and one-wide shapes
    // must still add (the patch also guards its row loop against an empty row, which upstream's
    // layout collapse does not let reach it today).
    let d = device::cpu();
    for (rows, cols) in [(0, 5), (5, 0), (1, 3), (3, 1)] {
        let m = Tensor::<2>::zeros([rows, cols], &d);
        let b = Tensor::<2>::from_data(TensorData::new(values(cols, 5), [1, cols]), &d);
        let got = (m + b).into_data().try_to_vec::<f32>().unwrap();
        let want: Vec<f32> = (0..rows).flat_map(|_| values(cols, 5)).collect();
        assert_eq!(got, want, "[{rows}, {cols}]");
    }
}

#[test]
fn element_wise_ops_on_strided_views_equal_the_scalar_ops() {
    // Patch 6: unary and scalar ops on a non-contiguous view (a column, a block of columns, a
    // transposed matrix, a view with an offset) walk the collapsed loop nest. Each result must
    // be the scalar op of the viewed elements, in the view's logical order, to the bit.
    use burn::tensor::activation::sigmoid;
    let d = device::cpu();
    let (rows, cols) = (1_000, 12);
    let x = values(rows * cols, 61);
    let t = Tensor::<2>::from_data(TensorData::new(x.clone(), [rows, cols]), &d);
    let sig = |v: f32| {
        if v >= 0.0 {
            1.0 / (1.0 + (-v).exp())
        } else {
            let e = v.exp();
            e / (1.0 + e)
        }
    };
    let views: Vec<(&str, Tensor<2>, Vec<f32>)> = vec![
        ("column 6", t.clone().narrow(1, 6, 1), (0..rows).map(|i| x[i * cols + 6]).collect()),
        (
            "columns 1..4",
            t.clone().narrow(1, 1, 3),
            (0..rows)
                .flat_map(|i| (1..4).map(move |j| (i, j)))
                .map(|(i, j)| x[i * cols + j])
                .collect(),
        ),
        (
            "transposed rows 10..20",
            t.clone().narrow(0, 10, 10).swap_dims(0, 1),
            (0..cols)
                .flat_map(|j| (10..20).map(move |i| (i, j)))
                .map(|(i, j)| x[i * cols + j])
                .collect(),
        ),
    ];
    for (what, view, elems) in views {
        let shape = view.dims();
        let check = |got: Tensor<2>, f: &dyn Fn(f32) -> f32, op: &str| {
            assert_eq!(got.dims(), shape, "{what}: {op} shape");
            let got = got.into_data().try_to_vec::<f32>().unwrap();
            for (i, (g, &e)) in got.iter().zip(&elems).enumerate() {
                assert_eq!(g.to_bits(), f(e).to_bits(), "{what}: {op}[{i}] of {e}");
            }
        };
        check(sigmoid(view.clone()), &sig, "sigmoid");
        check(view.clone().exp(), &|v| v.exp(), "exp");
        check(view.clone().mul_scalar(0.3), &|v| v * 0.3, "mul_scalar");
        check(view.clone().add_scalar(-1.5), &|v| v + -1.5, "add_scalar");
        check(view.clone().neg(), &|v| -v, "neg");
    }
}
