//! The layer tables of every model: which MLPs a configuration builds, their widths, depths,
//! skips and where the direction features enter ([`mlp_configs`]). brdf-neural builds the
//! networks from them; the parameter counts follow from them alone.
//!
//! **Parametric models.** The parametric models' layer table (spec 3 and 4.1): an MLP (6 x 128, ReLU, input skip to
//! layer 3) maps the spatial features of x to the parameters of an analytic BRDF, [`Analytic`];
//! brdf-neural maps its raw outputs through sigmoids and softpluses into the parameters'
//! ranges and evaluates a tensor twin of the `brdf-analytic` model for the sample's
//! directions.
//!
//! **Single MLP.** The Single MLP's layer table (spec 4.2): one 6 x 128 ReLU MLP with the input skip to layer 3
//! maps [spatial features, PE(angles)] to the 3 outputs that brdf-neural's softplus turns into
//! RGB.
//!
//! NOL ablation: the directions enter at linear layer `nol_layer` (default 3, the paper's
//! "layer 4") instead of layer 0, so they pass through 3 instead of 6 layers; the spatial input
//! still enters at layer 0 and the skip re-injects it (only it) at layer 3.
//!
//! **Additive Separate.** The layer table of Additive Separate (NeRFactor-style split, spec 4.3) and its enhanced
//! variant (spec 4.5), f = f_d(x) + f_s(x, l, v) (enhanced: (1 - xi) f_d + f_s): two
//! independent 4 x 128 MLPs with the input concatenated after hidden layer 2, the diffuse one
//! on the spatial features (3 outputs), the specular one on [spatial features, PE(angles)]
//! ([`specular_outputs`] outputs: f_s, and xi when
//! enhanced).
//!
//! NOL ablation: the specular MLP has 2 hidden layers and no skip.
//!
//! **Additive Shared.** The layer table of Additive Shared (LitNeRF-style, spec 4.4) and its enhanced variant
//! (spec 4.5): a shared trunk (5 x 128, skip to layer 3) maps the spatial features to a 128-d
//! feature; a diffuse head (one hidden layer, then 3 outputs) and a specular head (input
//! [feature, PE(angles)], two hidden layers, then 3 outputs; +3 for xi when enhanced).
//!
//! NOL ablation: trunk 3 layers (no skip: layer 3 does not exist), heads +2 hidden layers each,
//! so the directions pass through 4 layers.
//!
//! **Specular outputs.** The width of the additive models' specular output, which their layer tables need: 3 RGB
//! channels (1 with the NeRFactor ablation `scalar_specular`, broadcast to RGB), then 3 more
//! for xi in the enhanced models. brdf-neural's `AdditiveHead` turns the outputs into f_d, f_s
//! and xi.

use crate::config::ModelConfig;
use crate::kind::{Analytic, ModelKind};
use crate::mlp::MlpConfig;

/// The MLP configurations of the model `c` configures, in the order brdf-neural builds them.
pub fn mlp_configs(c: &ModelConfig) -> Vec<MlpConfig> {
    if let Some(a) = c.kind.analytic() {
        return vec![parametric_config(c, a)];
    }
    match c.kind {
        ModelKind::SingleMlp => vec![single_mlp_config(c)],
        ModelKind::AdditiveSeparate | ModelKind::AdditiveSeparateEnhanced => {
            let (d, s) = additive_separate_configs(c);
            vec![d, s]
        }
        _ => {
            let (t, d, s) = additive_shared_configs(c);
            vec![t, d, s]
        }
    }
}

/// Width of the specular network's output of an additive model configured by `c`.
pub fn specular_outputs(c: &ModelConfig) -> usize {
    (if c.scalar_specular { 1 } else { 3 }) + if c.kind.is_enhanced() { 3 } else { 0 }
}

/// The MLP configuration of a Single MLP.
pub fn single_mlp_config(c: &ModelConfig) -> MlpConfig {
    let mut m = MlpConfig::new(c.spatial_dim);
    m.width = c.width;
    m.hidden_layers = 5;
    m.d_output = Some(3);
    m.skip_into = Some(c.skip_layer);
    m.d_late = c.angles.dim();
    m.late_into = if c.nol { c.nol_layer } else { 0 };
    m
}

/// The two MLP configurations (diffuse, specular).
pub fn additive_separate_configs(c: &ModelConfig) -> (MlpConfig, MlpConfig) {
    let mut d = MlpConfig::new(c.spatial_dim);
    d.width = c.width;
    d.hidden_layers = 4;
    d.d_output = Some(3);
    d.skip_into = Some(c.separate_skip_at + 1);
    let mut s = d.clone();
    s.d_output = Some(specular_outputs(c));
    s.d_late = c.angles.dim();
    if c.nol {
        s.hidden_layers = 2;
        s.skip_into = None;
    }
    (d, s)
}

/// The trunk, diffuse-head and specular-head configurations.
pub fn additive_shared_configs(c: &ModelConfig) -> (MlpConfig, MlpConfig, MlpConfig) {
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
    s.d_output = Some(specular_outputs(c));
    s.d_late = c.angles.dim();
    (t, d, s)
}

/// The parameter MLP's configuration.
pub fn parametric_config(c: &ModelConfig, analytic: Analytic) -> MlpConfig {
    let mut m = MlpConfig::new(c.spatial_dim);
    m.width = c.width;
    m.hidden_layers = 5;
    m.d_output = Some(analytic.outputs());
    m.skip_into = Some(c.skip_layer);
    m
}
