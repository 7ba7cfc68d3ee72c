//! The `[train]` table of a run configuration: optimiser, learning-rate schedule, validation
//! split and the plateau rule that stops a converged run (project decisions: the paper gives
//! no learning rate, schedule, initialisation or iteration count).
//!
//! ```toml
//! [train]
//! profile = "quick"          # quick | cpu | full: defaults for every other key
//! iterations = 20000         # the step budget: a guard, the plateau rule stops earlier
//! learning_rate = 1e-3
//! schedule = "plateau"       # plateau | exponential | cosine | constant
//! validation_fraction = 0.1  # training lights held out per view for the validation loss
//! ```
//!
//! # The plateau schedule (the default)
//!
//! Every `validate_every` steps the gamma-MSE on the validation records (a fixed subset of at
//! most `validation_records` records of the held-out training lights, never test data) is
//! computed; the rule watches the mean of the last `smoothing` of them. That mean counts as an
//! improvement when it is below the best mean so far by more than the relative
//! `min_improvement`. After `patience` steps without an improvement the learning rate
//! is multiplied by `lr_decay`; when that would take it below `lr_final`, the run has converged
//! and stops (`stop_reason = "plateau"`). A run that reaches `iterations` first stops with
//! `stop_reason = "budget"` and is reported as not converged. The learning rate therefore
//! depends on the validation curve only, never on the budget, so an intermediate snapshot of a
//! long run is exactly what a shorter budget would have produced (the run-time curves rely on
//! this). The other schedules decay from `learning_rate` to `lr_final` over `iterations` and
//! always run the whole budget.
//!
//! # Defaults
//!
//! | key | quick | cpu | full |
//! | --- | ---: | ---: | ---: |
//! | `iterations` | 6,000 | 20,000 | 200,000 |
//! | `batch_size` | 8,192 | 8,192 | 32,768 |
//! | `learning_rate` | 1e-3 | 1e-3 | 1e-3 |
//! | `lr_final` | 1e-4 | 1.5e-5 | 1e-6 |
//! | `schedule` | plateau | plateau | plateau |
//! | `warmup_steps` | 50 | 50 | 500 |
//! | `adam_epsilon` | 1e-8 | 1e-8 | 1e-8 |
//! | `output_init` | data | data | data |
//! | `validation_fraction` | 0.1 | 0.1 | 0.1 |
//! | `validate_every` | 100 | 100 | 250 |
//! | `validation_records` | 32,768 | 32,768 | 262,144 |
//! | `patience` | 300 | 600 | 5,000 |
//! | `final_patience` | 200 | = patience | = patience |
//! | `smoothing` | 1 | 1 | 1 |
//! | `min_improvement` | 0.01 | 0.005 | 0.002 |
//! | `lr_decay` | 0.1 | 0.25 | 0.25 |
//! | `checkpoint_every` | 1,000 | 2,000 | 5,000 |
//! | `log_every` | 10 | 10 | 100 |
//! | `snapshots` | false | false | false |
//! | `diffuse_reg_weight`, `specular_reg_weight` | 5e-4 | 5e-4 | 5e-4 |
//! | `matmul_precision` | f32 | f32 | f32 |
//!
//! `quick` decays once (1e-3 to 1e-4) and stops at the next plateau, with 200 steps of patience at
//! the floor. The default profile (`crates/sweep/profiles/default.toml`) takes its rule with
//! `smoothing = 3` and 100 steps at the floor, to bring every table within the 90 minutes asked
//! of a 2-core machine (`benches/README.md` has the times measured on each CPU). `cpu` is the
//! patient rule the `runtime` profile measures plateaus with (three decays by 4, 0.5 % threshold
//! over 600 steps). `docs/reproduce.md` gives the measurements that chose these values.
//! `smoothing = 3` watches the mean of the last 3 validation losses instead of each one: at 1e-3
//! a metal's loss jitters by 4 to 8 % between validations, against a trend of 2 to 4 % per 300
//! steps, and the single-loss rule decays on a lucky low as often as on a plateau, so where a
//! run decays, and what it converges to, is partly a draw. The sweep's `default` profile sets
//! it; the training profiles keep 1, so that their run ids and results stay those measured.
//! The regulariser
//! weights are the paper's (enhanced split, spec 4.5) and apply to the enhanced additive
//! models only. `output_init = "data"` starts every model's output layer (FMBRDF's excepted) at the
//! least-squares constant BRDF of the training records (experiments' `RecordSet::mean_brdf`),
//! so that an untrained model renders at the right brightness; `adam_epsilon` defaults to
//! PyTorch's 1e-8 (burn's own default, 1e-5, damps every update whose gradient is that small).
//! `matmul_precision = "bf16"` trains with the network's large matrix products on bf16 operands
//! and f32 sums (brdf-neural's `precision`: flex on the CPU, cuda on tensor cores; evaluation
//! stays f32); `"f16"` on binary16 operands scaled per row and column, summed in binary16 over
//! runs of 64 and in f32 over runs (flex only, native with AVX512-FP16; the weight gradients
//! stay f32). `docs/reproduce.md` gives their measured speed and what they do to the converged
//! scores.

