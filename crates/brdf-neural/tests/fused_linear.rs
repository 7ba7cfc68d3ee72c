//! The models' linear layers (`brdf_neural::linear_op`, the `cpu-kernels` crate behind a burn
//! backend extension) with the bias added in the matrix product's store, and the hidden layers
//! with the bias and the ReLU added there (`linear_relu`).
//!
//! A layer's value and its gradients must be those of the unfused form, the product followed
//! by a broadcast add, to the bit: in f32 (the gemm in blocks of rows) also against burn-flex's
//! own product, and in bf16 (the AMX kernel's block store, and the AVX-512 kernel or the
//! emulation with the add after), for shapes with tails in every dimension and outputs narrower
//! than the fused path takes; the gradients through the extension's autodiff node against
//! burn's autodiff of the product and the add.
#![cfg(feature = "flex")]

use brdf_neural::device::{self, Backend};
use brdf_neural::linear_op::{linear, linear_relu, relu};
use brdf_neural::precision::MatmulPrecision;
use brdf_neural::precision::PrecisionSupport;
use brdf_neural::products::Products;
use burn::tensor::{Tensor, TensorData};

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

/// (rows, d_in, d_out): rows past one block of the f32 path (1,024 rows at 128 outputs) with a
/// tail, rows and columns off the AMX kernel's 32 x 32 blocks, an odd inner dimension, the
/// first layer's and the skip layer's inner dimensions, and a 3-channel head (not fused).
const SHAPES: [(usize, usize, usize); 7] = [
    (2_085, 128, 128),
    (77, 33, 19),
    (300, 188, 128),
    (1_030, 40, 48),
    (64, 7, 16),
    (513, 64, 3),
    (1, 5, 200),
];

fn bits(t: Tensor<2>) -> Vec<u32> {
    t.into_data().try_to_vec::<f32>().unwrap().iter().map(|v| v.to_bits()).collect()
}

/// Fails with the first element that differs (and how many do).
fn assert_same_bits(got: &[u32], want: &[u32], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    let differ = got.iter().zip(want).filter(|(g, w)| g != w).count();
    if let Some(i) = got.iter().zip(want).position(|(g, w)| g != w) {
        let (g, w) = (f32::from_bits(got[i]), f32::from_bits(want[i]));
        panic!("{what}: {differ} of {} elements differ, first [{i}]: {g} vs {w}", got.len());
    }
}

/// The layer with the bias fused, the layer without bias plus a broadcast add, and burn-flex's
/// own product plus the add, as bit patterns, the layers' products in precision `p`.
fn fused_and_plain(
    (m, k, n): (usize, usize, usize),
    seed: u64,
    p: Products,
) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let d = device::cpu();
    let x = Tensor::<2>::from_data(TensorData::new(values(m * k, seed), [m, k]), &d);
    let w = Tensor::<2>::from_data(TensorData::new(values(k * n, seed + 1), [k, n]), &d);
    let b = Tensor::<1>::from_data(TensorData::new(values(n, seed + 2), [n]), &d);
    let fused = linear(x.clone(), w.clone(), Some(b.clone()), p);
    let plain = linear(x.clone(), w.clone(), None, p) + b.clone().unsqueeze::<2>();
    let flex = x.matmul(w) + b.unsqueeze::<2>();
    (bits(fused), bits(plain), bits(flex))
}

#[test]
fn f32_linear_layers_equal_the_product_plus_the_bias_to_the_bit() {
    for (i, &(m, k, n)) in SHAPES.iter().enumerate() {
        let (fused, plain, flex) = fused_and_plain((m, k, n), 10 * i as u64, Products::F32);
        assert_same_bits(&fused, &plain, &format!("[{m}, {k}] x [{k}, {n}] + b"));
        assert_same_bits(&fused, &flex, &format!("[{m}, {k}] x [{k}, {n}] + b against flex"));
    }
}

#[test]
fn bf16_linear_layers_equal_the_product_plus_the_bias_to_the_bit() {
    let kernels = if MatmulPrecision::bf16_on_amx() { vec![true, false] } else { vec![false] };
    for amx in kernels {
        MatmulPrecision::Bf16.check(Backend::Flex).unwrap();
        let bf16 =
            Products { precision: MatmulPrecision::Bf16, ..Products::F32 }.with_bf16_amx(amx);
        for (i, &(m, k, n)) in SHAPES.iter().enumerate() {
            let seed = 100 + 10 * i as u64;
            let (fused, plain, _) = fused_and_plain((m, k, n), seed, bf16);
            let what = format!("bf16 (AMX: {amx}) [{m}, {k}] x [{k}, {n}] + b");
            assert_same_bits(&fused, &plain, &what);
        }
    }
}

#[test]
fn linear_layer_gradients_equal_the_unfused_gradients_to_the_bit() {
    let d = device::cpu_training();
    let (m, k, n) = (1_100, 36, 64);
    let r = Tensor::<2>::from_data(TensorData::new(values(m * n, 7), [m, n]), &d);
    let run = |fused: bool| {
        let x =
            Tensor::<2>::from_data(TensorData::new(values(m * k, 1), [m, k]), &d).require_grad();
        let w =
            Tensor::<2>::from_data(TensorData::new(values(k * n, 2), [k, n]), &d).require_grad();
        let b = Tensor::<1>::from_data(TensorData::new(values(n, 3), [n]), &d).require_grad();
        let y = if fused {
            linear(x.clone(), w.clone(), Some(b.clone()), Products::F32)
        } else {
            x.clone().matmul(w.clone()) + b.clone().unsqueeze::<2>()
        };
        let grads = (y.clone() * r.clone()).sum().backward();
        let g = |t: Tensor<2>| bits(t.grad(&grads).unwrap());
        let gb = b.grad(&grads).unwrap().into_data().try_to_vec::<f32>().unwrap();
        (bits(y), g(x), g(w), gb.iter().map(|v| v.to_bits()).collect::<Vec<_>>())
    };
    let (fused, plain) = (run(true), run(false));
    assert_same_bits(&fused.0, &plain.0, "values");
    assert_same_bits(&fused.1, &plain.1, "dL/dx");
    assert_same_bits(&fused.2, &plain.2, "dL/dW");
    assert_same_bits(&fused.3, &plain.3, "dL/db");
}

