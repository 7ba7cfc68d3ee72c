//! The Fresnel Microfacet BRDF (FMBRDF) with its two pretrained helper networks.

pub(crate) mod geometry;
mod network;
pub(crate) mod quadrature;
pub(crate) mod weights;

use crate::brdf::{Brdf, BrdfSample, Rgb};
use crate::microfacet::{ALPHA_MIN, PairGeometry};
use crate::params::{ParamError, check, check_rgb, clamp_or, clamp_rgb};
use crate::sampling::{
    cosine_pdf, ggx_reflection_pdf, lobe_probabilities, mean3, sample_cosine_or_ggx,
};
use angles::vec3::try_normalize;
use angles::{Real, Vec3};
use geometry::{COS_EPS, DEN_EPS, body_features, fresnel, smith_tan};
use network::Nets;
use std::fmt;

/// Range and default of the refractive index eta.
const ETA: (f64, f64, f64) = (1.1, 2.5, 1.5);
/// Range and default of each channel of the body albedo rho.
const RHO: (f64, f64, f64) = (0.0, 1.0, 0.5);
/// Range and default of the specular scale k_s.
const K_S: (f64, f64, f64) = (0.0, 100.0, 1.0);
/// Range and default of the distribution width alpha (radians).
const ALPHA: (f64, f64, f64) = (0.001, std::f64::consts::TAU, 0.3);
/// Range and default of the distribution shape beta.
const BETA: (f64, f64, f64) = (0.5, 4.0, 2.0);
/// Range and default of the body network's extra input kappa.
const KAPPA: (f64, f64, f64) = (0.0, 100.0, 0.0);

/// Parameters of [`Fmbrdf`].
///
/// | parameter | range | unit | default |
/// | --- | --- | --- | --- |
/// | `eta` | [1.1, 2.5] | - | 1.5 |
/// | `rho` | [0, 1]^3 | - | 0.5 |
/// | `k_s` | [0, 100] | - | 1 |
/// | `alpha` | [0.001, 2 pi] | rad | 0.3 |
/// | `beta` | [0.5, 4] | - | 2 |
/// | `kappa` | [0, 100] | - | 0 |
///
/// The ranges of eta, alpha, beta and kappa are the official code's clamps. The official code
/// only asks rho >= 0 and k_s >= 0 (its MERL fits use rho = albedo_ratio k_s, unbounded):
/// * rho is capped at 1, the project's sigmoid output. It scales the body network's output, and
///   at rho = 1 the body term alone reflects 0.84 of the incident energy at normal incidence and
///   less towards grazing (see [`Fmbrdf`], "Energy"), so [0, 1] spans dark to white bodies.
/// * k_s is capped at 100: the specular lobe is weighted by the dielectric Fresnel factor, whose
///   normal-incidence value ((eta - 1)/(eta + 1))^2 is 0.0023 to 0.18 over the eta range, so a
///   fitted k_s well above 1 is legitimate (a bright specular on a low-index material needs
///   k_s ~ 1/F0 = 25 at eta = 1.5); 100 leaves room for that while keeping every value finite
///   in f32 (see [`Fmbrdf`], "Numerics").
///
/// Sampling: not exact (B is a network and the generalized Gaussian has no closed-form inverse).
/// A one-sample mixture (balance heuristic) of the cosine-weighted hemisphere (body) and GGX
/// visible normals reflected about the sampled normal (specular), picked with probabilities
/// from 0.8 mean(rho) (the body's albedo scale) against k_s F(n.v; eta), each at least 5 %;
/// pdf = the mixture density. The GGX proxy takes alpha = the width alpha clamped into
/// [0.001, 1]: the same angular scale (not the same shape: GGX's tails are heavier, which keeps
/// the weights bounded), and for widths far above 1 rad, where the generalized Gaussian is nearly
/// flat, GGX at alpha = 1 is flat too (D = 1/pi). The weight f cos / pdf carries the mismatch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FmbrdfParams<T> {
    /// Refractive index eta of the dielectric (relative to the outside medium).
    pub eta: T,
    /// Body (subsurface) albedo rho, linear RGB; multiplies the body network's output.
    pub rho: Rgb<T>,
    /// Specular scale k_s (one scalar for all channels).
    pub k_s: T,
    /// Width alpha of the generalized Gaussian distribution of microfacet polar angles, radians.
    pub alpha: T,
    /// Shape beta of the generalized Gaussian (2 is Gaussian in theta_h, 1 exponential).
    pub beta: T,
    /// The body network's extra input kappa (unnamed in the official code, which keeps it at 0).
    pub kappa: T,
}