use crate::{Error, Result};
use model_spec::MatmulPrecision;
use serde::{Deserialize, Serialize};

/// Which defaults a run starts from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// This machine, minutes per run.
    #[default]
    Quick,
    /// A long CPU run.
    Cpu,
    /// Full length (GPU).
    Full,
}

/// Learning-rate schedule.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Schedule {
    /// `learning_rate` throughout.
    Constant,
    /// Geometric decay to `lr_final` at the last step.
    Exponential,
    /// Cosine annealing to `lr_final` at the last step.
    Cosine,
    /// Decay by `lr_decay` on validation plateaus, stop on the plateau at the smallest rate.
    Plateau,
}

/// How the output layers are initialised.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OutputInit {
    /// burn's default (PyTorch-style uniform) for every layer.
    None,
    /// Output biases set so that the untrained model predicts the least-squares constant BRDF
    /// of the training records.
    Data,
}

/// The training section as written (every key optional; defaults from `profile`).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTrain {
    profile: Option<Profile>,
    iterations: Option<u64>,
    batch_size: Option<usize>,
    learning_rate: Option<f64>,
    lr_final: Option<f64>,
    schedule: Option<Schedule>,
    warmup_steps: Option<u64>,
    adam_epsilon: Option<f64>,
    output_init: Option<OutputInit>,
    validation_fraction: Option<f64>,
    validate_every: Option<u64>,
    validation_records: Option<usize>,
    patience: Option<u64>,
    final_patience: Option<u64>,
    smoothing: Option<u64>,
    min_improvement: Option<f64>,
    lr_decay: Option<f64>,
    checkpoint_every: Option<u64>,
    log_every: Option<u64>,
    snapshots: Option<bool>,
    diffuse_reg_weight: Option<f64>,
    specular_reg_weight: Option<f64>,
    matmul_precision: Option<MatmulPrecision>,
}

/// The training schedule, resolved against the profile's defaults (deserialised through a
/// table of optional keys, unknown keys rejected).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrainConfig {
    /// The profile the defaults came from.
    pub profile: Profile,
    /// Step budget (the plateau schedule usually stops earlier).
    pub iterations: u64,
    /// Samples per batch (2^15 in the paper).
    pub batch_size: usize,
    /// Learning rate after the warm-up (Adam).
    pub learning_rate: f64,
    /// Smallest learning rate: the end of the decaying schedules, the floor of `plateau`.
    pub lr_final: f64,
    /// The schedule.
    pub schedule: Schedule,
    /// Linear warm-up: the rate is scaled by (step + 1) / warmup_steps for the first steps
    /// (0: none).
    pub warmup_steps: u64,
    /// Adam's epsilon.
    pub adam_epsilon: f64,
    /// Output-layer initialisation.
    pub output_init: OutputInit,
    /// Fraction of each training view's lights held out for the validation loss (0: none).
    pub validation_fraction: f64,
    /// Steps between validation losses.
    pub validate_every: u64,
    /// At most this many validation records (a fixed, seeded subset).
    pub validation_records: usize,
    /// Plateau schedule: steps without improvement before the rate decays (or the run stops).
    pub patience: u64,
    /// Plateau schedule: the patience once the rate is at its smallest (only the stop is
    /// left to decide); `None`: `patience`. Not serialised when `None`, so existing run ids
    /// are unchanged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_patience: Option<u64>,
    /// Plateau schedule: the rule compares the mean of the last `smoothing` validation losses
    /// (1: each loss alone), so that the jitter of the loss at a high rate is not taken for a
    /// plateau. Not serialised when 1, so existing run ids are unchanged.
    #[serde(skip_serializing_if = "is_one")]
    pub smoothing: u64,
    /// Plateau schedule: relative decrease of the validation loss that counts as improvement.
    pub min_improvement: f64,
    /// Plateau schedule: factor on the rate at each plateau.
    pub lr_decay: f64,
    /// Steps between checkpoints.
    pub checkpoint_every: u64,
    /// Steps between rows of the training curve and progress updates.
    pub log_every: u64,
    /// Keep the weights at geometrically spaced steps ([`TrainConfig::snapshot_steps`]) for
    /// the run-time curve.
    pub snapshots: bool,
    /// Weight of the enhanced split's diffuse regulariser.
    pub diffuse_reg_weight: f64,
    /// Weight of the enhanced split's specular regulariser.
    pub specular_reg_weight: f64,
    /// Precision of the training step's matrix products (f32 or bf16 operands). Not serialised
    /// when f32, so existing run ids are unchanged.
    #[serde(skip_serializing_if = "is_f32")]
    pub matmul_precision: MatmulPrecision,
}

