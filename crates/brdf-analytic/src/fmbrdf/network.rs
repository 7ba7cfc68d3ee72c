//! Evaluation of the two FMBRDF helper networks in precision `T`, without allocation.
//!
//! * Smith Lambda network (fc1..fc4, 4 -> 300 -> 100 -> 50 -> 1, ReLU after every layer):
//!   input (alpha, beta, tan theta, alpha tan theta). For a fixed model only t = tan theta varies,
//!   so layer 1 is relu(b + k t) per unit and layer 2's pre-activation is piecewise linear in t,
//!   with a breakpoint where a layer-1 unit switches. The model stores, per interval between
//!   breakpoints, its line A + B t (computed in f64, exactly the same function); an evaluation
//!   is a binary search, 100 multiply-adds, then layers 3 and 4. This replaces ~18k of the
//!   ~19k multiply-adds per Lambda.
//! * Body-reflection network, intensity branch (fc_I1..fc_I4, 11 -> 200 -> 100 -> 100 -> 1, ReLU
//!   between layers, softplus output): input (n'' (3), l'' (3), eta, alpha, beta, kappa, n''.l'').
//!   l''_y is always 0 and (eta, alpha, beta, kappa) are fixed per model, so layer 1 keeps the six
//!   varying columns and a per-model bias.
//!
//! Dense layers run over W transposed ([in, out], contiguous per input): y = b, then for every
//! input i with x_i != 0, y += x_i W[:, i]. The inner loop is an elementwise update of fixed
//! length (no reduction), which LLVM vectorises, and inputs zeroed by the previous ReLU are
//! skipped (45 % to 90 % of the hidden activations are 0). With the Lambda folding, one BRDF
//! evaluation does ~10k instead of ~100k multiply-adds. Weights are converted to `T` on the fly
//! (exactly); every buffer is a fixed-size stack array.

use super::weights::{Layer, weights};
use angles::Real;
use std::sync::{Arc, OnceLock};

/// Hidden widths of the Lambda network.
const LAMBDA_H: [usize; 3] = [300, 100, 50];
/// Hidden widths of the body network.
const BODY_H: [usize; 3] = [200, 100, 100];
/// Columns of the body network's first layer that vary per evaluation: n''_x, n''_y, n''_z,
/// l''_x, l''_z and n''.l'' (column 4, l''_y, is always 0; 6..=9 are the parameters).
const BODY_VARYING: [usize; 6] = [0, 1, 2, 3, 5, 10];
/// PyTorch's `Softplus` default threshold: above it softplus(x) = x.
const SOFTPLUS_THRESHOLD: f64 = 20.0;
/// Lower end of the range of tan(theta) the Lambda network sees: the clamped cosine 1 - 1e-6
/// gives 1.414e-3, halved against rounding in `T`.
const T_MIN: f64 = 0.7e-3;
/// Upper end: the clamped cosine 1e-6 gives 1e6, doubled.
const T_MAX: f64 = 2e6;

/// The varying columns of the body network's first layer, transposed ([6][200]).
fn body_first_columns() -> &'static [Vec<f32>; 6] {
    static C: OnceLock<[Vec<f32>; 6]> = OnceLock::new();
    C.get_or_init(|| {
        let l = &weights().body[0];
        BODY_VARYING.map(|col| l.wt[col * l.n_out..(col + 1) * l.n_out].to_vec())
    })
}

/// Layers 1 and 2 of the Lambda network for fixed (alpha, beta), as an exact piecewise-linear
/// function of t = tan(theta): layer-1 unit i is relu(b_i + k_i t), so between two consecutive
/// breakpoints t = -b_i / k_i the set of active units is fixed and the layer-2 pre-activation is
/// z2(t) = A_j + B_j t with A_j = b2 + sum_active W2[:, i] b_i and B_j = sum_active W2[:, i] k_i.
/// Built in f64 (one sweep over the sorted breakpoints), stored in `T`.
#[derive(Debug, PartialEq)]
struct LambdaFold<T> {
    /// The sorted breakpoints in [T_MIN, T_MAX) of the layer-1 units.
    breaks: Vec<T>,
    /// For interval j (breaks[j - 1] < t <= breaks[j]): A_j then B_j, `LAMBDA_H[1]` values each.
    lines: Vec<T>,
}

