//! What a model returns, and the output nonlinearities shared by the additive models.

use crate::ModelConfig;
use burn::tensor::Tensor;
use burn::tensor::activation::{sigmoid, softplus};
use std::f32::consts::FRAC_1_PI;

/// The sRGB-to-linear bounds of NeRFactor's albedo range [0.03, 0.80] (spec 4.3 (a)).
pub const NERFACTOR_ALBEDO_RANGE: (f32, f32) = (0.0023, 0.6038);

/// A model's output for a batch.
#[derive(Clone, Debug)]
pub struct BrdfOutput {
    /// The BRDF value f_r in 1/sr, linear RGB, `[batch, 3]`, finite and >= 0.
    pub f: Tensor<2>,
    /// Additive models: the raw diffuse part f_d (without the enhanced models' 1 - xi),
    /// `[batch, 3]`.
    pub diffuse: Option<Tensor<2>>,
    /// Additive models: the specular part f_s, `[batch, 3]`.
    pub specular: Option<Tensor<2>>,
    /// Enhanced additive models: xi in [0, 1]^3, `[batch, 3]`.
    pub xi: Option<Tensor<2>>,
}

/// How the additive models turn raw network outputs into f_d, f_s and xi.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AdditiveHead {
    /// Clamp the albedo into [`NERFACTOR_ALBEDO_RANGE`] instead of sigmoid / pi.
    pub albedo_clamp: bool,
    /// One specular channel broadcast to RGB.
    pub scalar_specular: bool,
    /// Predict xi (3 extra specular outputs) and combine (1 - xi) f_d + f_s.
    pub enhanced: bool,
    /// Factor on the specular softplus (0.5 in the paper).
    pub specular_scale: f32,
}

impl AdditiveHead {
    /// The additive output head of the configuration `c`.
    pub fn of(c: &ModelConfig) -> Self {
        AdditiveHead {
            albedo_clamp: c.albedo_clamp,
            scalar_specular: c.scalar_specular,
            enhanced: c.kind.is_enhanced(),
            specular_scale: c.specular_softplus_scale as f32,
        }
    }

    /// Combines the raw diffuse `[batch, 3]` and specular `[batch, k]` outputs, k the width
    /// [`model_spec::layers::specular_outputs`] gives the specular network.
    pub fn combine(&self, diffuse_raw: Tensor<2>, specular_raw: Tensor<2>) -> BrdfOutput {
        let s = sigmoid(diffuse_raw);
        let fd = if self.albedo_clamp {
            let (lo, hi) = NERFACTOR_ALBEDO_RANGE;
            s.mul_scalar(hi - lo).add_scalar(lo).mul_scalar(FRAC_1_PI)
        } else {
            s.mul_scalar(FRAC_1_PI)
        };
        let n_spec = if self.scalar_specular { 1 } else { 3 };
        let batch = specular_raw.dims()[0];
        let fs = softplus(specular_raw.clone().narrow(1, 0, n_spec), 1.0)
            .mul_scalar(self.specular_scale)
            .expand([batch, 3]);
        if self.enhanced {
            let xi = sigmoid(specular_raw.narrow(1, n_spec, 3));
            let f = xi.clone().neg().add_scalar(1.0) * fd.clone() + fs.clone();
            BrdfOutput { f, diffuse: Some(fd), specular: Some(fs), xi: Some(xi) }
        } else {
            BrdfOutput {
                f: fd.clone() + fs.clone(),
                diffuse: Some(fd),
                specular: Some(fs),
                xi: None,
            }
        }
    }
}
