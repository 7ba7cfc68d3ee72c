//! The Fresnel microfacet BRDF (FMBRDF, Ichikawa et al. CVPR 2023; spec 3.4 and addendum) on
//! tensors: f = G (I_s + rho I_b) / (n.l + 1e-9), with G = 1 / ((1 + Lambda_l)(1 + Lambda_v)),
//! I_s = k_s c exp(-(theta_h / alpha)^beta) cos(theta_h) F(v.h; eta) / (4 n.v n.h + 1e-9).
//!
//! The normalization c(alpha, beta) is the 24-node Gauss-Legendre rule of `brdf-analytic`
//! (theta = theta_max u^2 on [0, min(pi/2, alpha 40^(1/beta))]), here differentiable in alpha
//! and beta.

use super::geometry::DEN_EPS;
use super::{FmbrdfNets, Geometry};
use crate::products::Products;
use brdf_analytic::quadrature::gauss_legendre;
use burn::tensor::{Device, Tensor, TensorData};
use std::f64::consts::{FRAC_PI_2, PI};

/// The normalisation rule of the scalar FMBRDF: the same nodes and tail cut, so the two agree.
use brdf_analytic::{FMBRDF_NORMALIZATION_NODES as NODES, FMBRDF_NORMALIZATION_TAIL as TAIL};

/// FMBRDF parameters.
#[derive(Clone, Debug)]
pub struct FmbrdfTensorParams {
    /// Refractive index eta in [1.1, 2.5], `[batch, 1]`.
    pub eta: Tensor<2>,
    /// Body albedo rho >= 0, `[batch, 3]`.
    pub rho: Tensor<2>,
    /// Specular scale k_s >= 0 (scalar per sample), `[batch, 1]`.
    pub k_s: Tensor<2>,
    /// Body-network input kappa in [0, 100], `[batch, 1]`.
    pub kappa: Tensor<2>,
    /// GGD width alpha in [0.001, 2 pi], one per object, `[1, 1]`.
    pub alpha: Tensor<2>,
    /// GGD shape beta in [0.5, 4], one per object, `[1, 1]`.
    pub beta: Tensor<2>,
}

/// The normalization c(alpha, beta) of the GGD microfacet distribution.
///
/// # Shapes
/// - alpha, beta: `[1, 1]`
/// - output: `[1, 1]`
pub fn fmbrdf_normalization(alpha: Tensor<2>, beta: Tensor<2>, device: &Device) -> Tensor<2> {
    let nodes = gauss_legendre(NODES);
    let u: Vec<f32> = nodes.iter().map(|&(x, _)| (0.5 * (x + 1.0)) as f32).collect();
    // w/2 * 2 u (d theta = 2 theta_max u du, du = dx / 2), folded into one weight.
    let wu: Vec<f32> = nodes.iter().map(|&(x, w)| (w * 0.5 * (x + 1.0)) as f32).collect();
    let u = Tensor::<2>::from_data(TensorData::new(u, [1, NODES]), device);
    let wu = Tensor::<2>::from_data(TensorData::new(wu, [1, NODES]), device);
    let theta_max =
        (alpha.clone() * beta.clone().recip().mul_scalar(TAIL.ln()).exp()).clamp_max(FRAC_PI_2);
    let theta = theta_max.clone() * u.clone() * u;
    let g = (theta.clone() / alpha).powf(beta).neg().exp() * theta.clone().cos() * theta.sin();
    let sum = (g * wu).sum_dim(1) * theta_max;
    sum.mul_scalar(2.0 * PI).recip()
}

/// Dielectric Fresnel (R_s + R_p) / 2 as the official code writes it, with cos r and sin r
/// precomputed.
fn fresnel(cos_r: Tensor<2>, sin_r: Tensor<2>, eta: Tensor<2>) -> Tensor<2> {
    let cap = (1.0 - super::geometry::COS_EPS) as f32;
    let a = eta.recip();
    let sin_t = (a.clone() * sin_r).clamp(0.0, cap);
    let cos_t = (sin_t.clone().neg().add_scalar(1.0) * sin_t.add_scalar(1.0)).sqrt();
    let acr = a.clone() * cos_r.clone();
    let act = a * cos_t.clone();
    let rs = (acr.clone() - cos_t.clone()) / (acr + cos_t).add_scalar(DEN_EPS);
    let rp = (cos_r.clone() - act.clone()) / (act + cos_r).add_scalar(DEN_EPS);
    (rs.square() + rp.square()).mul_scalar(0.5)
}

/// Evaluates FMBRDF (twin of `brdf_analytic::Fmbrdf`).
///
/// # Shapes
/// - params: see [`FmbrdfTensorParams`]; geometry of `batch` pairs with FMBRDF terms
/// - output: `[batch, 3]`
///
/// # Panics
/// If the geometry was built without the FMBRDF terms.
pub fn fmbrdf(
    p: &FmbrdfTensorParams,
    nets: &FmbrdfNets,
    g: &Geometry,
    products: Products,
) -> Tensor<2> {
    let fm = g.fmbrdf.as_ref().expect("geometry built without FMBRDF terms");
    let n = g.len();
    let device = g.mask.device();
    let c = fmbrdf_normalization(p.alpha.clone(), p.beta.clone(), &device);
    let lambda = nets
        .lambda(fm.tan_lv.clone(), &fm.tan_lv_host, p.alpha.clone(), p.beta.clone(), products)
        .add_scalar(1.0);
    let g_smith = (lambda.clone().narrow(0, 0, n) * lambda.narrow(0, n, n)).recip();
    let dist = (fm.theta_h.clone() / p.alpha.clone()).powf(p.beta.clone()).neg().exp()
        * c
        * fm.cos_h.clone();
    let f = fresnel(fm.cos_r.clone(), fm.sin_r.clone(), p.eta.clone());
    let den = (fm.nv.clone() * fm.nh.clone()).mul_scalar(4.0).add_scalar(DEN_EPS);
    let i_s = p.k_s.clone() * dist * f / den;
    let body_params = Tensor::cat(
        vec![
            p.eta.clone(),
            p.alpha.clone().expand([n, 1]),
            p.beta.clone().expand([n, 1]),
            p.kappa.clone(),
        ],
        1,
    );
    let i_b = nets.body(fm.body.clone(), body_params, products);
    let scale = g_smith / fm.nl.clone().add_scalar(DEN_EPS);
    (i_s + p.rho.clone() * i_b) * scale * g.mask.clone()
}
