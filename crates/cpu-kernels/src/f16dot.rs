//! f32 matrix products through binary16 multiply-adds (AVX512-FP16).
//!
//! Intel's CPUs from Sapphire Rapids on run `vfmadd231ph`, 32 binary16 multiply-adds per
//! instruction, at the rate of the f32 FMA's 16: twice the products of f32, where their
//! `vdpbf16ps` runs at a quarter rate and gains nothing (`examples/instruction_rates.rs` prints
//! all three rates). The hardware sums in binary16, so this path keeps the sums short and the
//! operands in range; its value, for an m x k by k x n product, is defined as:
//!
//! 1. k is cut into parts ([`parts`], a function of the shape only: one part unless the product
//!    is a weight gradient, a long k into a small output).
//! 2. Within a part, row i of the left operand is scaled by 2^ea_i and column j of the right by
//!    2^eb_j, the powers of two that put each one's largest magnitude in [8, 16)
//!    ([`scale_exp`]), then rounded to binary16 (to nearest, ties to even). Every product of two
//!    such values is at most 256 in magnitude, every sum of [`RUN`] of them about 2^14 at most, well
//!    within binary16's 65,504; a power of two changes no bits of a significand.
//! 3. The part's k are taken in runs of [`RUN`] from its start: each run's products are summed
//!    in binary16 by fused multiply-adds in k order from +0, and the runs' sums are added in f32
//!    in order from +0.
//! 4. The part's f32 sum is multiplied by 2^-ea_i, then by 2^-eb_j (f32); the parts' values are
//!    added in f32 in part order, then the epilogue follows.
//!
//! binary16's significand has 11 bits to bfloat16's 8: an operand's rounding is 8 times
//! smaller than in [`crate::bf16dot`], and a run's sum adds at most [`RUN`] roundings of 2^-11
//! relative to its partial sums (about 8 of them in a random walk). The value depends on the
//! operands and the shape only, never on the thread count. [`emulated_row_major`] computes the
//! same bits on any CPU (slowly), so the kernel is tested against it to the bit; CPUs without
//! AVX512-FP16 run the emulation.
//!
//! The kernel (`f16dot_x86`) computes a tile of 12 rows x 32 columns: 12 binary16 accumulators
//! (one run), 24 f32 accumulators (the whole part). The left operand's 12 rows are read one
//! binary16 at a time, broadcast from memory by the multiply-add itself; the right operand is
//! packed in panels of 32 columns, one k a 64-byte row.

use crate::{Epilogue, MatRef};
use alloc::vec;
use alloc::vec::Vec;

/// k summed in binary16 before a run's sum joins the f32 sum: 64 widens the accumulators
/// half as often as 32 (each widening costs about 7 instructions of the 64 multiply-adds).
pub const RUN: usize = 64;
/// A product with at least this k, into an output of at most 16 k elements, is split over k.
const SPLIT_MIN_K: usize = 2048;
/// k per part of a split product (a multiple of [`RUN`]), and at most this many parts.
const PART_K: usize = 1024;
const MAX_PARTS: usize = 32;

/// Whether this CPU runs binary16 multiply-adds natively (AVX512-FP16); otherwise the f16
/// precision is emulated.
pub fn f16_native() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512bw")
            && std::is_x86_feature_detected!("avx512vl")
            && std::is_x86_feature_detected!("avx512fp16")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// How an m x k by k x n product is cut over k: (parts, k per part, a multiple of [`RUN`]).
pub fn parts(m: usize, n: usize, k: usize) -> (usize, usize) {
    if k < SPLIT_MIN_K || m.saturating_mul(n) > k.saturating_mul(16) {
        return (1, k.max(1));
    }
    let parts = (k / PART_K).clamp(1, MAX_PARTS);
    let per = k.div_ceil(parts).next_multiple_of(RUN);
    (k.div_ceil(per), per)
}

/// The exponent e that puts `amax` * 2^e in [8, 16); 0 for zero, NaN or infinity.
pub fn scale_exp(amax: f32) -> i32 {
    if !(amax.is_finite() && amax > 0.0) {
        return 0;
    }
    let e = if amax >= f32::MIN_POSITIVE {
        ((amax.to_bits() >> 23) as i32) - 127
    } else {
        amax.log2().floor() as i32
    };
    (3 - e).clamp(-120, 120)
}

/// 2^e as f32, for |e| <= 126.
#[inline]
pub fn pow2(e: i32) -> f32 {
    f32::from_bits(((e + 127) as u32) << 23)
}