fn is_one(n: &u64) -> bool {
    *n == 1
}

fn is_f32(p: &MatmulPrecision) -> bool {
    *p == MatmulPrecision::F32
}

impl TrainConfig {
    /// The defaults of `profile` (see the module table).
    pub fn profile(profile: Profile) -> Self {
        let quick = Self {
            profile,
            iterations: 6_000,
            batch_size: 8_192,
            learning_rate: 1e-3,
            lr_final: 1e-4,
            schedule: Schedule::Plateau,
            warmup_steps: 50,
            adam_epsilon: 1e-8,
            output_init: OutputInit::Data,
            validation_fraction: 0.1,
            validate_every: 100,
            validation_records: 32_768,
            patience: 300,
            final_patience: Some(200),
            smoothing: 1,
            min_improvement: 0.01,
            lr_decay: 0.1,
            checkpoint_every: 1_000,
            log_every: 10,
            snapshots: false,
            diffuse_reg_weight: 5e-4,
            specular_reg_weight: 5e-4,
            matmul_precision: MatmulPrecision::F32,
        };
        match profile {
            Profile::Quick => quick,
            Profile::Cpu => Self {
                iterations: 20_000,
                final_patience: None,
                lr_final: 1.5e-5,
                patience: 600,
                min_improvement: 0.005,
                lr_decay: 0.25,
                checkpoint_every: 2_000,
                ..quick
            },
            Profile::Full => Self {
                iterations: 200_000,
                final_patience: None,
                batch_size: 1 << 15,
                lr_final: 1e-6,
                warmup_steps: 500,
                validate_every: 250,
                validation_records: 262_144,
                patience: 5_000,
                min_improvement: 0.002,
                lr_decay: 0.25,
                checkpoint_every: 5_000,
                log_every: 100,
                ..quick
            },
        }
    }

    /// The learning rate of `step` (0-based) for the decaying schedules; for `plateau`, the
    /// rate before plateau decays (multiply by [`crate::plateau::Plateau::lr_scale`]).
    pub fn lr_at(&self, step: u64) -> f64 {
        let t = if self.iterations <= 1 {
            0.0
        } else {
            (step as f64 / (self.iterations - 1) as f64).clamp(0.0, 1.0)
        };
        let (a, b) = (self.learning_rate, self.lr_final);
        let warmup = if step < self.warmup_steps {
            (step + 1) as f64 / self.warmup_steps as f64
        } else {
            1.0
        };
        warmup
            * match self.schedule {
                Schedule::Constant | Schedule::Plateau => a,
                Schedule::Exponential => a * (b / a).powf(t),
                Schedule::Cosine => b + 0.5 * (a - b) * (1.0 + (std::f64::consts::PI * t).cos()),
            }
    }

    /// Whether validation losses are computed.
    pub fn validates(&self) -> bool {
        self.validation_fraction > 0.0
    }

    /// The steps after which a snapshot of the weights is kept when `snapshots` is on:
    /// `validate_every` times powers of sqrt(2), rounded, below `iterations` (the final weights
    /// are the last point of every curve).
    pub fn snapshot_steps(&self) -> Vec<u64> {
        let mut out: Vec<u64> = Vec::new();
        let base = self.validate_every.max(1) as f64;
        for k in 0.. {
            let s = (base * 2f64.powf(k as f64 / 2.0)).round() as u64;
            if s >= self.iterations {
                break;
            }
            if out.last() != Some(&s) {
                out.push(s);
            }
        }
        out
    }

