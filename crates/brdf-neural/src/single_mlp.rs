//! Single MLP (spec 4.2): one 6 x 128 ReLU MLP with the input skip to layer 3 maps
//! [spatial features, PE(angles)] to RGB through a softplus, f = s softplus(z) with the scale
//! s = `single_mlp_softplus_scale` (default 1).
//!
//! The layer table, and where the NOL ablation feeds the directions in, is
//! [`model_spec::layers::single_mlp_config`].

use crate::mlp::Mlp;
use crate::output::BrdfOutput;
use crate::products::Products;
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
    pub fn forward(&self, spatial: Tensor<2>, angles: Tensor<2>, products: Products) -> BrdfOutput {
        let z = self.mlp.forward(spatial, Some(angles), products);
        let f = softplus(z, 1.0).mul_scalar(self.output_scale);
        BrdfOutput { f, diffuse: None, specular: None, xi: None }
    }
}