impl<T: Real> Default for FmbrdfParams<T> {
    fn default() -> Self {
        Self {
            eta: T::lit(ETA.2),
            rho: [T::lit(RHO.2); 3],
            k_s: T::lit(K_S.2),
            alpha: T::lit(ALPHA.2),
            beta: T::lit(BETA.2),
            kappa: T::lit(KAPPA.2),
        }
    }
}

/// The Fresnel Microfacet BRDF, intensity (unpolarised) part:
///
/// ```text
/// f(l, v) = G(l, v) [ I_s + rho I_b ] / (n.l + eps)
/// I_s     = k_s P(h) F(v.h; eta) / (4 (n.v)(n.h) + eps)
/// I_b     = B(n'', l''; eta, alpha, beta, kappa)
/// P(h)    = c exp(-(theta_h / alpha)^beta) cos(theta_h)
/// 1/c     = 2 pi int_0^{pi/2} exp(-(t / alpha)^beta) cos(t) sin(t) dt
/// G(l, v) = 1 / ((1 + Lambda(theta_l)) (1 + Lambda(theta_v)))
/// ```
///
/// with eps = 1e-9 (the official code's guards), h = (l + v)/|l + v|, F the unpolarised dielectric
/// Fresnel reflectance (R_s + R_p)/2, and two pretrained networks of the official implementation:
/// Lambda, the Smith function of the generalized Gaussian (input alpha, beta, tan theta,
/// alpha tan theta), and B, the body (subsurface) radiance per unit irradiance, which already
/// contains the foreshortening cos(theta_l) that the division by n.l removes. Both terms are
/// radiances per unit irradiance in the official code; dividing by n.l gives the BRDF, as its
/// MERL fitting does. Returns 0 unless n.l > 0 and n.v > 0.
///
/// Ichikawa et al., "Fresnel Microfacet BRDF: Unification of Polari-Radiometric Surface-Body
/// Reflection", CVPR 2023; official code kyotovision-public/fmbrdf (MIT). The network weights
/// ship with this crate (`assets/fmbrdf/`, MIT, Copyright (c) 2023 kyotovision-public, values
/// unchanged). Parameters: [`FmbrdfParams`] (eta, rho, k_s, alpha, beta, kappa; table there).
///
/// **Frames.** Everything but B is written in the local frame (normal +z). B is evaluated, as in
/// the official code, in a view-aligned frame: frame 1 rotates u = -v onto +z with
/// R = Rx(-rot_x) Ry(-rot_y), rot_y = atan2(u_x, u_z), rot_x = -asin(u_y) (so v' = (0, 0, -1) and
/// n'_z, l'_z < 0); frame 2 then rotates about z by -atan2(l'_y, l'_x) so that l'' lies in the
/// x-z plane with l''_x >= 0. The network input is (n'', l'', eta, alpha, beta, kappa, n''.l'').
/// Theta angles use the official clamps: theta_{l,v} = acos(clamp(n.w, 1e-6, 1 - 1e-6)) for
/// Lambda, theta_h = acos(clamp(n.h, 0, 1 - 1e-6)) and cos r = clamp(v.h, 0, 1 - 1e-6). The
/// implementation builds the rotations without trigonometry and takes theta_h from atan2, which
/// keeps narrow lobes accurate in f32; it agrees with a literal f64 evaluation of the official
/// formulas to 4e-8 relative (1,748 random and fixed configurations).
///
/// **Normalisation.** c depends only on (alpha, beta) and is computed once in [`Fmbrdf::new`],
/// in f64, by 24-node Gauss-Legendre quadrature on [0, min(pi/2, alpha 40^(1/beta))] after the
/// substitution theta = theta_max u^2: relative error below 1e-8 over the whole (alpha, beta)
/// range (16 nodes: 1.5e-5, 20 nodes: 5e-7, 22 nodes: 4e-8). The official 100,000-step rectangle
/// rule agrees with it to 3.3e-7 for alpha >= 0.01; it carries its own O(h^2) error, 1.3e-10
/// absolute, which reaches 4.6e-5 relative at alpha = 0.001, where this value is the exact one.
///
/// **Reciprocity.** Not reciprocal: B sees l and v asymmetrically (view-aligned frame). Measured at
/// the default parameters over 4,000 random upper-hemisphere pairs (uniform in solid angle), the
/// relative difference |f(l, v) - f(v, l)| / mean has median 0.42 %, 90th percentile 12 % and
/// maximum 197 % (grazing pairs), the order the spec reports (0.4 %, 13 %).
///
/// **Energy.** Not guaranteed to conserve energy (k_s and rho are free scales). Directional
/// albedo (cosine-weighted Monte Carlo, 20,000 samples) at theta_l = 0, 45, 75, 85 deg:
/// 0.46, 0.47, 0.51, 0.58 at the default parameters; body term alone (rho = 1, k_s = 0) 0.84,
/// 0.83, 0.71, 0.63; specular term alone (k_s = 1) 0.04, 0.05, 0.15, 0.27.
///
/// **Numerics.** Finite and >= 0 for every pair of unit vectors and every parameter in range, in
/// f32 and f64 (tested on 10^6 random and adversarial pairs at all 64 combinations of range
/// ends): tan theta is at most 1e6 (the official clamp), the specular denominator is
/// 4 (n.v)(n.h) + 1e-9, and the final division uses n.l + 1e-9 (the official MERL conversion,
/// the same constant in f32 and f64), so the result is at most 1e9 G (...) even as n.l -> 0,
/// far inside the f32 range. Inputs that are not unit vectors within 16 ulp are renormalised;
/// zero or non-finite ones give 0. f32 agrees with f64 to a median 1.6e-7 and 99th percentile
/// 1.1e-4 relative (max 1.8e-4 for alpha >= 0.01; up to ~1e-2 for alpha ~ 0.001 at grazing
/// mirror pairs, where rounding the input directions to f32 alone moves theta_h by 1e-3 alpha).
/// For l = v the second frame rotation is the identity (atan2(0, 0) = 0); B is not
/// rotation-invariant there, so f jumps by up to 2.9 % (default parameters) between l = v and
/// its immediate neighbours: a property of the network.
///
/// **Cost.** About 2 us per evaluation in f32 and 3 us in f64 (release, one core): the Smith
/// network's first two layers are folded into a piecewise-linear function of tan theta at
/// construction, and the dense layers skip inputs zeroed by ReLU. [`Fmbrdf::new`] takes ~30 us;
/// [`Fmbrdf::with_params`] (same alpha, beta) under 1 us.
#[derive(Clone, PartialEq)]
pub struct Fmbrdf<T> {
    params: FmbrdfParams<T>,
    c: T,
    theta_h_min: T,
    nets: Nets<T>,
}

