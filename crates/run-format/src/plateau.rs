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
    /// Best validation loss so far (`None` before the first): what a run reports.
    pub best: Option<f64>,
    /// Best mean of `smoothing` consecutive validation losses so far: what the rule compares
    /// with (equal to `best` when `smoothing` is 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub best_mean: Option<f64>,
    /// The last finite validation losses since the last decay, at most `smoothing` of them,
    /// oldest first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub recent: Vec<f64>,
    /// Step of the last improvement (or of the last decay, which restarts the patience).
    pub since: u64,
    /// Factor on the schedule's rate (1 until the first decay).
    pub lr_scale: f64,
    /// Decays so far.
    pub decays: u32,
}

impl Default for Plateau {
    fn default() -> Self {
        Self { best: None, best_mean: None, recent: Vec::new(), since: 0, lr_scale: 1.0, decays: 0 }
    }
}

impl Plateau {
    /// Feeds the validation loss `loss` measured after `step` steps.
    ///
    /// The rule compares the mean of the last `t.smoothing` finite losses (fewer at the start)
    /// with the best such mean; a non-finite loss restarts the patience and is not counted.
    /// Schedules other than `plateau` only track the best loss and always continue.
    pub fn update(&mut self, step: u64, loss: f64, t: &TrainConfig) -> Decision {
        if !loss.is_finite() {
            self.since = step;
            return Decision::Continue;
        }
        self.best = Some(self.best.map_or(loss, |b| b.min(loss)));
        let window = t.smoothing.max(1) as usize;
        self.recent.push(loss);
        if self.recent.len() > window {
            self.recent.drain(..self.recent.len() - window);
        }
        let mean = self.recent.iter().sum::<f64>() / self.recent.len() as f64;
        let improved = match self.best_mean {
            None => true,
            Some(best) => mean < best * (1.0 - t.min_improvement),
        };
        if improved {
            self.best_mean = Some(mean);
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
        // Losses at the new rate are another curve: the window restarts, so that the mean is
        // not held up by losses of the old rate.
        self.recent.clear();
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
            smoothing: 1,
            min_improvement: 0.01,
            ..TrainConfig::default()
        }
    }

    /// A brass-like validation curve at the high rate: 0.9 + 0.3 * 400 / step (about 3.5 % of
    /// improvement per 300 steps at step 1,000, 1 % near step 2,000) times log-normal jitter of
    /// `sigma`, drawn from `seed` (xorshift and Box-Muller: no dependency).
    fn jittered(seed: u64, sigma: f64) -> impl Iterator<Item = (u64, f64)> {
        let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut uniform = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (1..=60u64).map(move |i| {
            let step = 100 * i;
            let z = (-2.0 * uniform().ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos();
            (step, trend(step) * (sigma * z).exp())
        })
    }

    fn trend(step: u64) -> f64 {
        0.9 + 0.3 * 400.0 / step as f64
    }

    /// The step of the first decay on `losses` under `t` (the budget's end if none).
    fn first_decay(losses: impl Iterator<Item = (u64, f64)>, t: &TrainConfig) -> u64 {
        let mut p = Plateau::default();
        for (step, loss) in losses {
            if p.update(step, loss, t) != Decision::Continue {
                return step;
            }
        }
        6_000
    }

    fn spread(xs: &[f64]) -> f64 {
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64).sqrt()
    }

    #[test]
    fn smoothing_makes_the_first_decay_less_of_a_draw() {
        // Over 400 jitter draws, the underlying (noise-free) loss at the first decay: with
        // single losses the rule decays on a lucky low as often as on a plateau, so where a
        // run decays, and what it converges to, spreads; the mean of 3 narrows that spread by
        // about a third and decays nearer the trend's 1 % point.
        for sigma in [0.03, 0.07] {
            let at_decay = |smoothing| {
                let t = TrainConfig { smoothing, ..config() };
                (0..400)
                    .map(|seed| trend(first_decay(jittered(seed, sigma), &t)))
                    .collect::<Vec<_>>()
            };
            let (single, mean3) = (at_decay(1), at_decay(3));
            assert!(
                spread(&mean3) < 0.8 * spread(&single),
                "sigma {sigma}: spread {} (mean of 3) against {} (single)",
                spread(&mean3),
                spread(&single)
            );
            let avg = |xs: &[f64]| xs.iter().sum::<f64>() / xs.len() as f64;
            assert!(avg(&mean3) < avg(&single), "sigma {sigma}: decays later, lower");
        }
    }

    #[test]
    fn smoothing_of_one_is_the_single_loss_rule() {
        // A jittered curve, decided loss by loss, against the rule written out directly.
        let t = config();
        for seed in 0..50 {
            let (mut best, mut since) = (f64::INFINITY, 0);
            let mut expected = 6_000;
            for (step, loss) in jittered(seed, 0.07) {
                if loss < best * (1.0 - t.min_improvement) {
                    (best, since) = (loss, step);
                } else if step - since >= t.patience {
                    expected = step;
                    break;
                }
            }
            assert_eq!(first_decay(jittered(seed, 0.07), &t), expected, "seed {seed}");
        }
    }

    #[test]
    fn a_resumed_state_decides_as_an_uninterrupted_one() {
        let t = TrainConfig { smoothing: 3, ..config() };
        let losses: Vec<_> = jittered(7, 0.07).collect();
        let decisions = |resume_at: usize| {
            let mut p = Plateau::default();
            let mut out = Vec::new();
            for (i, &(step, loss)) in losses.iter().enumerate() {
                if i == resume_at {
                    let json = serde_json::to_string(&p).unwrap();
                    p = serde_json::from_str(&json).unwrap();
                }
                out.push(p.update(step, loss, &t));
            }
            out
        };
        let whole = decisions(usize::MAX);
        for at in [1, 5, 17, 30] {
            assert_eq!(decisions(at), whole, "resumed at validation {at}");
        }
        // A state written before `smoothing` existed still reads.
        let old: Plateau =
            serde_json::from_str(r#"{"best":0.5,"since":300,"lr_scale":0.1,"decays":1}"#).unwrap();
        assert_eq!((old.best_mean, old.recent.len()), (None, 0));
    }

    #[test]
    fn the_smoothed_rule_still_stops_a_flat_loss_and_reports_the_true_best() {
        let t = TrainConfig { smoothing: 3, ..config() };
        let mut p = Plateau::default();
        let mut stop = None;
        for i in 0..100u64 {
            let step = 10 * (i + 1);
            let loss = if i % 2 == 0 { 0.5 } else { 0.49 };
            if p.update(step, loss, &t) == Decision::Stop {
                stop = Some(step);
                break;
            }
        }
        assert!(stop.is_some_and(|s| s <= 10 + 5 * 30), "stopped at {stop:?}");
        assert_eq!(p.best, Some(0.49));
        let bad = TrainConfig { smoothing: 0, ..config() };
        assert!(bad.validate().unwrap_err().to_string().contains("train.smoothing"));
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