/// `x` rounded to binary16 (nearest, ties to even; overflow to infinity), as f64.
pub fn round_f16(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let e = ((((x.to_bits() >> 52) & 0x7ff) as i32) - 1023).max(-14);
    let q = f64::from_bits(((e - 10 + 1023) as u64) << 52);
    let r = (x / q).round_ties_even() * q;
    if r.abs() > 65504.0 { f64::INFINITY.copysign(x) } else { r }
}

/// binary16's fused multiply-add `round16(a b + c)` on binary16 values held in f64: the
/// product is exact in f64, the sum is rounded to odd and then to binary16, which is one
/// correct rounding (53 bits hold binary16's 11 and two more).
pub fn fma_f16(a: f64, b: f64, c: f64) -> f64 {
    let p = a * b;
    let s = p + c;
    if !s.is_finite() {
        return s;
    }
    // Knuth's two-sum: the exact error of s.
    let bv = s - p;
    let err = (p - (s - bv)) + (c - bv);
    let odd = if err != 0.0 && s.to_bits() & 1 == 0 {
        let up = (err > 0.0) == (s > 0.0);
        f64::from_bits(if up { s.to_bits() + 1 } else { s.to_bits() - 1 })
    } else {
        s
    };
    round_f16(odd)
}

/// The row scales' exponents of rows `0..m` of `op` over k in `k0..k1` (`col_major`: of its
/// columns, for the right operand).
fn exps(count: usize, k0: usize, k1: usize, op: MatRef, columns: bool) -> Vec<i32> {
    (0..count)
        .map(|i| {
            let amax = (k0..k1)
                .map(|kk| unsafe { if columns { op.at(kk, i) } else { op.at(i, kk) } }.abs())
                .fold(0f32, f32::max);
            scale_exp(amax)
        })
        .collect()
}

/// The defined value ([module docs](self)) on any CPU, one element at a time.
///
/// # Safety
/// As [`matmul_f16`]; `out` holds m n floats.
unsafe fn emulated(m: usize, n: usize, k: usize, lhs: MatRef, rhs: MatRef, out: &mut [f32]) {
    out.fill(0.0);
    let (count, per) = parts(m, n, k);
    for p in 0..count {
        let (k0, k1) = (p * per, ((p + 1) * per).min(k));
        let ea = exps(m, k0, k1, lhs, false);
        let eb = exps(n, k0, k1, rhs, true);
        let a: Vec<f64> = (0..m * (k1 - k0))
            .map(|x| {
                let (i, kk) = (x / (k1 - k0), k0 + x % (k1 - k0));
                round_f16((unsafe { lhs.at(i, kk) } * pow2(ea[i])) as f64)
            })
            .collect();
        let b: Vec<f64> = (0..(k1 - k0) * n)
            .map(|x| {
                let (kk, j) = (k0 + x / n, x % n);
                round_f16((unsafe { rhs.at(kk, j) } * pow2(eb[j])) as f64)
            })
            .collect();
        for i in 0..m {
            for j in 0..n {
                let mut s = 0f32;
                let mut r0 = 0;
                while r0 < k1 - k0 {
                    let mut h = 0f64;
                    for kk in r0..(r0 + RUN).min(k1 - k0) {
                        h = fma_f16(a[i * (k1 - k0) + kk], b[kk * n + j], h);
                    }
                    s += h as f32;
                    r0 += RUN;
                }
                let v = (s * pow2(-ea[i])) * pow2(-eb[j]);
                out[i * n + j] = if p == 0 { v } else { out[i * n + j] + v };
            }
        }
    }
}

/// The emulated path on row-major operands (what CPUs without AVX512-FP16 run), public so
/// that tests on any machine can check it: `a` is m x k, `b` is k x n, the result m x n.
///
/// # Panics
/// If the slice lengths do not match the shapes.
pub fn emulated_row_major(m: usize, n: usize, k: usize, a: &[f32], b: &[f32]) -> Vec<f32> {
    assert!(a.len() == m * k && b.len() == k * n, "f16dot::emulated_row_major: shapes");
    let mut out = vec![0f32; m * n];
    let lhs = MatRef { ptr: a.as_ptr(), rs: k as isize, cs: 1 };
    let rhs = MatRef { ptr: b.as_ptr(), rs: n as isize, cs: 1 };
    // SAFETY: the views address exactly the checked slices.
    unsafe { emulated(m, n, k, lhs, rhs, &mut out) };
    out
}

