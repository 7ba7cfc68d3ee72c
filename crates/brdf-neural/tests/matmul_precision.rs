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
use brdf_neural::precision::PrecisionSupport;
use brdf_neural::products::Products;
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

fn product(
    a: &[f32],
    b: &[f32],
    (m, k, n): (usize, usize, usize),
    layout: Layout,
    products: Products,
) -> Vec<f32> {
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
    // A linear layer without bias: the products the models' layers issue.
    brdf_neural::linear_op::linear(lhs, rhs, None, products)
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
        check_bf16_products(amx);
    }
}

/// bf16 products, on AMX tiles where available (`amx`) or on the AVX512-BF16 kernel.
fn bf16_products(amx: bool) -> Products {
    Products { precision: MatmulPrecision::Bf16, ..Products::F32 }.with_bf16_amx(amx)
}

fn check_bf16_products(amx: bool) {
    for (si, &(m, k, n)) in SHAPES.iter().enumerate() {
        for layout in [Layout::RowMajor, Layout::LhsTransposed, Layout::RhsTransposed] {
            let mut r = rng(si as u64 * 3 + layout as u64);
            let a: Vec<f32> = (0..m * k).map(|_| r()).collect();
            let b: Vec<f32> = (0..k * n).map(|_| r()).collect();
            let got = product(&a, &b, (m, k, n), layout, bf16_products(amx));
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
fn f32_is_plain_f32_and_bf16_the_rounded_product_on_any_thread() {
    let (m, k, n) = (512, 128, 64);
    let mut r = rng(99);
    let a: Vec<f32> = (0..m * k).map(|_| r()).collect();
    let b: Vec<f32> = (0..k * n).map(|_| r()).collect();
    let (exact, scale) = reference(&a, &b, m, k, n, |x| x as f64);
    let (rounded, _) = reference(&a, &b, m, k, n, bf16);
    let plain = product(&a, &b, (m, k, n), Layout::RowMajor, Products::F32);
    assert!(max_scaled_error(&plain, &exact, &scale) < 1e-5, "f32 is not the plain product");
    let bf = product(&a, &b, (m, k, n), Layout::RowMajor, bf16_products(true));
    assert!(max_scaled_error(&bf, &rounded, &scale) < 1e-5, "bf16 is not the rounded product");
    // The same on another thread: nothing of a product's precision lives in the thread.
    let (a2, b2) = (a.clone(), b.clone());
    let other = std::thread::spawn(move || {
        product(&a2, &b2, (m, k, n), Layout::RowMajor, bf16_products(true))
    })
    .join()
    .unwrap();
    assert!(other == bf, "bf16 differs between threads");
}

/// A batch runs plain f32 products unless it is told otherwise, and a bf16 batch changes the
/// model's output without changing the next f32 batch's.
#[test]
fn a_batch_carries_its_products() {
    use brdf_neural::{BrdfBatch, BrdfModel, ModelConfig, ModelKind, Samples};
    let device = Backend::Flex.device().unwrap();
    let c = ModelConfig { kind: ModelKind::SingleMlp, spatial_dim: 8, ..ModelConfig::default() };
    let model = BrdfModel::init_seeded(&c, &device, 5, None).unwrap();
    let n = 4096;
    let mut r = rng(3);
    let spatial: Vec<f32> = (0..n * 8).map(|_| r()).collect();
    let dir = |x: f32, y: f32| {
        let z = (1.0 - x * x - y * y).max(0.01).sqrt();
        let len = (x * x + y * y + z * z).sqrt();
        [x / len, y / len, z / len]
    };
    let l: Vec<[f32; 3]> = (0..n).map(|_| dir(0.5 * r(), 0.5 * r())).collect();
    let v: Vec<[f32; 3]> = (0..n).map(|_| dir(0.5 * r(), 0.5 * r())).collect();
    let batch =
        BrdfBatch::new(&c, &Samples { spatial: &spatial, l: &l, v: &v }, None, &device).unwrap();
    assert_eq!(batch.products, Products::F32);
    let f = |b: &BrdfBatch| model.forward(b).f.into_data().try_to_vec::<f32>().unwrap();
    let plain = f(&batch);
    let bf16 = Products::training(MatmulPrecision::Bf16, Backend::Flex, n).unwrap();
    let rounded = f(&batch.clone().with_products(bf16));
    assert!(plain != rounded, "bf16 products left the output unchanged");
    assert!(f(&batch) == plain, "an f32 batch after a bf16 one changed");
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
        let got = product(&a, &b, (m, k, n), Layout::RowMajor, bf16_products(true));
        let (exact, scale) = reference(&a, &b, m, k, n, |x| x as f64);
        assert!(max_scaled_error(&got, &exact, &scale) < 1e-5, "{m}x{k}x{n}");
    }
}

#[test]
fn bf16_is_refused_where_no_kernel_implements_it() {
    for backend in [Backend::NdArray, Backend::Wgpu] {
        let e = MatmulPrecision::Bf16.check(backend).expect_err("refused").to_string();
        assert!(e.contains("bf16"), "{backend}: {e}");
    }
    // wgpu's refusal says where bf16 runs on a GPU.
    let e = MatmulPrecision::Bf16.check(Backend::Wgpu).expect_err("refused").to_string();
    assert!(e.contains("--backend cuda") && e.contains("tensor cores"), "{e}");
    assert!(MatmulPrecision::Bf16.check(Backend::Flex).is_ok());
    // On cuda, the gpu-kernels' tensor-core products (the default kernels) implement it.
    assert!(MatmulPrecision::Bf16.check(Backend::Cuda).is_ok());
    assert!(MatmulPrecision::F32.check(Backend::Wgpu).is_ok());
}
