//! A finished run opened for analysis: its configuration, fitted model and scene, shared by
//! `eval`, `energy` and `export-merl`.

use crate::data::{RecordSet, spatial_features};
use crate::{Error, Result};
use brdf_neural::BrdfModel;
use brdf_neural::device::Backend;
use brdf_neural::device::BackendDevice;
use burn::tensor::{Bytes, Device};
use run_format::config::RunConfig;
use run_format::run_dir::RunDir;
use scene::Split;
use scene::{SampleSet, SceneDataset};
use std::path::{Path, PathBuf};

/// Loads the final weights of a finished run.
pub fn load_weights(config: &RunConfig, run: &RunDir, device: &Device) -> Result<BrdfModel> {
    use burn::module::Module;
    let path = run.weights();
    if !path.is_file() {
        return Err(Error::format(&path, "no final weights: the run has not finished (run fit)"));
    }
    BrdfModel::init(&config.model, device)?
        .try_load_file(&path)
        .map_err(|e| Error::format(&path, format!("cannot load weights: {e:?}")))
}

/// The weights' file of `model` (a burnpack container), in memory.
pub fn weight_pack(model: &BrdfModel) -> Result<Bytes> {
    use burn::module::Module;
    model
        .clone()
        .into_record()
        .into_bytes()
        .map_err(|e| Error::format("weights.bpk", format!("cannot serialise the weights: {e:?}")))
}

/// A finished run with its model loaded and its scene opened.
pub struct FittedRun {
    /// The run's configuration (`scene` possibly overridden).
    pub config: RunConfig,
    /// The device the model lives on.
    pub device: Device,
    /// The fitted model.
    pub model: BrdfModel,
    /// The scene.
    pub dataset: SceneDataset,
    /// The eigenpair / feature cache directory.
    pub cache: PathBuf,
}

impl FittedRun {
    /// Opens `run` on the default CPU backend; `scene` overrides the configured scene
    /// directory, `cache` the cache.
    pub fn open(run: &Path, scene: Option<&Path>, cache: Option<&Path>) -> Result<Self> {
        Self::open_on(run, scene, cache, brdf_neural::device::default_backend())
    }

    /// [`FittedRun::open`] with the model on `backend`'s device.
    pub fn open_on(
        run: &Path,
        scene: Option<&Path>,
        cache: Option<&Path>,
        backend: Backend,
    ) -> Result<Self> {
        let run = RunDir::new(run);
        let mut config = run.read_config()?;
        if let Some(s) = scene {
            config.scene = Some(s.to_path_buf());
        }
        let cache = run.cache(&config, cache);
        Self::load(config, cache, &run, backend)
    }

    /// The finished run `run` of `config` (its cache `cache`, its scene the configured one)
    /// with its final weights loaded on `backend`'s device.
    pub fn load(config: RunConfig, cache: PathBuf, run: &RunDir, backend: Backend) -> Result<Self> {
        let scene_dir = config
            .scene
            .clone()
            .ok_or_else(|| Error::config("scene", "no scene directory (pass --scene)"))?;
        let device = backend.device()?;
        let model = load_weights(&config, run, &device)?;
        let dataset = SceneDataset::open(&scene_dir)?;
        Ok(Self { config, device, model, dataset, cache })
    }

    /// Another weight file of the same configuration (a snapshot) on the run's device.
    pub fn load_weights_file(&self, path: &Path) -> Result<BrdfModel> {
        use burn::module::Module;
        BrdfModel::init(&self.config.model, &self.device)?
            .try_load_file(path)
            .map_err(|e| Error::format(path, format!("cannot load weights: {e:?}")))
    }

    /// The lit test samples and their training records (features, local directions).
    pub fn test_records(&self) -> Result<(SampleSet, RecordSet)> {
        let samples = self.dataset.samples(Split::Test)?;
        let spatial =
            spatial_features(&self.dataset, &samples, &self.config.features, (&self.cache, None))?;
        let data = RecordSet::new(&samples, &spatial);
        Ok((samples, data))
    }
}
