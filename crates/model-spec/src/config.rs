//! The configuration of any model of the comparison, [`ModelConfig`], selectable by name, and
//! what follows from it without building the model: validation, the MLP layer tables
//! ([`ModelConfig::mlp_configs`]) and the parameter count (brdf-neural builds the model from
//! the same layer tables).
//!
//! ```toml
//! kind = "additive_shared_enhanced"   # or a paper row name: "Enh. Add. Shared"
//! spatial_dim = 160
//! [angles]
//! parametrization = "rusinkiewicz"
//! reciprocity = "mapping"
//! ```

use crate::features::AngleConfig;
use crate::kind::ModelKind;
use crate::mlp::MlpConfig;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// Configuration of any model of the comparison (spec sections 3 and 4, decisions table).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ModelConfig {
    /// Which model (default `single_mlp`).
    pub kind: ModelKind,
    /// Width of the spatial feature vector (default 160, the LBO encoding).
    pub spatial_dim: usize,
    /// Width of every hidden layer (default 128).
    pub width: usize,
    /// Linear layer (0-based) that the input skip of the 6-layer nets and of the Additive
    /// Shared trunk enters (default 3, the intrinsic-neural-fields convention).
    pub skip_layer: usize,
    /// Additive Separate: the raw input is concatenated to the output of this hidden layer
    /// (default 2, NeRFactor's `mlp_skip_at`).
    pub separate_skip_at: usize,
    /// Additive Shared: hidden layers of the diffuse head (default 1).
    pub shared_diffuse_head_layers: usize,
    /// Direction features (default: Rusinkiewicz angles, no reciprocity option, PE with 3
    /// frequencies). Ignored by the parametric models.
    pub angles: AngleConfig,
    /// The NOL ablation of the purely neural models (default false).
    pub nol: bool,
    /// Single MLP NOL: the linear layer the directions enter (default 3, "layer 4").
    pub nol_layer: usize,
    /// NeRFactor ablation: albedo clamped into [0.0023, 0.6038] (default false; additive only).
    pub albedo_clamp: bool,
    /// NeRFactor ablation: one specular channel broadcast to RGB (default false; additive only).
    pub scalar_specular: bool,
    /// Factor on the additive models' specular softplus (default 0.5).
    pub specular_softplus_scale: f64,
    /// Factor on the Single MLP's output softplus (default 1.0).
    pub single_mlp_softplus_scale: f64,
    /// Disney: apply base_color^2.2 (default false: linear base colour).
    pub disney_gamma: bool,
}

impl Default for ModelConfig {
    fn default() -> Self {
        Self {
            kind: ModelKind::SingleMlp,
            spatial_dim: 160,
            width: 128,
            skip_layer: 3,
            separate_skip_at: 2,
            shared_diffuse_head_layers: 1,
            angles: AngleConfig::default(),
            nol: false,
            nol_layer: 3,
            albedo_clamp: false,
            scalar_specular: false,
            specular_softplus_scale: 0.5,
            single_mlp_softplus_scale: 1.0,
            disney_gamma: false,
        }
    }
}

impl ModelConfig {
    /// The default configuration of `kind`.
    pub fn new(kind: ModelKind) -> Self {
        Self { kind, ..Self::default() }
    }

    /// The default configuration of the model named `name` (configuration or paper name).
    pub fn from_name(name: &str) -> Result<Self> {
        Ok(Self::new(ModelKind::from_name(name)?))
    }

    /// The MLP configurations the model is built from.
    pub fn mlp_configs(&self) -> Vec<MlpConfig> {
        crate::layers::mlp_configs(self)
    }

