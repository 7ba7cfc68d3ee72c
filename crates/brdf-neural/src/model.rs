//! The model a configuration builds, [`BrdfModel`] ([`BrdfModel::init`], and
//! [`BrdfModel::init_seeded`] for a fit), from the layer tables of its [`ModelConfig`]. The
//! configuration (its TOML form included) and the model kinds are defined in `model-spec` and
//! re-exported here.

use crate::Result;
use crate::additive_separate::AdditiveSeparate;
use crate::additive_shared::AdditiveShared;
use crate::batch::{BrdfBatch, Samples};
use crate::mlp::Mlp;
use crate::output::{AdditiveHead, BrdfOutput};
use crate::parametric::ParametricModel;
use crate::single_mlp::SingleMlp;
use burn::module::Module;
use burn::tensor::Device;
pub use model_spec::{ModelConfig, ModelKind};

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
    /// Builds the model on `device` (use an autodiff device for training), its parameter ids
    /// numbered deterministically ([`crate::param_ids`]), its initial weights drawn from the
    /// backend's random generator as it stands (a fit uses [`BrdfModel::init_seeded`]).
    pub fn init(config: &ModelConfig, device: &Device) -> Result<BrdfModel> {
        let _draws = initial_draws();
        let model = Self::init_drawn(config, device)?;
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
    /// every draw happen under one process-wide lock, which [`BrdfModel::init`] takes as
    /// well, in the order a fit has always drawn them (the output biases, then the
    /// parameters as a forward pass reads them), so fits keep their weights to the bit.
    pub fn init_seeded(
        config: &ModelConfig,
        device: &Device,
        seed: u64,
        initial_brdf: Option<[f32; 3]>,
    ) -> Result<BrdfModel> {
        let _draws = initial_draws();
        device.seed(seed);
        let mut model = Self::init_drawn(config, device)?;
        if let Some(f0) = initial_brdf {
            model = model.with_initial_brdf(f0);
        }
        let n = [[0.0, 0.0, 1.0_f32]];
        let spatial = vec![0.0; config.spatial_dim];
        let one = Samples { spatial: &spatial, l: &n, v: &n };
        drop(model.forward(&BrdfBatch::new(config, &one, None, device)?));
        model.visit(&mut Materialize);
        Ok(model)
    }

    /// The model, its parameters not yet drawn (burn draws a parameter when it is first read).
    fn init_drawn(config: &ModelConfig, device: &Device) -> Result<BrdfModel> {
        config.validate()?;
        let mut mlps = config.mlp_configs().into_iter().map(|m| Mlp::new(&m, device));
        let mut next = || mlps.next().expect("MLP count");
        Ok(crate::param_ids::deterministic_ids(match config.kind {
            k if k.analytic().is_some() => BrdfModel::Parametric(ParametricModel::new(
                next(),
                k.analytic().expect("parametric"),
                config.disney_gamma,
                device,
            )),
            ModelKind::SingleMlp => BrdfModel::SingleMlp(SingleMlp::new(
                next(),
                config.single_mlp_softplus_scale as f32,
            )),
            ModelKind::AdditiveSeparate | ModelKind::AdditiveSeparateEnhanced => {
                let (d, s) = (next(), next());
                BrdfModel::AdditiveSeparate(AdditiveSeparate::new(d, s, AdditiveHead::of(config)))
            }
            _ => {
                let (t, d, s) = (next(), next(), next());
                BrdfModel::AdditiveShared(AdditiveShared::new(t, d, s, AdditiveHead::of(config)))
            }
        }))
    }

    /// Evaluates the model on a batch built by [`BrdfBatch::new`] (or its siblings) for the
    /// same configuration, its linear layers' products as the batch's
    /// [`BrdfBatch::products`] say.
    ///
    /// # Shapes
    /// - batch: `batch` samples
    /// - output: `f` `[batch, 3]` (see [`BrdfOutput`] for the parts)
    ///
    /// # Panics
    /// If the batch lacks the inputs the model needs (a batch of another configuration).
    pub fn forward(&self, batch: &BrdfBatch) -> BrdfOutput {
        let angles = || batch.angles.clone().expect("batch without angle features");
        let (spatial, products) = (batch.spatial.clone(), batch.products);
        match self {
            BrdfModel::Parametric(m) => m.forward(
                spatial,
                batch.geometry.as_ref().expect("batch without geometry"),
                products,
            ),
            BrdfModel::SingleMlp(m) => m.forward(spatial, angles(), products),
            BrdfModel::AdditiveSeparate(m) => m.forward(spatial, angles(), products),
            BrdfModel::AdditiveShared(m) => m.forward(spatial, angles(), products),
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
                let got = values(&BrdfModel::init_seeded(&c, &device, 9, f0).unwrap());
                // The old sequence, on a batch of two real samples.
                let _draws = initial_draws();
                device.seed(9);
                let mut old = BrdfModel::init_drawn(&c, &device).unwrap();
                if let Some(f0) = f0 {
                    old = old.with_initial_brdf(f0);
                }
                let (l, v) =
                    ([[0.3, 0.1, 0.95], [0.0, 0.6, 0.8]], [[0.0, 0.0, 1.0], [0.5, 0.0, 0.87]]);
                let spatial = [0.1, -0.4, 0.7, 0.2, 0.0, -0.9];
                let s = Samples { spatial: &spatial, l: &l, v: &v };
                drop(old.forward(&BrdfBatch::new(&c, &s, None, &device).unwrap()));
                assert!(values(&old) == got, "{kind:?}, initial BRDF {f0:?}");
            }
        }
    }
}
