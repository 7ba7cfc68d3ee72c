//! Training, evaluation, run directories, result tables and figures (spec sections 6 and 7).
//!
//! * [`config`]: the run configuration (TOML), profiles and validation.
//! * [`data`]: the lit training records (spatial features, local directions, E cos) and batches.
//! * [`loss`]: the sRGB-gamma MSE and the enhanced split's regularisers.
//! * [`train`]: [`fit`], the training loop with checkpoints, resume and non-finite detection.
//! * [`checkpoint`], [`run_dir`]: what a run directory holds, written atomically.
//! * [`eval`]: test renders, maps and every metric of a finished run.
//! * [`export`]: a fitted model as a MERL-format table at one surface point.
//! * [`sweep`]: profiles, content-addressed runs, parallel / cluster execution, `collect`.
//! * [`report`]: result tables (Markdown, LaTeX) and figures (PNG) from evaluated runs.
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
//! Learning rate, schedule and iteration counts are the project's decisions (the paper gives
//! none); see [`config`] for the profiles' defaults.

pub mod checkpoint;
pub mod config;
pub mod data;
pub mod diagnose;
mod error;
pub mod eval;
pub mod export;
pub mod loss;
pub mod report;
pub mod run_dir;
pub mod sweep;
pub mod train;

pub use config::{RunConfig, TrainConfig};
pub use error::{Error, Result};
pub use train::{FitOptions, FitOutcome, fit};