    /// Checks the configuration: options only where the paper combines them, sizes > 0,
    /// consistent layer indices.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidConfig(m));
        self.angles.validate()?;
        if self.spatial_dim == 0 || self.width == 0 {
            return bad("spatial_dim and width must be positive".into());
        }
        let name = self.kind.config_name();
        if (self.albedo_clamp || self.scalar_specular) && !self.kind.is_additive() {
            return bad(format!(
                "albedo_clamp / scalar_specular apply to additive models, not {name}"
            ));
        }
        if self.nol && self.kind.analytic().is_some() {
            return bad(format!("nol applies to the purely neural models, not {name}"));
        }
        if !(self.specular_softplus_scale > 0.0 && self.single_mlp_softplus_scale > 0.0) {
            return bad("softplus scales must be positive".into());
        }
        if let Some(m) = self.mlp_configs().iter().find(|m| !m.is_valid()) {
            return bad(format!("layer indices out of range in {m:?} (skip_layer, nol_layer)"));
        }
        Ok(())
    }

    /// Number of trainable scalars of the model.
    pub fn param_count(&self) -> usize {
        let mlps: usize = self.mlp_configs().iter().map(MlpConfig::param_count).sum();
        mlps + if self.kind == ModelKind::Fmbrdf { 2 } else { 0 }
    }

    /// Whether the model consumes direction features (the purely neural models).
    pub fn uses_angle_features(&self) -> bool {
        self.kind.analytic().is_none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Reciprocity;

    #[test]
    fn parameter_counts_match_the_crate_docs() {
        // The table in the crate-level docs (default configuration, 160 spatial inputs).
        let documented = [
            (ModelKind::Rp, 108_039, None, None),
            (ModelKind::Ts, 108_039, None, None),
            (ModelKind::Fmbrdf, 107_912, None, None),
            (ModelKind::Disney, 108_684, None, None),
            (ModelKind::SingleMlp, 112_899, Some(114_691), Some(110_211)),
            (ModelKind::AdditiveSeparate, 187_398, Some(189_190), Some(131_206)),
            (ModelKind::AdditiveShared, 160_134, Some(161_030), Some(172_678)),
            (ModelKind::AdditiveSeparateEnhanced, 187_785, Some(189_577), Some(131_593)),
            (ModelKind::AdditiveSharedEnhanced, 160_521, Some(161_417), Some(173_065)),
        ];
        for (kind, default, mapping, nol) in documented {
            let c = ModelConfig::new(kind);
            assert_eq!(c.param_count(), default, "{kind:?}");
            if let (Some(m), Some(n)) = (mapping, nol) {
                let mut cm = c.clone();
                cm.angles.reciprocity = Reciprocity::Mapping;
                assert_eq!(cm.param_count(), m, "{kind:?} mapping");
                let mut cn = c.clone();
                cn.nol = true;
                assert_eq!(cn.param_count(), n, "{kind:?} nol");
            }
        }
    }

    #[test]
    fn validation_names_the_fault() {
        for kind in ModelKind::ALL {
            assert!(ModelConfig::new(kind).validate().is_ok(), "{kind:?}");
        }
        let message = |c: ModelConfig| c.validate().unwrap_err().to_string();
        let mut c = ModelConfig::new(ModelKind::SingleMlp);
        c.albedo_clamp = true;
        assert_eq!(
            message(c),
            "invalid model configuration: albedo_clamp / scalar_specular apply to additive \
             models, not single_mlp"
        );
        let c = ModelConfig { nol: true, ..ModelConfig::new(ModelKind::Disney) };
        assert!(message(c).contains("nol applies to the purely neural models, not disney"));
        let c = ModelConfig { width: 0, ..ModelConfig::default() };
        assert!(message(c).contains("spatial_dim and width must be positive"));
        let c = ModelConfig { skip_layer: 6, ..ModelConfig::default() };
        assert!(message(c).contains("layer indices out of range"));
        let mut c = ModelConfig::default();
        c.angles.reciprocity = Reciprocity::Mapping;
        c.angles.parametrization = crate::AngleParametrization::ViewLight;
        assert!(message(c).contains("Rusinkiewicz angles only"));
        assert_eq!(
            ModelConfig::from_name("Add. Shared").unwrap(),
            ModelConfig::new(ModelKind::AdditiveShared)
        );
        assert!(ModelConfig::from_name("nope").is_err());
    }
}