/// out (m x n, row-major, every element written; it may start uninitialised) =
/// epilogue(lhs (m x k) * rhs (k x n)) in the f16 precision of the [module docs](self).
///
/// # Safety
/// `lhs` and `rhs` must address valid m x k and k x n matrices, `out` m * n writable floats;
/// the epilogue's bias, if any, holds n values.
#[allow(clippy::too_many_arguments)]
pub unsafe fn matmul_f16(
    m: usize,
    n: usize,
    k: usize,
    lhs: MatRef,
    rhs: MatRef,
    out: *mut f32,
    epilogue: Epilogue,
) {
    if m == 0 || n == 0 {
        return;
    }
    if k == 0 {
        unsafe { core::ptr::write_bytes(out, 0, m * n) };
    } else {
        #[cfg(target_arch = "x86_64")]
        if f16_native() {
            unsafe { crate::f16dot_x86::matmul(m, n, k, lhs, rhs, out, epilogue) };
            return;
        }
        unsafe { emulated(m, n, k, lhs, rhs, core::slice::from_raw_parts_mut(out, m * n)) };
    }
    unsafe { epilogue.apply_rows(m, n, out) };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_to_binary16() {
        assert_eq!(round_f16(1.0), 1.0);
        assert_eq!(round_f16(1.0 + 2f64.powi(-11)), 1.0); // a tie, to even
        assert_eq!(round_f16(1.0 + 3.0 * 2f64.powi(-11)), 1.0 + 2.0 * 2f64.powi(-10));
        assert_eq!(round_f16(65504.0), 65504.0);
        assert_eq!(round_f16(65519.0), 65504.0);
        assert_eq!(round_f16(65520.0), f64::INFINITY);
        assert_eq!(round_f16(2f64.powi(-24)), 2f64.powi(-24)); // the smallest subnormal
        assert_eq!(round_f16(2f64.powi(-25)), 0.0); // a tie, to even (zero)
        assert_eq!(round_f16(1.5 * 2f64.powi(-25)), 2f64.powi(-24));
    }

    #[test]
    fn fused_multiply_add_rounds_once() {
        let a = 1.0 + 2f64.powi(-10);
        assert_eq!(fma_f16(a, a, 0.0), 1.0 + 2f64.powi(-9)); // 2^-20 of the product dropped
        assert_eq!(fma_f16(1.0, 2f64.powi(-11), 1.0), 1.0); // a tie, to even
        assert_eq!(fma_f16(2f64.powi(-20), 2f64.powi(-20), 1.0), 1.0);
        // Just above the tie: rounded once, up (two roundings would give 1).
        assert_eq!(fma_f16(2f64.powi(-11), a, 1.0), a);
        assert_eq!(fma_f16(-2.0, 3.0, 6.0).to_bits(), 0f64.to_bits()); // +0
    }

    #[test]
    fn scales_put_the_largest_magnitude_in_8_to_16() {
        for amax in [1e-30f32, 1e-7, 0.3, 1.0, 7.99, 8.0, 15.9, 16.0, 1e6, 1e30] {
            let v = amax * pow2(scale_exp(amax));
            assert!((8.0..16.0).contains(&v), "{amax}: {v}");
        }
        assert_eq!(scale_exp(0.0), 0);
        assert_eq!(scale_exp(f32::NAN), 0);
    }

    #[test]
    fn parts_depend_on_the_shape() {
        assert_eq!(parts(8192, 128, 128), (1, 128));
        let (count, per) = parts(128, 128, 8192);
        assert_eq!((count, per), (8, 1024));
        assert_eq!(per % RUN, 0);
        let (count, per) = parts(64, 3, 8200);
        assert!(count * per >= 8200 && (count - 1) * per < 8200 && per % RUN == 0);
    }

    #[test]
    fn emulation_is_close_to_f64() {
        let (m, n, k) = (5, 7, 300);
        let a: Vec<f32> = (0..m * k).map(|x| ((x * 37 % 101) as f32 - 50.0) * 0.013).collect();
        let b: Vec<f32> = (0..k * n).map(|x| ((x * 53 % 97) as f32 - 48.0) * 0.0007).collect();
        let got = emulated_row_major(m, n, k, &a, &b);
        for i in 0..m {
            for j in 0..n {
                let (mut exact, mut mag) = (0f64, 0f64);
                for kk in 0..k {
                    let p = a[i * k + kk] as f64 * b[kk * n + j] as f64;
                    exact += p;
                    mag += p.abs();
                }
                let err = (got[i * n + j] as f64 - exact).abs();
                assert!(err <= mag * 2e-3, "({i}, {j}): {} against {exact}", got[i * n + j]);
            }
        }
    }
}
