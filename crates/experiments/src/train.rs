//! `fit`: trains a model on a scene's training split into a run directory (spec 6).
//!
//! Adam (epsilon from the configuration); each step draws `batch_size` uniform random indices
//! into the lit training records (with replacement) from a generator seeded with (seed, step),
//! renders L = f E cos(theta_l) and minimises the gamma-MSE loss ([`crate::loss`]), plus the
//! regularisers of the enhanced models; with `reciprocity = "random_swap"` the network input
//! swaps l and v per sample. A fraction of each training view's lights is held out: their
//! validation loss drives the plateau schedule, which decays the rate and stops a converged
//! run ([`run_format::train_config`], [`run_format::plateau`]). The loop itself is in
//! [`crate::train_loop`].
//!
//! Checkpoints every `checkpoint_every` steps hold the weights, Adam's state, the curve and
//! the plateau rule's state, so a resumed run computes the same steps as an uninterrupted one.
//! A NaN or infinite loss stops the run at once with [`Error::NonFinite`] (step and parameter
//! group), keeping the last good checkpoint. A failing backend (a GPU out of memory or lost,
//! which burn and CubeCL report by panicking) ends it with [`Error::BackendFault`], naming the
//! checkpoint that resumes it.

use crate::checkpoint::{self, CheckpointState};
use crate::data::{RecordSet, spatial_features, split_validation, validation_pairs};
use crate::fitted::{FittedRun, weight_pack};
use crate::train_loop::{GPU_LOSS_READS, Loop, LoopEnd, gamma_mse};
use crate::{Error, Result};
use brdf_neural::BrdfModel;
use brdf_neural::device::{Backend, BackendDevice};
use brdf_neural::products::Products;
use brdf_neural::training_inputs::TrainingInputs;
use burn::module::Module;
use burn::optim::{AdamConfig, ModuleOptimizer};
use burn::tensor::Device;
use run_format::ComputeSettings;
use run_format::config::RunConfig;
use run_format::held_run::HeldRun;
use run_format::run_dir::{RunDir, RunMetrics};
use run_format::train_config::OutputInit;
use scene::SceneDataset;
use scene::Split;
use std::path::{Path, PathBuf};

pub use crate::train_loop::StepHook;

/// Options of [`fit`] that are not part of the run's configuration.
#[derive(Default)]
pub struct FitOptions {
    /// Show a progress bar.
    pub progress: bool,
    /// Cache directory (overrides `features.cache_dir`; default: `RunDir::cache`).
    pub cache_dir: Option<PathBuf>,
    /// Stop (with a checkpoint) after this many steps in total, as if interrupted.
    pub stop_after: Option<u64>,
    /// Called before each step.
    pub hook: Option<StepHook>,
    /// The burn backend that trains (`--backend`; default: the CPU backend).
    pub backend: brdf_neural::device::Backend,
    /// Whether each batch selects its inputs from tables kept on the device
    /// ([`TrainingInputs`]: its spatial rows and its records' directions, weights and targets),
    /// so that a step uploads only its record indices;
    /// `None`: on GPU backends. The same values either way (tests compare the two on the CPU).
    pub inputs_on_device: Option<bool>,
    /// How the run computes beyond its configuration: the bf16 kernel, and the steps between
    /// host reads of the training loss (`loss_reads`; between reads each step's loss stays on
    /// the device and the host queues the next step at once; `None`: 1 on the CPU,
    /// [`crate::train_loop::GPU_LOSS_READS`] on GPU backends; the losses and weights do not
    /// depend on it, and a non-finite loss is still named at its step). Recorded in
    /// `metrics.json` (`compute`).
    pub compute: ComputeSettings,
}

