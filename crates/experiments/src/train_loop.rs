//! The training loop of [`crate::fit`]: optimiser steps, validation losses, the plateau rule,
//! the curve, snapshots and checkpoints.
//!
//! The loop's inputs that never change (configuration, records, devices, run directory,
//! progress bar) live in `Loop`; what changes (model, optimiser, [`CheckpointState`]) is
//! passed through it explicitly, so every step is a function of (state, step) and a resumed
//! run repeats an uninterrupted one exactly.

use crate::checkpoint::{self, CheckpointState};
use crate::data::RecordSet;
use crate::diagnose::{all_finite, diagnose, worst_input};
use crate::loss::{LossWeights, loss, srgb_oetf};
use crate::loss_window::{FreshLeaves, LossWindow, ReadStep, StepLoss, WindowStart};
use crate::{Error, Result};
use brdf_neural::fitted::predict_on;
use brdf_neural::products::Products;
use brdf_neural::training_inputs::TrainingInputs;
use brdf_neural::{BrdfBatch, BrdfModel, Reciprocity, Samples, SpatialTable};
use burn::module::Module;
use burn::optim::{GradientsParams, ModuleOptimizer};
use burn::tensor::{Device, Tensor, TensorData};
use indicatif::ProgressBar;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use run_format::config::RunConfig;
use run_format::phases::{Phase, PhaseTimer};
use run_format::plateau::{Decision, StopReason};
use run_format::run_dir::{CurveRow, RunDir, Snapshot};
use std::path::PathBuf;
use std::time::Instant;

/// A callback run before each step with the step index and the model (tests use it to inject
/// faults).
pub type StepHook = Box<dyn FnMut(u64, BrdfModel) -> BrdfModel>;

/// How the loop ended.
pub(crate) enum LoopEnd {
    /// Training is over (plateau or budget); the state says which.
    Done(Box<(BrdfModel, CheckpointState)>),
    /// Interrupted on request after this many steps (a checkpoint was written).
    Interrupted(u64),
}

/// The unchanging inputs of the loop.
pub(crate) struct Loop<'a> {
    /// The run's configuration.
    pub config: &'a RunConfig,
    /// The run directory.
    pub run: &'a RunDir,
    /// Training records.
    pub data: &'a RecordSet,
    /// Validation records (empty without a validation split).
    pub val: &'a RecordSet,
    /// The training (autodiff) device.
    pub device: Device,
    /// How the training steps' linear layers compute their products (the run's
    /// `matmul_precision`, the batch split on a GPU); validation runs plain f32.
    pub products: Products,
    /// On a GPU: the spatial rows of the training and validation points and every training
    /// record's direction inputs, weights and targets, on the device, where each batch selects
    /// its rows; `None` parts: batches gather them on the CPU.
    pub inputs: TrainingInputs,
    /// The progress bar (hidden when not shown).
    pub bar: ProgressBar,
    /// Steps between host reads of the training loss ([`crate::loss_window`]): 1 on the CPU,
    /// [`GPU_LOSS_READS`] on a GPU.
    pub loss_reads: u64,
    /// When this process's fit began.
    pub started: Instant,
    /// Seconds from [`Loop::started`] to the end of this process's first step (its kernels
    /// launched, its loss read), once it has run.
    pub startup_seconds: std::cell::Cell<Option<f64>>,
}

/// Steps between host reads of the loss on a GPU (`FitOptions::loss_reads`' default there).
pub const GPU_LOSS_READS: u64 = 100;

/// A window to replay: its start, the index of its first non-finite step, and the plateau's
/// rate scale (constant within a window: it changes only at validations, which read).
struct Replay {
    from: WindowStart,
    bad: u64,
    plateau_lr_scale: f64,
}

/// The batch generator of `step`: a function of (seed, step) only.
fn step_rng(seed: u64, step: u64) -> StdRng {
    StdRng::seed_from_u64(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ step)
}

/// Uploads a flattened `[rows, 3]` buffer.
fn tensor(values: Vec<f32>, rows: usize, device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(values, [rows, 3]), device)
}