impl<T: Real> fmt::Debug for Fmbrdf<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Fmbrdf").field("params", &self.params).field("c", &self.c).finish()
    }
}

impl<T: Real> Fmbrdf<T> {
    /// Builds the model, clamping every parameter into its range (NaN becomes the default), and
    /// computes the normalisation c(alpha, beta).
    pub fn new(params: FmbrdfParams<T>) -> Self {
        let p = clamp_params(params);
        let c = quadrature::normalization(p.alpha.to_f64_exact(), p.beta.to_f64_exact());
        Self {
            params: p,
            c: T::lit(c),
            theta_h_min: T::lit((1.0 - COS_EPS).acos()),
            nets: Nets::new(p.eta, p.alpha, p.beta, p.kappa),
        }
    }

    /// The model with other parameters, clamped as in [`Self::new`]. When alpha and beta are
    /// unchanged (one distribution per object, the other parameters per point) it reuses this
    /// model's normalisation and folded Smith network, which makes it ~50 times cheaper than
    /// [`Self::new`].
    pub fn with_params(&self, params: FmbrdfParams<T>) -> Self {
        let p = clamp_params(params);
        if p.alpha != self.params.alpha || p.beta != self.params.beta {
            return Self::new(p);
        }
        Self {
            params: p,
            c: self.c,
            theta_h_min: self.theta_h_min,
            nets: self.nets.with_body_params(p.eta, p.alpha, p.beta, p.kappa),
        }
    }

    /// Builds the model, rejecting any parameter outside its range (or NaN). The range ends are
    /// rounded to `T` first (in f32, 2 pi rounds up to `f32::consts::TAU`), as in [`Self::new`].
    pub fn try_new(params: FmbrdfParams<T>) -> Result<Self, ParamError> {
        const M: &str = "FMBRDF";
        let r = |range: (f64, f64, f64)| {
            (T::lit(range.0).to_f64_exact(), T::lit(range.1).to_f64_exact())
        };
        let ((e0, e1), (r0, r1), (k0, k1)) = (r(ETA), r(RHO), r(K_S));
        let ((a0, a1), (b0, b1), (q0, q1)) = (r(ALPHA), r(BETA), r(KAPPA));
        check(M, "eta", params.eta, e0, e1)?;
        check_rgb(M, "rho", params.rho, r0, r1)?;
        check(M, "k_s", params.k_s, k0, k1)?;
        check(M, "alpha", params.alpha, a0, a1)?;
        check(M, "beta", params.beta, b0, b1)?;
        check(M, "kappa", params.kappa, q0, q1)?;
        Ok(Self::new(params))
    }

