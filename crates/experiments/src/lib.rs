//! The stages of one run (spec sections 6 and 7): training, evaluation and export, importing
//! one way: `export` may use `eval`; `train` and `eval` use neither other stage. What they
//! pass on sits below them: [`data`] (records, features), [`fitted`] (a fitted run opened
//! for analysis) and [`portable`] (the weights for other tools, written after evaluation).
//! Everything the stages share about a run (its configuration, its directory, its records,
//! the results version) lives in the crate `run_format` below; sweeps of many runs live in
//! the crate `sweep` above.
//!
//! * [`data`]: the lit training records (spatial features, local directions, E cos) and batches.
//! * [`loss`]: the sRGB-gamma MSE and the enhanced split's regularisers.
//! * [`train`], [`train_loop`]: [`fit`] and its loop: validation, checkpoints, snapshots, resume
//!   and non-finite detection ([`checkpoint`], [`diagnose`]); [`interrupt`]: a SIGTERM (a
//!   cluster's preemption or time limit) ends a fit at a step boundary with a checkpoint.
//! * [`eval`]: test renders, maps and every metric of a finished run.
//! * [`fitted`]: a finished (or just trained) run: configuration, model, scene.
//! * [`export`]: a fitted model for renderers (glTF, Mitsuba 3, pbrt-v4) and as a MERL table.
//! * [`places`]: where a process finds the data root, the LPIPS weights and the GPU cache.
//!
//! The binary `experiments` wraps these as `fit`, `eval` and `export` (`experiments --help`;
//! `cargo xtask` has the same subcommands):
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
//! gives none); see `run_format::train_config` for the profiles' defaults and
//! `docs/reproduce.md` for the measurements behind them.

pub mod checkpoint;
pub mod cli;
#[cfg(test)]
mod corrupted_inputs;
pub mod data;
pub mod diagnose;
mod error;
pub mod eval;
pub mod export;
pub mod fitted;
pub mod interrupt;
pub mod loss;
mod loss_window;
pub mod places;
pub mod portable;
pub mod train;
pub mod train_loop;

/// The burn backend a fit or an evaluation runs on (`--backend`).
pub use brdf_neural::device::{Backend, BackendDevice};
pub use brdf_neural::precision::MatmulPrecision;
pub use error::{Error, Result};
pub use run_format::RunConfig;
pub use train::{FitOptions, FitOutcome, fit};
