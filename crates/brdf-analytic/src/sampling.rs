//! Importance sampling shared by the models: the lobe samplers, their densities, and the
//! one-sample mixture that combines them.
//!
//! Every sampler maps two uniforms in [0, 1)^2 to a direction in the local frame (normal +z) and
//! comes with its density in 1/sr. The lobes: the cosine-weighted hemisphere (Malley's method),
//! GGX visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", written
//! as pbrt-v4's `TrowbridgeReitzDistribution::Sample_wm`) reflected about the sampled normal,
//! a cos^N lobe about an axis (Realistic Phong) and the GTR1 normal distribution (Burley 2012,
//! Disney's clear coat). A model with several lobes picks one with probabilities from a cheap
//! estimate of each lobe's albedo ([`lobe_probabilities`]), samples it, and reports the mixture
//! density sum_i p_i pdf_i(l): one-sample multiple importance sampling with the balance
//! heuristic (Veach 1997, section 9.2.4), so the weight f cos / pdf is unbiased whichever lobe
//! drew l. Every lobe a model lists keeps a probability of at least [`MIN_LOBE_PROBABILITY`],
//! so that the cosine lobe, whose support is the whole hemisphere, bounds the weights wherever
//! the model's estimate is off. A reflected direction below the horizon is no sample: the
//! density then integrates over the hemisphere to the success probability, below 1. The models compute the returned density with the same code as their
//! [`crate::Brdf::pdf`], from the sampled direction, so the two agree bit for bit.

use crate::brdf::{Brdf, BrdfSample};
use crate::microfacet::{ggx_d, smith_ggx_visibility};
use angles::vec3::{cross, dot, normalize_or_zero};
use angles::{Real, Vec3};

/// Smallest probability with which a mixture picks any of its lobes.
pub const MIN_LOBE_PROBABILITY: f64 = 0.05;

/// Whether `w` lies strictly above the horizon (w.z > 0; false for NaN).
#[inline(always)]
pub fn above_horizon<T: Real>(w: Vec3<T>) -> bool {
    w[2] > T::zero()
}

/// `u` clamped into [0, 1 - eps/2] (the largest value below 1 in `T`); NaN becomes 0.
#[inline(always)]
pub fn clamp_uniform<T: Real>(u: T) -> T {
    let top = T::one() - T::lit(0.5) * T::epsilon();
    if u > T::zero() { u.min(top) } else { T::zero() }
}

/// A cosine-weighted direction about +z (Malley's method): the uniform disk point
/// (sqrt(u0) cos 2 pi u1, sqrt(u0) sin 2 pi u1) lifted onto the hemisphere. With `u0` in
/// [0, 1) the result has z > 0.
#[inline]
pub fn cosine_hemisphere<T: Real>(u: [T; 2]) -> Vec3<T> {
    let r = u[0].sqrt();
    let (s, c) = (T::TAU() * u[1]).sin_cos();
    [r * c, r * s, (T::one() - u[0]).max(T::zero()).sqrt()]
}

/// The density cos(theta) / pi of [`cosine_hemisphere`] for a direction with n.l = `cos_theta`
/// (0 below the horizon).
#[inline(always)]
pub fn cosine_pdf<T: Real>(cos_theta: T) -> T {
    cos_theta.max(T::zero()) * T::FRAC_1_PI()
}

/// The cosine density of `l` for the pair (v, l): 0 unless both are above the horizon.
#[inline(always)]
pub(crate) fn cosine_pdf_pair<T: Real>(v: Vec3<T>, l: Vec3<T>) -> T {
    if l[2] > T::zero() && v[2] > T::zero() { cosine_pdf(l[2]) } else { T::zero() }
}

/// The default [`Brdf::sample`]: a cosine-weighted direction, weight f cos / pdf = f pi.
pub(crate) fn sample_cosine<T: Real, B: Brdf<T> + ?Sized>(
    brdf: &B,
    v: Vec3<T>,
    u: [T; 2],
) -> Option<BrdfSample<T>> {
    if !above_horizon(v) {
        return None;
    }
    let l = cosine_hemisphere(u.map(clamp_uniform));
    finish(brdf, v, l, cosine_pdf_pair(v, l))
}