impl<T: Real> LambdaFold<T> {
    fn new(alpha: f64, beta: f64) -> Self {
        const N2: usize = LAMBDA_H[1];
        let w = weights();
        let (l1, l2) = (&w.lambda[0], &w.lambda[1]);
        let col = |c: usize, i: usize| f64::from(l1.wt[c * l1.n_out + i]);
        let b: Vec<f64> = (0..l1.n_out)
            .map(|i| f64::from(l1.b[i]) + col(0, i) * alpha + col(1, i) * beta)
            .collect();
        let k: Vec<f64> = (0..l1.n_out).map(|i| col(2, i) + alpha * col(3, i)).collect();
        let mut a_j: Vec<f64> = l2.b.iter().map(|&x| f64::from(x)).collect();
        let mut b_j = vec![0.0; N2];
        let toggle = |i: usize, sign: f64, a_j: &mut [f64], b_j: &mut [f64]| {
            for ((a, bb), &w2) in a_j.iter_mut().zip(b_j.iter_mut()).zip(&l2.wt[i * N2..][..N2]) {
                *a += sign * f64::from(w2) * b[i];
                *bb += sign * f64::from(w2) * k[i];
            }
        };
        // Only t in [T_MIN, T_MAX] is ever asked for: start with the units active just above
        // T_MIN and keep the breakpoints in [T_MIN, T_MAX) (both decided from the same tau, so
        // every unit is toggled consistently; k > 0: on for t > tau, k < 0: on for t < tau).
        let tau = |i: usize| -b[i] / k[i];
        for i in 0..l1.n_out {
            let on = match k[i] {
                k if k > 0.0 => tau(i) < T_MIN,
                k if k < 0.0 => tau(i) >= T_MIN,
                _ => b[i] > 0.0,
            };
            if on {
                toggle(i, 1.0, &mut a_j, &mut b_j);
            }
        }
        let inside = |i: usize| k[i] != 0.0 && (T_MIN..T_MAX).contains(&tau(i));
        let mut order: Vec<usize> = (0..l1.n_out).filter(|&i| inside(i)).collect();
        order.sort_by(|&i, &j| tau(i).total_cmp(&tau(j)));
        let mut lines = Vec::with_capacity((order.len() + 1) * 2 * N2);
        lines.extend(a_j.iter().chain(&b_j).map(|&x| T::lit(x)));
        for &i in &order {
            // Crossing tau_i upwards switches unit i on (k > 0) or off (k < 0).
            toggle(i, k[i].signum(), &mut a_j, &mut b_j);
            lines.extend(a_j.iter().chain(&b_j).map(|&x| T::lit(x)));
        }
        Self { breaks: order.iter().map(|&i| T::lit(tau(i))).collect(), lines }
    }

    /// relu(z2(t)), the Lambda network's second hidden layer.
    #[inline]
    fn hidden2(&self, t: T, h2: &mut [T; LAMBDA_H[1]]) {
        const N2: usize = LAMBDA_H[1];
        let j = self.breaks.partition_point(|&x| x < t);
        let (a, b) = self.lines[j * 2 * N2..][..2 * N2].split_at(N2);
        for ((h, &a), &b) in h2.iter_mut().zip(a).zip(b) {
            *h = (a + b * t).max(T::zero());
        }
    }
}

/// Per-model parts of both networks: the Lambda network's first two layers folded for this
/// (alpha, beta) (shared between clones), and the body network's first-layer bias with the fixed
/// inputs (eta, alpha, beta, kappa) folded in.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Nets<T> {
    lambda: Arc<LambdaFold<T>>,
    body_b1: Vec<T>,
}

impl<T: Real> Nets<T> {
    /// Folds the fixed inputs (already clamped into their ranges) into the first layers.
    pub(crate) fn new(eta: T, alpha: T, beta: T, kappa: T) -> Self {
        Self {
            lambda: Arc::new(LambdaFold::new(alpha.to_f64_exact(), beta.to_f64_exact())),
            body_b1: body_bias(eta, alpha, beta, kappa),
        }
    }

    /// The same networks with new body inputs; alpha and beta must be those of `self`.
    pub(crate) fn with_body_params(&self, eta: T, alpha: T, beta: T, kappa: T) -> Self {
        Self { lambda: Arc::clone(&self.lambda), body_b1: body_bias(eta, alpha, beta, kappa) }
    }

    /// Lambda(theta) for tan(theta) = `tan_theta`.
    pub(crate) fn lambda(&self, tan_theta: T) -> T {
        let w = &weights().lambda;
        let zero = T::zero();
        let mut h2 = [zero; LAMBDA_H[1]];
        self.lambda.hidden2(tan_theta, &mut h2);
        let mut h3 = [zero; LAMBDA_H[2]];
        dense(&w[2], &h2, &mut h3, true);
        let mut out = [zero; 1];
        dense(&w[3], &h3, &mut out, true);
        out[0]
    }

    /// The body network's intensity output (>= 0) for the varying inputs
    /// [n''_x, n''_y, n''_z, l''_x, l''_z, n''.l''].
    pub(crate) fn body(&self, x: [T; 6]) -> T {
        let w = &weights().body;
        let zero = T::zero();
        let mut h1 = [zero; BODY_H[0]];
        h1.copy_from_slice(&self.body_b1);
        for (col, &xk) in body_first_columns().iter().zip(&x) {
            for (h, &c) in h1.iter_mut().zip(col) {
                *h = *h + T::from_f32(c) * xk;
            }
        }
        for h in &mut h1 {
            *h = h.max(zero);
        }
        let mut h2 = [zero; BODY_H[1]];
        dense(&w[1], &h1, &mut h2, true);
        let mut h3 = [zero; BODY_H[2]];
        dense(&w[2], &h2, &mut h3, true);
        let mut out = [zero; 1];
        dense(&w[3], &h3, &mut out, false);
        softplus(out[0])
    }
}

