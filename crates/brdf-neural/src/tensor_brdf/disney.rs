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

/// mix(a, b, t) = a (1 - t) + b t.
fn mix(a: Tensor<2>, b: Tensor<2>, t: Tensor<2>) -> Tensor<2> {
    a * t.clone().neg().add_scalar(1.0) + b * t
}

/// mix(1, b, t) = (1 - t) + b t, for a scalar one.
fn mix_one(b: Tensor<2>, t: Tensor<2>) -> Tensor<2> {
    t.clone().neg().add_scalar(1.0) + b * t
}

/// Evaluates Disney (twin of `brdf_analytic::Disney`).
///
/// # Shapes
/// - params: see [`DisneyTensorParams`]; geometry of `batch` pairs
/// - output: `[batch, 3]`
pub fn disney(p: &DisneyTensorParams, g: &Geometry) -> Tensor<2> {
    // Per-sample constants (the scalar model's `new`).
    let cdlin = if p.gamma_base_color {
        p.base_color.clone().powf_scalar(2.2)
    } else {
        p.base_color.clone()
    };
    let ch = |k: usize| cdlin.clone().narrow(1, k, 1);
    let cdlum = ch(0).mul_scalar(0.3) + ch(1).mul_scalar(0.6) + ch(2).mul_scalar(0.1);
    // White where the luminance is (near) zero, like the scalar twin; the division's floor keeps
    // its derivative (which squares the luminance) finite in f32.
    let floor = brdf_analytic::DISNEY_TINT_LUMINANCE_MIN as f32;
    let dark = cdlum.clone().lower_equal_elem(floor).repeat_dim(1, 3);
    let ctint = (cdlin.clone() / cdlum.clamp_min(floor)).mask_fill(dark, 1.0);
    let dielectric = p.specular.clone().mul_scalar(0.5 * 0.16);
    let cspec0 = mix(
        dielectric * mix_one(ctint.clone(), p.specular_tint.clone()),
        cdlin.clone(),
        p.metallic.clone(),
    );
    let dielectric_weight = p.metallic.clone().neg().add_scalar(1.0);
    let diffuse_c = cdlin.mul_scalar(FRAC_1_PI) * dielectric_weight.clone();
    let sheen_c = mix_one(ctint, p.sheen_tint.clone()) * p.sheen.clone() * dielectric_weight;
    let cc_alpha = p.clearcoat_gloss.clone().mul_scalar(0.001 - 0.1).add_scalar(0.1);
    let cc_a2 = cc_alpha.square();
    let cc_scale = p.clearcoat.clone().mul_scalar(0.25) * cc_a2.clone().sub_scalar(1.0)
        / cc_a2.clone().log().mul_scalar(PI);
    let alpha = alpha_from_roughness(p.roughness.clone());

    // Evaluation.
    let (fl, fv, fh) = (g.schlick_l.clone(), g.schlick_v.clone(), g.schlick_h.clone());
    let lh2r = g.lh2.clone() * p.roughness.clone();
    let fd90m1 = (lh2r.clone() + lh2r.clone()).sub_scalar(0.5);
    let diffuse =
        (fd90m1.clone() * fl.clone()).add_scalar(1.0) * (fd90m1 * fv.clone()).add_scalar(1.0);
    let fss90m1 = lh2r.sub_scalar(1.0);
    let fss = (fss90m1.clone() * fl).add_scalar(1.0) * (fss90m1 * fv).add_scalar(1.0);
    let ss = (fss * g.subsurface_cos.clone()).add_scalar(0.5).mul_scalar(1.25);
    let diffuse = diffuse.clone() + (ss - diffuse) * p.subsurface.clone();
    let spec = ggx_d(g.sin2_h.clone(), g.cos2_h.clone(), alpha.clone())
        * (smith_visibility(g.nl.clone(), g.nl2.clone(), alpha.clone())
            * smith_visibility(g.nv.clone(), g.nv2.clone(), alpha));
    let dr = cc_scale / (g.sin2_h.clone() + cc_a2 * g.cos2_h.clone());
    let clearcoat = dr * g.clearcoat_fresnel.clone() * g.clearcoat_visibility.clone();
    let fs = cspec0.clone() + cspec0.neg().add_scalar(1.0) * fh.clone();
    (diffuse_c * diffuse + sheen_c * fh + spec * fs + clearcoat) * g.mask.clone()
}