/// The sample for direction `l` with density `pdf`: `None` unless l is above the horizon and
/// the density is positive and finite; weight = f(l, v) cos(theta_l) / pdf.
#[inline]
pub(crate) fn finish<T: Real, B: Brdf<T> + ?Sized>(
    brdf: &B,
    v: Vec3<T>,
    l: Vec3<T>,
    pdf: T,
) -> Option<BrdfSample<T>> {
    if !(l[2] > T::zero() && pdf > T::zero() && pdf.is_finite()) {
        return None;
    }
    let f = brdf.eval(l, v);
    let s = l[2] / pdf;
    let weight = f.map(|x| x * s);
    weight.iter().all(|w| w.is_finite()).then_some(BrdfSample { l, weight, pdf })
}

/// One sample of the two-lobe mixture Torrance-Sparrow and FMBRDF use: the cosine hemisphere
/// (lobe 0) or the reflection of `v` about a GGX visible normal of `alpha` (lobe 1), chosen with
/// `probabilities(n.v)`; the density is `mixture_pdf(l)`, the balance-heuristic mixture.
pub(crate) fn sample_cosine_or_ggx<T: Real, B: Brdf<T> + ?Sized>(
    brdf: &B,
    v: Vec3<T>,
    u: [T; 2],
    probabilities: impl FnOnce(T) -> [T; 2],
    alpha: T,
    mixture_pdf: impl FnOnce(Vec3<T>) -> T,
) -> Option<BrdfSample<T>> {
    if !above_horizon(v) {
        return None;
    }
    let (k, u0) = pick_lobe(probabilities(v[2].min(T::one())), clamp_uniform(u[0]));
    let u = [u0, clamp_uniform(u[1])];
    let l = if k == 0 { cosine_hemisphere(u) } else { reflect(v, ggx_visible_normal(v, alpha, u)) };
    finish(brdf, v, l, mixture_pdf(l))
}

/// The mirror direction of `v` about the unit normal `h`: 2 (v.h) h - v.
#[inline(always)]
pub fn reflect<T: Real>(v: Vec3<T>, h: Vec3<T>) -> Vec3<T> {
    let d = T::lit(2.0) * dot(v, h);
    [d * h[0] - v[0], d * h[1] - v[1], d * h[2] - v[2]]
}

/// Two unit tangents completing the unit vector `n` to a right-handed orthonormal basis
/// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited"; no branch on the axis).
#[inline]
pub fn orthonormal_basis<T: Real>(n: Vec3<T>) -> (Vec3<T>, Vec3<T>) {
    let one = T::one();
    let sign = if n[2] >= T::zero() { one } else { -one };
    let a = -(sign + n[2]).recip();
    let b = n[0] * n[1] * a;
    ([one + sign * n[0] * n[0] * a, sign * b, -sign * n[0]], [b, sign + n[1] * n[1] * a, -n[1]])
}

/// A GGX microfacet normal drawn from the distribution of normals visible from `v`,
/// D_v(m) = G1(v) max(0, v.m) D(m) / (n.v) (Heitz 2018), as pbrt-v4's `Sample_wm` writes it:
/// stretch v to the unit-roughness configuration, sample the projected hemisphere, unstretch.
/// `v` must be a unit vector with `v.z > 0`; the result is a unit vector with z > 0.
#[inline]
pub fn ggx_visible_normal<T: Real>(v: Vec3<T>, alpha: T, u: [T; 2]) -> Vec3<T> {
    let (zero, one) = (T::zero(), T::one());
    let wh = normalize_or_zero([alpha * v[0], alpha * v[1], v[2]]);
    // pbrt-v4 switches to a fixed tangent when wh.z >= 0.99999; the tangent along v's azimuth
    // keeps the map continuous in v, so f32 and f64 draw the same normal from the same u. Only
    // a v within ~1e-19 (f32) of the normal, where the squared length underflows, uses (1, 0, 0).
    let txy2 = wh[0] * wh[0] + wh[1] * wh[1];
    let t1 = if txy2 > T::min_positive_value() {
        let inv = txy2.sqrt().recip();
        [-wh[1] * inv, wh[0] * inv, zero]
    } else {
        [one, zero, zero]
    };
    let t2 = cross(wh, t1);
    let r = u[0].sqrt();
    let (s, c) = (T::TAU() * u[1]).sin_cos();
    let (px, py) = (r * c, r * s);
    let h = (one - px * px).max(zero).sqrt();
    let t = T::lit(0.5) * (one + wh[2]);
    let py = (one - t) * h + t * py;
    let pz = (one - px * px - py * py).max(zero).sqrt();
    let nh = [0, 1, 2].map(|i| px * t1[i] + py * t2[i] + pz * wh[i]);
    normalize_or_zero([alpha * nh[0], alpha * nh[1], nh[2].max(T::lit(1e-6))])
}

