//! The model configuration, selectable by name, and the model it builds.
//!
//! ```toml
//! kind = "additive_shared_enhanced"   # or a paper row name: "Enh. Add. Shared"
//! spatial_dim = 160
//! [angles]
//! parametrization = "rusinkiewicz"
//! reciprocity = "mapping"
//! ```

use crate::additive_separate::{AdditiveSeparate, additive_separate_configs};
use crate::additive_shared::{AdditiveShared, additive_shared_configs};
use crate::batch::{BrdfBatch, Samples};
use crate::features::AngleConfig;
use crate::mlp::MlpConfig;
use crate::output::{AdditiveHead, BrdfOutput};
use crate::parametric::{Analytic, ParametricModel, parametric_config};
use crate::single_mlp::{SingleMlp, single_mlp_config};
use crate::{Error, Result};
use burn::module::Module;
use burn::tensor::Device;
use serde::{Deserialize, Serialize};

/// The models of the paper's tables.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// Realistic Phong driven by an MLP ("RP").
    Rp,
    /// Torrance-Sparrow driven by an MLP ("TS").
    Ts,
    /// FMBRDF driven by an MLP ("FMBRDF").
    Fmbrdf,
    /// Disney driven by an MLP ("Disney").
    Disney,
    /// Single MLP ("Single MLP", default).
    #[default]
    SingleMlp,
    /// Additive Separate ("Add. Sep.").
    AdditiveSeparate,
    /// Additive Shared ("Add. Shared").
    AdditiveShared,
    /// Enhanced Additive Separate ("Enh. Add. Sep.").
    AdditiveSeparateEnhanced,
    /// Enhanced Additive Shared ("Enh. Add. Shared").
    AdditiveSharedEnhanced,
}

impl ModelKind {
    /// Every model, in the paper's table order.
    pub const ALL: [ModelKind; 9] = [
        ModelKind::Rp,
        ModelKind::Ts,
        ModelKind::Fmbrdf,
        ModelKind::Disney,
        ModelKind::SingleMlp,
        ModelKind::AdditiveSeparate,
        ModelKind::AdditiveShared,
        ModelKind::AdditiveSeparateEnhanced,
        ModelKind::AdditiveSharedEnhanced,
    ];