/// How [`fit`] ended.
#[derive(Clone, Debug, PartialEq)]
pub enum FitOutcome {
    /// Trained to the end (possibly after resuming from step `resumed_from`).
    Finished {
        /// The run's metrics.
        metrics: RunMetrics,
        /// Step of the checkpoint the run resumed from (0: fresh).
        resumed_from: u64,
    },
    /// The run directory already held a finished run; nothing was done.
    AlreadyFinished(RunMetrics),
    /// Stopped after this many steps, with a checkpoint, by [`FitOptions::stop_after`] or by a
    /// signal ([`crate::interrupt`]).
    Stopped(u64),
}

/// What a fit that trained to the end hands to evaluation in the same process, so that
/// neither the configuration, the weights nor the scene are read back from disk.
pub struct Trained {
    /// The configuration it trained.
    pub config: RunConfig,
    /// Its cache directory.
    pub cache: PathBuf,
    /// The fitted model in inference mode, on `device`.
    pub model: BrdfModel,
    /// The inference device of the backend it trained on.
    pub device: Device,
    /// The scene it was trained on, opened and verified once.
    pub scene: SceneDataset,
}

impl Trained {
    /// The run that was just trained, opened for evaluation (no weights or scene read back
    /// from disk).
    pub fn into_fitted(self) -> FittedRun {
        let Trained { config, cache, model, device, scene } = self;
        FittedRun { config, device, model, dataset: scene, cache }
    }
}

/// What a fit that ended finished hands to the stages after it: the model in memory when it
/// trained here, or what it read of a run an earlier process finished.
#[allow(clippy::large_enum_variant)] // one per run, moved once
pub enum Handoff {
    /// Trained to the end in this process.
    Trained(Trained),
    /// Finished before this fit began: its configuration and cache as the fit read them; the
    /// weights are on disk.
    Finished {
        /// The configuration it trained.
        config: RunConfig,
        /// Its cache directory.
        cache: PathBuf,
    },
}

impl Handoff {
    /// The finished run `run` opened for evaluation, its model on `backend`'s device when it
    /// is read from disk.
    pub fn into_fitted(self, run: &RunDir, backend: Backend) -> Result<FittedRun> {
        match self {
            Handoff::Trained(trained) => Ok(trained.into_fitted()),
            Handoff::Finished { config, cache } => FittedRun::load(config, cache, run, backend),
        }
    }
}

/// The records a run trains and validates on.
pub struct RunData {
    /// The scene.
    pub scene: SceneDataset,
    /// Training records (the training split less the validation lights).
    pub train: RecordSet,
    /// Validation records (empty without a validation split).
    pub val: RecordSet,
    /// The validation loss of the ground-truth BRDF: the noise floor no model gets below
    /// (`None` without validation records or without a ground truth, as for captures).
    pub val_floor: Option<f64>,
}

/// Reads the scene and builds the training and validation records (features computed once up
/// front; an LBO solve the cache does not spare within `lbo_memory` bytes,
/// [`crate::data::lbo_table`]).
pub fn training_data(
    config: &RunConfig,
    (cache_dir, lbo_memory): (&Path, Option<u64>),
) -> Result<RunData> {
    let scene_dir = config.scene.as_ref().ok_or_else(|| {
        Error::config("scene", "no scene directory (set `scene` or pass --scene)")
    })?;
    let scene = SceneDataset::open(scene_dir)?;
    let samples = scene.samples(Split::Train)?;
    let spatial = spatial_features(&scene, &samples, &config.features, (cache_dir, lbo_memory))?;
    let t = &config.train;
    let pairs = validation_pairs(&scene, t.validation_fraction);
    let (train, val) = split_validation(&samples, &pairs, t.validation_records, config.seed);
    let clip = crate::data::clip_level(&scene);
    let mut train = RecordSet::from_indices(&samples, &spatial, train);
    let mut val = RecordSet::from_indices(&samples, &spatial, val);
    (train.clip, val.clip) = (clip, clip);
    if train.is_empty() {
        return Err(Error::NoSamples { path: scene_dir.clone() });
    }
    let has_gt = !val.is_empty() && val.source.iter().any(|&i| samples.gt_valid[i]);
    let val_floor = has_gt.then(|| {
        let gt: Vec<[f32; 3]> = val.source.iter().map(|&i| samples.gt_brdf[i]).collect();
        gamma_mse(&val, &gt)
    });
    Ok(RunData { scene, train, val, val_floor })
}

