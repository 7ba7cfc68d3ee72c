//! Single MLP (spec 4.2): one 6 x 128 ReLU MLP with the input skip to layer 3 maps
//! [spatial features, PE(angles)] to RGB through a softplus.
//!
//! NOL ablation: the directions enter at linear layer `nol_layer` (default 3, the paper's
//! "layer 4") instead of layer 0, so they pass through 3 instead of 6 layers; the spatial input
//! still enters at layer 0 and the skip re-injects it (only it) at layer 3.

use crate::mlp::{Mlp, MlpConfig};
use crate::output::BrdfOutput;
use burn::module::Module;
use burn::tensor::Tensor;
use burn::tensor::activation::softplus;

/// The Single MLP.
#[derive(Module, Debug)]
pub struct SingleMlp {
    /// The network.
    pub mlp: Mlp,
    #[module(skip)]
    output_scale: f32,
}

/// The MLP configuration of a Single MLP.
pub(crate) fn single_mlp_config(c: &crate::ModelConfig) -> MlpConfig {
    let mut m = MlpConfig::new(c.spatial_dim);
    m.width = c.width;
    m.hidden_layers = 5;
    m.d_output = Some(3);
    m.skip_into = Some(c.skip_layer);
    m.d_late = c.angles.dim();
    m.late_into = if c.nol { c.nol_layer } else { 0 };
    m
}

impl SingleMlp {
    /// Builds the model from its MLP and the softplus output scale.
    pub(crate) fn new(mlp: Mlp, output_scale: f32) -> Self {
        Self { mlp, output_scale }
    }

    /// The factor on the output softplus.
    pub fn scale(&self) -> f32 {
        self.output_scale
    }

    /// Evaluates the model.
    ///
    /// # Shapes
    /// - spatial: `[batch, spatial_dim]`; angles: `[batch, angle_dim]`
    /// - output: `f` `[batch, 3]`
    pub fn forward(&self, spatial: Tensor<2>, angles: Tensor<2>) -> BrdfOutput {
        let z = self.mlp.forward(spatial, Some(angles));
        let f = softplus(z, 1.0).mul_scalar(self.output_scale);
        BrdfOutput { f, diffuse: None, specular: None, xi: None }
    }
}
