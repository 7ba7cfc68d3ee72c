//! Gauss-Legendre quadrature, shared by the FMBRDF normalisation here and its tensor twin in
//! `brdf-neural` (one rule, so the two agree).

use std::f64::consts::PI;

/// Gauss-Legendre nodes and weights on [-1, 1], `n` points, by Newton iteration on the Legendre
/// recurrence (accurate to a few ulp for the small `n` used here).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let legendre = |x: f64| {
        // (P_n(x), P_{n-1}(x))
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let kf = k as f64;
            (p0, p1) = (p1, ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf);
        }
        (p1, p0)
    };
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, q) = legendre(x);
                let dp = n as f64 * (x * p - q) / (x * x - 1.0);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (p, q) = legendre(x);
            let dp = n as f64 * (x * p - q) / (x * x - 1.0);
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_exactly() {
        // An n-point rule is exact for degree 2n - 1: int_{-1}^{1} x^k dx.
        let rule = gauss_legendre(8);
        for k in 0..16 {
            let got: f64 = rule.iter().map(|(x, w)| w * x.powi(k)).sum();
            let expect = if k % 2 == 1 { 0.0 } else { 2.0 / (k as f64 + 1.0) };
            assert!((got - expect).abs() < 1e-14, "x^{k}: {got} vs {expect}");
        }
    }
}
