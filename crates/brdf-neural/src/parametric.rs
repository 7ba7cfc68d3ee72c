//! Parametric models (spec 3 and 4.1): an MLP (6 x 128, ReLU, input skip to layer 3) maps the
//! spatial features of x to the parameters of an analytic BRDF, which a tensor twin of the
//! `brdf-analytic` model then evaluates for the sample's directions.
//!
//! The layer table and the columns of the MLP's output are `model-spec`'s
//! ([`model_spec::layers`], with [`Analytic`], re-exported here). Output nonlinearities
//! ("sigmoid or softplus depending on the range"; roughness scaled by 0.5 before its sigmoid):
//!
//! | model | outputs | mapping |
//! | --- | --- | --- |
//! | RP | 7 | k = sigmoid (RGB), zeta = sigmoid (RGB), k_d = zeta k, k_s = (1 - zeta) k, N = 1 + softplus |
//! | TS | 7 | r = sigmoid(0.5 z), rho_d = sigmoid (RGB), F0 = sigmoid (RGB) |
//! | Disney | 12 | base colour (RGB) and the 9 scalars, all sigmoid; roughness sigmoid(0.5 z); anisotropic fixed to 0 (not predicted) |
//! | FMBRDF | 6 + 2 global | eta = 1.1 + 1.4 sigmoid, rho = sigmoid (RGB), k_s = softplus, kappa = 100 sigmoid per point; alpha = 0.001 + (2 pi - 0.001) sigmoid(g a), beta = 0.5 + 3.5 sigmoid(g b) with a, b two trainable scalars per object and the gain g = [`FMBRDF_GLOBAL_GAIN`] |

use crate::mlp::Mlp;
use crate::output::BrdfOutput;
use crate::products::Products;
use crate::tensor_brdf::{
    DisneyTensorParams, FmbrdfNets, FmbrdfTensorParams, Geometry, PhongTensorParams,
    TorranceSparrowTensorParams, disney, fmbrdf, realistic_phong, torrance_sparrow,
};
use burn::module::{Module, Param};
use burn::tensor::activation::{sigmoid, softplus};
use burn::tensor::{Device, Tensor, TensorData};
pub use model_spec::Analytic;
use std::f64::consts::TAU;

/// FMBRDF ranges of the global alpha and beta.
pub const FMBRDF_ALPHA_RANGE: (f64, f64) = (0.001, TAU);
/// See [`FMBRDF_ALPHA_RANGE`].
pub const FMBRDF_BETA_RANGE: (f64, f64) = (0.5, 4.0);
/// Initial alpha and beta (the scalar model's defaults).
const FMBRDF_INIT: (f64, f64) = (0.3, 2.0);
/// FMBRDF's two per-object scalars are stored divided by this gain and multiplied by it before
/// their sigmoid. Adam's step is about the learning rate in the units of the stored value,
/// whatever the gradient's size, so a lone scalar at rate 1e-3 needs thousands of steps to
/// cross the O(1) span of its sigmoid's argument (on Spot x blue-acrylic the test PSNR was
/// still climbing after thousands of steps; `benches/README.md`). The gain moves them as fast
/// as the per-point parameters, which the MLP's many weights move together.
pub const FMBRDF_GLOBAL_GAIN: f64 = 10.0;

/// The parameters a parametric model predicts for a batch.
#[allow(clippy::large_enum_variant)] // one per forward pass; Disney has 10 tensors
#[derive(Clone, Debug)]
pub enum BrdfParams {
    /// Realistic Phong.
    RealisticPhong(PhongTensorParams),
    /// Torrance-Sparrow.
    TorranceSparrow(TorranceSparrowTensorParams),
    /// Disney.
    Disney(DisneyTensorParams),
    /// FMBRDF.
    Fmbrdf(FmbrdfTensorParams),
}

/// A parametric model.
#[derive(Module, Debug)]
pub struct ParametricModel {
    /// The parameter MLP (spatial features -> raw outputs).
    pub mlp: Mlp,
    /// FMBRDF: the raw global alpha, `[1, 1]`.
    pub fm_alpha: Option<Param<Tensor<2>>>,
    /// FMBRDF: the raw global beta, `[1, 1]`.
    pub fm_beta: Option<Param<Tensor<2>>>,
    /// FMBRDF: the fixed helper networks.
    pub fm_nets: Option<FmbrdfNets>,
    #[module(skip)]
    analytic: Analytic,
    #[module(skip)]
    gamma_base_color: bool,
}

fn logit(p: f64) -> f64 {
    (p / (1.0 - p)).ln()
}

fn scalar_param(x: f64, device: &Device) -> Param<Tensor<2>> {
    Param::from_tensor(Tensor::from_data(TensorData::new(vec![x as f32], [1, 1]), device))
}

/// sigmoid(z) of every column at once, with the roughness column `half` scaled by 0.5 first
/// (one element-wise pass over the contiguous outputs; the same values as a sigmoid per column,
/// since multiplying by 1 and 0.5 is exact).
fn sigmoid_scaled(z: Tensor<2>, half: usize) -> Tensor<2> {
    let k = z.dims()[1];
    let scale: Vec<f32> = (0..k).map(|i| if i == half { 0.5 } else { 1.0 }).collect();
    let scale = Tensor::<2>::from_data(TensorData::new(scale, [1, k]), &z.device());
    sigmoid(z * scale)
}

/// sigmoid mapped into [lo, hi].
fn ranged(z: Tensor<2>, (lo, hi): (f64, f64)) -> Tensor<2> {
    sigmoid(z).mul_scalar(hi - lo).add_scalar(lo)
}