    /// The parameters in use (after clamping).
    pub fn params(&self) -> &FmbrdfParams<T> {
        &self.params
    }

    /// The normalisation constant c of the microfacet distribution P(h).
    pub fn normalization(&self) -> T {
        self.c
    }

    /// The Smith Lambda network's value for a direction with n.w = `cos_theta` (clamped into
    /// [1e-6, 1 - 1e-6]), at this model's alpha and beta.
    pub fn smith_lambda(&self, cos_theta: T) -> T {
        self.nets.lambda(smith_tan(cos_theta))
    }

    /// The shipped network tensors as (name, PyTorch shape, row-major values), names
    /// `shadowing.fc1.weight` ... `body_reflection.fc_I4.bias` (format and licence in the crate's
    /// `assets/fmbrdf/NOTICE.md`), for tensor re-implementations of the model.
    pub fn network_tensors()
    -> impl Iterator<Item = (&'static str, &'static [usize], &'static [f32])> {
        weights::weights().raw.iter().map(|(n, s, v)| (*n, *s, v.as_slice()))
    }

    /// The GGX alpha of the specular sampler: the width alpha clamped into [0.001, 1].
    #[inline]
    fn sampling_alpha(&self) -> T {
        self.params.alpha.max(T::lit(ALPHA_MIN)).min(T::one())
    }

    /// Probabilities of picking the body (cosine) and the specular (GGX) sampler for n.v = `nv`.
    #[inline]
    fn lobe_probabilities(&self, nv: T) -> [T; 2] {
        let p = &self.params;
        let body = T::lit(0.8) * mean3(p.rho);
        let specular = p.k_s * fresnel(nv, p.eta);
        lobe_probabilities([body, specular])
    }

    /// The mixture density of l for v (both above the horizon).
    #[inline]
    fn mixture_pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        let Some(g) = PairGeometry::of(l, v) else { return T::zero() };
        let p = self.lobe_probabilities(g.nv);
        p[0] * cosine_pdf(g.nl) + p[1] * ggx_reflection_pdf(g.nv, g.sin2_h, self.sampling_alpha())
    }

    /// The two terms before the final scaling, for one unit pair with l.z, v.z > 0:
    /// (G / (n.l + eps), I_s, I_b).
    #[inline]
    fn terms(&self, l: Vec3<T>, v: Vec3<T>) -> (T, T, T) {
        let one = T::one();
        let eps = T::lit(DEN_EPS);
        let p = &self.params;
        let (nl, nv) = (l[2].min(one), v[2].min(one));
        let lambda_l = self.nets.lambda(smith_tan(nl));
        let lambda_v = self.nets.lambda(smith_tan(nv));
        let g = ((one + lambda_l) * (one + lambda_v)).recip();

        // Specular. a = l + v has a.z > 0, so |a| > 0; theta_h from atan2 is accurate near 0.
        let a = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
        let txy = a[0].hypot(a[1]);
        let len = txy.hypot(a[2]);
        let nh = (a[2] / len).min(one);
        let theta_h = txy.atan2(a[2]).max(self.theta_h_min);
        let cos_h = nh.min(T::lit(1.0 - COS_EPS));
        let dist = self.c * (-(theta_h / p.alpha).powf(p.beta)).exp() * cos_h;
        // v.h = |l + v| / 2 for unit l, v.
        let f = fresnel(T::lit(0.5) * len, p.eta);
        let i_s = p.k_s * dist * f / (T::lit(4.0) * nv * nh + eps);

        let i_b = self.nets.body(body_features(l, v));
        (g / (nl + eps), i_s, i_b)
    }
}

/// Every parameter clamped into its range, NaN replaced by the default.
fn clamp_params<T: Real>(p: FmbrdfParams<T>) -> FmbrdfParams<T> {
    FmbrdfParams {
        eta: clamp_or(p.eta, ETA.0, ETA.1, ETA.2),
        rho: clamp_rgb(p.rho, RHO.0, RHO.1, RHO.2),
        k_s: clamp_or(p.k_s, K_S.0, K_S.1, K_S.2),
        alpha: clamp_or(p.alpha, ALPHA.0, ALPHA.1, ALPHA.2),
        beta: clamp_or(p.beta, BETA.0, BETA.1, BETA.2),
        kappa: clamp_or(p.kappa, KAPPA.0, KAPPA.1, KAPPA.2),
    }
}