    /// Checks every range; errors name the key.
    pub fn validate(&self) -> Result<()> {
        let pos = |key: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::config(key, format!("must be finite and > 0, got {v}")))
            }
        };
        for (key, v) in [
            ("train.iterations", self.iterations),
            ("train.checkpoint_every", self.checkpoint_every),
            ("train.log_every", self.log_every),
            ("train.validate_every", self.validate_every),
            ("train.smoothing", self.smoothing),
        ] {
            if v == 0 {
                return Err(Error::config(key, "must be >= 1"));
            }
        }
        if self.batch_size == 0 {
            return Err(Error::config("train.batch_size", "must be >= 1"));
        }
        if self.validation_records == 0 {
            return Err(Error::config("train.validation_records", "must be >= 1"));
        }
        pos("train.learning_rate", self.learning_rate)?;
        pos("train.lr_final", self.lr_final)?;
        pos("train.adam_epsilon", self.adam_epsilon)?;
        if !(self.validation_fraction >= 0.0 && self.validation_fraction < 0.5) {
            return Err(Error::config(
                "train.validation_fraction",
                format!("must be in [0, 0.5), got {}", self.validation_fraction),
            ));
        }
        if !(self.min_improvement >= 0.0 && self.min_improvement < 1.0) {
            return Err(Error::config(
                "train.min_improvement",
                format!("must be in [0, 1), got {}", self.min_improvement),
            ));
        }
        if !(self.lr_decay > 0.0 && self.lr_decay < 1.0) {
            return Err(Error::config(
                "train.lr_decay",
                format!("must be in (0, 1), got {}", self.lr_decay),
            ));
        }
        if self.schedule == Schedule::Plateau {
            if !self.validates() {
                return Err(Error::config(
                    "train.validation_fraction",
                    "the plateau schedule needs a validation split (> 0)",
                ));
            }
            for (key, p) in [
                ("train.patience", Some(self.patience)),
                ("train.final_patience", self.final_patience),
            ] {
                if p.is_some_and(|p| p < self.validate_every) {
                    return Err(Error::config(
                        key,
                        format!("must be at least validate_every = {}", self.validate_every),
                    ));
                }
            }
            if self.lr_final > self.learning_rate {
                return Err(Error::config(
                    "train.lr_final",
                    "the plateau schedule's floor must not exceed learning_rate",
                ));
            }
        }
        for (k, v) in [
            ("train.diffuse_reg_weight", self.diffuse_reg_weight),
            ("train.specular_reg_weight", self.specular_reg_weight),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::config(k, format!("must be finite and >= 0, got {v}")));
            }
        }
        Ok(())
    }
}