/// The density in 1/sr of l = reflect(v, m) for m drawn by [`ggx_visible_normal`]:
/// D_v(m) / (4 v.m) = D(m) G1(v) / (4 n.v) = D(m) V(v) / 2, with V(v) = G1(v) / (2 n.v) the
/// visibility form of [`smith_ggx_visibility`] (finite as n.v -> 0). Arguments are n.v and
/// sin^2(theta_h) of the half vector of (l, v).
#[inline(always)]
pub fn ggx_reflection_pdf<T: Real>(nv: T, sin2_h: T, alpha: T) -> T {
    T::lit(0.5) * ggx_d(sin2_h, alpha) * smith_ggx_visibility(nv, alpha)
}

/// A direction about the unit `axis` with density (N + 1) / (2 pi) cos^N(angle to the axis) over
/// the sphere of directions: cos = u0^(1/(N+1)), computed as 1 - cos = -expm1(ln(u0) / (N + 1))
/// so that narrow lobes (large N) keep their angular resolution.
#[inline]
pub fn phong_lobe<T: Real>(axis: Vec3<T>, exponent: T, u: [T; 2]) -> Vec3<T> {
    let one = T::one();
    let one_minus_cos = (-(u[0].ln() / (exponent + one)).exp_m1()).max(T::zero()).min(one);
    let cos = one - one_minus_cos;
    let sin = (one_minus_cos * (T::lit(2.0) - one_minus_cos)).max(T::zero()).sqrt();
    let (sp, cp) = (T::TAU() * u[1]).sin_cos();
    let (t1, t2) = orthonormal_basis(axis);
    [0, 1, 2].map(|i| sin * (cp * t1[i] + sp * t2[i]) + cos * axis[i])
}

/// The density (N + 1) / (2 pi) cos^N of [`phong_lobe`] for a direction at cosine `cos` to the
/// axis (0 for cos <= 0).
#[inline(always)]
pub fn phong_lobe_pdf<T: Real>(cos: T, exponent: T) -> T {
    if cos > T::zero() {
        (exponent + T::one()) * T::FRAC_1_PI() * T::lit(0.5) * cos.min(T::one()).powf(exponent)
    } else {
        T::zero()
    }
}

/// A microfacet normal drawn with density D(m) cos(theta_m) for Burley's GTR1 distribution
/// D = (a^2 - 1) / (pi ln(a^2) (1 + (a^2 - 1) cos^2)), `a2` = a^2 in (0, 1):
/// cos^2 = (1 - a2^(1 - u0)) / (1 - a2), and sin^2 = (a2^(1 - u0) - a2) / (1 - a2) alongside
/// (no cancellation near the pole).
#[inline]
pub fn gtr1_normal<T: Real>(a2: T, u: [T; 2]) -> Vec3<T> {
    let (zero, one) = (T::zero(), T::one());
    let p = a2.powf(one - u[0]);
    let den = one - a2;
    let cos = ((one - p) / den).max(zero).min(one).sqrt();
    let sin = ((p - a2) / den).max(zero).min(one).sqrt();
    let (sp, cp) = (T::TAU() * u[1]).sin_cos();
    [sin * cp, sin * sp, cos]
}

/// The density D(m) cos(theta_m) of [`gtr1_normal`] for a normal with sin^2(theta_m) = `sin2`,
/// in the form 1 + (a2 - 1) cos^2 = sin^2 + a2 cos^2.
#[inline(always)]
pub fn gtr1_normal_pdf<T: Real>(sin2: T, a2: T) -> T {
    let cos2 = (T::one() - sin2).max(T::zero());
    let norm = (a2 - T::one()) / (T::PI() * a2.ln());
    norm * cos2.sqrt() / (sin2 + a2 * cos2)
}