/// Puts the losses of a read window's earlier steps on the curve, every `log_every` steps.
fn log_losses(state: &mut CheckpointState, earlier: &[ReadStep], log_every: u64) {
    for s in earlier.iter().filter(|s| s.step.is_multiple_of(log_every)) {
        let row =
            CurveRow { step: s.step, loss: s.loss, val_loss: None, lr: s.lr, seconds: s.seconds };
        state.curve.push(row);
    }
}

impl Loop<'_> {
    /// Trains from `state` until the plateau rule or the budget stops it, or until
    /// `stop_after` steps or a stop requested by a signal ([`crate::interrupt`]; then
    /// checkpointed and reported as interrupted).
    pub fn run(
        &self,
        mut model: BrdfModel,
        optim: &mut ModuleOptimizer,
        mut state: CheckpointState,
        mut last_checkpoint: Option<PathBuf>,
        mut hook: Option<StepHook>,
        stop_after: Option<u64>,
    ) -> Result<LoopEnd> {
        let t = &self.config.train;
        let (start, seconds_before) = (Instant::now(), state.seconds);
        let mut window = (Instant::now(), state.step);
        let mut timer = PhaseTimer::start(std::mem::take(&mut state.phases));
        let mut losses = LossWindow::default();
        // A SIGTERM from here on stops at a step boundary ([`crate::interrupt`]).
        let _training = crate::interrupt::Training::begin();
        while state.step < t.iterations && state.stopped.is_none() {
            let step = state.step;
            if losses.is_empty() {
                // Handles to the same tensors: the replay's start, should a loss in the
                // window not be finite.
                let keep = (self.loss_reads > 1).then(|| (model.clone(), optim.clone()));
                losses.open(step, keep);
            }
            if let Some(h) = hook.as_mut() {
                model = apply_hook(h, step, model);
            }
            let lr = t.lr_at(step) * state.plateau.lr_scale;
            timer.charge(Phase::Bookkeeping);
            let loss;
            (model, loss) =
                self.timed_step(model, optim, (step, lr), &last_checkpoint, &mut timer)?;
            state.step += 1;
            losses.push(state.step, lr, seconds_before + start.elapsed().as_secs_f64(), loss);
            self.bar.set_position(state.step);
            if !self.must_read(state.step, stop_after) {
                timer.end_step();
                continue;
            }
            let read = match losses.read() {
                Ok(read) => read,
                Err(bad_window) => {
                    let (from, bad) = *bad_window;
                    let replay = Replay { from, bad, plateau_lr_scale: state.plateau.lr_scale };
                    return Err(self.replay(
                        replay,
                        optim,
                        &last_checkpoint,
                        &mut hook,
                        &mut timer,
                    ));
                }
            };
            timer.charge(Phase::Loss);
            let Some((last, earlier)) = read.split_last() else { continue };
            log_losses(&mut state, earlier, t.log_every);
            let (value, lr) = (last.loss, last.lr);
            let val_loss = self.maybe_validate(&model, &mut state)?;
            timer.charge(Phase::Validation);
            timer.end_step();
            state.phases = timer.phases().clone();
            let seconds = seconds_before + start.elapsed().as_secs_f64();
            if state.step.is_multiple_of(t.log_every) || val_loss.is_some() {
                state.curve.push(CurveRow { step: state.step, loss: value, val_loss, lr, seconds });
                self.report(&state, value, &mut window);
            }
            let progress = (value, seconds, stop_after);
            let interrupted =
                self.save_progress(&model, optim, &mut state, progress, &mut last_checkpoint)?;
            if interrupted && state.stopped.is_none() {
                self.bar.abandon();
                return Ok(LoopEnd::Interrupted(state.step));
            }
        }
        timer.charge(Phase::Bookkeeping);
        state.phases = timer.phases().clone();
        Ok(LoopEnd::Done(Box::new((model, state))))
    }

    /// After a read and its validation: the budget's stop, then the weight snapshot and the
    /// checkpoint (every `checkpoint_every` steps, at a stop and when asked to stop), written
    /// together once the weights are checked; returns whether a stop was asked for
    /// (`stop_after` reached, or a signal).
    fn save_progress(
        &self,
        model: &BrdfModel,
        optim: &ModuleOptimizer,
        state: &mut CheckpointState,
        (value, seconds, stop_after): (f32, f64, Option<u64>),
        last_checkpoint: &mut Option<PathBuf>,
    ) -> Result<bool> {
        let t = &self.config.train;
        let snapshot = t.snapshots && t.snapshot_steps().contains(&state.step);
        if snapshot {
            state.snapshots.push(Snapshot { step: state.step, seconds });
        }
        if state.step >= t.iterations && state.stopped.is_none() {
            state.stopped = Some(StopReason::Budget);
        }
        let interrupted =
            stop_after.is_some_and(|s| state.step >= s) || crate::interrupt::requested();
        let checkpoint =
            state.step.is_multiple_of(t.checkpoint_every) || interrupted || state.stopped.is_some();
        if checkpoint {
            state.seconds = seconds;
        }
        if snapshot || checkpoint {
            self.check_finite(model, state, value)?;
            let writes = checkpoint::Writes { snapshot, checkpoint };
            if let Some(dir) = checkpoint::save(self.run, (model, optim), state, writes)? {
                *last_checkpoint = Some(dir);
            }
        }
        Ok(interrupted)
    }

    /// Whether the losses must be read after `step` steps: every `loss_reads` steps, and
    /// wherever the loop needs them or the weights (validation, checkpoint, snapshot, the end).
    fn must_read(&self, step: u64, stop_after: Option<u64>) -> bool {
        let t = &self.config.train;
        step.is_multiple_of(self.loss_reads)
            || (!self.val.is_empty() && step.is_multiple_of(t.validate_every))
            || step.is_multiple_of(t.checkpoint_every)
            || (t.snapshots && t.snapshot_steps().contains(&step))
            || step >= t.iterations
            || stop_after.is_some_and(|s| step >= s)
            || crate::interrupt::requested()
    }

    /// Puts back the model and optimiser of the window's start and repeats its steps reading
    /// every loss, up to the first non-finite one: the error an immediate read gives (the
    /// step, the weights' diagnosis, the batch's worst input).
    fn replay(
        &self,
        replay: Replay,
        optim: &mut ModuleOptimizer,
        last_checkpoint: &Option<PathBuf>,
        hook: &mut Option<StepHook>,
        timer: &mut PhaseTimer,
    ) -> Error {
        let Replay { from, bad, plateau_lr_scale } = replay;
        let not_reproduced = |detail: &str| {
            self.bar.abandon();
            Error::NonFinite {
                step: bad,
                loss: f32::NAN,
                diagnosis: format!("the loss of step {bad} was not finite; {detail}"),
                checkpoint: last_checkpoint.clone(),
            }
        };
        let first = from.step;
        let Some((mut model, saved)) = from.into_state() else {
            return not_reproduced("no state was kept to replay it");
        };
        *optim = saved;
        for step in first..=bad {
            if let Some(h) = hook.as_mut() {
                model = apply_hook(h, step, model);
            }
            let lr = self.config.train.lr_at(step) * plateau_lr_scale;
            match self.step(model, optim, (step, lr), last_checkpoint, timer, true) {
                Ok((next, _)) => model = next,
                Err(e) => return e,
            }
        }
        not_reproduced(&format!("replaying steps {first}..={bad} did not repeat it"))
    }

    /// [`Loop::step`], its loss read at once every `loss_reads` steps or when it is the
    /// process's first step, whose end is the start-up's (recorded).
    fn timed_step(
        &self,
        model: BrdfModel,
        optim: &mut ModuleOptimizer,
        (step, lr): (u64, f64),
        last_checkpoint: &Option<PathBuf>,
        timer: &mut PhaseTimer,
    ) -> Result<(BrdfModel, StepLoss)> {
        let first = self.startup_seconds.get().is_none();
        let read_now = self.loss_reads == 1 || first;
        let out = self.step(model, optim, (step, lr), last_checkpoint, timer, read_now)?;
        if first {
            self.startup_seconds.set(Some(self.started.elapsed().as_secs_f64()));
        }
        Ok(out)
    }

    /// One optimiser step number `step` at rate `lr`: the batch of `step`, the loss, its
    /// gradient, Adam; `timer` is charged with each phase. With `read_now` the loss is read
    /// (and a non-finite one is an error at once); otherwise it stays on the device.
    fn step(
        &self,
        model: BrdfModel,
        optim: &mut ModuleOptimizer,
        (step, lr): (u64, f64),
        last_checkpoint: &Option<PathBuf>,
        timer: &mut PhaseTimer,
        read_now: bool,
    ) -> Result<(BrdfModel, StepLoss)> {
        let (t, c) = (&self.config.train, &self.config.model);
        let bs = t.batch_size;
        let mut rng = step_rng(self.config.seed, step);
        let n = self.data.len();
        let indices: Vec<usize> = (0..bs).map(|_| rng.random_range(0..n)).collect();
        let (batch, weight, target) = self.batch(&indices, &mut rng, timer)?;
        timer.charge(Phase::Encode);
        let out = model.forward(&batch.with_products(self.products));
        timer.charge(Phase::Forward);
        let weights = LossWeights {
            diffuse: t.diffuse_reg_weight,
            specular: t.specular_reg_weight,
            clip: self.data.clip,
        };
        let total = loss(&out, weight, target, c.kind.is_enhanced(), weights);
        let value = match read_now {
            true => StepLoss::Read(total.clone().into_scalar::<f32>()),
            false => StepLoss::OnDevice(Box::new(total.clone().detach())),
        };
        timer.charge(Phase::Loss);
        if let StepLoss::Read(bad) = &value
            && !bad.is_finite()
        {
            self.bar.abandon();
            // The batch again, unsanitised (the batch took its spatial rows): what was fed.
            let cpu = self.data.gather(&indices);
            let samples = Samples { spatial: &cpu.spatial, l: &cpu.l, v: &cpu.v };
            let input = worst_input(&out, &samples);
            return Err(Error::NonFinite {
                step,
                loss: *bad,
                diagnosis: format!("{}; {input}", diagnose(&model)),
                checkpoint: last_checkpoint.clone(),
            });
        }
        let grads = GradientsParams::from_grads(total.backward(), &model);
        timer.charge(Phase::Backward);
        let model = optim.step(lr, model, grads);
        timer.charge(Phase::Optimizer);
        Ok((model, value))
    }

    /// The batch of the records `indices` (model input, weights, targets), with the swap mask
    /// drawn from `rng` after the indices: selected on the device from the records the loop
    /// keeps there ([`TrainingInputs::records`]), else gathered, encoded and uploaded here. The
    /// same values either way.
    fn batch(
        &self,
        indices: &[usize],
        rng: &mut StdRng,
        timer: &mut PhaseTimer,
    ) -> Result<(BrdfBatch, Tensor<2>, Tensor<2>)> {
        let (c, bs) = (&self.config.model, indices.len());
        let swap = c.angles.reciprocity == Reciprocity::RandomSwap;
        if let Some(records) = &self.inputs.records {
            let rows: Vec<u32> = indices.iter().map(|&i| i as u32).collect();
            timer.charge(Phase::Gather);
            let mask = swap.then(|| c.angles.swap_mask(bs, rng));
            let index = records.table.index(&rows, mask.as_deref(), &self.device)?;
            let batch = BrdfBatch::from_records(
                c,
                &records.table,
                self.inputs.spatial.as_ref(),
                &index,
                &self.device,
            )?;
            let weight = records.weight.clone().select(0, index.rows.clone());
            let target = records.target.clone().select(0, index.rows);
            timer.charge(Phase::Encode);
            return Ok((batch, weight, target));
        }
        let cpu = match &self.inputs.spatial {
            Some(_) => self.data.gather_fields(indices),
            None => self.data.gather(indices),
        };
        timer.charge(Phase::Gather);
        let mask = swap.then(|| c.angles.swap_mask(bs, rng));
        let (l, v, mask) = (&cpu.l, &cpu.v, mask.as_deref());
        let batch = match &self.inputs.spatial {
            Some(table) => {
                let points = self.data.points_of(indices);
                BrdfBatch::from_table(c, table, &points, l, v, mask, &self.device)?
            }
            None => BrdfBatch::from_owned(c, cpu.spatial, l, v, mask, &self.device)?,
        };
        let weight = tensor(cpu.weight, bs, &self.device);
        let target = tensor(cpu.target_gamma, bs, &self.device);
        timer.charge(Phase::Encode);
        Ok((batch, weight, target))
    }

    /// After every `validate_every` steps: the validation loss, fed to the plateau rule (which
    /// may decay the rate or mark the run stopped).
    fn maybe_validate(
        &self,
        model: &BrdfModel,
        state: &mut CheckpointState,
    ) -> Result<Option<f32>> {
        let t = &self.config.train;
        if self.val.is_empty() || !state.step.is_multiple_of(t.validate_every) {
            return Ok(None);
        }
        // In f32 even when the steps run bf16 products (the evaluation's batches are plain f32):
        // the plateau rule compares these losses.
        let inference = self.device.clone().inner();
        let table = self.inputs.val_spatial.as_ref();
        let v = validation_loss(model, self.config, self.val, table, &inference)?;
        match state.plateau.update(state.step, v, t) {
            Decision::Stop => state.stopped = Some(StopReason::Plateau),
            Decision::Decayed | Decision::Continue => {}
        }
        Ok(Some(v as f32))
    }

    /// Progress message: losses, rate and throughput since the last report.
    fn report(&self, state: &CheckpointState, loss: f32, window: &mut (Instant, u64)) {
        let (t0, s0) = *window;
        let samples = (state.step - s0) as f64 * self.config.train.batch_size as f64;
        let rate = samples / t0.elapsed().as_secs_f64().max(1e-9);
        let best = state.plateau.best.map_or(String::new(), |b| format!("  val {b:.3e}"));
        let lr = self.config.train.learning_rate * state.plateau.lr_scale;
        self.bar.set_message(format!("loss {loss:.3e}{best}  lr {lr:.1e}  {rate:.0} samples/s"));
        *window = (Instant::now(), state.step);
    }

    /// Fails with [`Error::NonFinite`] (naming the last good checkpoint) when a weight is not
    /// finite: nothing is written of such weights.
    fn check_finite(&self, model: &BrdfModel, state: &CheckpointState, loss: f32) -> Result<()> {
        if all_finite(model) {
            return Ok(());
        }
        self.bar.abandon();
        Err(Error::NonFinite {
            step: state.step.saturating_sub(1),
            loss,
            diagnosis: diagnose(model),
            checkpoint: self.run.latest_checkpoint()?,
        })
    }
}

