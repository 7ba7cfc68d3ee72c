//! Each operation of `gpu_kernels::linear` against an f64 reference on the wgpu runtime (any
//! Vulkan device; Mesa's lavapipe will do), on every tiling (64 and 128 wide, and 64 wide with 4-wide shared reads): shapes that fill
//! the tiles and shapes that do not, one split and many, NaN and negative inputs through the ReLU, the same bits on a
//! second run, the same bits from checked launches, and shape errors that name the operation.
//!
//! The bf16 products on tensor cores (`Precision::Bf16`) are checked against an f64 reference
//! of the bf16-rounded operands where the device has them, and must be refused, naming the
//! operation, where it has not (lavapipe, any WGSL device).
//!
//! `cargo test -p gpu-kernels --features wgpu`; on an NVIDIA GPU also
//! `GPU_KERNELS_RUNTIME=cuda cargo test -p gpu-kernels --features wgpu,cuda`.

use cubecl::prelude::*;
use gpu_kernels::checks;
use gpu_kernels::linear::{self, Matrix};
use gpu_kernels::plan::Precision::{Bf16, F32};
use gpu_kernels::plan::{self, Tiling, Tuning};
use test_support::assert_close;

/// The runtime under test: `GPU_KERNELS_RUNTIME=cuda` (with the `cuda` feature), else wgpu.
fn client() -> Client {
    match std::env::var("GPU_KERNELS_RUNTIME").as_deref() {
        Ok("cuda") if cfg!(feature = "cuda") => cubecl::Device::Cuda(Default::default()).client(),
        Ok("wgpu") | Err(_) => cubecl::Device::Wgpu(Default::default()).client(),
        Ok(other) => {
            panic!("GPU_KERNELS_RUNTIME={other:?}: expected wgpu, or cuda when built with it")
        }
    }
}

/// `v` rounded to the nearest bf16 (ties to even), as the tensor-core kernel rounds.
fn bf16_round(v: f32) -> f32 {
    let bits = v.to_bits();
    let rounded = bits.wrapping_add(0x7fff + ((bits >> 16) & 1)) & 0xffff_0000;
    f32::from_bits(rounded)
}

fn rounded(v: &[f32]) -> Vec<f32> {
    v.iter().copied().map(bf16_round).collect()
}

/// Deterministic values in [-1, 1) (xorshift).
fn values(len: usize, seed: u64) -> Vec<f32> {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    (0..len)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            ((s >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        })
        .collect()
}

/// `a [m, k] b [k, n]` in f64, row-major.
fn product(a: &[f32], b: &[f32], m: usize, k: usize, n: usize) -> Vec<f64> {
    let mut c = vec![0.0f64; m * n];
    for i in 0..m {
        for p in 0..k {
            let av = a[i * k + p] as f64;
            for j in 0..n {
                c[i * n + j] += av * b[p * n + j] as f64;
            }
        }
    }
    c
}

fn transpose(a: &[f32], rows: usize, cols: usize) -> Vec<f32> {
    let mut t = vec![0.0; a.len()];
    for i in 0..rows {
        for j in 0..cols {
            t[j * rows + i] = a[i * cols + j];
        }
    }
    t
}

/// The shapes: (rows, d_in, d_out), tile-filling and ragged, short and long batches (the long
/// ones take several splits in the weight gradient).
const SHAPES: [(u32, u32, u32); 5] =
    [(64, 64, 64), (1, 1, 1), (77, 19, 33), (4_100, 38, 128), (9_000, 128, 3)];

#[test]
fn forward_matches_the_reference_with_and_without_bias_and_relu() {
    for tiling in Tiling::ALL {
        forward_matches_on(tiling);
    }
}

