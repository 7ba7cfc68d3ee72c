//! Lambertian reflectance.

use crate::brdf::{Brdf, BrdfSample, Rgb};
use crate::params::{ParamError, check_rgb, clamp_rgb};
use crate::sampling::{above_horizon, clamp_uniform, cosine_hemisphere, cosine_pdf};
use angles::{Real, Vec3};

/// Parameters of [`Lambert`].
///
/// | parameter | range | unit | default |
/// | --- | --- | --- | --- |
/// | `albedo` | [0, 1]^3 | - | 0.5 |
///
/// Sampling: exact. l is drawn from the cosine-weighted hemisphere, whose density cos / pi is
/// proportional to f cos, so every sample's weight is the albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LambertParams<T> {
    /// Diffuse albedo rho, linear RGB.
    pub albedo: Rgb<T>,
}

impl<T: Real> Default for LambertParams<T> {
    fn default() -> Self {
        Self { albedo: [T::lit(0.5); 3] }
    }
}

/// The Lambertian BRDF f = rho / pi.
///
/// Energy-conserving for rho <= 1 (directional albedo exactly rho) and reciprocal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert<T> {
    params: LambertParams<T>,
    value: Rgb<T>,
}

impl<T: Real> Lambert<T> {
    /// Builds the model, clamping the albedo into [0, 1] (NaN becomes 0.5).
    pub fn new(params: LambertParams<T>) -> Self {
        let albedo = clamp_rgb(params.albedo, 0.0, 1.0, 0.5);
        Self { params: LambertParams { albedo }, value: albedo.map(|a| a * T::FRAC_1_PI()) }
    }

    /// Builds the model, rejecting an albedo outside [0, 1].
    pub fn try_new(params: LambertParams<T>) -> Result<Self, ParamError> {
        check_rgb("Lambert", "albedo", params.albedo, 0.0, 1.0)?;
        Ok(Self::new(params))
    }

    /// The parameters in use (after clamping).
    pub fn params(&self) -> &LambertParams<T> {
        &self.params
    }
}

impl<T: Real> Brdf<T> for Lambert<T> {
    #[inline(always)]
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        if l[2] > T::zero() && v[2] > T::zero() { self.value } else { [T::zero(); 3] }
    }

    fn name(&self) -> &'static str {
        "Lambert"
    }

    /// Cosine-weighted l; weight = albedo exactly.
    fn sample(&self, v: Vec3<T>, u: [T; 2]) -> Option<BrdfSample<T>> {
        if !above_horizon(v) {
            return None;
        }
        let l = cosine_hemisphere(u.map(clamp_uniform));
        let pdf = cosine_pdf(l[2]);
        (pdf > T::zero()).then_some(BrdfSample { l, weight: self.params.albedo, pdf })
    }

    fn pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        if l[2] > T::zero() && v[2] > T::zero() { cosine_pdf(l[2]) } else { T::zero() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_value() {
        let m = Lambert::new(LambertParams { albedo: [0.2_f64, 0.5, 1.0] });
        let f = m.eval([0.0, 0.6, 0.8], [0.0, 0.0, 1.0]);
        assert_eq!(
            f,
            [0.2 / std::f64::consts::PI, 0.5 / std::f64::consts::PI, 1.0 / std::f64::consts::PI]
        );
        assert_eq!(m.eval([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), [0.0; 3]);
        assert!(Lambert::try_new(LambertParams { albedo: [1.5_f32, 0.0, 0.0] }).is_err());
        let clamped = Lambert::new(LambertParams { albedo: [f32::NAN, 2.0, -1.0] });
        assert_eq!(clamped.params().albedo, [0.5, 1.0, 0.0]);
    }
}
