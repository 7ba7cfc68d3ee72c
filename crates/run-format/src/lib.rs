//! What a run directory holds, and the one home of everything the stages share: the run
//! configuration a fit reads (`config.toml`), the records it and `eval` write
//! (`metrics.json`, `curve.csv`, snapshots), the named paths of a run and of a sweep, and the
//! results version that content-addressed runs are keyed by.
//!
//! Training, evaluation, export and the sweep (crates `experiments` and `sweep`) all import
//! this crate; it imports none of them. It has no numerics beyond checking ranges.
//!
//! * [`config`]: the run configuration (TOML): model, spatial features, seed.
//! * [`train_config`]: its `[train]` table (optimiser, schedule, validation split, profiles).
//! * [`eval_config`]: its `[eval]` table (energy estimator, reciprocity, LPIPS, images).
//! * [`plateau`]: the plateau rule that decays the rate and stops a converged run.
//! * [`run_dir`]: the run directory's and the sweep directory's named paths, and
//!   `metrics.json`'s record ([`run_dir::RunMetrics`]).
//! * [`held_run`]: a run directory locked once for the stages that work in it, its
//!   checkpoints' folders, and the check of its state before a fit.
//! * [`test_metrics`]: the scores `eval` adds to it; [`metric_settings`]: their exact
//!   settings per protocol.
//! * [`phases`]: where a fit's and an evaluation's time goes (step timing).
//! * [`compute_settings`]: how a run computes beyond its configuration (bf16 kernel, loss
//!   reads, LBO memory), the CLI's one typed value for what environment variables override.
//!
//! The format is an API boundary: the Python package, `collect` and users' scripts read it
//! (`docs/reproduce.md`, "Run directories").

pub mod compute_settings;
pub mod config;
mod error;
pub mod eval_config;
pub mod held_run;
pub mod metric_settings;
pub mod phases;
pub mod plateau;
pub mod run_dir;
pub mod serde_inf;
pub mod test_metrics;
pub mod train_config;

pub use compute_settings::ComputeSettings;
pub use config::{RunConfig, TrainConfig};
pub use error::{Error, Result};
pub use eval_config::{EnergyEstimator, EvalConfig, EvalSettings};
pub use held_run::HeldRun;
pub use run_dir::{RunDir, RunMetrics};
pub use test_metrics::{CurvePoint, EnergySummary, ImageMetrics, TestMetrics};

/// The version of the code that results depend on: bump it with any change that alters a
/// result (training, models, data generation or metrics), so that content-addressed runs of
/// the old code are not reused.
pub const CODE_VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "+results-4");