    /// The configuration name (`snake_case`, as in TOML).
    pub fn config_name(self) -> &'static str {
        match self {
            ModelKind::Rp => "rp",
            ModelKind::Ts => "ts",
            ModelKind::Fmbrdf => "fmbrdf",
            ModelKind::Disney => "disney",
            ModelKind::SingleMlp => "single_mlp",
            ModelKind::AdditiveSeparate => "additive_separate",
            ModelKind::AdditiveShared => "additive_shared",
            ModelKind::AdditiveSeparateEnhanced => "additive_separate_enhanced",
            ModelKind::AdditiveSharedEnhanced => "additive_shared_enhanced",
        }
    }

    /// The paper's table row name.
    pub fn paper_name(self) -> &'static str {
        match self {
            ModelKind::Rp => "RP",
            ModelKind::Ts => "TS",
            ModelKind::Fmbrdf => "FMBRDF",
            ModelKind::Disney => "Disney",
            ModelKind::SingleMlp => "Single MLP",
            ModelKind::AdditiveSeparate => "Add. Sep.",
            ModelKind::AdditiveShared => "Add. Shared",
            ModelKind::AdditiveSeparateEnhanced => "Enh. Add. Sep.",
            ModelKind::AdditiveSharedEnhanced => "Enh. Add. Shared",
        }
    }

    /// Looks a model up by configuration name or paper row name (case-insensitive).
    pub fn from_name(name: &str) -> Result<ModelKind> {
        let n = name.trim();
        Self::ALL
            .into_iter()
            .find(|k| {
                k.config_name().eq_ignore_ascii_case(n) || k.paper_name().eq_ignore_ascii_case(n)
            })
            .ok_or_else(|| Error::UnknownModel(name.to_string()))
    }

    /// The analytic model of a parametric kind.
    pub fn analytic(self) -> Option<Analytic> {
        match self {
            ModelKind::Rp => Some(Analytic::RealisticPhong),
            ModelKind::Ts => Some(Analytic::TorranceSparrow),
            ModelKind::Disney => Some(Analytic::Disney),
            ModelKind::Fmbrdf => Some(Analytic::Fmbrdf),
            _ => None,
        }
    }

    /// Whether the kind is an additive split model.
    pub fn is_additive(self) -> bool {
        matches!(
            self,
            ModelKind::AdditiveSeparate
                | ModelKind::AdditiveShared
                | ModelKind::AdditiveSeparateEnhanced
                | ModelKind::AdditiveSharedEnhanced
        )
    }

    /// Whether the kind is an enhanced additive model.
    pub fn is_enhanced(self) -> bool {
        matches!(self, ModelKind::AdditiveSeparateEnhanced | ModelKind::AdditiveSharedEnhanced)
    }
}

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

    /// The additive output head of this configuration.
    pub(crate) fn additive_head(&self) -> AdditiveHead {
        AdditiveHead {
            albedo_clamp: self.albedo_clamp,
            scalar_specular: self.scalar_specular,
            enhanced: self.kind.is_enhanced(),
            specular_scale: self.specular_softplus_scale as f32,
        }
    }

    /// The MLP configurations the model is built from.
    pub fn mlp_configs(&self) -> Vec<MlpConfig> {
        if let Some(a) = self.kind.analytic() {
            return vec![parametric_config(self, a)];
        }
        match self.kind {
            ModelKind::SingleMlp => vec![single_mlp_config(self)],
            ModelKind::AdditiveSeparate | ModelKind::AdditiveSeparateEnhanced => {
                let (d, s) = additive_separate_configs(self);
                vec![d, s]
            }
            _ => {
                let (t, d, s) = additive_shared_configs(self);
                vec![t, d, s]
            }
        }
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

    /// Builds the model on `device` (use an autodiff device for training), its parameter ids
    /// numbered deterministically ([`crate::param_ids`]), its initial weights drawn from the
    /// backend's random generator as it stands (a fit uses [`ModelConfig::init_seeded`]).
    pub fn init(&self, device: &Device) -> Result<BrdfModel> {
        let _draws = initial_draws();
        let model = self.init_drawn(device)?;
        model.visit(&mut Materialize);
        Ok(model)
    }

    /// The model a fit starts from: the backend's generator seeded with `seed`, the output
    /// biases set for `initial_brdf` ([`BrdfModel::with_initial_brdf`]) where given. The same
    /// seed gives the same initial weights whatever other threads of the process do.
    ///
    /// burn keeps one random generator per backend for the whole process, and a parameter
    /// draws its initial values from it lazily, when it is first read. Seeding, building and
    /// training one after the other thus let a model built or trained on another thread in
    /// between (two fits in one process, the tests of one binary) take some of the draws: the
    /// weights, and the whole fit, depended on the timing of the threads. Here the seed and
    /// every draw happen under one process-wide lock, which [`ModelConfig::init`] takes as
    /// well, in the order a fit has always drawn them (the output biases, then the
    /// parameters as a forward pass reads them), so fits keep their weights to the bit.
    pub fn init_seeded(
        &self,
        device: &Device,
        seed: u64,
        initial_brdf: Option<[f32; 3]>,
    ) -> Result<BrdfModel> {
        let _draws = initial_draws();
        device.seed(seed);
        let mut model = self.init_drawn(device)?;
        if let Some(f0) = initial_brdf {
            model = model.with_initial_brdf(f0);
        }
        let n = [[0.0, 0.0, 1.0_f32]];
        let spatial = vec![0.0; self.spatial_dim];
        let one = Samples { spatial: &spatial, l: &n, v: &n };
        drop(model.forward(&self.batch(&one, None, device)?));
        model.visit(&mut Materialize);
        Ok(model)
    }

    /// The model, its parameters not yet drawn (burn draws a parameter when it is first read).
    fn init_drawn(&self, device: &Device) -> Result<BrdfModel> {
        self.validate()?;
        let mut mlps = self.mlp_configs().into_iter().map(|m| m.init(device));
        let mut next = || mlps.next().expect("MLP count");
        Ok(crate::param_ids::deterministic_ids(match self.kind {
            k if k.analytic().is_some() => BrdfModel::Parametric(ParametricModel::new(
                next(),
                k.analytic().expect("parametric"),
                self.disney_gamma,
                device,
            )),
            ModelKind::SingleMlp => {
                BrdfModel::SingleMlp(SingleMlp::new(next(), self.single_mlp_softplus_scale as f32))
            }
            ModelKind::AdditiveSeparate | ModelKind::AdditiveSeparateEnhanced => {
                let (d, s) = (next(), next());
                BrdfModel::AdditiveSeparate(AdditiveSeparate::new(d, s, self.additive_head()))
            }
            _ => {
                let (t, d, s) = (next(), next(), next());
                BrdfModel::AdditiveShared(AdditiveShared::new(t, d, s, self.additive_head()))
            }
        }))
    }
}