impl<'de> Deserialize<'de> for TrainConfig {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let r = RawTrain::deserialize(d)?;
        let p = TrainConfig::profile(r.profile.unwrap_or_default());
        Ok(TrainConfig {
            profile: p.profile,
            iterations: r.iterations.unwrap_or(p.iterations),
            batch_size: r.batch_size.unwrap_or(p.batch_size),
            learning_rate: r.learning_rate.unwrap_or(p.learning_rate),
            lr_final: r.lr_final.unwrap_or(p.lr_final),
            schedule: r.schedule.unwrap_or(p.schedule),
            warmup_steps: r.warmup_steps.unwrap_or(p.warmup_steps),
            adam_epsilon: r.adam_epsilon.unwrap_or(p.adam_epsilon),
            output_init: r.output_init.unwrap_or(p.output_init),
            validation_fraction: r.validation_fraction.unwrap_or(p.validation_fraction),
            validate_every: r.validate_every.unwrap_or(p.validate_every),
            validation_records: r.validation_records.unwrap_or(p.validation_records),
            patience: r.patience.unwrap_or(p.patience),
            final_patience: r.final_patience.or(p.final_patience),
            smoothing: r.smoothing.unwrap_or(p.smoothing),
            min_improvement: r.min_improvement.unwrap_or(p.min_improvement),
            lr_decay: r.lr_decay.unwrap_or(p.lr_decay),
            checkpoint_every: r.checkpoint_every.unwrap_or(p.checkpoint_every),
            log_every: r.log_every.unwrap_or(p.log_every),
            snapshots: r.snapshots.unwrap_or(p.snapshots),
            diffuse_reg_weight: r.diffuse_reg_weight.unwrap_or(p.diffuse_reg_weight),
            specular_reg_weight: r.specular_reg_weight.unwrap_or(p.specular_reg_weight),
            matmul_precision: r.matmul_precision.unwrap_or(p.matmul_precision),
        })
    }
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self::profile(Profile::Quick)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_reads_and_is_written_only_when_set() {
        // Left at 1 it is not serialised, so the run ids of configurations without it stay.
        let text = toml::to_string(&TrainConfig::default()).unwrap();
        assert!(!text.contains("smoothing"), "{text}");
        let t: TrainConfig = toml::from_str("profile = \"quick\"\nsmoothing = 3").unwrap();
        assert_eq!(t.smoothing, 3);
        assert!(toml::to_string(&t).unwrap().contains("smoothing = 3"));
    }

    #[test]
    fn schedules_hit_both_ends() {
        for schedule in [Schedule::Exponential, Schedule::Cosine] {
            let t = TrainConfig {
                iterations: 11,
                schedule,
                warmup_steps: 0,
                learning_rate: 5e-4,
                lr_final: 5e-5,
                ..TrainConfig::default()
            };
            assert!((t.lr_at(0) - 5e-4).abs() < 1e-12);
            assert!((t.lr_at(10) - 5e-5).abs() < 1e-12);
            assert!(t.lr_at(5) < 5e-4 && t.lr_at(5) > 5e-5);
        }
        let t = TrainConfig { warmup_steps: 4, schedule: Schedule::Constant, ..Default::default() };
        assert!((t.lr_at(0) - t.learning_rate / 4.0).abs() < 1e-12);
        assert_eq!(t.lr_at(4), t.learning_rate);
        // The plateau schedule's base rate does not depend on the budget.
        let p = TrainConfig::default();
        let longer = TrainConfig { iterations: 10 * p.iterations, ..p.clone() };
        assert_eq!(p.lr_at(1234), longer.lr_at(1234));
    }

    #[test]
    fn snapshot_steps_are_geometric_and_inside_the_budget() {
        let t = TrainConfig { validate_every: 100, iterations: 1000, ..Default::default() };
        assert_eq!(t.snapshot_steps(), vec![100, 141, 200, 283, 400, 566, 800]);
        let short = TrainConfig { validate_every: 100, iterations: 50, ..Default::default() };
        assert!(short.snapshot_steps().is_empty());
    }

    #[test]
    fn plateau_needs_a_validation_split_and_sane_ranges() {
        let t = TrainConfig { validation_fraction: 0.0, ..Default::default() };
        assert!(t.validate().unwrap_err().to_string().contains("train.validation_fraction"));
        let t = TrainConfig { schedule: Schedule::Exponential, ..t };
        assert!(t.validate().is_ok());
        let t = TrainConfig { patience: 10, validate_every: 100, ..Default::default() };
        assert!(t.validate().unwrap_err().to_string().contains("train.patience"));
        let t = TrainConfig { lr_decay: 1.0, ..Default::default() };
        assert!(t.validate().unwrap_err().to_string().contains("train.lr_decay"));
        let t = TrainConfig { adam_epsilon: 0.0, ..Default::default() };
        assert!(t.validate().unwrap_err().to_string().contains("train.adam_epsilon"));
    }

    #[test]
    fn matmul_precision_parses_and_stays_out_of_f32_run_ids() {
        let t: TrainConfig = toml::from_str("matmul_precision = \"bf16\"").unwrap();
        assert_eq!(t.matmul_precision, MatmulPrecision::Bf16);
        assert!(serde_json::to_string(&t).unwrap().contains("\"matmul_precision\":\"bf16\""));
        let t: TrainConfig = toml::from_str("").unwrap();
        assert_eq!(t.matmul_precision, MatmulPrecision::F32);
        assert!(!serde_json::to_string(&t).unwrap().contains("matmul_precision"));
        let t: TrainConfig = toml::from_str("matmul_precision = \"f16\"").unwrap();
        assert_eq!(t.matmul_precision, MatmulPrecision::F16);
        let bad = toml::from_str::<TrainConfig>("matmul_precision = \"fp8\"").unwrap_err();
        assert!(bad.to_string().contains("fp8"), "{bad}");
    }
}
