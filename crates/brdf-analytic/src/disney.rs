//! The isotropic Disney principled BRDF (Burley 2012), every lobe.

use crate::brdf::{Brdf, BrdfSample, Rgb};
use crate::microfacet::{
    PairGeometry, alpha_from_roughness, ggx_d, schlick_weight, smith_ggx_visibility,
};
use crate::params::{ParamError, check, check_rgb, clamp_or, clamp_rgb};
use crate::sampling::{
    above_horizon, clamp_uniform, cosine_hemisphere, cosine_pdf, finish, ggx_reflection_pdf,
    ggx_visible_normal, gtr1_normal, gtr1_normal_pdf, lobe_probabilities, mean3, pick_lobe,
    reflect,
};
use angles::{Real, Vec3};

/// Parameters of [`Disney`], all in [0, 1], with the reference shader's defaults.
///
/// | parameter | default | meaning |
/// | --- | --- | --- |
/// | `base_color` | (0.82, 0.67, 0.16) | base colour (linear unless `gamma_base_color`) |
/// | `metallic` | 0 | dielectric (0) to metal (1) |
/// | `subsurface` | 0 | blend of the diffuse lobe towards the Hanrahan-Krueger approximation |
/// | `specular` | 0.5 | dielectric specular amount (F0 = 0.08 specular) |
/// | `roughness` | 0.5 | GGX roughness, alpha = max(0.001, roughness^2) |
/// | `specular_tint` | 0 | tints the dielectric specular towards the base hue |
/// | `sheen` | 0 | grazing sheen amount |
/// | `sheen_tint` | 0.5 | tints the sheen towards the base hue |
/// | `clearcoat` | 0 | clear-coat lobe amount |
/// | `clearcoat_gloss` | 1 | clear-coat glossiness (GTR1 alpha from 0.1 to 0.001) |
///
/// `anisotropic` is fixed to 0 ([P supp. "Disney BRDF"]). The paper's network predicts the 13
/// values by sigmoid, roughness as sigmoid(0.5 z). `gamma_base_color` (default false, the
/// project's decision) applies the reference shader's `mon2lin` (c^2.2) to the base colour.
///
/// Sampling: a one-sample mixture (balance heuristic) of three samplers: the cosine-weighted
/// hemisphere (diffuse, subsurface and sheen), GGX visible normals reflected about the sampled
/// normal (specular, Heitz 2018) and GTR1 normals drawn with density D cos and reflected
/// (clear coat, only when `clearcoat` > 0). The lobes are picked with probabilities from
/// estimates of their albedo at the view angle (diffuse: mean(Cdlin)(1 - metallic) plus
/// 0.1 mean(Csheen) sheen (1 - metallic); specular: mean of Fs at l.h = n.v; clear coat:
/// 0.25 clearcoat Fr at n.v), each at least 5 %; pdf = the mixture density. A reflected
/// direction below the horizon is no sample (`None`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisneyParams<T> {
    /// Base colour, RGB.
    pub base_color: Rgb<T>,
    /// Metallic.
    pub metallic: T,
    /// Subsurface.
    pub subsurface: T,
    /// Specular.
    pub specular: T,
    /// Roughness.
    pub roughness: T,
    /// Specular tint.
    pub specular_tint: T,
    /// Sheen.
    pub sheen: T,
    /// Sheen tint.
    pub sheen_tint: T,
    /// Clear coat.
    pub clearcoat: T,
    /// Clear-coat gloss.
    pub clearcoat_gloss: T,
    /// Apply c^2.2 to the base colour, as the reference shader does.
    pub gamma_base_color: bool,
}

impl<T: Real> Default for DisneyParams<T> {
    fn default() -> Self {
        Self {
            base_color: [T::lit(0.82), T::lit(0.67), T::lit(0.16)],
            metallic: T::zero(),
            subsurface: T::zero(),
            specular: T::lit(0.5),
            roughness: T::lit(0.5),
            specular_tint: T::zero(),
            sheen: T::zero(),
            sheen_tint: T::lit(0.5),
            clearcoat: T::zero(),
            clearcoat_gloss: T::one(),
            gamma_base_color: false,
        }
    }
}

/// Lower bound on n.l + n.v in the subsurface term's 1 / (n.l + n.v), which diverges at grazing.
const MIN_COS_SUM: f64 = 1e-12;

/// The base colour's luminance at or below which the tint colour is white (the reference
/// shader's `Cdlum > 0 ? Cdlin / Cdlum : 1`, with the test moved from 0 to this small floor: the
/// tensor twin divides by the luminance, and the derivative of x / y squares y, which underflows
/// f32 to 0 for y below ~1e-19 and turned the gradients of a near-black base colour into NaN).
pub const TINT_LUMINANCE_MIN: f64 = 1e-15;

