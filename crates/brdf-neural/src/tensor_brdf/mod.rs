//! Tensor versions of the analytic BRDFs of `brdf-analytic` (spec section 3), differentiable in
//! their parameters, for the parametric models.
//!
//! Each mirrors its scalar twin operation for operation (the robust forms of
//! `brdf_analytic::microfacet`: GGX as sin^2 + alpha^2 cos^2, Smith in visibility form,
//! alpha = max(r^2, 1e-3), l.h = |l + v| / 2) and agrees with it to 1e-5 relative (tests in
//! `tests/tensor_brdf_agreement.rs`). Direction-only terms come precomputed in [`Geometry`].
//! Parameters are per-sample tensors `[batch, k]` (or `[1, k]`, broadcast); every function
//! returns f_r as `[batch, 3]` linear RGB, zero outside the upper hemisphere.

mod disney;
mod fmbrdf;
mod fmbrdf_nets;
mod geometry;
mod lambda_segments;
mod phong;
mod torrance_sparrow;

pub use disney::{DisneyTensorParams, disney};
pub use fmbrdf::{FmbrdfTensorParams, fmbrdf, fmbrdf_normalization};
pub use fmbrdf_nets::FmbrdfNets;
pub use geometry::{FmbrdfGeometry, Geometry};
pub use phong::{PhongTensorParams, realistic_phong};
pub use torrance_sparrow::{TorranceSparrowTensorParams, torrance_sparrow};

use burn::tensor::Tensor;

/// GGX alpha = max(roughness^2, 1e-3) (`brdf_analytic::microfacet::alpha_from_roughness`).
pub(crate) fn alpha_from_roughness(roughness: Tensor<2>) -> Tensor<2> {
    roughness.square().clamp_min(brdf_analytic::microfacet::ALPHA_MIN)
}

/// GGX D from sin^2 and cos^2 of theta_h: alpha^2 / (pi (sin^2 + alpha^2 cos^2)^2).
pub(crate) fn ggx_d(sin2_h: Tensor<2>, cos2_h: Tensor<2>, alpha: Tensor<2>) -> Tensor<2> {
    let a2 = alpha.square();
    let t = sin2_h + a2.clone() * cos2_h;
    a2 / (t.clone() * t).mul_scalar(std::f32::consts::PI)
}

/// Smith-GGX visibility 1 / (c + sqrt(alpha^2 + c^2 - alpha^2 c^2)), with c^2 given.
pub(crate) fn smith_visibility(c: Tensor<2>, c2: Tensor<2>, alpha: Tensor<2>) -> Tensor<2> {
    let a2 = alpha.square();
    (c + (a2.clone() + c2.clone() - a2 * c2).sqrt()).recip()
}
