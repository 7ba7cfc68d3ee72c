//! Additive Separate (NeRFactor-style split, spec 4.3) and its enhanced variant (spec 4.5):
//! f = f_d(x) + f_s(x, l, v), two independent 4 x 128 MLPs with the input concatenated after
//! hidden layer 2; f_d = sigmoid / pi, f_s = 0.5 softplus. Enhanced: the specular MLP also
//! outputs xi in [0, 1]^3 and f = (1 - xi) f_d + f_s.
//!
//! NeRFactor ablations: albedo clamped into [0.0023, 0.6038], scalar specular. The layer table
//! (and the NOL ablation's: the specular MLP has 2 hidden layers and no skip) is
//! [`model_spec::layers::additive_separate_configs`].

use crate::mlp::Mlp;
use crate::output::{AdditiveHead, BrdfOutput};
use crate::products::Products;
use burn::module::Module;
use burn::tensor::Tensor;

/// Additive Separate (plain or enhanced).
#[derive(Module, Debug)]
pub struct AdditiveSeparate {
    /// Diffuse MLP, input: spatial features.
    pub diffuse: Mlp,
    /// Specular MLP, input: [spatial features, PE(angles)].
    pub specular: Mlp,
    #[module(skip)]
    head: AdditiveHead,
}

impl AdditiveSeparate {
    pub(crate) fn new(diffuse: Mlp, specular: Mlp, head: AdditiveHead) -> Self {
        Self { diffuse, specular, head }
    }

    /// How the raw outputs become f_d, f_s and xi.
    pub(crate) fn head(&self) -> &AdditiveHead {
        &self.head
    }

    /// Evaluates the model.
    ///
    /// # Shapes
    /// - spatial: `[batch, spatial_dim]`; angles: `[batch, angle_dim]`
    /// - output: `f`, `diffuse`, `specular` (and `xi` when enhanced) `[batch, 3]`
    pub fn forward(&self, spatial: Tensor<2>, angles: Tensor<2>, products: Products) -> BrdfOutput {
        let d = self.diffuse.forward(spatial.clone(), None, products);
        let s = self.specular.forward(spatial, Some(angles), products);
        self.head.combine(d, s)
    }
}
