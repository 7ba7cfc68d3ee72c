//! The one interface every analytic BRDF implements: evaluation, and importance sampling with
//! its density.

use crate::sampling;
use angles::{Real, Vec3};

/// Linear RGB triple.
pub type Rgb<T> = [T; 3];

/// One importance-sampled light direction, as [`Brdf::sample`] returns it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrdfSample<T> {
    /// The sampled light direction l: unit, local frame, `l.z > 0`.
    pub l: Vec3<T>,
    /// The estimator's weight f(l, v) cos(theta_l) / pdf, linear RGB, finite and >= 0.
    pub weight: Rgb<T>,
    /// The density of l in 1/sr (solid angle), finite and > 0; equal to [`Brdf::pdf`]`(v, l)`.
    pub pdf: T,
}

/// A BRDF evaluated in the local shading frame.
///
/// `l` points to the light and `v` to the viewer, both unit vectors in the frame whose +z axis is
/// the shading normal. The result is f_r(l, v) in 1/sr, linear RGB, **without** the cos(theta_l)
/// factor. Implementations return `[0; 3]` when `l.z <= 0` or `v.z <= 0`, and never NaN or Inf.
///
/// Sampling draws l for a given v (the direction a path tracer arrives from), in the style of
/// pbrt-v4's `BxDF::Sample_f` and Mitsuba 3's `BSDF::sample`. [`Brdf::sample`] and [`Brdf::pdf`]
/// come as a pair: a model that overrides one overrides both. The defaults draw l from the
/// cosine-weighted hemisphere, which is correct for every BRDF (if slow for glossy ones), so a
/// model that overrides neither still samples without bias. Each model's documentation says which
/// strategy it uses.
pub trait Brdf<T: Real>: Send + Sync {
    /// f_r(l, v), linear RGB in 1/sr.
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T>;

    /// The model's name as the paper's tables write it (for example "Disney").
    fn name(&self) -> &'static str;

    /// Whether f(l, v) = f(v, l) holds exactly in exact arithmetic.
    fn is_reciprocal(&self) -> bool {
        true
    }

    /// Draws a light direction l for the view direction `v` from two uniforms `u` in [0, 1)^2
    /// (values outside are clamped into [0, 1), NaN becomes 0), with density
    /// [`Brdf::pdf`]`(v, l)`.
    ///
    /// Returns `None` when no direction results: `v.z <= 0`, or the sampled direction lies at or
    /// below the horizon (a reflected microfacet or lobe direction can), in which case the
    /// sample contributes 0. So the density integrates over the upper hemisphere to the
    /// probability of success, 1 for the cosine-weighted default. Never NaN or Inf.
    fn sample(&self, v: Vec3<T>, u: [T; 2]) -> Option<BrdfSample<T>> {
        sampling::sample_cosine(self, v, u)
    }

    /// The density in 1/sr with which [`Brdf::sample`] draws `l` for `v`; 0 unless
    /// `l.z > 0` and `v.z > 0`. Finite and >= 0. The default is the cosine density
    /// cos(theta_l) / pi.
    fn pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        sampling::cosine_pdf_pair(v, l)
    }
}

impl<T: Real, B: Brdf<T> + ?Sized> Brdf<T> for &B {
    #[inline(always)]
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        (**self).eval(l, v)
    }
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn is_reciprocal(&self) -> bool {
        (**self).is_reciprocal()
    }
    #[inline(always)]
    fn sample(&self, v: Vec3<T>, u: [T; 2]) -> Option<BrdfSample<T>> {
        (**self).sample(v, u)
    }
    #[inline(always)]
    fn pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        (**self).pdf(v, l)
    }
}

impl<T: Real> Brdf<T> for Box<dyn Brdf<T>> {
    #[inline(always)]
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        (**self).eval(l, v)
    }
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn is_reciprocal(&self) -> bool {
        (**self).is_reciprocal()
    }
    #[inline(always)]
    fn sample(&self, v: Vec3<T>, u: [T; 2]) -> Option<BrdfSample<T>> {
        (**self).sample(v, u)
    }
    #[inline(always)]
    fn pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        (**self).pdf(v, l)
    }
}
