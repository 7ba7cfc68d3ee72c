//! Torrance-Sparrow with GGX, Smith-GGX and Schlick (spec 3.2) on tensors:
//! f = (1 - F) rho_d / pi + D F G / (4 n.l n.v).

use super::{Geometry, alpha_from_roughness, ggx_d, smith_visibility};
use burn::tensor::Tensor;
use std::f32::consts::FRAC_1_PI;

/// Torrance-Sparrow parameters, per sample.
#[derive(Clone, Debug)]
pub struct TorranceSparrowTensorParams {
    /// Perceptual roughness r in [0, 1], `[batch, 1]`; alpha = max(r^2, 1e-3).
    pub roughness: Tensor<2>,
    /// Diffuse albedo rho_d in [0, 1], `[batch, 3]`.
    pub diffuse: Tensor<2>,
    /// Fresnel reflectance at normal incidence F0 in [0, 1], `[batch, 3]`.
    pub f0: Tensor<2>,
}

/// Evaluates Torrance-Sparrow (twin of `brdf_analytic::TorranceSparrow`).
///
/// # Shapes
/// - params: see [`TorranceSparrowTensorParams`]; geometry of `batch` pairs
/// - output: `[batch, 3]`
pub fn torrance_sparrow(p: &TorranceSparrowTensorParams, g: &Geometry) -> Tensor<2> {
    let a = alpha_from_roughness(p.roughness.clone());
    let dg = ggx_d(g.sin2_h.clone(), g.cos2_h.clone(), a.clone())
        * (smith_visibility(g.nl.clone(), g.nl2.clone(), a.clone())
            * smith_visibility(g.nv.clone(), g.nv2.clone(), a));
    let w = g.schlick_h.clone();
    let f0 = p.f0.clone();
    let f = f0.clone() + f0.neg().add_scalar(1.0) * w;
    let diffuse = p.diffuse.clone().mul_scalar(FRAC_1_PI);
    (f.clone().neg().add_scalar(1.0) * diffuse + dg * f) * g.mask.clone()
}
