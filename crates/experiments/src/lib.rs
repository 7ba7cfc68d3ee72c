//! Training, evaluation, run directories and sweeps (spec sections 6 and 7); the sweep's
//! `collect` turns evaluated runs into the report crate's tables and figures.
//!
//! * [`config`]: the run configuration (TOML), profiles and validation.
//! * [`data`]: the lit training records (spatial features, local directions, E cos) and batches.
//! * [`loss`]: the sRGB-gamma MSE and the enhanced split's regularisers.
//! * [`train_config`], [`plateau`]: the `[train]` table (optimiser, schedule, validation
//!   split) and the plateau rule that decays the rate and stops a converged run.
//! * [`train`], [`trainer`]: [`fit`] and its loop: validation, checkpoints, snapshots, resume
//!   and non-finite detection.
//! * [`phases`]: where a fit's and an evaluation's time goes, per phase (step timing).
//! * [`checkpoint`], [`run_dir`]: what a run directory holds, written atomically.
//! * [`eval`]: test renders, maps and every metric of a finished run.
//! * [`export`]: a fitted model as a MERL-format table at one surface point.
//! * [`sweep`]: profiles, content-addressed runs, parallel / cluster execution, `collect`.
//!
//! The binary `experiments` wraps these as `fit` and `eval` (`experiments --help`):
//!
//! ```text
//! experiments fit --config run.toml --scene scenes/spot__blue-acrylic --out runs/spot-single
//! experiments eval runs/spot-single
//! ```
//!
//! `fit` on an existing run directory resumes from its last checkpoint (the configuration must
//! be the same; `--config` may be left out), and reports a finished run without training.
//! Runs are deterministic for a seed on a given machine and thread count: the tests check that
//! two runs give bit-identical loss curves and that a run interrupted and resumed equals an
//! uninterrupted one (Adam's moments are checkpointed).
//!
//! Learning rate, schedule, initialisation and stopping are the project's decisions (the paper
//! gives none); see [`train_config`] for the profiles' defaults and `docs/reproduce.md` for the
//! measurements behind them.

pub mod checkpoint;
pub mod config;
#[cfg(test)]
mod corrupted_inputs;
pub mod data;
pub mod diagnose;
mod error;
pub mod eval;
pub mod export;
pub mod loss;
mod loss_window;
pub mod phases;
pub mod plateau;
pub mod run_dir;
pub mod sweep;
pub mod train;
pub mod train_config;
pub mod trainer;

/// The burn backend a fit or an evaluation runs on (`--backend`).
pub use brdf_neural::device::Backend;
pub use brdf_neural::precision::MatmulPrecision;
pub use config::{RunConfig, TrainConfig};
pub use error::{Error, Result};
pub use train::{FitOptions, FitOutcome, fit};
