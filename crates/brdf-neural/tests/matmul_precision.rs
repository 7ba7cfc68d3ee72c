//! The bf16 matrix-product precision against an f64 reference of the bf16-rounded operands.
//!
//! Every product that takes the bf16 path must equal the exact product of the operands rounded
//! to bf16 up to f32 summation error, for the layouts training produces (row-major, a transposed
//! left operand as in the weight gradient, a transposed right operand as in the input gradient)
//! and for shapes with tails (odd k, rows not a multiple of the tile, columns not a multiple of
//! the panel). The same products under the default precision must be the plain f32 ones.
#![cfg(feature = "flex")]

use brdf_neural::device::Backend;
use brdf_neural::device::BackendDevice;
use brdf_neural::precision::MatmulPrecision;
use brdf_neural::precision::PrecisionScope;
use burn::tensor::{Tensor, TensorData};

fn rng(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }
}

fn bf16(x: f32) -> f64 {
    // Round to nearest even at 16 bits (no NaN in these tests).
    let b = x.to_bits();
    let r = b.wrapping_add(0x7FFF + ((b >> 16) & 1)) & 0xFFFF_0000;
    f32::from_bits(r) as f64
}

/// Row-major m x n of `a` (m x k) times `b` (k x n) with operands mapped by `f`, in f64, and
/// the sum of |a||b| per element (the scale of the summation error).
fn reference(
    a: &[f32],
    b: &[f32],
    m: usize,
    k: usize,
    n: usize,
    f: impl Fn(f32) -> f64,
) -> (Vec<f64>, Vec<f64>) {
    let mut c = vec![0.0; m * n];
    let mut s = vec![0.0; m * n];
    for i in 0..m {
        for p in 0..k {
            let x = f(a[i * k + p]);
            for j in 0..n {
                let y = f(b[p * n + j]);
                c[i * n + j] += x * y;
                s[i * n + j] += (x * y).abs();
            }
        }
    }
    (c, s)
}

#[derive(Clone, Copy, Debug)]
enum Layout {
    RowMajor,
    /// lhs given as the transpose of a k x m tensor (the weight gradient's x^T).
    LhsTransposed,
    /// rhs given as the transpose of an n x k tensor (the input gradient's W^T).
    RhsTransposed,
}

fn product(a: &[f32], b: &[f32], m: usize, k: usize, n: usize, layout: Layout) -> Vec<f32> {
    let device = Backend::Flex.device().unwrap();
    let transpose = |v: &[f32], r: usize, c: usize| {
        let mut t = vec![0.0; r * c];
        for i in 0..r {
            for j in 0..c {
                t[j * r + i] = v[i * c + j];
            }
        }
        t
    };
    let lhs: Tensor<2> = match layout {
        Layout::LhsTransposed => {
            Tensor::from_data(TensorData::new(transpose(a, m, k), [k, m]), &device).transpose()
        }
        _ => Tensor::from_data(TensorData::new(a.to_vec(), [m, k]), &device),
    };
    let rhs: Tensor<2> = match layout {
        Layout::RhsTransposed => {
            Tensor::from_data(TensorData::new(transpose(b, k, n), [n, k]), &device).transpose()
        }
        _ => Tensor::from_data(TensorData::new(b.to_vec(), [k, n]), &device),
    };
    // A linear layer without bias: the products the models' layers issue, in the precision of
    // the calling thread's scope.
    brdf_neural::linear_op::linear(lhs, rhs, None, MatmulPrecision::current())
        .into_data()
        .try_to_vec::<f32>()
        .unwrap()
}

fn max_scaled_error(got: &[f32], want: &[f64], scale: &[f64]) -> f64 {
    got.iter()
        .zip(want.iter().zip(scale))
        .map(|(&g, (&w, &s))| (g as f64 - w).abs() / s.max(1e-30))
        .fold(0.0, f64::max)
}

/// Products large and wide enough to take the bf16 path (m n k >= 2^18, n >= 16, k >= 8), with
/// tails in every dimension.
const SHAPES: [(usize, usize, usize); 7] = [
    (8192, 128, 128),
    (4096, 181, 128),
    (128, 8192, 128),
    (40, 4097, 20),
    (301, 65, 33),
    (611, 7 * 3, 48),
    (13, 129, 200),
];

/// The bf16 kernels this machine can run: AMX tiles (where the CPU and the OS allow them) and
/// the AVX-512 kernel, or the one it has.
fn kernels() -> Vec<bool> {
    if MatmulPrecision::bf16_on_amx() { vec![true, false] } else { vec![false] }
}

#[test]
fn bf16_products_equal_the_rounded_operands_product() {
    for amx in kernels() {
        // Process-wide; the other tests here are indifferent to which bf16 kernel runs.
        MatmulPrecision::set_bf16_amx_enabled(amx);
        assert_eq!(MatmulPrecision::bf16_on_amx(), amx);
        check_bf16_products(amx);
    }
    MatmulPrecision::set_bf16_amx_enabled(true);
}

