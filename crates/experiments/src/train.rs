//! `fit`: trains a model on a scene's training split into a run directory (spec 6).
//!
//! Adam; each step draws `batch_size` uniform random indices into the lit training records
//! (with replacement) from a generator seeded with (seed, step), renders L = f E cos(theta_l)
//! and minimises the gamma-MSE loss ([`crate::loss`]), plus the regularisers of the enhanced
//! models; with `reciprocity = "random_swap"` the network input swaps l and v per sample.
//! The learning rate follows [`crate::config::TrainConfig::lr_at`].
//!
//! Checkpoints every `checkpoint_every` steps hold the weights, Adam's state and the curve, so
//! a resumed run computes the same steps as an uninterrupted one. A NaN or infinite loss stops
//! the run at once with [`Error::NonFinite`] (step and parameter group), keeping the last good
//! checkpoint.

use crate::checkpoint::{self, CheckpointState};
use crate::config::RunConfig;
use crate::data::{TrainingData, spatial_features};
use crate::diagnose::{all_finite, diagnose};
use crate::loss::{LossWeights, loss};
use crate::run_dir::{
    CONFIG_FILE, CURVE_FILE, CurveRow, METRICS_FILE, RunMetrics, WEIGHTS_FILE, temp_path,
    write_atomic, write_curve,
};
use crate::{Error, Result};
use brdf_neural::{BrdfModel, Reciprocity, Samples};
use burn::module::Module;
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Tensor, TensorData};
use dataset_merl::SceneDataset;
use dataset_merl::scene::Split;
use indicatif::{ProgressBar, ProgressStyle};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A callback run before each step with the step index and the model (tests use it to inject
/// faults).
pub type StepHook = Box<dyn FnMut(u64, BrdfModel) -> BrdfModel>;

/// Options of [`fit`] that are not part of the run's configuration.
#[derive(Default)]
pub struct FitOptions {
    /// Show a progress bar.
    pub progress: bool,
    /// Eigenpair cache (overrides `features.cache_dir`; default `<run>/../cache`).
    pub cache_dir: Option<PathBuf>,
    /// Stop (with a checkpoint) after this many steps in total, as if interrupted.
    pub stop_after: Option<u64>,
    /// Called before each step.
    pub hook: Option<StepHook>,
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
    /// Stopped by [`FitOptions::stop_after`] after this many steps.
    Stopped(u64),
}

/// Reads the scene and builds the training records (features computed once up front).
pub fn training_data(config: &RunConfig, cache_dir: &Path) -> Result<(SceneDataset, TrainingData)> {
    let scene_dir = config.scene.as_ref().ok_or_else(|| {
        Error::config("scene", "no scene directory (set `scene` or pass --scene)")
    })?;
    let scene = SceneDataset::open(scene_dir)?;
    let samples = scene.samples(Split::Train)?;
    let (spatial, dim) = spatial_features(&scene, &samples, &config.features, cache_dir)?;
    let data = TrainingData::new(&samples, &spatial, dim);
    if data.is_empty() {
        return Err(Error::NoSamples { path: scene_dir.clone() });
    }
    Ok((scene, data))
}

/// The eigenpair cache of a run: the option, else the config, else `<run>/../cache`.
pub fn cache_dir_for(config: &RunConfig, run: &Path, option: Option<&Path>) -> PathBuf {
    option
        .map(Path::to_path_buf)
        .or_else(|| config.features.cache_dir.clone())
        .unwrap_or_else(|| run.parent().unwrap_or(Path::new(".")).join("cache"))
}

/// Checks a run directory against `config`: a new run writes the config; an existing one must
/// hold the same configuration. Returns the finished run's metrics, if finished.
fn prepare_run_dir(config: &RunConfig, run: &Path) -> Result<Option<RunMetrics>> {
    let path = run.join(CONFIG_FILE);
    if path.is_file() {
        let existing = RunConfig::read(&path)?;
        if existing != *config {
            let keys = differing_keys(&existing, config);
            return Err(Error::format(
                &path,
                format!(
                    "the run directory holds a different configuration (keys {}); use a new \
                     run directory",
                    keys.join(", ")
                ),
            ));
        }
        if run.join(WEIGHTS_FILE).is_file() && run.join(METRICS_FILE).is_file() {
            return Ok(Some(RunMetrics::read(&run.join(METRICS_FILE))?));
        }
    } else {
        write_atomic(&path, config.to_toml()?.as_bytes())?;
    }
    Ok(None)
}

/// Dotted keys whose values differ between two configurations.
fn differing_keys(a: &RunConfig, b: &RunConfig) -> Vec<String> {
    fn walk(prefix: &str, a: &toml::Value, b: &toml::Value, out: &mut Vec<String>) {
        match (a, b) {
            (toml::Value::Table(x), toml::Value::Table(y)) => {
                let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
                for k in keys {
                    let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                    match (x.get(k), y.get(k)) {
                        (Some(p), Some(q)) => walk(&key, p, q, out),
                        _ => out.push(key),
                    }
                }
            }
            _ if a != b => out.push(prefix.to_string()),
            _ => {}
        }
    }
    let table = |c: &RunConfig| toml::Value::try_from(c).unwrap_or(toml::Value::Boolean(false));
    let mut out = Vec::new();
    walk("", &table(a), &table(b), &mut out);
    out
}

/// The batch generator of `step`: a function of (seed, step) only.
fn step_rng(seed: u64, step: u64) -> StdRng {
    StdRng::seed_from_u64(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ step)
}

/// Trains `config` into `run` (created if needed; resumed from its last checkpoint).
pub fn fit(config: &RunConfig, run: &Path, mut options: FitOptions) -> Result<FitOutcome> {
    config.validate()?;
    std::fs::create_dir_all(run).map_err(|e| Error::io(run, e))?;
    if let Some(metrics) = prepare_run_dir(config, run)? {
        return Ok(FitOutcome::AlreadyFinished(metrics));
    }
    let cache = cache_dir_for(config, run, options.cache_dir.as_deref());
    let (_scene, data) = training_data(config, &cache)?;
    let t = &config.train;

    let device = brdf_neural::device::cpu_training();
    device.seed(config.seed);
    let mut model = config.model.init(&device)?;
    let mut optim = AdamConfig::new().init();
    let mut state = CheckpointState::default();
    let mut last_checkpoint = checkpoint::latest(run)?;
    if let Some(dir) = &last_checkpoint {
        (model, optim, state) = checkpoint::load(dir, model, optim)?;
    }
    let resumed_from = state.step;

    let bar = if options.progress {
        let bar = ProgressBar::new(t.iterations);
        bar.set_style(
            ProgressStyle::with_template(
                "{bar:30} {pos}/{len} [{elapsed_precise} < {eta_precise}] {msg}",
            )
            .expect("static template"),
        );
        bar.set_position(state.step);
        bar
    } else {
        ProgressBar::hidden()
    };

    let weights = LossWeights { diffuse: t.diffuse_reg_weight, specular: t.specular_reg_weight };
    let regularise = config.model.kind.is_enhanced();
    let swap = config.model.angles.reciprocity == Reciprocity::RandomSwap;
    let n = data.len();
    let bs = t.batch_size;
    let seconds_before = state.seconds;
    let start = Instant::now();
    let mut window_start = (Instant::now(), state.step);

    while state.step < t.iterations {
        let step = state.step;
        if let Some(hook) = options.hook.as_mut() {
            model = hook(step, model);
        }
        let mut rng = step_rng(config.seed, step);
        let indices: Vec<usize> = (0..bs).map(|_| rng.random_range(0..n)).collect();
        let cpu = data.gather(&indices);
        let mask = swap.then(|| config.model.angles.swap_mask(bs, &mut rng));
        let batch = config.model.batch(
            &Samples { spatial: &cpu.spatial, l: &cpu.l, v: &cpu.v },
            mask.as_deref(),
            &device,
        )?;
        let weight = tensor(cpu.weight, bs, &device);
        let target = tensor(cpu.target_gamma, bs, &device);
        let out = model.forward(&batch);
        let total = loss(&out, weight, target, regularise, weights);
        let value: f32 = total.clone().into_scalar::<f32>();
        if !value.is_finite() {
            bar.abandon();
            return Err(Error::NonFinite {
                step,
                loss: value,
                diagnosis: diagnose(&model),
                checkpoint: last_checkpoint,
            });
        }
        let lr = t.lr_at(step);
        let grads = GradientsParams::from_grads(total.backward(), &model);
        model = optim.step(lr, model, grads);
        state.step += 1;

        let seconds = seconds_before + start.elapsed().as_secs_f64();
        if state.step % t.log_every == 0 || state.step == t.iterations {
            state.curve.push(CurveRow { step: state.step, loss: value, lr, seconds });
            let (t0, s0) = window_start;
            let rate = (state.step - s0) as f64 * bs as f64 / t0.elapsed().as_secs_f64().max(1e-9);
            bar.set_message(format!("loss {value:.3e}  {rate:.0} samples/s"));
            window_start = (Instant::now(), state.step);
        }
        bar.set_position(state.step);
        let stopping = options.stop_after.is_some_and(|s| state.step >= s);
        if state.step % t.checkpoint_every == 0 || stopping || state.step == t.iterations {
            state.seconds = seconds;
            if !all_finite(&model) {
                bar.abandon();
                return Err(Error::NonFinite {
                    step,
                    loss: value,
                    diagnosis: diagnose(&model),
                    checkpoint: last_checkpoint,
                });
            }
            last_checkpoint = Some(checkpoint::save(run, &model, &optim, &state)?);
            write_curve(&run.join(CURVE_FILE), &state.curve)?;
        }
        if stopping && state.step < t.iterations {
            bar.abandon();
            return Ok(FitOutcome::Stopped(state.step));
        }
    }
    bar.finish();

    let weights_path = run.join(WEIGHTS_FILE);
    let tmp = temp_path(&weights_path);
    model
        .clone()
        .save_file(&tmp)
        .map_err(|e| Error::format(&tmp, format!("cannot write weights: {e:?}")))?;
    std::fs::rename(&tmp, &weights_path).map_err(|e| Error::io(&weights_path, e))?;
    let tail = (state.curve.len() / 10).max(1).min(state.curve.len());
    let final_loss = state.curve[state.curve.len() - tail..].iter().map(|r| r.loss).sum::<f32>()
        / tail.max(1) as f32;
    let metrics = RunMetrics {
        steps: state.step,
        final_train_loss: final_loss,
        samples_per_second: state.step as f64 * bs as f64 / state.seconds.max(1e-9),
        wall_seconds: state.seconds,
        train_records: n,
        zero_prediction_loss: data.zero_prediction_loss(),
        parameters: config.model.param_count(),
        test: None,
    };
    metrics.write(&run.join(METRICS_FILE))?;
    Ok(FitOutcome::Finished { metrics, resumed_from })
}

/// Uploads a flattened `[rows, 3]` buffer.
fn tensor(values: Vec<f32>, rows: usize, device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(values, [rows, 3]), device)
}

/// Loads the final weights of a finished run.
pub fn load_weights(config: &RunConfig, run: &Path, device: &Device) -> Result<BrdfModel> {
    let path = run.join(WEIGHTS_FILE);
    if !path.is_file() {
        return Err(Error::format(&path, "no final weights: the run has not finished (run fit)"));
    }
    config
        .model
        .init(device)?
        .try_load_file(&path)
        .map_err(|e| Error::format(&path, format!("cannot load weights: {e:?}")))
}