/// The isotropic Disney BRDF (Burley 2012, "Physically-Based Shading at Disney"; reference
/// shader wdas/brdf `disney.brdf`; spec section 3.3). With FL, FV, FH = (1 - cos)^5 of n.l, n.v, l.h:
///
/// f = ((1/pi) mix(Fd, ss, subsurface) Cdlin + FH sheen Csheen)(1 - metallic)
///     + Gs Fs Ds + 0.25 clearcoat Gr Fr Dr
///
/// * Fd = mix(1, Fd90, FL) mix(1, Fd90, FV), Fd90 = 0.5 + 2 (l.h)^2 roughness;
/// * ss = 1.25 (Fss (1/(n.l + n.v) - 0.5) + 0.5), Fss as Fd with Fss90 = (l.h)^2 roughness;
/// * Ds = GGX(alpha), Gs = smithG(n.l) smithG(n.v) (visibility form), Fs = mix(Cspec0, 1, FH),
///   Cspec0 = mix(0.08 specular mix(1, Ctint, specular_tint), Cdlin, metallic);
/// * Dr = GTR1(mix(0.1, 0.001, clearcoat_gloss)), Gr with a fixed alpha 0.25, Fr = mix(0.04, 1, FH).
///
/// Reciprocal. Not energy-conserving in general (the retro-reflective diffuse and sheen add
/// energy at grazing angles). Everything that depends only on the parameters is precomputed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disney<T> {
    params: DisneyParams<T>,
    /// Cdlin / pi (1 - metallic).
    diffuse: Rgb<T>,
    /// Csheen sheen (1 - metallic).
    sheen: Rgb<T>,
    cspec0: Rgb<T>,
    alpha: T,
    /// Clear-coat GTR1 alpha^2, and 0.25 clearcoat (alpha^2 - 1) / (pi ln alpha^2).
    cc_a2: T,
    cc_scale: T,
}

impl<T: Real> Disney<T> {
    /// Builds the model, clamping every parameter into [0, 1] (NaN becomes the default).
    pub fn new(params: DisneyParams<T>) -> Self {
        let d = DisneyParams::<T>::default();
        let c = |x: T, def: T| clamp_or(x, 0.0, 1.0, def.to_f64_exact());
        let p = DisneyParams {
            base_color: clamp_rgb(params.base_color, 0.0, 1.0, 0.5),
            metallic: c(params.metallic, d.metallic),
            subsurface: c(params.subsurface, d.subsurface),
            specular: c(params.specular, d.specular),
            roughness: c(params.roughness, d.roughness),
            specular_tint: c(params.specular_tint, d.specular_tint),
            sheen: c(params.sheen, d.sheen),
            sheen_tint: c(params.sheen_tint, d.sheen_tint),
            clearcoat: c(params.clearcoat, d.clearcoat),
            clearcoat_gloss: c(params.clearcoat_gloss, d.clearcoat_gloss),
            gamma_base_color: params.gamma_base_color,
        };
        let one = T::one();
        let mix = |a: T, b: T, t: T| a * (one - t) + b * t;
        let cdlin = if p.gamma_base_color {
            p.base_color.map(|x| x.powf(T::lit(2.2)))
        } else {
            p.base_color
        };
        let cdlum = T::lit(0.3) * cdlin[0] + T::lit(0.6) * cdlin[1] + T::lit(0.1) * cdlin[2];
        let ctint =
            if cdlum > T::lit(TINT_LUMINANCE_MIN) { cdlin.map(|x| x / cdlum) } else { [one; 3] };
        let dielectric = T::lit(0.5) * T::lit(0.16) * p.specular; // specular * 0.08
        let cspec0 = [0, 1, 2]
            .map(|i| mix(dielectric * mix(one, ctint[i], p.specular_tint), cdlin[i], p.metallic));
        let dielectric_weight = one - p.metallic;
        let diffuse = cdlin.map(|x| x * T::FRAC_1_PI() * dielectric_weight);
        let sheen = ctint.map(|t| mix(one, t, p.sheen_tint) * p.sheen * dielectric_weight);
        let cc_alpha = mix(T::lit(0.1), T::lit(0.001), p.clearcoat_gloss);
        let cc_a2 = cc_alpha * cc_alpha;
        let cc_scale = T::lit(0.25) * p.clearcoat * (cc_a2 - one) / (T::PI() * cc_a2.ln());
        Self {
            params: p,
            diffuse,
            sheen,
            cspec0,
            alpha: alpha_from_roughness(p.roughness),
            cc_a2,
            cc_scale,
        }
    }

    /// Builds the model, rejecting any parameter outside [0, 1].
    pub fn try_new(params: DisneyParams<T>) -> Result<Self, ParamError> {
        const M: &str = "Disney";
        check_rgb(M, "base_color", params.base_color, 0.0, 1.0)?;
        for (name, x) in [
            ("metallic", params.metallic),
            ("subsurface", params.subsurface),
            ("specular", params.specular),
            ("roughness", params.roughness),
            ("specular_tint", params.specular_tint),
            ("sheen", params.sheen),
            ("sheen_tint", params.sheen_tint),
            ("clearcoat", params.clearcoat),
            ("clearcoat_gloss", params.clearcoat_gloss),
        ] {
            check(M, name, x, 0.0, 1.0)?;
        }
        Ok(Self::new(params))
    }