/// The gamma-MSE of `model` on the records `val` (no regularisers), computed in inference
/// mode on `device` (the inference device of the training backend), the spatial rows of
/// `val`'s points selected from `table` (on `device`) where there is one.
pub fn validation_loss(
    model: &BrdfModel,
    config: &RunConfig,
    val: &RecordSet,
    table: Option<&SpatialTable>,
    device: &Device,
) -> Result<f64> {
    let model = model.valid();
    let pred = predict_on(&model, &config.model, val.records(), table, device, false)?;
    Ok(gamma_mse(val, &pred.f))
}

/// The gamma-MSE of the BRDF values `f` (one per record) on the records, renders clipped like
/// the observations: the training loss without regularisers.
pub fn gamma_mse(records: &RecordSet, f: &[[f32; 3]]) -> f64 {
    let mut sum = 0.0_f64;
    let clip = records.clip.unwrap_or(f32::INFINITY);
    for ((f, w), g) in f.iter().zip(&records.weight).zip(&records.observed_gamma) {
        for c in 0..3 {
            let d = srgb_oetf((f[c] * w[c]).min(clip)) - g[c];
            sum += d as f64 * d as f64;
        }
    }
    sum / (3 * records.len().max(1)) as f64
}

/// The model after a step hook: a hook that computes parameters from parameters (a test's
/// NaN) leaves them inside its operation's graph, which the step's backward pass consumes, so
/// the next step (inside a loss window) gets them as leaves again.
fn apply_hook(hook: &mut StepHook, step: u64, model: BrdfModel) -> BrdfModel {
    hook(step, model).map(&mut FreshLeaves)
}
