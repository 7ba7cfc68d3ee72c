//! The isotropic Disney BRDF (Burley 2012, spec 3.3) on tensors: diffuse with retro-reflection,
//! Hanrahan-Krueger subsurface, GGX specular, sheen and a GTR1 clearcoat.

use super::{Geometry, alpha_from_roughness, ggx_d, smith_visibility};
use burn::tensor::Tensor;
use std::f32::consts::{FRAC_1_PI, PI};

/// Disney parameters, per sample; all in [0, 1]. Anisotropic is fixed to 0 (the paper).
#[derive(Clone, Debug)]
pub struct DisneyTensorParams {
    /// Base colour, `[batch, 3]` (linear RGB unless `gamma_base_color`).
    pub base_color: Tensor<2>,
    /// Metallic, `[batch, 1]`.
    pub metallic: Tensor<2>,
    /// Subsurface, `[batch, 1]`.
    pub subsurface: Tensor<2>,
    /// Specular, `[batch, 1]`.
    pub specular: Tensor<2>,
    /// Roughness, `[batch, 1]`.
    pub roughness: Tensor<2>,
    /// Specular tint, `[batch, 1]`.
    pub specular_tint: Tensor<2>,
    /// Sheen, `[batch, 1]`.
    pub sheen: Tensor<2>,
    /// Sheen tint, `[batch, 1]`.
    pub sheen_tint: Tensor<2>,
    /// Clearcoat, `[batch, 1]`.
    pub clearcoat: Tensor<2>,
    /// Clearcoat gloss, `[batch, 1]`.
    pub clearcoat_gloss: Tensor<2>,
    /// Apply the reference shader's base_color^2.2 (default in the models: false).
    pub gamma_base_color: bool,
}

/// 1 - t.
fn one_minus(t: Tensor<2>) -> Tensor<2> {
    t.neg().add_scalar(1.0)
}

/// Evaluates Disney (twin of `brdf_analytic::Disney`).
///
/// The scalar model's colour terms are all affine in the base colour C and the tint colour
/// C_tint (C over its luminance), with per-sample scalar coefficients:
///
/// f = C A + C_tint B + K, where, with w = 1 - metallic, s = 0.08 specular, F_H the Schlick
/// weight of l.h and D G the GGX specular lobe,
/// - A = w f_diffuse / pi + D G (1 - F_H) metallic,
/// - B = D G (1 - F_H) s w specular_tint + sheen w F_H sheen_tint,
/// - K = D G (1 - F_H) s w (1 - specular_tint) + D G F_H + sheen w F_H (1 - sheen_tint)
///   + clearcoat;
///
/// and C_tint = C / lum(C) (white where the luminance is near zero), so f = C (A + B / lum) + K
/// (or C A + B + K). Evaluated this way, everything but the last two products is `[batch, 1]`
/// work: a third of the element-wise passes over `[batch, 3]` tensors of the term-by-term form,
/// and none of their broadcast gradient reductions. The values are the term-by-term form's up
/// to f32 rounding (`tests/tensor_brdf_agreement.rs` holds both to the scalar model).
///
/// # Shapes
/// - params: see [`DisneyTensorParams`]; geometry of `batch` pairs
/// - output: `[batch, 3]`
pub fn disney(p: &DisneyTensorParams, g: &Geometry) -> Tensor<2> {
    let cdlin = if p.gamma_base_color {
        p.base_color.clone().powf_scalar(2.2)
    } else {
        p.base_color.clone()
    };
    let ch = |k: usize| cdlin.clone().narrow(1, k, 1);
    let cdlum = ch(0).mul_scalar(0.3) + ch(1).mul_scalar(0.6) + ch(2).mul_scalar(0.1);
    // C_tint = C tint_scale + tint_white: C / lum, or white where the luminance is (near) zero,
    // like the scalar twin; the floor keeps the reciprocal's derivative (which squares the
    // luminance) finite in f32.
    let floor = brdf_analytic::DISNEY_TINT_LUMINANCE_MIN as f32;
    let dark = cdlum.clone().lower_equal_elem(floor);
    let tint_scale = cdlum.clamp_min(floor).recip().mask_fill(dark.clone(), 0.0);
    let tint_white = dark.float();
    let w = one_minus(p.metallic.clone());
    let dielectric_w = p.specular.clone().mul_scalar(0.5 * 0.16) * w.clone();
    let fh = g.schlick_h.clone();

    // Diffuse with retro-reflection, blended with the Hanrahan-Krueger subsurface term.
    let (fl, fv) = (g.schlick_l.clone(), g.schlick_v.clone());
    let lh2r = g.lh2.clone() * p.roughness.clone();
    let fd90m1 = (lh2r.clone() + lh2r.clone()).sub_scalar(0.5);
    let diffuse =
        (fd90m1.clone() * fl.clone()).add_scalar(1.0) * (fd90m1 * fv.clone()).add_scalar(1.0);
    let fss90m1 = lh2r.sub_scalar(1.0);
    let fss = (fss90m1.clone() * fl).add_scalar(1.0) * (fss90m1 * fv).add_scalar(1.0);
    let ss = (fss * g.subsurface_cos.clone()).add_scalar(0.5).mul_scalar(1.25);
    let diffuse = diffuse.clone() + (ss - diffuse) * p.subsurface.clone();

    // GGX specular lobe D G, and its share 1 - F_H that takes the specular colour.
    let alpha = alpha_from_roughness(p.roughness.clone());
    let spec = ggx_d(g.sin2_h.clone(), g.cos2_h.clone(), alpha.clone())
        * (smith_visibility(g.nl.clone(), g.nl2.clone(), alpha.clone())
            * smith_visibility(g.nv.clone(), g.nv2.clone(), alpha));
    let spec_tinted = spec.clone() * one_minus(fh.clone());

    // GTR1 clearcoat (colourless).
    let cc_alpha = p.clearcoat_gloss.clone().mul_scalar(0.001 - 0.1).add_scalar(0.1);
    let cc_a2 = cc_alpha.square();
    let cc_scale = p.clearcoat.clone().mul_scalar(0.25) * cc_a2.clone().sub_scalar(1.0)
        / cc_a2.clone().log().mul_scalar(PI);
    let dr = cc_scale / (g.sin2_h.clone() + cc_a2 * g.cos2_h.clone());
    let clearcoat = dr * g.clearcoat_fresnel.clone() * g.clearcoat_visibility.clone();

    let sheen = p.sheen.clone() * w.clone() * fh.clone();
    let a = (w * diffuse).mul_scalar(FRAC_1_PI) + spec_tinted.clone() * p.metallic.clone();
    let b = spec_tinted.clone() * dielectric_w.clone() * p.specular_tint.clone()
        + sheen.clone() * p.sheen_tint.clone();
    let k = spec_tinted * dielectric_w * one_minus(p.specular_tint.clone())
        + spec * fh
        + sheen * one_minus(p.sheen_tint.clone())
        + clearcoat;
    let a = (a + b.clone() * tint_scale) * g.mask.clone();
    let k = (k + b * tint_white) * g.mask.clone();
    cdlin * a + k
}
