//! Directional albedo by cosine-weighted Monte Carlo, with a standard error.
//!
//! The directional albedo of a BRDF for light direction l is
//! a(l) = int f(l, v) cos(theta_v) dv over the upper hemisphere. With v drawn from the
//! cosine-weighted density p(v) = cos(theta_v) / pi (Malley's method) the estimator is
//! a ~ (pi / N) sum f(l, v_i), per channel, and its standard error is the sample standard
//! deviation over sqrt(N). By reciprocity this is also the energy reflected towards v = l, the
//! quantity the paper's energy-conservation analysis thresholds at 1 (spec section 7).
//!
//! Deterministic for a seed: the random numbers come from SplitMix64.

use crate::brdf::Brdf;
use angles::{Real, Vec3};
use stdx::rng::SplitMix64;

/// A Monte Carlo estimate per RGB channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlbedoEstimate {
    /// Estimated directional albedo.
    pub mean: [f64; 3],
    /// Standard error of the mean.
    pub std_error: [f64; 3],
    /// Number of samples.
    pub samples: usize,
}

impl AlbedoEstimate {
    /// Whether every channel is at most `bound` within `sigmas` standard errors.
    pub fn at_most(&self, bound: f64, sigmas: f64) -> bool {
        (0..3).all(|c| self.mean[c] - sigmas * self.std_error[c] <= bound)
    }
}

/// A cosine-weighted direction about +z from two uniforms (Malley's method):
/// v = (sqrt(u1) cos 2 pi u2, sqrt(u1) sin 2 pi u2, sqrt(1 - u1)).
pub fn cosine_sample(u1: f64, u2: f64) -> Vec3<f64> {
    let r = u1.sqrt();
    let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
    [r * c, r * s, (1.0 - u1).max(0.0).sqrt()]
}

/// Estimates the directional albedo of `brdf` for the local-frame light direction `l` with
/// `samples` cosine-weighted view directions. Evaluation is in `T`, accumulation in f64.
pub fn directional_albedo<T: Real, B: Brdf<T> + ?Sized>(
    brdf: &B,
    l: Vec3<T>,
    samples: usize,
    seed: u64,
) -> AlbedoEstimate {
    let mut rng = SplitMix64::new(seed);
    // Welford's running mean and sum of squared deviations: no cancellation for near-constant
    // integrands (a Lambertian BRDF gives a standard error of exactly 0).
    let mut mean = [0.0_f64; 3];
    let mut m2 = [0.0_f64; 3];
    for k in 0..samples {
        let v = cosine_sample(rng.next_f64(), rng.next_f64());
        let f = brdf.eval(l, v.map(T::lit));
        for c in 0..3 {
            let x = std::f64::consts::PI * f[c].to_f64_exact();
            let delta = x - mean[c];
            mean[c] += delta / (k + 1) as f64;
            m2[c] += delta * (x - mean[c]);
        }
    }
    let n = samples.max(1) as f64;
    let std_error = m2.map(|m| (m.max(0.0) / (n - 1.0).max(1.0) / n).sqrt());
    AlbedoEstimate { mean, std_error, samples }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Lambert, LambertParams};

    #[test]
    fn lambert_albedo_is_its_parameter() {
        let m = Lambert::new(LambertParams { albedo: [0.25_f64, 0.5, 0.9] });
        let e = directional_albedo(&m, [0.0, 0.6, 0.8], 10_000, 7);
        // Constant integrand: zero variance, exact up to rounding.
        for (c, a) in [0.25, 0.5, 0.9].into_iter().enumerate() {
            assert!((e.mean[c] - a).abs() < 1e-12, "{e:?}");
            assert!(e.std_error[c] < 1e-9);
        }
    }

    #[test]
    fn cosine_samples_are_unit_and_upper() {
        let mut r = SplitMix64::new(1);
        for _ in 0..1000 {
            let v = cosine_sample(r.next_f64(), r.next_f64());
            assert!((angles::vec3::length(v) - 1.0).abs() < 1e-12 && v[2] >= 0.0);
        }
    }
}