    /// The parameters in use (after clamping).
    pub fn params(&self) -> &DisneyParams<T> {
        &self.params
    }

    /// Probabilities of picking the diffuse, specular and clear-coat samplers for n.v = `nv`
    /// (the last is 0 without a clear coat).
    #[inline]
    fn lobe_probabilities(&self, nv: T) -> [T; 3] {
        let one = T::one();
        let w = schlick_weight(nv);
        let diffuse = mean3(self.diffuse) * T::PI() + T::lit(0.1) * mean3(self.sheen);
        let specular = mean3(self.cspec0.map(|c| c + (one - c) * w));
        if self.cc_scale != T::zero() {
            let clearcoat =
                T::lit(0.25) * self.params.clearcoat * (T::lit(0.04) + T::lit(0.96) * w);
            lobe_probabilities([diffuse, specular, clearcoat])
        } else {
            let [d, s] = lobe_probabilities([diffuse, specular]);
            [d, s, T::zero()]
        }
    }

    /// The mixture density of l for v (both above the horizon).
    #[inline]
    fn mixture_pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        let Some(g) = PairGeometry::of(l, v) else { return T::zero() };
        let p = self.lobe_probabilities(g.nv);
        let mut pdf =
            p[0] * cosine_pdf(g.nl) + p[1] * ggx_reflection_pdf(g.nv, g.sin2_h, self.alpha);
        if p[2] > T::zero() && g.lh > T::zero() {
            pdf = pdf + p[2] * gtr1_normal_pdf(g.sin2_h, self.cc_a2) / (T::lit(4.0) * g.lh);
        }
        pdf
    }
}

impl<T: Real> Brdf<T> for Disney<T> {
    #[inline(always)]
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        let Some(g) = PairGeometry::of(l, v) else { return [T::zero(); 3] };
        let (one, p) = (T::one(), &self.params);
        let fl = schlick_weight(g.nl);
        let fv = schlick_weight(g.nv);
        let fh = schlick_weight(g.lh);
        let lh2r = g.lh * g.lh * p.roughness;
        // Diffuse with retro-reflection: mix(1, Fd90, F) = 1 + (Fd90 - 1) F.
        let fd90m1 = lh2r + lh2r - T::lit(0.5);
        let mut diffuse = (one + fd90m1 * fl) * (one + fd90m1 * fv);
        if p.subsurface > T::zero() {
            let fss90m1 = lh2r - one;
            let fss = (one + fss90m1 * fl) * (one + fss90m1 * fv);
            let inv_sum = (g.nl + g.nv).max(T::lit(MIN_COS_SUM)).recip();
            let ss = T::lit(1.25) * (fss * (inv_sum - T::lit(0.5)) + T::lit(0.5));
            diffuse = diffuse + (ss - diffuse) * p.subsurface;
        }
        let a = self.alpha;
        let spec =
            ggx_d(g.sin2_h, a) * (smith_ggx_visibility(g.nl, a) * smith_ggx_visibility(g.nv, a));
        let clearcoat = if self.cc_scale != T::zero() {
            // GTR1 / (pi ln a^2) folded into cc_scale; 1 + (a^2 - 1) cos^2 = sin^2 + a^2 cos^2.
            let dr = self.cc_scale / (g.sin2_h + self.cc_a2 * (one - g.sin2_h));
            let q = T::lit(0.25);
            let fr = T::lit(0.04) + T::lit(0.96) * fh;
            dr * fr * (smith_ggx_visibility(g.nl, q) * smith_ggx_visibility(g.nv, q))
        } else {
            T::zero()
        };
        [0, 1, 2].map(|c| {
            let fs = self.cspec0[c] + (one - self.cspec0[c]) * fh;
            self.diffuse[c] * diffuse + self.sheen[c] * fh + spec * fs + clearcoat
        })
    }

    fn name(&self) -> &'static str {
        "Disney"
    }

    /// Mixture of the cosine hemisphere, GGX visible-normal reflection and GTR1 reflection.
    fn sample(&self, v: Vec3<T>, u: [T; 2]) -> Option<BrdfSample<T>> {
        if !above_horizon(v) {
            return None;
        }
        let (k, u0) = pick_lobe(self.lobe_probabilities(v[2].min(T::one())), clamp_uniform(u[0]));
        let u = [u0, clamp_uniform(u[1])];
        let l = match k {
            0 => cosine_hemisphere(u),
            1 => reflect(v, ggx_visible_normal(v, self.alpha, u)),
            _ => reflect(v, gtr1_normal(self.cc_a2, u)),
        };
        finish(self, v, l, self.mixture_pdf(v, l))
    }

    fn pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        self.mixture_pdf(v, l)
    }
}
