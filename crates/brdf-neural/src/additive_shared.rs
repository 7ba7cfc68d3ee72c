//! Additive Shared (LitNeRF-style, spec 4.4) and its enhanced variant (spec 4.5): a shared
//! trunk (5 x 128, skip to layer 3) maps the spatial features to a 128-d feature; a diffuse head
//! (one hidden layer, then 3 outputs, sigmoid / pi) and a specular head (input [feature,
//! PE(angles)], two hidden layers, then 3 outputs, 0.5 softplus; +3 for xi when enhanced).
//!
//! The layer table (and the NOL ablation's: trunk 3 layers, no skip, heads +2 hidden layers
//! each, so the directions pass through 4 layers) is
//! [`model_spec::layers::additive_shared_configs`].

use crate::mlp::Mlp;
use crate::output::{AdditiveHead, BrdfOutput};
use crate::products::Products;
use burn::module::Module;
use burn::tensor::Tensor;

/// Additive Shared (plain or enhanced).
#[derive(Module, Debug)]
pub struct AdditiveShared {
    /// The shared trunk (no output layer).
    pub trunk: Mlp,
    /// The diffuse head.
    pub diffuse: Mlp,
    /// The specular head.
    pub specular: Mlp,
    #[module(skip)]
    head: AdditiveHead,
}

impl AdditiveShared {
    pub(crate) fn new(trunk: Mlp, diffuse: Mlp, specular: Mlp, head: AdditiveHead) -> Self {
        Self { trunk, diffuse, specular, head }
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
        let feature = self.trunk.forward(spatial, None, products);
        let d = self.diffuse.forward(feature.clone(), None, products);
        let s = self.specular.forward(feature, Some(angles), products);
        self.head.combine(d, s)
    }
}