/// `w` if it is a unit vector to within 16 ulp (left untouched: renormalising would only add
/// rounding), else `w` normalised as the official code does, or `None` if it is zero, infinite
/// or NaN.
#[inline]
fn unit<T: Real>(w: Vec3<T>) -> Option<Vec3<T>> {
    let len2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    if (len2 - T::one()).abs() <= T::lit(16.0) * T::epsilon() { Some(w) } else { try_normalize(w) }
}

impl<T: Real> Brdf<T> for Fmbrdf<T> {
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        let zero = T::zero();
        if !(l[2] > zero && v[2] > zero) {
            return [zero; 3];
        }
        let (Some(l), Some(v)) = (unit(l), unit(v)) else {
            return [zero; 3];
        };
        if !(l[2] > zero && v[2] > zero) {
            return [zero; 3];
        }
        let (scale, i_s, i_b) = self.terms(l, v);
        self.params.rho.map(|r| (i_s + r * i_b) * scale)
    }

    fn name(&self) -> &'static str {
        "FMBRDF"
    }

    fn is_reciprocal(&self) -> bool {
        false
    }

    /// Mixture of the cosine hemisphere and GGX visible-normal reflection (see
    /// [`FmbrdfParams`], "Sampling").
    fn sample(&self, v: Vec3<T>, u: [T; 2]) -> Option<BrdfSample<T>> {
        let probabilities = |nv| self.lobe_probabilities(nv);
        sample_cosine_or_ggx(self, v, u, probabilities, self.sampling_alpha(), |l| {
            self.mixture_pdf(v, l)
        })
    }

    fn pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        self.mixture_pdf(v, l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn params_are_clamped_or_rejected() {
        let bad = FmbrdfParams {
            eta: f32::NAN,
            rho: [2.0, -1.0, f32::NAN],
            k_s: 1e9,
            alpha: 0.0,
            beta: 9.0,
            kappa: -3.0,
        };
        let m = Fmbrdf::new(bad);
        let p = m.params();
        assert_eq!(p.eta, 1.5);
        assert_eq!(p.rho, [1.0, 0.0, 0.5]);
        assert_eq!((p.k_s, p.alpha, p.beta, p.kappa), (100.0, 0.001, 4.0, 0.0));
        assert!(Fmbrdf::try_new(bad).is_err());
        assert!(Fmbrdf::try_new(FmbrdfParams::<f64>::default()).is_ok());
        let e = Fmbrdf::try_new(FmbrdfParams { kappa: 101.0_f64, ..Default::default() });
        assert_eq!(e.unwrap_err().param, "kappa");
    }

    #[test]
    fn with_params_equals_new() {
        let base = Fmbrdf::<f64>::new(FmbrdfParams::default());
        let (l, v) = ([0.3, -0.2, 0.932_737_905_308_881_5], [-0.1, 0.4, 0.910_494_371_207_203_7]);
        for p in [
            FmbrdfParams {
                eta: 2.0,
                rho: [0.1, 0.9, 0.3],
                k_s: 7.0,
                kappa: 40.0,
                ..Default::default()
            },
            FmbrdfParams { alpha: 0.05, beta: 3.0, ..Default::default() },
            FmbrdfParams { eta: f64::NAN, k_s: -1.0, ..Default::default() },
        ] {
            let derived = base.with_params(p);
            let fresh = Fmbrdf::new(p);
            assert_eq!(derived, fresh);
            assert_eq!(derived.eval(l, v), fresh.eval(l, v));
        }
    }

    #[test]
    fn zero_outside_the_hemisphere_and_finite_inside() {
        let m = Fmbrdf::<f32>::new(FmbrdfParams::default());
        assert_eq!(m.eval([0.0, 0.6, -0.8], [0.0, 0.0, 1.0]), [0.0; 3]);
        assert_eq!(m.eval([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), [0.0; 3]);
        assert_eq!(m.eval([f32::NAN, 0.0, 1.0], [0.0, 0.0, 1.0]), [0.0; 3]);
        let f = m.eval([0.0, 0.6, 0.8], [0.0, 0.0, 1.0]);
        assert!(f.iter().all(|x| x.is_finite() && *x > 0.0), "{f:?}");
        assert_eq!(m.name(), "FMBRDF");
        assert!(!m.is_reciprocal());
    }
}