fn check_bf16_products(amx: bool) {
    for (si, &(m, k, n)) in SHAPES.iter().enumerate() {
        for layout in [Layout::RowMajor, Layout::LhsTransposed, Layout::RhsTransposed] {
            let mut r = rng(si as u64 * 3 + layout as u64);
            let a: Vec<f32> = (0..m * k).map(|_| r()).collect();
            let b: Vec<f32> = (0..k * n).map(|_| r()).collect();
            let got = {
                let _g = MatmulPrecision::Bf16.scope(Backend::Flex).unwrap();
                product(&a, &b, m, k, n, layout)
            };
            let (want, scale) = reference(&a, &b, m, k, n, bf16);
            let err = max_scaled_error(&got, &want, &scale);
            // f32 sums of k terms: a few ulp of the sum of magnitudes.
            assert!(
                err < 4e-6 * (k as f64).sqrt().max(1.0),
                "{m}x{k}x{n} {layout:?} (amx {amx}): bf16 error {err:e}"
            );
            // And the plain f32 product is measurably different (the switch switched).
            let (exact, _) = reference(&a, &b, m, k, n, |x| x as f64);
            let bf_vs_exact = max_scaled_error(&got, &exact, &scale);
            assert!(
                bf_vs_exact > 1e-4,
                "{m}x{k}x{n} {layout:?} (amx {amx}): bf16 too close to f32 ({bf_vs_exact:e})"
            );
        }
    }
}

#[test]
fn default_precision_is_plain_f32_and_the_guard_restores_it() {
    let (m, k, n) = (512, 128, 64);
    let mut r = rng(99);
    let a: Vec<f32> = (0..m * k).map(|_| r()).collect();
    let b: Vec<f32> = (0..k * n).map(|_| r()).collect();
    let (exact, scale) = reference(&a, &b, m, k, n, |x| x as f64);
    {
        let _g = MatmulPrecision::Bf16.scope(Backend::Flex).unwrap();
    }
    let got = product(&a, &b, m, k, n, Layout::RowMajor);
    let err = max_scaled_error(&got, &exact, &scale);
    assert!(err < 1e-5, "after the guard dropped the product is not f32: {err:e}");
    // Another thread never sees this thread's setting.
    let _g = MatmulPrecision::Bf16.scope(Backend::Flex).unwrap();
    {
        // f32_scope returns to plain f32 inside a bf16 scope (the validation loss).
        let _f32 = MatmulPrecision::f32_scope();
        let inner = product(&a, &b, m, k, n, Layout::RowMajor);
        assert!(max_scaled_error(&inner, &exact, &scale) < 1e-5);
    }
    let (rounded, _) = reference(&a, &b, m, k, n, bf16);
    let restored = product(&a, &b, m, k, n, Layout::RowMajor);
    assert!(max_scaled_error(&restored, &rounded, &scale) < 1e-5, "bf16 not restored");
    let other =
        std::thread::spawn(move || product(&a, &b, m, k, n, Layout::RowMajor)).join().unwrap();
    assert!(max_scaled_error(&other, &exact, &scale) < 1e-5);
}

#[test]
fn the_emulation_for_cpus_without_bf16_agrees() {
    // Machines without AVX512-BF16 round the operands and call the f32 gemm instead.
    for &(m, k, n) in &SHAPES[4..] {
        let mut r = rng(m as u64);
        let a: Vec<f32> = (0..m * k).map(|_| r()).collect();
        let b: Vec<f32> = (0..k * n).map(|_| r()).collect();
        let got = cpu_kernels::emulated_row_major(m, n, k, &a, &b);
        let (want, scale) = reference(&a, &b, m, k, n, bf16);
        let err = max_scaled_error(&got, &want, &scale);
        assert!(err < 4e-6 * (k as f64).sqrt(), "{m}x{k}x{n}: emulated error {err:e}");
    }
}

#[test]
fn narrow_and_small_products_stay_f32_under_bf16() {
    // The 3-channel head and tiny products gain nothing from bf16 and keep f32.
    for (m, k, n) in [(8192, 128, 3), (40, 40, 40)] {
        let mut r = rng(7);
        let a: Vec<f32> = (0..m * k).map(|_| r()).collect();
        let b: Vec<f32> = (0..k * n).map(|_| r()).collect();
        let _g = MatmulPrecision::Bf16.scope(Backend::Flex).unwrap();
        let got = product(&a, &b, m, k, n, Layout::RowMajor);
        let (exact, scale) = reference(&a, &b, m, k, n, |x| x as f64);
        assert!(max_scaled_error(&got, &exact, &scale) < 1e-5, "{m}x{k}x{n}");
    }
}

#[test]
fn bf16_is_refused_where_no_kernel_implements_it() {
    for backend in [Backend::NdArray, Backend::Wgpu] {
        let e = MatmulPrecision::Bf16.scope(backend).err().expect("refused").to_string();
        assert!(e.contains("bf16"), "{backend}: {e}");
    }
    // wgpu's refusal says where bf16 runs on a GPU.
    let e = MatmulPrecision::Bf16.scope(Backend::Wgpu).err().expect("refused").to_string();
    assert!(e.contains("--backend cuda") && e.contains("tensor cores"), "{e}");
    assert!(MatmulPrecision::Bf16.scope(Backend::Flex).is_ok());
    // On cuda, the gpu-kernels' tensor-core products (the default kernels) implement it.
    if std::env::var(brdf_neural::gpu_linear::VAR).is_err() {
        assert!(MatmulPrecision::Bf16.scope(Backend::Cuda).is_ok());
    }
    assert!(MatmulPrecision::F32.scope(Backend::Wgpu).is_ok());
}