fn forward_matches_on(tiling: Tiling) {
    let client = client();
    let tu = Tuning { tiling, split_len: None };
    for (t, &(rows, d_in, d_out)) in SHAPES.iter().enumerate() {
        let (m, k, n) = (rows as usize, d_in as usize, d_out as usize);
        let xv = values(m * k, 1 + t as u64);
        let wv = values(k * n, 100 + t as u64);
        let bv = values(n, 200 + t as u64);
        let x = Matrix::upload(&client, &xv, rows, d_in).unwrap();
        let w = Matrix::upload(&client, &wv, d_in, d_out).unwrap();
        let b = Matrix::upload(&client, &bv, 1, d_out).unwrap();
        let plain = product(&xv, &wv, m, k, n);
        let with_bias: Vec<f64> =
            plain.iter().enumerate().map(|(e, v)| v + bv[e % n] as f64).collect();
        let relu: Vec<f64> = with_bias.iter().map(|v| v.max(0.0)).collect();
        let tol = 4e-7 * k as f64;
        let got = linear::forward(&client, &x, &w, None, false, F32, tu).unwrap().read(&client);
        assert_close(&format!("x W {rows}x{d_in}x{d_out} {tiling:?}"), &got, &plain, tol);
        let got = linear::forward(&client, &x, &w, Some(&b.handle), false, F32, tu).unwrap();
        assert_close(
            &format!("x W + b {rows}x{d_in}x{d_out} {tiling:?}"),
            &got.read(&client),
            &with_bias,
            tol,
        );
        let got = linear::forward(&client, &x, &w, Some(&b.handle), true, F32, tu).unwrap();
        let label = format!("relu {rows}x{d_in}x{d_out} {tiling:?}");
        assert_close(&label, &got.read(&client), &relu, tol);
    }
}

#[test]
fn gradients_match_the_reference() {
    for tiling in Tiling::ALL {
        gradients_match_on(tiling);
    }
}

fn gradients_match_on(tiling: Tiling) {
    let client = client();
    let tu = Tuning { tiling, split_len: None };
    for (t, &(rows, d_in, d_out)) in SHAPES.iter().enumerate() {
        let (m, k, n) = (rows as usize, d_in as usize, d_out as usize);
        let xv = values(m * k, 300 + t as u64);
        let wv = values(k * n, 400 + t as u64);
        let dyv = values(m * n, 500 + t as u64);
        let x = Matrix::upload(&client, &xv, rows, d_in).unwrap();
        let w = Matrix::upload(&client, &wv, d_in, d_out).unwrap();
        let dy = Matrix::upload(&client, &dyv, rows, d_out).unwrap();
        let label = format!("{rows}x{d_in}x{d_out} {tiling:?}");

        let dx = linear::x_backward(&client, &w, &dy, F32, tu).unwrap().read(&client);
        let want = product(&dyv, &transpose(&wv, k, n), m, n, k);
        assert_close(&format!("dY Wᵀ {label}"), &dx, &want, 4e-7 * n as f64);

        let dw = linear::weight_backward(&client, &x, &dy, F32, tu).unwrap();
        let want = product(&transpose(&xv, m, k), &dyv, k, m, n);
        assert_close(&format!("Xᵀ dY {label}"), &dw.read(&client), &want, 4e-7 * m as f64);

        let db = linear::bias_backward(&client, &dy).unwrap().read(&client);
        let want: Vec<f64> = (0..n).map(|j| (0..m).map(|i| dyv[i * n + j] as f64).sum()).collect();
        assert_close(&format!("bias gradient {label}"), &db, &want, 4e-7 * m as f64);
    }
}

#[test]
fn results_are_the_same_bits_on_a_second_run() {
    let client = client();
    let (rows, d_in, d_out) = (20_000u32, 128u32, 128u32);
    let xv = values((rows * d_in) as usize, 7);
    let dyv = values((rows * d_out) as usize, 8);
    let x = Matrix::upload(&client, &xv, rows, d_in).unwrap();
    let dy = Matrix::upload(&client, &dyv, rows, d_out).unwrap();
    assert_eq!(plan::splits(rows, 4, None), 64);
    let tu = Tuning::default();
    assert_eq!(plan::bias_blocks(rows), 157);
    let first = linear::weight_backward(&client, &x, &dy, F32, tu).unwrap().read(&client);
    let second = linear::weight_backward(&client, &x, &dy, F32, tu).unwrap().read(&client);
    assert!(first.iter().zip(&second).all(|(a, b)| a.to_bits() == b.to_bits()));
    let first = linear::bias_backward(&client, &dy).unwrap().read(&client);
    let second = linear::bias_backward(&client, &dy).unwrap().read(&client);
    assert!(first.iter().zip(&second).all(|(a, b)| a.to_bits() == b.to_bits()));
}