/// Reads every parameter once, so that any not yet drawn is drawn now.
struct Materialize;

impl burn::module::ModuleVisitor for Materialize {
    fn visit_float<const D: usize>(
        &mut self,
        param: &burn::module::Param<burn::tensor::Tensor<D>>,
    ) {
        drop(param.val());
    }
}

/// The process-wide lock under which initial weights are drawn from burn's generator (a test
/// that reads a lazily built [`crate::mlp::Mlp`] holds it too).
pub(crate) fn initial_draws() -> std::sync::MutexGuard<'static, ()> {
    static DRAWS: std::sync::Mutex<()> = std::sync::Mutex::new(());
    // A panic while drawing leaves nothing to repair: the next seed restarts the generator.
    DRAWS.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Any model of the comparison.
// Built once per run; the variants differ in size because FMBRDF carries its helper networks.
#[allow(clippy::large_enum_variant)]
#[derive(Module, Debug)]
pub enum BrdfModel {
    /// RP, TS, Disney or FMBRDF driven by an MLP.
    Parametric(ParametricModel),
    /// Single MLP.
    SingleMlp(SingleMlp),
    /// Additive Separate (plain or enhanced).
    AdditiveSeparate(AdditiveSeparate),
    /// Additive Shared (plain or enhanced).
    AdditiveShared(AdditiveShared),
}

impl BrdfModel {
    /// Evaluates the model on a batch built by [`ModelConfig::batch`] of the same
    /// configuration.
    ///
    /// # Shapes
    /// - batch: `batch` samples
    /// - output: `f` `[batch, 3]` (see [`BrdfOutput`] for the parts)
    ///
    /// # Panics
    /// If the batch lacks the inputs the model needs (a batch of another configuration).
    pub fn forward(&self, batch: &BrdfBatch) -> BrdfOutput {
        let angles = || batch.angles.clone().expect("batch without angle features");
        match self {
            BrdfModel::Parametric(m) => m.forward(
                batch.spatial.clone(),
                batch.geometry.as_ref().expect("batch without geometry"),
            ),
            BrdfModel::SingleMlp(m) => m.forward(batch.spatial.clone(), angles()),
            BrdfModel::AdditiveSeparate(m) => m.forward(batch.spatial.clone(), angles()),
            BrdfModel::AdditiveShared(m) => m.forward(batch.spatial.clone(), angles()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::module::{ModuleVisitor, Param};
    use burn::tensor::Tensor;

    struct Values(Vec<Vec<f32>>);

    impl ModuleVisitor for Values {
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            self.0.push(param.val().into_data().convert::<f32>().try_into_vec::<f32>().unwrap());
        }
    }

    fn values(model: &BrdfModel) -> Vec<Vec<f32>> {
        let mut v = Values(Vec::new());
        model.visit(&mut v);
        v.0
    }

    /// `init_seeded` draws what a fit drew before it existed (seed, build, set the output
    /// biases, train: every parameter drawn when first read), so fits keep their weights.
    #[test]
    fn seeded_init_draws_what_a_fit_drew_before() {
        let device = crate::device::cpu_training();
        for kind in ModelKind::ALL {
            let c = ModelConfig { kind, spatial_dim: 3, ..ModelConfig::default() };
            for f0 in [None, Some([0.2, 0.3, 0.4])] {
                let got = values(&c.init_seeded(&device, 9, f0).unwrap());
                // The old sequence, on a batch of two real samples.
                let _draws = initial_draws();
                device.seed(9);
                let mut old = c.init_drawn(&device).unwrap();
                if let Some(f0) = f0 {
                    old = old.with_initial_brdf(f0);
                }
                let (l, v) =
                    ([[0.3, 0.1, 0.95], [0.0, 0.6, 0.8]], [[0.0, 0.0, 1.0], [0.5, 0.0, 0.87]]);
                let spatial = [0.1, -0.4, 0.7, 0.2, 0.0, -0.9];
                let s = Samples { spatial: &spatial, l: &l, v: &v };
                drop(old.forward(&c.batch(&s, None, &device).unwrap()));
                assert!(values(&old) == got, "{kind:?}, initial BRDF {f0:?}");
            }
        }
    }
}