/// The body network's first-layer bias with the fixed inputs (eta, alpha, beta, kappa) folded in.
fn body_bias<T: Real>(eta: T, alpha: T, beta: T, kappa: T) -> Vec<T> {
    let b1 = &weights().body[0];
    let row = |o: usize, c: usize| T::from_f32(b1.wt[c * b1.n_out + o]);
    (0..b1.n_out)
        .map(|o| {
            T::from_f32(b1.b[o])
                + row(o, 6) * eta
                + row(o, 7) * alpha
                + row(o, 8) * beta
                + row(o, 9) * kappa
        })
        .collect()
}

/// PyTorch's softplus ln(1 + e^x) with its linear branch above the threshold 20.
#[inline]
pub(crate) fn softplus<T: Real>(x: T) -> T {
    if x > T::lit(SOFTPLUS_THRESHOLD) { x } else { x.exp().ln_1p() }
}

/// y = W x + b (then ReLU if `relu`), skipping the inputs that are exactly 0.
#[inline(always)]
fn dense<T: Real, const N: usize>(layer: &Layer, x: &[T], y: &mut [T; N], relu: bool) {
    debug_assert!(layer.n_in == x.len() && layer.n_out == N && layer.b.len() == N);
    for (yo, &b) in y.iter_mut().zip(&layer.b) {
        *yo = T::from_f32(b);
    }
    for (&xi, col) in x.iter().zip(layer.wt.chunks_exact(N)) {
        if xi != T::zero() {
            for (yo, &w) in y.iter_mut().zip(col) {
                *yo = *yo + T::from_f32(w) * xi;
            }
        }
    }
    if relu {
        for yo in y.iter_mut() {
            *yo = yo.max(T::zero());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Plain forward pass of a layer stack from the stored tensors (no folding), in f64.
    fn plain(layers: &[Layer], x: &[f64], last: fn(f64) -> f64) -> f64 {
        let mut h = x.to_vec();
        for (i, l) in layers.iter().enumerate() {
            h = (0..l.n_out)
                .map(|o| {
                    let s = (0..l.n_in).map(|k| l.wt[k * l.n_out + o] as f64 * h[k]).sum::<f64>()
                        + l.b[o] as f64;
                    if i + 1 < layers.len() { s.max(0.0) } else { last(s) }
                })
                .collect();
        }
        h[0]
    }

    #[test]
    fn folded_layers_match_plain_forward() {
        let w = weights();
        for (alpha, beta) in [(0.001, 0.5), (0.35, 1.3), (2.0, 4.0), (std::f64::consts::TAU, 2.2)] {
            let nets = Nets::<f64>::new(1.7, alpha, beta, 2.5);
            // A log grid over the whole tan range, plus both sides of every breakpoint.
            let mut ts: Vec<f64> = (0..=300).map(|i| 1e-3 * 10f64.powf(i as f64 / 50.0)).collect();
            for &b in &nets.lambda.breaks {
                ts.extend([b, b * (1.0 - 1e-9), b * (1.0 + 1e-9)].into_iter().filter(|t| *t > 0.0));
            }
            for t in ts {
                let expect = plain(&w.lambda, &[alpha, beta, t, alpha * t], |s| s.max(0.0));
                let got = nets.lambda(t);
                assert!(
                    (got - expect).abs() <= 1e-10 * expect.max(1.0),
                    "t {t}: {got} vs {expect}"
                );
            }
        }
        let (eta, alpha, beta, kappa) = (1.7, 0.35, 1.3, 2.5);
        let nets = Nets::<f64>::new(eta, alpha, beta, kappa);
        let n = [0.3, -0.2, -0.93];
        let l = [0.6, 0.0, -0.8];
        let nl = n[0] * l[0] + n[2] * l[2];
        let x = [n[0], n[1], n[2], l[0], l[1], l[2], eta, alpha, beta, kappa, nl];
        let expect = plain(&w.body, &x, |s| s.exp().ln_1p());
        let got = nets.body([n[0], n[1], n[2], l[0], l[2], nl]);
        assert!((got - expect).abs() <= 1e-12 * expect, "{got} vs {expect}");
    }

    #[test]
    fn dense_skips_zeros_exactly() {
        let layer = Layer {
            wt: (0..12).map(|i| i as f32 * 0.5 - 2.0).collect(),
            b: vec![1.0; 3],
            n_in: 4,
            n_out: 3,
        };
        let x = [1.5_f64, 0.0, -2.0, 3.0];
        let mut y = [0.0; 3];
        dense(&layer, &x, &mut y, false);
        for (o, yo) in y.iter().enumerate() {
            let expect: f64 = 1.0 + (0..4).map(|i| layer.wt[i * 3 + o] as f64 * x[i]).sum::<f64>();
            assert_eq!(*yo, expect);
        }
        let mut r = [0.0; 3];
        dense(&layer, &x, &mut r, true);
        assert_eq!(r, y.map(|v| v.max(0.0)));
        assert_eq!(softplus(30.0_f64), 30.0);
        assert!((softplus(0.0_f64) - 2f64.ln()).abs() < 1e-15);
        assert_eq!(softplus(-200.0_f32), 0.0);
    }
}