/// `linear_relu` and `relu(linear)` as bit patterns, on inputs whose first row is NaN and
/// whose bias makes some outputs exactly 0 (a column of zero weights with a zero bias).
fn fused_relu_and_plain((m, k, n): (usize, usize, usize), seed: u64, p: Products) -> [Vec<u32>; 2] {
    let d = device::cpu();
    let mut xs = values(m * k, seed);
    xs[..k].fill(f32::NAN);
    let mut ws = values(k * n, seed + 1);
    let mut bs = values(n, seed + 2);
    for r in 0..k {
        ws[r * n] = 0.0;
    }
    bs[0] = 0.0;
    let x = Tensor::<2>::from_data(TensorData::new(xs, [m, k]), &d);
    let w = Tensor::<2>::from_data(TensorData::new(ws, [k, n]), &d);
    let b = Tensor::<1>::from_data(TensorData::new(bs, [n]), &d);
    let fused = linear_relu(x.clone(), w.clone(), b.clone(), p);
    let plain = relu(linear(x, w, Some(b), p));
    [bits(fused), bits(plain)]
}

#[test]
fn hidden_layers_equal_the_layer_then_the_relu_to_the_bit() {
    let mut precisions = vec![("f32".to_string(), Products::F32)];
    MatmulPrecision::Bf16.check(Backend::Flex).unwrap();
    let amx = if MatmulPrecision::bf16_on_amx() { vec![true, false] } else { vec![false] };
    for amx in amx {
        let p = Products { precision: MatmulPrecision::Bf16, ..Products::F32 }.with_bf16_amx(amx);
        precisions.push((format!("bf16 (AMX: {amx})"), p));
    }
    for (what, p) in precisions {
        for (i, &(m, k, n)) in SHAPES.iter().enumerate() {
            let [fused, plain] = fused_relu_and_plain((m, k, n), 200 + 10 * i as u64, p);
            assert_same_bits(&fused, &plain, &format!("{what} relu([{m}, {k}] x [{k}, {n}] + b)"));
            let f: Vec<f32> = fused.iter().map(|b| f32::from_bits(*b)).collect();
            assert!(f[..n].iter().all(|v| v.is_nan()), "{what}: a NaN row stays NaN");
            assert!(
                f[n..].iter().all(|v| *v >= 0.0 && v.to_bits() >> 31 == 0),
                "{what}: +0 or more"
            );
            assert!(f[n..].chunks(n).all(|r| r[0].to_bits() == 0), "{what}: relu(0) is +0");
        }
    }
}

#[test]
fn hidden_layer_gradients_equal_the_unfused_gradients_to_the_bit() {
    let d = device::cpu_training();
    for (m, k, n) in [(1_100, 36, 64), (2_085, 128, 128), (77, 33, 19)] {
        let r = Tensor::<2>::from_data(TensorData::new(values(m * n, 7), [m, n]), &d);
        let run = |fused: bool| {
            let x = Tensor::<2>::from_data(TensorData::new(values(m * k, 1), [m, k]), &d)
                .require_grad();
            let w = Tensor::<2>::from_data(TensorData::new(values(k * n, 2), [k, n]), &d)
                .require_grad();
            let b = Tensor::<1>::from_data(TensorData::new(values(n, 3), [n]), &d).require_grad();
            let y = if fused {
                linear_relu(x.clone(), w.clone(), b.clone(), Products::F32)
            } else {
                burn::tensor::activation::relu(
                    x.clone().matmul(w.clone()) + b.clone().unsqueeze::<2>(),
                )
            };
            // A second layer on top, so the ReLU's output is also the next layer's input.
            let y2 = linear(
                y.clone(),
                w.clone().transpose().slice([0..n, 0..n.min(k)]),
                None,
                Products::F32,
            );
            let grads = ((y.clone() * r.clone()).sum() + y2.sum()).backward();
            let g = |t: Tensor<2>| bits(t.grad(&grads).unwrap());
            let gb = b.grad(&grads).unwrap().into_data().try_to_vec::<f32>().unwrap();
            (bits(y), g(x), g(w), gb.iter().map(|v| v.to_bits()).collect::<Vec<_>>())
        };
        let (fused, plain) = (run(true), run(false));
        let at = format!("[{m}, {k}] x [{k}, {n}]");
        let positive = fused.0.iter().filter(|b| f32::from_bits(**b) > 0.0).count();
        assert!(positive > 0 && positive < fused.0.len(), "{at}: the ReLU cuts some outputs");
        assert_same_bits(&fused.0, &plain.0, &format!("{at} values"));
        assert_same_bits(&fused.1, &plain.1, &format!("{at} dL/dx"));
        assert_same_bits(&fused.2, &plain.2, &format!("{at} dL/dW"));
        assert_same_bits(&fused.3, &plain.3, &format!("{at} dL/db"));
    }
}