/// Trains `config` into `run` (created if needed; resumed from its last checkpoint), holding
/// the run directory's lock while it trains.
pub fn fit(config: &RunConfig, run: &Path, options: FitOptions) -> Result<FitOutcome> {
    config.validate()?;
    let held = RunDir::new(run).hold("training")?;
    fit_and_keep(Some(config), &held, options).map(|(outcome, _)| outcome)
}

/// [`fit`] in a run directory this process holds, also handing the finished run to the stages
/// after it ([`Handoff`]: the model, its configuration and its scene when it trained to the
/// end; the configuration and cache of a run that was already finished; `None` for a run that
/// was stopped). `config: None` trains the configuration the directory holds (a
/// sweep's prepared run).
pub fn fit_and_keep(
    config: Option<&RunConfig>,
    held: &HeldRun,
    options: FitOptions,
) -> Result<(FitOutcome, Option<Handoff>)> {
    let started = std::time::Instant::now();
    let begun = held.begin_training(config, options.cache_dir.as_deref())?;
    if let Some(metrics) = begun.finished {
        let finished = Handoff::Finished { config: begun.config, cache: begun.cache };
        return Ok((FitOutcome::AlreadyFinished(metrics), Some(finished)));
    }
    let (config, cache, last_checkpoint) = (&begun.config, begun.cache, begun.checkpoint);
    let (dir, t) = (held.dir(), &config.train);
    // How the steps compute, settled before the data are read, so that a configuration the
    // backend cannot run fails at once. The training steps' products: the run's precision
    // (checked against the backend), and on a GPU the weight gradients' sum over the batch
    // split into parts (split-K), which the GPU's matrix-product kernels do not split
    // themselves. Evaluation keeps plain f32.
    let products = Products::training(t.matmul_precision, options.backend, t.batch_size)?
        .with_bf16_amx(options.compute.bf16_amx)
        .with_gpu(options.compute.gpu);
    products.check(options.backend)?;
    if let Some(why) = products.slow_bf16_warning(options.backend) {
        eprintln!("{}: warning: {why}", dir.path().display());
    }
    let on_device = options.inputs_on_device.unwrap_or(options.backend.is_gpu());
    let gpu_reads = if options.backend.is_gpu() { GPU_LOSS_READS } else { 1 };
    let loss_reads = options.compute.loss_reads.unwrap_or(gpu_reads).max(1);
    let bar = stdx::progress::bar(t.iterations, "steps at most", "train", options.progress);

    let RunData { scene, train: data, val, val_floor } =
        training_data(config, (&cache, options.compute.lbo_memory_bytes()))?;
    let device = options.backend.training_device()?;
    let (model, mut optim, state) = start(config, last_checkpoint.as_deref(), &data, &device)?;
    let resumed_from = state.step;
    if resumed_from > 0 {
        eprintln!("{}: resuming from the checkpoint at step {resumed_from}", dir.path().display());
    }
    let records = (data.records(), &data.weight[..], &data.observed_gamma[..]);
    let inputs = TrainingInputs::new(&config.model, records, val.records(), on_device, &device)?;
    bar.set_position(state.step);
    let lp = Loop {
        config,
        run: dir,
        data: &data,
        val: &val,
        device,
        products,
        inputs,
        bar,
        loss_reads,
        started,
        startup_seconds: Default::default(),
    };
    let (hook, stop_after) = (options.hook, options.stop_after);
    let run_loop = || lp.run(model, &mut optim, state, last_checkpoint, hook, stop_after);
    let end = guarded(run_loop, &lp, (dir, options.backend))?;
    let (model, state) = match end {
        LoopEnd::Done(done) => *done,
        LoopEnd::Interrupted(step) => return Ok((FitOutcome::Stopped(step), None)),
    };
    lp.bar.finish_with_message(if state.stopped.is_some_and(|r| r.converged()) {
        format!("converged after {} steps", state.step)
    } else {
        format!("step budget reached ({} steps)", state.step)
    });
    let mut metrics = run_metrics(config, &state, &data, val.len());
    metrics.backend = Some(options.backend);
    metrics.compute = Some(options.compute.clone());
    metrics.startup_seconds = lp.startup_seconds.get();
    metrics.val_loss_floor = val_floor;
    // The weights for other tools are export's ([`crate::portable`]), written after evaluation.
    let weights = weight_pack(&model)?;
    held.write_trained(&state.curve, &weights, &metrics)?;
    let device = lp.device.inner();
    let trained = Trained { config: config.clone(), cache, model: model.valid(), device, scene };
    Ok((FitOutcome::Finished { metrics, resumed_from }, Some(Handoff::Trained(trained))))
}