/// Every operation's outputs, on shapes that fill no tile, with one tile.
fn all_outputs(client: &Client, tiling: Tiling) -> Vec<Vec<f32>> {
    let tu = Tuning { tiling, split_len: None };
    let (rows, d_in, d_out) = (1_000u32, 70u32, 50u32);
    let x = Matrix::upload(client, &values((rows * d_in) as usize, 11), rows, d_in).unwrap();
    let w = Matrix::upload(client, &values((d_in * d_out) as usize, 12), d_in, d_out).unwrap();
    let b = Matrix::upload(client, &values(d_out as usize, 13), 1, d_out).unwrap();
    let dy = Matrix::upload(client, &values((rows * d_out) as usize, 14), rows, d_out).unwrap();
    let y = linear::forward(client, &x, &w, Some(&b.handle), true, F32, tu).unwrap();
    vec![
        y.read(client),
        linear::x_backward(client, &w, &dy, F32, tu).unwrap().read(client),
        linear::weight_backward(client, &x, &dy, F32, tu).unwrap().read(client),
        linear::bias_backward(client, &dy).unwrap().read(client),
        linear::relu_backward(client, &y, &dy).unwrap().read(client),
    ]
}

#[test]
fn checked_launches_give_the_same_bits_as_unchecked_ones() {
    // The kernels guard their own indices, so CubeCL's checks (a debugging aid) change
    // nothing. The setting is process-wide: another test running meanwhile may run checked,
    // which by this very property changes none of its results.
    let client = client();
    for tiling in Tiling::ALL {
        assert!(!checks::checked(), "unchecked is the default");
        let unchecked = all_outputs(&client, tiling);
        checks::set_checked(true);
        let checked = all_outputs(&client, tiling);
        checks::set_checked(false);
        for (op, (u, c)) in unchecked.iter().zip(&checked).enumerate() {
            assert_eq!(u.len(), c.len(), "operation {op}");
            assert!(
                u.iter().zip(c).all(|(a, b)| a.to_bits() == b.to_bits()),
                "operation {op} on {tiling:?}: checked and unchecked launches differ"
            );
        }
    }
}

#[test]
fn relu_keeps_nan_and_its_backward_masks_the_gradient() {
    let client = client();
    let tu = Tuning::default();
    // One row: x W + b with W = identity, so the ReLU sees the inputs themselves.
    let xv = [-2.0, -0.0, 0.0, 3.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e-30];
    let n = xv.len() as u32;
    let mut id = vec![0.0f32; (n * n) as usize];
    for i in 0..n as usize {
        id[i * n as usize + i] = 1.0;
    }
    // NaN and infinities times 0 give NaN in a product: compare the elementwise kernel alone
    // for those, and the fused ReLU on the finite entries.
    let finite: Vec<f32> = xv.iter().map(|v| if v.is_finite() { *v } else { 0.5 }).collect();
    let x = Matrix::upload(&client, &finite, 1, n).unwrap();
    let w = Matrix::upload(&client, &id, n, n).unwrap();
    let b = Matrix::upload(&client, &vec![0.0; n as usize], 1, n).unwrap();
    let y = linear::forward(&client, &x, &w, Some(&b.handle), true, F32, tu).unwrap().read(&client);
    let want: Vec<f64> = finite.iter().map(|v| (*v as f64).max(0.0)).collect();
    assert_close("fused ReLU", &y, &want, 0.0);

    let x = Matrix::upload(&client, &xv, 1, n).unwrap();
    let g = Matrix::upload(&client, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0], 1, n).unwrap();
    let got = linear::relu_backward(&client, &x, &g).unwrap().read(&client);
    assert_eq!(got, [0.0, 0.0, 0.0, 4.0, 5.0, 6.0, 0.0, 8.0]);
}

#[test]
fn mismatched_shapes_are_errors_that_name_the_operation() {
    let client = client();
    let tu = Tuning::default();
    let x = Matrix::upload(&client, &values(6, 1), 2, 3).unwrap();
    let w = Matrix::upload(&client, &values(8, 2), 4, 2).unwrap();
    let e = linear::forward(&client, &x, &w, None, false, F32, tu).unwrap_err().to_string();
    assert!(e.contains("linear forward") && e.contains("2 x 3") && e.contains("4 x 2"), "{e}");
    let e = linear::weight_backward(&client, &x, &w, F32, tu).unwrap_err().to_string();
    assert!(e.contains("weight gradient"), "{e}");
    let e = linear::x_backward(&client, &w, &x, F32, tu).unwrap_err().to_string();
    assert!(e.contains("input gradient"), "{e}");
    let e = Matrix::upload(&client, &values(5, 1), 2, 3).unwrap_err().to_string();
    assert!(e.contains("5 values for a 2 x 3"), "{e}");
}

