//! Shared microfacet physics: local geometry of a direction pair, Fresnel terms, the GGX (GTR2)
//! distribution and the Smith-GGX visibility term.
//!
//! Everything here is written for numerical robustness in f32: the GGX denominator uses
//! sin^2 + alpha^2 cos^2 rather than 1 + (alpha^2 - 1) cos^2 (no cancellation at theta_h = 0), and
//! the Smith term is used in its visibility form G1(w) / (2 n.w), which stays finite at n.w = 0.

use angles::{Real, Vec3};

/// Smallest GGX alpha used anywhere (alpha = roughness^2 is clamped to at least this), so that
/// roughness 0 gives a very sharp but finite lobe: D <= 1 / (pi alpha_min^2) ~ 3.2e5.
pub const ALPHA_MIN: f64 = 1e-3;

/// Cosines of a local-frame direction pair with its half vector h = (l + v)/|l + v|.
#[derive(Clone, Copy, Debug)]
pub struct PairGeometry<T> {
    /// n.l = l_z.
    pub nl: T,
    /// n.v = v_z.
    pub nv: T,
    /// n.h.
    pub nh: T,
    /// l.h = v.h = cos(theta_d), computed as |l + v| / 2 (exact for unit vectors).
    pub lh: T,
    /// sin^2(theta_h), computed from the tangential part of h.
    pub sin2_h: T,
}

impl<T: Real> PairGeometry<T> {
    /// Geometry of the pair, or `None` unless both directions are strictly above the horizon.
    #[inline(always)]
    pub fn of(l: Vec3<T>, v: Vec3<T>) -> Option<Self> {
        let zero = T::zero();
        if !(l[2] > zero && v[2] > zero) {
            return None;
        }
        let a = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
        let txy = a[0] * a[0] + a[1] * a[1];
        let len2 = txy + a[2] * a[2];
        // l.z, v.z > 0 implies a.z > 0, hence len2 > 0 (barring underflow: handled below).
        let len = len2.sqrt();
        let nh = if len > zero { (a[2] / len).min(T::one()) } else { T::one() };
        // For unit l, v: l.h = (1 + l.v) / |l + v| = |l + v| / 2, which is symmetric in l and v.
        let lh = (T::lit(0.5) * len).min(T::one());
        let sin2_h = if len2 > zero { txy / len2 } else { zero };
        Some(Self { nl: l[2].min(T::one()), nv: v[2].min(T::one()), nh, lh, sin2_h })
    }
}

/// Schlick's weight (1 - u)^5 with u clamped into [0, 1].
#[inline(always)]
pub fn schlick_weight<T: Real>(u: T) -> T {
    let m = (T::one() - u).max(T::zero()).min(T::one());
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's Fresnel approximation F0 + (1 - F0)(1 - cos)^5.
#[inline(always)]
pub fn fresnel_schlick<T: Real>(f0: T, cos: T) -> T {
    f0 + (T::one() - f0) * schlick_weight(cos)
}

/// Unpolarized dielectric Fresnel reflectance (R_s + R_p)/2 for incidence cosine `cos_i` from
/// outside into a medium of relative index `eta` (> 0), as the official FMBRDF code writes it.
#[inline]
pub fn fresnel_dielectric<T: Real>(cos_i: T, eta: T) -> T {
    let one = T::one();
    let cos_i = cos_i.max(T::zero()).min(one);
    let a = eta.recip();
    let sin_i = (one - cos_i * cos_i).max(T::zero()).sqrt();
    let sin_t = (a * sin_i).min(one);
    let cos_t = (one - sin_t * sin_t).max(T::zero()).sqrt();
    let rs = safe_ratio(a * cos_i - cos_t, a * cos_i + cos_t);
    let rp = safe_ratio(cos_i - a * cos_t, cos_i + a * cos_t);
    T::lit(0.5) * (rs * rs + rp * rp)
}

/// num / den, or 1 (total reflection limit) when den is 0.
#[inline(always)]
fn safe_ratio<T: Real>(num: T, den: T) -> T {
    if den != T::zero() { num / den } else { T::one() }
}

/// The GGX (Trowbridge-Reitz, GTR2) distribution D(h) = alpha^2 / (pi (cos^2 (alpha^2 - 1) + 1)^2),
/// written as alpha^2 / (pi (sin^2 + alpha^2 cos^2)^2) with cos^2 = 1 - sin^2 of theta_h.
#[inline(always)]
pub fn ggx_d<T: Real>(sin2_h: T, alpha: T) -> T {
    let a2 = alpha * alpha;
    let cos2 = T::one() - sin2_h;
    let t = sin2_h + a2 * cos2;
    a2 / (T::PI() * t * t)
}

/// Smith-GGX visibility of one direction, G1(w) / (2 n.w) = 1 / (c + sqrt(alpha^2 + c^2 - alpha^2 c^2))
/// with c = n.w (Disney's `smithG_GGX`). Bounded by 1/alpha.
#[inline(always)]
pub fn smith_ggx_visibility<T: Real>(c: T, alpha: T) -> T {
    let a2 = alpha * alpha;
    let c2 = c * c;
    (c + (a2 + c2 - a2 * c2).sqrt()).recip()
}

/// Smith-GGX masking G1(w) = 2 c / (c + sqrt(alpha^2 + (1 - alpha^2) c^2)).
#[inline(always)]
pub fn smith_ggx_g1<T: Real>(c: T, alpha: T) -> T {
    T::lit(2.0) * c * smith_ggx_visibility(c, alpha)
}

/// GGX alpha from perceptual roughness: max(roughness^2, [`ALPHA_MIN`]).
#[inline(always)]
pub fn alpha_from_roughness<T: Real>(roughness: T) -> T {
    (roughness * roughness).max(T::lit(ALPHA_MIN))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ggx_is_normalized() {
        // int D(h) cos(theta_h) d omega_h = 1, by midpoint quadrature in theta_h.
        for alpha in [0.05_f64, 0.3, 1.0] {
            let n = 200_000;
            let dt = std::f64::consts::FRAC_PI_2 / n as f64;
            let s: f64 = (0..n)
                .map(|i| {
                    let t = (i as f64 + 0.5) * dt;
                    ggx_d(t.sin().powi(2), alpha) * t.cos() * t.sin() * dt
                })
                .sum::<f64>()
                * 2.0
                * std::f64::consts::PI;
            assert!((s - 1.0).abs() < 1e-4, "alpha {alpha}: {s}");
        }
    }

    #[test]
    fn fresnel_limits() {
        // Normal incidence: ((eta - 1)/(eta + 1))^2; grazing: 1.
        let eta = 1.5_f64;
        assert!((fresnel_dielectric(1.0, eta) - 0.04).abs() < 1e-12);
        assert!((fresnel_dielectric(0.0, eta) - 1.0).abs() < 1e-12);
        assert_eq!(schlick_weight(1.0_f32), 0.0);
        assert_eq!(fresnel_schlick(0.04_f64, 0.0), 1.0);
        assert!((smith_ggx_g1(1.0_f64, 0.5) - 1.0).abs() < 1e-15);
        assert_eq!(smith_ggx_g1(0.0_f64, 0.5), 0.0);
    }
}
