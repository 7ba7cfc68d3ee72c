//! Sweeps: the whole reproduction (`cargo xtask reproduce-tables`) and `collect`.
//!
//! * [`profile`]: the sweep profiles (`default`, `smoke`, `quick`, `runtime`, `full`, `real`,
//!   `figure`; `all-tables` is an alias of `default`; or a TOML file).
//! * [`plan`]: scenes and runs of a profile, content-addressed run directories.
//! * [`execute`]: scene generation, shared LBO tables, runs in-process, as child processes
//!   (`--jobs`) or as a job file for a cluster (`--emit-jobs`).
//! * [`collect`](mod@collect): tables (Markdown + LaTeX) and figures (PNG) from any set of run directories.
//! * [`collected`]: one evaluated run as `collect` reads it, and what `collect` wrote.
//! * [`brdf_figures`]: the BRDF plots of `collect` (lit spheres, slices, albedo, validity).
//! * [`html_report`]: the HTML report `collect` writes beside them.
//! * [`heartbeat`]: plain progress lines when the output goes to a file.
//! * [`slurm`]: the sweep as Slurm job arrays (requests, requeue on preemption, the collect
//!   job, resubmission of failures).
//! * [`shell`]: quoting the words of job files and scripts.
//! * [`status`]: where each run stands, read from the run directories (`sweep-status`).
//! * [`timing`]: where a sweep's time went (its phases, each model's training and evaluation).
//! * [`sources`]: mesh sources (embedded in the binary, under the data root) and real captures.
//! * The profiles (`smoke`, `quick`, `runtime`, `full`, `real`, or a TOML file) mix generated
//!   scenes and real captures (imported from DiLiGenT and DiLiGenT-MV).
//!
//! Layout of a sweep's output directory:
//!
//! ```text
//! <out>/scenes/<mesh>__<material>/   generated scenes (kept when complete)
//! <out>/scenes/<object>/             imported captures (kept when complete)
//! <out>/cache/                       LBO eigenpairs and feature tables
//! <out>/runs/<object>__<model>__<options>__<steps>__<id>/   one run (config, weights, metrics,
//!                                    renders, FLIP maps, run.json)
//! <out>/timing.json                  the last sweep's phases ([`timing`])
//! <out>/tables/, <out>/figures/      the results (see [`collect`])
//! ```

pub mod brdf_figures;
pub mod collect;
pub mod collected;
pub mod execute;
pub mod heartbeat;
pub mod html_report;
pub mod plan;
pub mod profile;
pub mod shell;
pub mod slurm;
pub mod sources;
pub mod status;
pub mod timing;

pub use collect::collect;
pub use collected::CollectSummary;
pub use execute::{
    Execution, RunEnd, RunOn, SweepSettings, SweepSummary, exit_with_parent, run_one, sweep,
    sweep_with,
};
pub use heartbeat::ProgressLines;
pub use profile::{DEFAULT_PROFILE, SweepProfile};
