//! Where a fit's time goes: wall seconds per phase of the training step, accumulated over a
//! run (kept in checkpoints, so a resumed run keeps counting) and written to `metrics.json`.
//!
//! The CPU backends execute eagerly, so a phase's time is the time of its tensor operations:
//!
//! | phase | what |
//! | --- | --- |
//! | `gather` | drawing the batch indices and gathering the records (features, directions, weights, targets) |
//! | `encode` | the model's input encoding (angles, positional encoding) and the uploads |
//! | `forward` | the network and the BRDF evaluation |
//! | `loss` | the sRGB-gamma loss (and regularisers) and reading its value |
//! | `backward` | the gradient |
//! | `optimizer` | Adam |
//! | `validation` | the validation loss every `validate_every` steps |
//! | `bookkeeping` | curve, snapshots, checkpoints, progress |
//!
//! [`EvalPhases`] does the same for an evaluation (`metrics.json`'s `test.phases`).

use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Seconds per phase of the training step, summed over the steps counted.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct StepPhases {
    /// Steps counted.
    pub steps: u64,
    /// Batch indices and record gathering.
    pub gather: f64,
    /// Input encoding and uploads.
    pub encode: f64,
    /// Network and BRDF evaluation.
    pub forward: f64,
    /// Loss and its value.
    pub loss: f64,
    /// Gradient.
    pub backward: f64,
    /// Adam.
    pub optimizer: f64,
    /// Validation losses.
    pub validation: f64,
    /// Curve, snapshots, checkpoints, progress.
    pub bookkeeping: f64,
}

impl StepPhases {
    /// The phases with their names, in step order.
    pub fn named(&self) -> [(&'static str, f64); 8] {
        [
            ("gather", self.gather),
            ("encode", self.encode),
            ("forward", self.forward),
            ("loss", self.loss),
            ("backward", self.backward),
            ("optimizer", self.optimizer),
            ("validation", self.validation),
            ("bookkeeping", self.bookkeeping),
        ]
    }

    /// The sum of the phases, seconds.
    pub fn total(&self) -> f64 {
        self.named().iter().map(|(_, s)| s).sum()
    }

    /// Milliseconds per step of each phase.
    pub fn per_step_ms(&self) -> [(&'static str, f64); 8] {
        let n = self.steps.max(1) as f64;
        self.named().map(|(name, s)| (name, 1e3 * s / n))
    }
}

/// Seconds per phase of an evaluation.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EvalPhases {
    /// The test samples and their features.
    pub records: f64,
    /// The model's prediction for every test sample, and the cube-root RMSE.
    pub predict: f64,
    /// Rendering the test images and scoring them (PSNR, DSSIM, FLIP, LPIPS, the ceiling).
    pub images: f64,
    /// Reciprocity RMSE.
    pub reciprocity: f64,
    /// Energy conservation.
    pub energy: f64,
    /// The snapshots' test curve.
    pub curve: f64,
    /// The BRDF plots' probes (lit sphere, slices, albedo, validity maps).
    pub probe: f64,
}

impl EvalPhases {
    /// The phases with their names, in order.
    pub fn named(&self) -> [(&'static str, f64); 7] {
        [
            ("records", self.records),
            ("predict", self.predict),
            ("images", self.images),
            ("reciprocity", self.reciprocity),
            ("energy", self.energy),
            ("curve", self.curve),
            ("probe", self.probe),
        ]
    }
}

/// A phase of the training step (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Batch indices and record gathering.
    Gather,
    /// Input encoding and uploads.
    Encode,
    /// Network and BRDF evaluation.
    Forward,
    /// Loss and its value.
    Loss,
    /// Gradient.
    Backward,
    /// Adam.
    Optimizer,
    /// Validation losses.
    Validation,
    /// Curve, snapshots, checkpoints, progress.
    Bookkeeping,
}

/// A stopwatch over a run's steps: each call charges the time since the previous one to a
/// phase.
pub struct PhaseTimer {
    phases: StepPhases,
    last: Instant,
}

impl PhaseTimer {
    /// Starts the clock, continuing from `phases` (a resumed run's).
    pub fn start(phases: StepPhases) -> Self {
        Self { phases, last: Instant::now() }
    }

    /// Adds the seconds since the last call to `phase`.
    pub fn charge(&mut self, phase: Phase) {
        let now = Instant::now();
        let s = (now - self.last).as_secs_f64();
        self.last = now;
        let p = &mut self.phases;
        *match phase {
            Phase::Gather => &mut p.gather,
            Phase::Encode => &mut p.encode,
            Phase::Forward => &mut p.forward,
            Phase::Loss => &mut p.loss,
            Phase::Backward => &mut p.backward,
            Phase::Optimizer => &mut p.optimizer,
            Phase::Validation => &mut p.validation,
            Phase::Bookkeeping => &mut p.bookkeeping,
        } += s;
    }

    /// Counts one step.
    pub fn end_step(&mut self) {
        self.phases.steps += 1;
    }

    /// The phases so far.
    pub fn phases(&self) -> &StepPhases {
        &self.phases
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phases_add_up_and_per_step_divides() {
        let mut t = PhaseTimer::start(StepPhases::default());
        std::thread::sleep(std::time::Duration::from_millis(2));
        t.charge(Phase::Forward);
        t.charge(Phase::Backward);
        t.end_step();
        let mut p = t.phases().clone();
        assert!(p.forward >= 0.002 && p.backward < p.forward && p.steps == 1);
        p.steps = 4;
        p.gather = 0.008;
        assert_eq!(p.per_step_ms()[0], ("gather", 2.0));
        assert!((p.total() - (p.gather + p.forward + p.backward)).abs() < 1e-15);
        let back: StepPhases = serde_json::from_str("{\"steps\": 3}").unwrap();
        assert_eq!(back.steps, 3);
    }
}