/// bf16 products: on a device with tensor cores, the three products against an f64 reference of
/// the operands rounded to bf16 (their products are exact in f32, so only the f32 sums differ);
/// elsewhere each product is refused with an error that names it.
#[test]
fn bf16_products_match_the_rounded_reference_or_are_refused() {
    let client = client();
    let tu = Tuning::default();
    if !linear::bf16_supported(&client) {
        let x = Matrix::upload(&client, &values(4, 1), 2, 2).unwrap();
        let refusals = [
            (
                "linear forward",
                linear::forward(&client, &x, &x, None, false, Bf16, Tuning::default()),
            ),
            ("input gradient", linear::x_backward(&client, &x, &x, Bf16, Tuning::default())),
            ("weight gradient", linear::weight_backward(&client, &x, &x, Bf16, Tuning::default())),
        ];
        for (op, result) in refusals {
            let e = result.unwrap_err().to_string();
            assert!(e.contains(op) && e.contains("bf16") && e.contains("tensor cores"), "{e}");
        }
        eprintln!("this device has no bf16 tensor cores: checked the refusals only");
        return;
    }
    for (t, &(rows, d_in, d_out)) in SHAPES.iter().enumerate() {
        let (m, k, n) = (rows as usize, d_in as usize, d_out as usize);
        let xv = values(m * k, 600 + t as u64);
        let wv = values(k * n, 700 + t as u64);
        let bv = values(n, 800 + t as u64);
        let dyv = values(m * n, 900 + t as u64);
        let x = Matrix::upload(&client, &xv, rows, d_in).unwrap();
        let w = Matrix::upload(&client, &wv, d_in, d_out).unwrap();
        let b = Matrix::upload(&client, &bv, 1, d_out).unwrap();
        let dy = Matrix::upload(&client, &dyv, rows, d_out).unwrap();
        let label = format!("bf16 {rows}x{d_in}x{d_out}");
        // The operands as the product sees them: rounded where it takes the tensor cores.
        let seen = |v: &[f32], (m, n, k): (u32, u32, u32)| {
            if plan::takes_bf16(m, n, k) { rounded(v) } else { v.to_vec() }
        };

        let fwd = (rows, d_out, d_in);
        let y = linear::forward(&client, &x, &w, Some(&b.handle), true, Bf16, Tuning::default())
            .unwrap();
        let want: Vec<f64> = product(&seen(&xv, fwd), &seen(&wv, fwd), m, k, n)
            .iter()
            .enumerate()
            .map(|(e, v)| (v + bv[e % n] as f64).max(0.0))
            .collect();
        assert_close(&format!("relu(x W + b) {label}"), &y.read(&client), &want, 4e-7 * k as f64);

        let xb = (rows, d_in, d_out);
        let dx =
            linear::x_backward(&client, &w, &dy, Bf16, Tuning::default()).unwrap().read(&client);
        let want = product(&seen(&dyv, xb), &transpose(&seen(&wv, xb), k, n), m, n, k);
        assert_close(&format!("dY Wᵀ {label}"), &dx, &want, 4e-7 * n as f64);

        let wb = (d_in, d_out, rows);
        let dw = linear::weight_backward(&client, &x, &dy, Bf16, Tuning::default())
            .unwrap()
            .read(&client);
        let want = product(&transpose(&seen(&xv, wb), m, k), &seen(&dyv, wb), k, m, n);
        assert_close(&format!("Xᵀ dY {label}"), &dw, &want, 4e-7 * m as f64);

        // Rounding is what changed where the tensor cores ran.
        if plan::takes_bf16(rows, d_out, d_in) {
            let f32_y = linear::forward(&client, &x, &w, Some(&b.handle), true, F32, tu).unwrap();
            assert_ne!(f32_y.read(&client), y.read(&client), "{label}: bf16 gave the f32 result");
        }
    }
}
