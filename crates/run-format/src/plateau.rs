//! The plateau rule: decays the learning rate when the validation loss stops improving and
//! decides when a run has converged ([`crate::train_config`] documents the keys).
//!
//! A pure state machine over (step, validation loss) pairs, so that the rule is tested on
//! synthetic loss sequences and a resumed run continues it exactly (the state is part of every
//! checkpoint).

use crate::train_config::{Schedule, TrainConfig};
use serde::{Deserialize, Serialize};

/// Why a run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StopReason {
    /// The validation loss stopped improving at the smallest learning rate: converged.
    Plateau,
    /// The step budget ran out first (for the plateau schedule: not converged; the other
    /// schedules always end here).
    Budget,
}

impl StopReason {
    /// Whether the run is known to have converged.
    pub fn converged(self) -> bool {
        self == StopReason::Plateau
    }
}

/// What the rule decided after a validation loss.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Decision {
    /// Keep training at the current rate.
    Continue,
    /// The loss plateaued: the rate was decayed (the new scale is in [`Plateau::lr_scale`]).
    Decayed,
    /// The loss plateaued at the smallest rate: stop.
    Stop,
}

/// The rule's state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plateau {
    /// Best validation loss so far (`None` before the first).
    pub best: Option<f64>,
    /// Step of the last improvement (or of the last decay, which restarts the patience).
    pub since: u64,
    /// Factor on the schedule's rate (1 until the first decay).
    pub lr_scale: f64,
    /// Decays so far.
    pub decays: u32,
}

impl Default for Plateau {
    fn default() -> Self {
        Self { best: None, since: 0, lr_scale: 1.0, decays: 0 }
    }
}

impl Plateau {
    /// Feeds the validation loss `loss` measured after `step` steps.
    ///
    /// Schedules other than `plateau` only track the best loss and always continue.
    pub fn update(&mut self, step: u64, loss: f64, t: &TrainConfig) -> Decision {
        let improved = match self.best {
            None => true,
            Some(best) => loss < best * (1.0 - t.min_improvement),
        };
        if improved || !loss.is_finite() {
            if loss.is_finite() {
                self.best = Some(loss);
            }
            self.since = step;
            return Decision::Continue;
        }
        let next = self.lr_scale * t.lr_decay;
        // The floor is compared with a little slack, so that a floor chosen as an exact power
        // of the decay factor is reached rather than missed by rounding.
        let at_floor = t.learning_rate * next < t.lr_final * (1.0 - 1e-9);
        let patience = if at_floor { t.final_patience.unwrap_or(t.patience) } else { t.patience };
        if t.schedule != Schedule::Plateau || step - self.since < patience {
            return Decision::Continue;
        }
        if at_floor {
            return Decision::Stop;
        }
        self.lr_scale = next;
        self.decays += 1;
        self.since = step;
        Decision::Decayed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> TrainConfig {
        TrainConfig {
            learning_rate: 1e-3,
            lr_final: 1e-4,
            lr_decay: 0.5,
            validate_every: 10,
            patience: 30,
            final_patience: None,
            min_improvement: 0.01,
            ..TrainConfig::default()
        }
    }

    /// Runs the rule over `losses` (one every 10 steps); returns the step it stopped at and the
    /// decays.
    fn run(losses: impl IntoIterator<Item = f64>) -> (Option<u64>, u32) {
        let t = config();
        let mut p = Plateau::default();
        for (i, loss) in losses.into_iter().enumerate() {
            let step = 10 * (i as u64 + 1);
            if p.update(step, loss, &t) == Decision::Stop {
                return (Some(step), p.decays);
            }
        }
        (None, p.decays)
    }

    #[test]
    fn a_flat_loss_decays_to_the_floor_then_stops() {
        // 1e-3 -> 5e-4 -> 2.5e-4 -> 1.25e-4 (three decays); the next would be below 1e-4.
        let (stop, decays) = run(std::iter::repeat_n(0.5, 100));
        assert_eq!(decays, 3);
        // First loss at step 10, a decay every 30 steps of no improvement, then the stop.
        assert_eq!(stop, Some(10 + 4 * 30));
    }

    #[test]
    fn a_falling_loss_never_stops() {
        let (stop, decays) = run((0..1000).map(|i| 0.98f64.powi(i)));
        assert_eq!((stop, decays), (None, 0));
    }

    #[test]
    fn improvements_below_the_threshold_count_as_flat() {
        // Falls by 0.1 % per validation: below the 1 % threshold, so it is a plateau.
        let (stop, _) = run((0..1000).map(|i| 0.999f64.powi(i)));
        assert!(stop.is_some());
    }

    #[test]
    fn final_patience_shortens_only_the_last_plateau() {
        let t = TrainConfig { final_patience: Some(10), ..config() };
        let mut p = Plateau::default();
        let mut stop = None;
        for i in 0..100u64 {
            let step = 10 * (i + 1);
            if p.update(step, 0.5, &t) == Decision::Stop {
                stop = Some(step);
                break;
            }
        }
        // Three decays 30 steps apart as before, then the stop 10 steps after the last.
        assert_eq!((stop, p.decays), (Some(10 + 3 * 30 + 10), 3));
        let bad = TrainConfig { final_patience: Some(5), ..config() };
        assert!(bad.validate().unwrap_err().to_string().contains("train.final_patience"));
    }

    #[test]
    fn noise_around_a_falling_trend_keeps_training() {
        // A 2 % per-validation trend with +-1.5 % alternating noise.
        let losses = (0..300).map(|i| 0.98f64.powi(i) * if i % 2 == 0 { 1.015 } else { 0.985 });
        assert_eq!(run(losses).0, None);
    }

    #[test]
    fn other_schedules_never_stop() {
        let t = TrainConfig { schedule: Schedule::Exponential, ..config() };
        let mut p = Plateau::default();
        for i in 1..1000 {
            assert_eq!(p.update(10 * i, 1.0, &t), Decision::Continue);
        }
        assert_eq!(p.lr_scale, 1.0);
        assert_eq!(p.best, Some(1.0));
    }

    #[test]
    fn non_finite_losses_do_not_become_the_best() {
        let t = config();
        let mut p = Plateau::default();
        p.update(10, 1.0, &t);
        p.update(20, f64::NAN, &t);
        assert_eq!(p.best, Some(1.0));
    }
}