impl ParametricModel {
    pub(crate) fn new(
        mlp: Mlp,
        analytic: Analytic,
        gamma_base_color: bool,
        device: &Device,
    ) -> Self {
        let fm = analytic == Analytic::Fmbrdf;
        let init = |x: f64, (lo, hi): (f64, f64)| {
            scalar_param(logit((x - lo) / (hi - lo)) / FMBRDF_GLOBAL_GAIN, device)
        };
        Self {
            mlp,
            fm_alpha: fm.then(|| init(FMBRDF_INIT.0, FMBRDF_ALPHA_RANGE)),
            fm_beta: fm.then(|| init(FMBRDF_INIT.1, FMBRDF_BETA_RANGE)),
            fm_nets: fm.then(|| FmbrdfNets::new(device)),
            analytic,
            gamma_base_color,
        }
    }

    /// The analytic model this one drives.
    pub fn analytic(&self) -> Analytic {
        self.analytic
    }

    /// The BRDF parameters of each sample.
    ///
    /// # Shapes
    /// - spatial: `[batch, spatial_dim]`
    /// - output: per-sample tensors `[batch, k]` (FMBRDF alpha and beta `[1, 1]`)
    pub fn params(&self, spatial: Tensor<2>) -> BrdfParams {
        self.params_of_outputs(self.mlp.forward(spatial, None, Products::F32))
    }

    /// The BRDF parameters of each sample from the parameter MLP's raw outputs (the output
    /// nonlinearities of the module table).
    ///
    /// # Shapes
    /// - z: `[batch, outputs]` ([`Analytic::outputs`])
    /// - output: as [`ParametricModel::params`]
    pub fn params_of_outputs(&self, z: Tensor<2>) -> BrdfParams {
        let col = |k: usize, n: usize| z.clone().narrow(1, k, n);
        match self.analytic {
            Analytic::RealisticPhong => {
                let k = sigmoid(col(0, 3));
                let zeta = sigmoid(col(3, 3));
                PhongTensorParams {
                    kd: zeta.clone() * k.clone(),
                    ks: zeta.neg().add_scalar(1.0) * k,
                    exponent: softplus(col(6, 1), 1.0).add_scalar(1.0),
                }
                .into()
            }
            Analytic::TorranceSparrow => {
                let s = sigmoid_scaled(z, 0);
                let col = |k: usize, n: usize| s.clone().narrow(1, k, n);
                TorranceSparrowTensorParams {
                    roughness: col(0, 1),
                    diffuse: col(1, 3),
                    f0: col(4, 3),
                }
                .into()
            }
            Analytic::Disney => {
                let s = sigmoid_scaled(z, 6);
                let col = |k: usize, n: usize| s.clone().narrow(1, k, n);
                DisneyTensorParams {
                    base_color: col(0, 3),
                    metallic: col(3, 1),
                    subsurface: col(4, 1),
                    specular: col(5, 1),
                    roughness: col(6, 1),
                    specular_tint: col(7, 1),
                    sheen: col(8, 1),
                    sheen_tint: col(9, 1),
                    clearcoat: col(10, 1),
                    clearcoat_gloss: col(11, 1),
                    gamma_base_color: self.gamma_base_color,
                }
                .into()
            }
            Analytic::Fmbrdf => {
                let raw = |p: &Option<Param<Tensor<2>>>| {
                    p.as_ref().expect("FMBRDF global").val().mul_scalar(FMBRDF_GLOBAL_GAIN)
                };
                FmbrdfTensorParams {
                    eta: ranged(col(0, 1), (1.1, 2.5)),
                    rho: sigmoid(col(1, 3)),
                    k_s: softplus(col(4, 1), 1.0),
                    kappa: sigmoid(col(5, 1)).mul_scalar(100.0),
                    alpha: ranged(raw(&self.fm_alpha), FMBRDF_ALPHA_RANGE),
                    beta: ranged(raw(&self.fm_beta), FMBRDF_BETA_RANGE),
                }
                .into()
            }
        }
    }

    /// Evaluates the model.
    ///
    /// # Shapes
    /// - spatial: `[batch, spatial_dim]`; geometry of `batch` pairs
    /// - output: `f` `[batch, 3]`
    pub fn forward(
        &self,
        spatial: Tensor<2>,
        geometry: &Geometry,
        products: Products,
    ) -> BrdfOutput {
        let z = self.mlp.forward(spatial, None, products);
        let f = self.brdf_of_outputs(z, geometry, products);
        BrdfOutput { f, diffuse: None, specular: None, xi: None }
    }

    /// The analytic BRDF of the parameters the raw outputs `z` map to (the model after its
    /// parameter MLP; the `tensor_brdf` bench times this alone).
    ///
    /// # Shapes
    /// - z: `[batch, outputs]`; geometry of `batch` pairs
    /// - output: `f` `[batch, 3]`
    pub fn brdf_of_outputs(
        &self,
        z: Tensor<2>,
        geometry: &Geometry,
        products: Products,
    ) -> Tensor<2> {
        match self.params_of_outputs(z) {
            BrdfParams::RealisticPhong(p) => realistic_phong(&p, geometry),
            BrdfParams::TorranceSparrow(p) => torrance_sparrow(&p, geometry),
            BrdfParams::Disney(p) => disney(&p, geometry),
            BrdfParams::Fmbrdf(p) => {
                fmbrdf(&p, self.fm_nets.as_ref().expect("FMBRDF nets"), geometry, products)
            }
        }
    }
}

macro_rules! into_params {
    ($($t:ident => $v:ident),*) => {$(
        impl From<$t> for BrdfParams {
            fn from(p: $t) -> Self {
                BrdfParams::$v(p)
            }
        }
    )*};
}
into_params!(
    PhongTensorParams => RealisticPhong,
    TorranceSparrowTensorParams => TorranceSparrow,
    DisneyTensorParams => Disney,
    FmbrdfTensorParams => Fmbrdf
);
