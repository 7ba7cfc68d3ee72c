//! Torrance-Sparrow microfacet model with GGX, Smith-GGX and Schlick, plus a (1 - F) diffuse term.

use crate::brdf::{Brdf, BrdfSample, Rgb};
use crate::microfacet::{
    PairGeometry, alpha_from_roughness, ggx_d, schlick_weight, smith_ggx_visibility,
};
use crate::params::{ParamError, check, check_rgb, clamp_or, clamp_rgb};
use crate::sampling::{
    cosine_pdf, ggx_reflection_pdf, lobe_probabilities, mean3, sample_cosine_or_ggx,
};
use angles::{Real, Vec3};

/// Parameters of [`TorranceSparrow`].
///
/// | parameter | range | unit | default |
/// | --- | --- | --- | --- |
/// | `roughness` | [0, 1] (alpha = max(roughness^2, 1e-3)) | - | 0.5 |
/// | `diffuse` | [0, 1]^3 | - | 0.5 |
/// | `f0` | [0, 1]^3 | - | 0.04 |
///
/// The paper's network predicts 7 values: roughness = sigmoid(0.5 z), diffuse and f0 by sigmoid.
///
/// Sampling: a one-sample mixture (balance heuristic) of the cosine-weighted hemisphere
/// (diffuse) and GGX visible normals reflected about the sampled normal (specular, Heitz 2018),
/// picked with probabilities from the Schlick reflectance at the view angle, F(n.v), against
/// rho_d (1 - F(n.v)) (each at least 5 %); pdf = the mixture density. A reflected direction
/// below the horizon is no sample (`None`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorranceSparrowParams<T> {
    /// Perceptual roughness r; alpha = r^2.
    pub roughness: T,
    /// Diffuse albedo rho_d, linear RGB.
    pub diffuse: Rgb<T>,
    /// Fresnel reflectance at normal incidence F0, linear RGB.
    pub f0: Rgb<T>,
}

impl<T: Real> Default for TorranceSparrowParams<T> {
    fn default() -> Self {
        Self { roughness: T::lit(0.5), diffuse: [T::lit(0.5); 3], f0: [T::lit(0.04); 3] }
    }
}

/// The Torrance-Sparrow BRDF as the paper uses it ([P supp. "Torrance-Sparrow Model"]; Torrance
/// and Sparrow 1967, GGX of Walter et al. 2007):
///
/// f = (1 - F) rho_d / pi + D F G / (4 (n.l)(n.v)), with
/// D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2), G = G1(l) G1(v),
/// G1(w) = 2 (n.w) / ((n.w) + sqrt(alpha^2 + (1 - alpha^2)(n.w)^2)),
/// F = F0 + (1 - F0)(1 - v.h)^5 (RGB).
///
/// alpha = roughness^2 is clamped to at least [`crate::microfacet::ALPHA_MIN`] so that roughness 0
/// stays finite. Reciprocal (every factor is symmetric in l and v). Not energy-conserving in
/// general: the diffuse and specular parts are not coupled beyond the (1 - F) factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorranceSparrow<T> {
    params: TorranceSparrowParams<T>,
    alpha: T,
    diffuse: Rgb<T>,
}

impl<T: Real> TorranceSparrow<T> {
    /// Builds the model, clamping every parameter into [0, 1] (NaN becomes the default).
    pub fn new(params: TorranceSparrowParams<T>) -> Self {
        let roughness = clamp_or(params.roughness, 0.0, 1.0, 0.5);
        let diffuse = clamp_rgb(params.diffuse, 0.0, 1.0, 0.5);
        let f0 = clamp_rgb(params.f0, 0.0, 1.0, 0.04);
        Self {
            params: TorranceSparrowParams { roughness, diffuse, f0 },
            alpha: alpha_from_roughness(roughness),
            diffuse: diffuse.map(|d| d * T::FRAC_1_PI()),
        }
    }

    /// Builds the model, rejecting parameters outside [0, 1].
    pub fn try_new(params: TorranceSparrowParams<T>) -> Result<Self, ParamError> {
        const M: &str = "TorranceSparrow";
        check(M, "roughness", params.roughness, 0.0, 1.0)?;
        check_rgb(M, "diffuse", params.diffuse, 0.0, 1.0)?;
        check_rgb(M, "f0", params.f0, 0.0, 1.0)?;
        Ok(Self::new(params))
    }

    /// The parameters in use (after clamping).
    pub fn params(&self) -> &TorranceSparrowParams<T> {
        &self.params
    }

    /// Probabilities of picking the diffuse and the specular sampler for n.v = `nv`.
    #[inline]
    fn lobe_probabilities(&self, nv: T) -> [T; 2] {
        let w = schlick_weight(nv);
        let p = &self.params;
        let f = p.f0.map(|f0| f0 + (T::one() - f0) * w);
        let diffuse = [0, 1, 2].map(|c| p.diffuse[c] * (T::one() - f[c]));
        lobe_probabilities([mean3(diffuse), mean3(f)])
    }

    /// The mixture density of l for v (both above the horizon).
    #[inline]
    fn mixture_pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        let Some(g) = PairGeometry::of(l, v) else { return T::zero() };
        let p = self.lobe_probabilities(g.nv);
        p[0] * cosine_pdf(g.nl) + p[1] * ggx_reflection_pdf(g.nv, g.sin2_h, self.alpha)
    }
}

impl<T: Real> Brdf<T> for TorranceSparrow<T> {
    #[inline(always)]
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        let Some(g) = PairGeometry::of(l, v) else { return [T::zero(); 3] };
        let a = self.alpha;
        // The visibility product first: commutative, so f(l, v) and f(v, l) agree bit for bit.
        let dg =
            ggx_d(g.sin2_h, a) * (smith_ggx_visibility(g.nl, a) * smith_ggx_visibility(g.nv, a));
        let w = schlick_weight(g.lh);
        let f0 = self.params.f0;
        [0, 1, 2].map(|c| {
            let f = f0[c] + (T::one() - f0[c]) * w;
            (T::one() - f) * self.diffuse[c] + dg * f
        })
    }

    fn name(&self) -> &'static str {
        "TS"
    }

    /// Mixture of the cosine hemisphere and GGX visible-normal reflection.
    fn sample(&self, v: Vec3<T>, u: [T; 2]) -> Option<BrdfSample<T>> {
        let probabilities = |nv| self.lobe_probabilities(nv);
        sample_cosine_or_ggx(self, v, u, probabilities, self.alpha, |l| self.mixture_pdf(v, l))
    }

    fn pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        self.mixture_pdf(v, l)
    }
}
