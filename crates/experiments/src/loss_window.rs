//! The training losses of the steps since the last host read.
//!
//! Reading a loss back to the host makes the host wait for its step to finish before it can
//! queue the next one: on a GPU that is a stall every step. So the trainer can keep each step's
//! loss on the device and read a whole window of them in one transfer: every `loss_reads`
//! steps, and at every step where something needs them (validation, a checkpoint, a snapshot,
//! the end). On the CPU the backend has finished the step anyway and `loss_reads` is 1: each
//! value is read at its step, as before, and no window is kept.
//!
//! A non-finite loss inside a window is found at its read, after later steps have already
//! updated the weights with it. The window therefore keeps the model and the optimiser as they
//! were at its first step (handles to the same tensors, not copies); the trainer puts them
//! back and replays the window reading every step, which stops at the first bad step with the
//! diagnosis an immediate read gives. The replay repeats the same steps (a step is a function
//! of the state and its index), so the losses and weights of a run do not depend on
//! `loss_reads`; tests compare the two bit for bit.

use brdf_neural::BrdfModel;
use burn::module::{Module, ModuleMapper, Param};
use burn::optim::ModuleOptimizer;
use burn::tensor::Tensor;

/// One step's loss: already read, or still on the device.
pub(crate) enum StepLoss {
    /// Read at its step.
    Read(f32),
    /// The loss tensor (one value, detached from the graph).
    OnDevice(Box<Tensor<1>>),
}

/// What the trainer knows of a step before its loss is read.
pub(crate) struct PendingStep {
    /// Steps done after it (the curve's step number).
    pub step: u64,
    /// Its learning rate.
    pub lr: f64,
    /// Training seconds when it ended.
    pub seconds: f64,
    loss: StepLoss,
}

/// A step with its loss read.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ReadStep {
    /// Steps done after it.
    pub step: u64,
    /// Its learning rate.
    pub lr: f64,
    /// Training seconds when it ended.
    pub seconds: f64,
    /// Its loss.
    pub loss: f32,
}

/// Where a window starts: the step index and, when its losses stay on the device, the model
/// and the optimiser before that step.
pub(crate) struct WindowStart {
    /// Index of the window's first step.
    pub step: u64,
    /// The model and optimiser before it (`None` when every loss is read at its step).
    pub state: Option<(BrdfModel, ModuleOptimizer)>,
}

impl WindowStart {
    /// The model and optimiser to replay from. The kept parameters were leaves of the first
    /// step's graph, which its backward pass consumed: each becomes a fresh leaf with the same
    /// values, id and gradient requirement.
    pub fn into_state(self) -> Option<(BrdfModel, ModuleOptimizer)> {
        self.state.map(|(model, optim)| (model.map(&mut FreshLeaves), optim))
    }
}

/// Detaches every float parameter from its graph: a leaf again, with the same values, id and
/// gradient requirement.
pub(crate) struct FreshLeaves;

impl ModuleMapper for FreshLeaves {
    fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        param.map(|t| {
            let grad = t.is_require_grad();
            t.detach().set_require_grad(grad)
        })
    }
}

/// The steps since the last read.
#[derive(Default)]
pub(crate) struct LossWindow {
    start: Option<WindowStart>,
    steps: Vec<PendingStep>,
}

impl LossWindow {
    /// Whether no step is waiting.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// Opens a window at step `step`, keeping `state` to replay it from.
    pub fn open(&mut self, step: u64, state: Option<(BrdfModel, ModuleOptimizer)>) {
        self.start = Some(WindowStart { step, state });
    }

    /// Adds a step.
    pub fn push(&mut self, step: u64, lr: f64, seconds: f64, loss: StepLoss) {
        self.steps.push(PendingStep { step, lr, seconds, loss });
    }

    /// Reads every waiting loss in one transfer and closes the window. `Err` carries the
    /// window's start and the index of its first step with a non-finite loss.
    pub fn read(&mut self) -> Result<Vec<ReadStep>, Box<(WindowStart, u64)>> {
        let steps = std::mem::take(&mut self.steps);
        let start = self.start.take();
        let on_device: Vec<Tensor<1>> = steps
            .iter()
            .filter_map(|s| match &s.loss {
                StepLoss::OnDevice(t) => Some((**t).clone()),
                StepLoss::Read(_) => None,
            })
            .collect();
        let mut values = match on_device.is_empty() {
            true => Vec::new(),
            false => Tensor::cat(on_device, 0).into_data().iter::<f32>().collect(),
        }
        .into_iter();
        let read: Vec<ReadStep> = steps
            .into_iter()
            .map(|s| ReadStep {
                step: s.step,
                lr: s.lr,
                seconds: s.seconds,
                loss: match s.loss {
                    StepLoss::Read(v) => v,
                    StepLoss::OnDevice(_) => values.next().unwrap_or(f32::NAN),
                },
            })
            .collect();
        match read.iter().find(|s| !s.loss.is_finite()) {
            None => Ok(read),
            Some(bad) => {
                let start = start.unwrap_or(WindowStart { step: bad.step - 1, state: None });
                Err(Box::new((start, bad.step - 1)))
            }
        }
    }
}