/// Lobe-selection probabilities from non-negative weights (estimates of each lobe's albedo):
/// p_i = p_min + (1 - N p_min) w_i / sum(w), with p_min = [`MIN_LOBE_PROBABILITY`]; equal
/// probabilities when every weight is 0 (negative, NaN and infinite weights count as 0).
#[inline]
pub fn lobe_probabilities<T: Real, const N: usize>(weights: [T; N]) -> [T; N] {
    let w = weights.map(|x| if x > T::zero() && x.is_finite() { x } else { T::zero() });
    let sum = w.iter().fold(T::zero(), |a, &b| a + b);
    let n = T::lit(N as f64);
    if !(sum > T::zero() && sum.is_finite()) {
        return [n.recip(); N];
    }
    let floor = T::lit(MIN_LOBE_PROBABILITY);
    let scale = (T::one() - n * floor) / sum;
    w.map(|x| floor + x * scale)
}

/// Picks a lobe with the probabilities `p` (summing to 1) from the uniform `u0`, and returns its
/// index with `u0` rescaled to a fresh uniform in [0, 1) (clamped). A lobe of probability 0 is
/// never picked, even when rounding leaves the sum of `p` just below `u0`.
#[inline]
pub fn pick_lobe<T: Real, const N: usize>(p: [T; N], u0: T) -> (usize, T) {
    let mut start = T::zero();
    let mut last = 0;
    for (i, &pi) in p.iter().enumerate() {
        if pi > T::zero() {
            if u0 < start + pi {
                return (i, clamp_uniform((u0 - start) / pi));
            }
            start = start + pi;
            last = i;
        }
    }
    (last, clamp_uniform(T::one()))
}

