//! Small test utilities: a seeded random generator, a scoped-thread parallel map, samplers.

use super::reference::RefParams;
use brdf_analytic::{FmbrdfParams, Real};
use std::f64::consts::TAU;

/// The workspace's seeded SplitMix64 generator (`next_f64` is uniform in [0, 1)).
pub use stdx::rng::SplitMix64 as Rng;

pub use crate::common::par_map;

/// Uniform direction on the upper hemisphere (uniform in solid angle).
pub fn hemisphere(rng: &mut Rng) -> [f64; 3] {
    let z = rng.next_f64();
    let phi = TAU * rng.next_f64();
    let r = (1.0 - z * z).max(0.0).sqrt();
    [r * phi.cos(), r * phi.sin(), z]
}

/// Cosine-weighted direction on the upper hemisphere (Malley's method).
pub fn cosine_hemisphere(rng: &mut Rng) -> [f64; 3] {
    brdf_analytic::albedo::cosine_sample(rng.next_f64(), rng.next_f64())
}

pub fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|x| x / n)
}

/// The `q`-quantile (0..=1) of `values` (sorted in place).
pub fn quantile(values: &mut [f64], q: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    values[((values.len() - 1) as f64 * q).round() as usize]
}

/// Random parameters over the whole ranges (alpha log-uniform, k_s log-uniform on [0.01, 100]),
/// each at one of its ends with probability 0.1 per end.
pub fn random_params(rng: &mut Rng) -> RefParams {
    let mut pick = |lo: f64, hi: f64, log: bool| {
        let u = rng.next_f64();
        if u < 0.1 {
            lo
        } else if u > 0.9 {
            hi
        } else if log {
            (lo.ln() + (hi.ln() - lo.ln()) * rng.next_f64()).exp()
        } else {
            lo + (hi - lo) * rng.next_f64()
        }
    };
    RefParams {
        eta: pick(1.1, 2.5, false),
        rho: [pick(0.0, 1.0, false), pick(0.0, 1.0, false), pick(0.0, 1.0, false)],
        k_s: pick(0.01, 100.0, true),
        alpha: pick(0.001, TAU, true),
        beta: pick(0.5, 4.0, false),
        kappa: pick(0.0, 100.0, false),
    }
}

pub fn params_t<T: Real>(p: &RefParams) -> FmbrdfParams<T> {
    FmbrdfParams {
        eta: T::lit(p.eta),
        rho: p.rho.map(T::lit),
        k_s: T::lit(p.k_s),
        alpha: T::lit(p.alpha),
        beta: T::lit(p.beta),
        kappa: T::lit(p.kappa),
    }
}

/// A pair near the mirror configuration (h within ~2 alpha of n), so the specular term matters.
pub fn near_mirror(rng: &mut Rng, alpha: f64) -> ([f64; 3], [f64; 3]) {
    let v = hemisphere(rng);
    let t = (2.0 * alpha * rng.next_f64()).min(1.2);
    let phi = TAU * rng.next_f64();
    let h = normalize([t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos()]);
    let vh = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
    (normalize([2.0 * vh * h[0] - v[0], 2.0 * vh * h[1] - v[1], 2.0 * vh * h[2] - v[2]]), v)
}

/// Directions for the stress test: every combination of these polar cosines and azimuths.
pub fn adversarial_directions() -> Vec<[f64; 3]> {
    let zs: [f64; 18] = [
        0.0,
        1e-300,
        1e-45,
        1e-40,
        1e-30,
        1e-20,
        1e-12,
        1e-9,
        1e-7,
        1e-6,
        1.5e-6,
        1e-5,
        1e-3,
        0.1,
        0.5,
        0.999_999,
        1.0 - 1e-12,
        1.0,
    ];
    let mut out = Vec::new();
    for z in zs {
        let r = (1.0 - z * z).max(0.0).sqrt();
        for phi in [0.0_f64, 37.0, 90.0, 180.0, 217.0, 270.0] {
            let (s, c) = phi.to_radians().sin_cos();
            out.push([r * c, r * s, z]);
        }
    }
    out
}

/// Every parameter at both ends of its range (64 sets) plus the defaults.
pub fn extreme_params() -> Vec<RefParams> {
    let mut out = Vec::new();
    for bits in 0..64u32 {
        let b = |k: u32| bits >> k & 1 == 1;
        out.push(RefParams {
            eta: if b(0) { 2.5 } else { 1.1 },
            rho: [if b(1) { 1.0 } else { 0.0 }; 3],
            k_s: if b(2) { 100.0 } else { 0.0 },
            alpha: if b(3) { TAU } else { 0.001 },
            beta: if b(4) { 4.0 } else { 0.5 },
            kappa: if b(5) { 100.0 } else { 0.0 },
        });
    }
    let d = FmbrdfParams::<f64>::default();
    out.push(RefParams {
        eta: d.eta,
        rho: d.rho,
        k_s: d.k_s,
        alpha: d.alpha,
        beta: d.beta,
        kappa: d.kappa,
    });
    out
}
