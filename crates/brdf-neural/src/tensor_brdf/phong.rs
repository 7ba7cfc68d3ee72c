//! Realistic Phong (spec 3.1) on tensors: f = k_d / pi + k_s (N + 2) / (2 pi) max(0, r.v)^N.

use super::Geometry;
use burn::tensor::Tensor;
use std::f32::consts::{FRAC_1_PI, TAU};

/// Largest exponent, as in the scalar model.
const MAX_EXPONENT: f64 = 1e6;

/// Realistic Phong parameters, per sample.
#[derive(Clone, Debug)]
pub struct PhongTensorParams {
    /// Diffuse albedo k_d, `[batch, 3]`, in [0, 1].
    pub kd: Tensor<2>,
    /// Specular albedo k_s, `[batch, 3]`, in [0, 1] with k_d + k_s <= 1.
    pub ks: Tensor<2>,
    /// Exponent N >= 1, `[batch, 1]`.
    pub exponent: Tensor<2>,
}

/// Evaluates Realistic Phong (twin of `brdf_analytic::RealisticPhong`).
///
/// # Shapes
/// - params: see [`PhongTensorParams`]; geometry of `batch` pairs
/// - output: `[batch, 3]`
pub fn realistic_phong(p: &PhongTensorParams, g: &Geometry) -> Tensor<2> {
    let n = p.exponent.clone().clamp(1.0, MAX_EXPONENT);
    let diffuse = p.kd.clone().mul_scalar(FRAC_1_PI);
    let lobe = p.ks.clone() * n.clone().add_scalar(2.0).div_scalar(TAU);
    let spec = g.rv.clone().powf(n) * g.rv_positive.clone();
    (diffuse + lobe * spec) * g.mask.clone()
}