/// The arithmetic mean of an RGB triple (the lobe weights' colour-blind summary).
#[inline(always)]
pub(crate) fn mean3<T: Real>(c: [T; 3]) -> T {
    (c[0] + c[1] + c[2]) / T::lit(3.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::PairGeometry;
    use crate::quadrature::gauss_legendre;
    use std::f64::consts::PI;

    /// int over the sphere (or the upper hemisphere) of `pdf(direction)` by Gauss-Legendre in
    /// (cos theta, phi), split into `bands` bands of cos theta (denser towards +z, where lobes
    /// about +z concentrate) and 32 sectors of phi (to resolve kinks such as max(0, v.m)).
    fn integrate(upper_only: bool, bands: usize, pdf: impl Fn([f64; 3]) -> f64) -> f64 {
        let rule = gauss_legendre(24);
        let lo = if upper_only { 0.0 } else { -1.0 };
        let sectors = 32;
        let dphi = 2.0 * PI / sectors as f64;
        let mut total = 0.0;
        for b in 0..bands {
            let edge = |k: usize| 1.0 - (1.0 - lo) * (1.0 - k as f64 / bands as f64).powi(4);
            let (z0, z1) = (edge(b), edge(b + 1));
            for &(xz, wz) in &rule {
                let z = 0.5 * (z0 + z1) + 0.5 * (z1 - z0) * xz;
                let r = (1.0 - z * z).max(0.0).sqrt();
                for k in 0..sectors {
                    for &(xp, wp) in &rule {
                        let phi = dphi * (k as f64 + 0.5 * (xp + 1.0));
                        let d = [r * phi.cos(), r * phi.sin(), z];
                        total += 0.5 * (z1 - z0) * wz * 0.5 * dphi * wp * pdf(d);
                    }
                }
            }
        }
        total
    }

    #[test]
    fn densities_integrate_to_one() {
        assert!((integrate(true, 4, |d| cosine_pdf(d[2])) - 1.0).abs() < 1e-12);
        for n in [1.0, 30.0, 1e3] {
            let s = integrate(false, 64, |d| phong_lobe_pdf(d[2], n));
            assert!((s - 1.0).abs() < 1e-6, "phong N = {n}: {s}");
        }
        for a in [0.1_f64, 0.01] {
            let a2 = a * a;
            let s = integrate(true, 64, |d| gtr1_normal_pdf(1.0 - d[2] * d[2], a2));
            assert!((s - 1.0).abs() < 1e-6, "gtr1 a = {a}: {s}");
        }
        // D_v(m) = D(m) G1(v) (v.m) / (n.v) integrates to 1 over the normals visible from v.
        for alpha in [0.1_f64, 0.5, 1.0] {
            for theta_v in [0.0, 1.0, 1.5] {
                let v = [f64::sin(theta_v), 0.0, f64::cos(theta_v)];
                let s = integrate(true, 32, |m| {
                    let vm = dot(v, m);
                    if vm <= 0.0 {
                        return 0.0;
                    }
                    let g1 = 2.0 * v[2] * smith_ggx_visibility(v[2], alpha);
                    ggx_d(1.0 - m[2] * m[2], alpha) * g1 * vm / v[2]
                });
                assert!((s - 1.0).abs() < 1e-6, "vndf alpha {alpha} theta {theta_v}: {s}");
            }
        }
    }

    #[test]
    fn samplers_return_unit_vectors_on_their_support() {
        let grid = [0.0, 1e-7, 0.25, 0.5, 0.999, clamp_uniform(1.0_f64)];
        let v = [0.6, 0.0, 0.8];
        for &a in &grid {
            for &b in &grid {
                let u = [a, b];
                let c = cosine_hemisphere(u);
                let m = ggx_visible_normal(v, 0.3, u);
                let p = phong_lobe([0.0, 0.6, 0.8], 20.0, u);
                let g = gtr1_normal(0.01, u);
                for w in [c, m, p, g] {
                    assert!((angles::vec3::length(w) - 1.0).abs() < 1e-12, "{u:?}: {w:?}");
                }
                assert!(c[2] > 0.0 && m[2] > 0.0 && g[2] >= 0.0);
            }
        }
        let (t1, t2) = orthonormal_basis([0.0, 0.0, -1.0_f64]);
        assert!(dot(t1, t2).abs() < 1e-15 && (dot(cross(t1, t2), [0.0, 0.0, -1.0]) - 1.0) < 1e-15);
    }

    #[test]
    fn visible_normal_matches_its_density_by_moments() {
        // The reflected direction's density D V / 2, integrated against l.z and against 1,
        // equals the sample means (the success rate and E[l.z; l.z > 0]).
        let (alpha, theta_v) = (0.4_f64, 1.2_f64);
        let v = [theta_v.sin(), 0.0, theta_v.cos()];
        let mut rng = stdx::rng::SplitMix64::new(5);
        let n = 400_000;
        let (mut hits, mut z_sum) = (0.0, 0.0);
        for _ in 0..n {
            let m = ggx_visible_normal(v, alpha, [rng.next_f64(), rng.next_f64()]);
            let l = reflect(v, m);
            if l[2] > 0.0 {
                hits += 1.0;
                z_sum += l[2];
            }
        }
        let pdf = |l: [f64; 3]| match PairGeometry::of(l, v) {
            Some(g) => ggx_reflection_pdf(g.nv, g.sin2_h, alpha),
            None => 0.0,
        };
        let p_hit = integrate(true, 32, pdf);
        let z_mean = integrate(true, 32, |l| pdf(l) * l[2]);
        let se = (p_hit * (1.0 - p_hit) / n as f64).sqrt();
        assert!(
            (hits / n as f64 - p_hit).abs() < 5.0 * se + 1e-4,
            "{} vs {p_hit}",
            hits / n as f64
        );
        assert!((z_sum / n as f64 - z_mean).abs() < 2e-3, "{} vs {z_mean}", z_sum / n as f64);
        assert!(p_hit < 1.0 && p_hit > 0.5);
    }

    #[test]
    fn lobe_selection() {
        let p = lobe_probabilities([1.0_f64, 3.0, 0.0]);
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert_eq!(p[2], MIN_LOBE_PROBABILITY);
        assert!((p[1] - (0.05 + 0.85 * 0.75)).abs() < 1e-15);
        assert_eq!(lobe_probabilities([0.0_f32, f32::NAN]), [0.5, 0.5]);
        let p = [0.25_f64, 0.5, 0.25];
        assert_eq!(pick_lobe(p, 0.0), (0, 0.0));
        assert_eq!(pick_lobe(p, 0.125), (0, 0.5));
        assert_eq!(pick_lobe(p, 0.5), (1, 0.5));
        let (k, u) = pick_lobe(p, clamp_uniform(1.0));
        assert!(k == 2 && u < 1.0);
        // A zero-probability lobe is skipped, also past a sum that rounds below u0.
        assert_eq!(pick_lobe([0.5_f64, 0.0, 0.5], 0.5).0, 2);
        assert_eq!(pick_lobe([0.5_f64, 0.49, 0.0], 0.995).0, 1);
        assert_eq!(clamp_uniform(f32::NAN), 0.0);
        assert!(clamp_uniform(1.0_f32) < 1.0);
    }
}