/// The model, optimiser and loop state training starts from: the seeded initialisation, or
/// the checkpoint `checkpoint` when there is one.
fn start(
    config: &RunConfig,
    checkpoint: Option<&Path>,
    data: &RecordSet,
    device: &Device,
) -> Result<(BrdfModel, ModuleOptimizer, CheckpointState)> {
    let t = &config.train;
    let initial_brdf = (t.output_init == OutputInit::Data).then(|| data.mean_brdf());
    let model = BrdfModel::init_seeded(&config.model, device, config.seed, initial_brdf)?;
    let optim = AdamConfig::new().with_epsilon(t.adam_epsilon as f32).init();
    match checkpoint {
        Some(c) => checkpoint::load(c, model, optim),
        None => Ok((model, optim, CheckpointState::default())),
    }
}

/// Runs the training loop with a panic in it turned into an error: burn and CubeCL panic when a
/// GPU runs out of memory or is lost, and the error says so and names the checkpoint that
/// resumes the run, as for any other failure.
fn guarded(
    run_loop: impl FnOnce() -> Result<LoopEnd>,
    lp: &Loop<'_>,
    (dir, backend): (&RunDir, Backend),
) -> Result<LoopEnd> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run_loop)) {
        Ok(end) => end,
        Err(payload) => {
            lp.bar.abandon();
            Err(Error::BackendFault {
                run: dir.path().to_path_buf(),
                step: lp.bar.position(),
                backend: backend.to_string(),
                message: panic_message(payload.as_ref()),
                checkpoint: dir.latest_checkpoint()?,
            })
        }
    }
}

/// The text of a caught panic.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    match (payload.downcast_ref::<&str>(), payload.downcast_ref::<String>()) {
        (Some(s), _) => s.to_string(),
        (_, Some(s)) => s.clone(),
        _ => "a panic without a message".into(),
    }
}

/// `metrics.json` of a run that finished training.
fn run_metrics(
    config: &RunConfig,
    state: &CheckpointState,
    data: &RecordSet,
    val_records: usize,
) -> RunMetrics {
    let tail = (state.curve.len() / 10).max(1).min(state.curve.len());
    let final_loss = state.curve[state.curve.len() - tail..].iter().map(|r| r.loss).sum::<f32>()
        / tail.max(1) as f32;
    let bs = config.train.batch_size;
    RunMetrics {
        steps: state.step,
        final_train_loss: final_loss,
        samples_per_second: state.step as f64 * bs as f64 / state.seconds.max(1e-9),
        wall_seconds: state.seconds,
        stop_reason: state.stopped,
        best_val_loss: state.plateau.best,
        val_loss_floor: None,
        lr_decays: state.plateau.decays,
        train_records: data.len(),
        val_records,
        zero_prediction_loss: data.zero_prediction_loss(),
        parameters: config.model.param_count(),
        snapshots: state.snapshots.clone(),
        test: None,
        phases: Some(state.phases.clone()),
        backend: None,
        startup_seconds: None,
        compute: None,
    }
}
