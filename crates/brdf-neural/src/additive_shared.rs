//! Additive Shared (LitNeRF-style, spec 4.4) and its enhanced variant (spec 4.5): a shared
//! trunk (5 x 128, skip to layer 3) maps the spatial features to a 128-d feature; a diffuse head
//! (one hidden layer, then 3 outputs, sigmoid / pi) and a specular head (input [feature,
//! PE(angles)], two hidden layers, then 3 outputs, 0.5 softplus; +3 for xi when enhanced).
//!
//! NOL ablation: trunk 3 layers (no skip: layer 3 does not exist), heads +2 hidden layers each,
//! so the directions pass through 4 layers.

use crate::mlp::{Mlp, MlpConfig};
use crate::output::{AdditiveHead, BrdfOutput};
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

/// The trunk, diffuse-head and specular-head configurations.
pub(crate) fn additive_shared_configs(c: &crate::ModelConfig) -> (MlpConfig, MlpConfig, MlpConfig) {
    let head = c.additive_head();
    let extra = if c.nol { 2 } else { 0 };
    let mut t = MlpConfig::new(c.spatial_dim);
    t.width = c.width;
    t.hidden_layers = if c.nol { 3 } else { 5 };
    t.skip_into = (c.skip_layer < t.hidden_layers).then_some(c.skip_layer);
    let mut d = MlpConfig::new(c.width);
    d.width = c.width;
    d.hidden_layers = c.shared_diffuse_head_layers + extra;
    d.d_output = Some(3);
    let mut s = d.clone();
    s.hidden_layers = 2 + extra;
    s.d_output = Some(head.specular_outputs());
    s.d_late = c.angles.dim();
    (t, d, s)
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
    pub fn forward(&self, spatial: Tensor<2>, angles: Tensor<2>) -> BrdfOutput {
        let feature = self.trunk.forward(spatial, None);
        let d = self.diffuse.forward(feature.clone(), None);
        let s = self.specular.forward(feature, Some(angles));
        self.head.combine(d, s)
    }
}
