//! Where runs live on disk: a run directory ([`RunDir`]) and the directory of a whole sweep
//! ([`SweepLayout`]), each with named paths, so no other module spells a file name. Every file
//! is written atomically (`stdx::fs`: temporary file in the same directory, then rename).
//!
//! ```text
//! <run>/config.toml        the resolved configuration
//! <run>/metrics.json       steps, why training stopped, wall time, losses (eval adds test metrics)
//! <run>/curve.csv          step,loss,val_loss,lr,wall_seconds
//! <run>/snapshots/         weights at geometrically spaced steps (`train.snapshots`)
//! <run>/weights.bpk        final model weights (burnpack)
//! <run>/checkpoints/step-NNNNNNNNN/{model.bpk, optim.bpk, state.json}
//! <run>/renders/           eval: per test image EXR + sRGB PNG (+ diffuse/specular parts)
//! <run>/flip/              eval: HDR-FLIP error map per test image
//! <run>/albedo/            eval: albedo maps of the additive models
//! <run>/probe.bin          eval: the model on the BRDF plots' probes (sphere, slices, albedo,
//!                          validity maps; `eval::probe`)
//! <run>/run.json           sweep runs only: id, object, dataset, purposes, code version
//! <run>/sweep.log          sweep runs in child processes and cluster tasks: their output
//! <run>/failure.json       sweep runs: the error of the last start, when it failed
//!
//! <out>/scenes/  <out>/runs/<run>/  <out>/cache/  <out>/tables/  <out>/figures/   (a sweep)
//! <out>/slurm/   a sweep submitted to Slurm (`sweep::slurm`)
//! ```
//!
//! The cache (eigenpairs, LBO tables, noise ceilings) of a run is, in this order: the one
//! given on the command line, the config's `features.cache_dir`, the sweep's `<out>/cache/` for
//! a run of a sweep (one holding `run.json`), else `cache/` beside the run directory.

use crate::config::RunConfig;
use crate::held_run::HeldRun;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The file whose presence marks a checkpoint folder complete (written last inside it).
pub const CHECKPOINT_STATE: &str = "state.json";

/// A run directory and the paths of its files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunDir(PathBuf);

impl RunDir {
    /// The run directory at `path` (nothing is created).
    pub fn new(path: impl Into<PathBuf>) -> Self {
        Self(path.into())
    }

    /// The directory itself.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// `config.toml`: the resolved configuration.
    pub fn config(&self) -> PathBuf {
        self.0.join("config.toml")
    }

    /// `metrics.json`: training figures, then the test metrics.
    pub fn metrics(&self) -> PathBuf {
        self.0.join("metrics.json")
    }

    /// `curve.csv`: the training curve.
    pub fn curve(&self) -> PathBuf {
        self.0.join("curve.csv")
    }

    /// `weights.bpk`: the final weights.
    pub fn weights(&self) -> PathBuf {
        self.0.join("weights.bpk")
    }

    /// `model.safetensors`: the final weights for other tools (experiments' `portable`).
    pub fn portable_weights(&self) -> PathBuf {
        self.0.join("model.safetensors")
    }

    /// `model.json`: the description beside [`RunDir::portable_weights`].
    pub fn portable_description(&self) -> PathBuf {
        self.0.join("model.json")
    }

    /// The snapshot of the weights after `step` steps.
    pub fn snapshot(&self, step: u64) -> PathBuf {
        self.0.join("snapshots").join(format!("step-{step:09}.bpk"))
    }

    /// The folder of the checkpoints.
    pub fn checkpoints(&self) -> PathBuf {
        self.0.join("checkpoints")
    }

    /// The folder of the checkpoint after `step` steps.
    pub fn checkpoint(&self, step: u64) -> PathBuf {
        self.checkpoints().join(format!("step-{step:09}"))
    }

    /// The rendered test images.
    pub fn renders(&self) -> PathBuf {
        self.0.join("renders")
    }

    /// The HDR-FLIP error maps.
    pub fn flip(&self) -> PathBuf {
        self.0.join("flip")
    }

    /// The albedo maps (additive models).
    pub fn albedo(&self) -> PathBuf {
        self.0.join("albedo")
    }

    /// `probe.bin`: the model on the BRDF plots' probes.
    pub fn probe(&self) -> PathBuf {
        self.0.join("probe.bin")
    }

    /// `run.json`: what a sweep knows of the run.
    pub fn info(&self) -> PathBuf {
        self.0.join("run.json")
    }

    /// `sweep.log`: the output of the child process that ran it.
    pub fn log(&self) -> PathBuf {
        self.0.join("sweep.log")
    }

    /// `failure.json`: why the last start of a sweep's run failed (removed by the next start).
    pub fn failure(&self) -> PathBuf {
        self.0.join("failure.json")
    }

    /// Whether the run finished training (weights and metrics written).
    pub fn is_trained(&self) -> bool {
        self.weights().is_file() && self.metrics().is_file()
    }

    /// Whether the run has been evaluated (test metrics written, in both protocols: a run
    /// evaluated before the paper's protocol existed is evaluated again, not trained again).
    pub fn is_evaluated(&self) -> bool {
        RunMetrics::read(&self.metrics()).is_ok_and(|m| m.test.is_some_and(|t| t.paper.is_some()))
    }

    /// Whether the run is complete: evaluated ([`RunDir::is_evaluated`]) and its weights
    /// exported for other tools (`model.safetensors` and `model.json`).
    pub fn is_complete(&self) -> bool {
        self.is_evaluated()
            && self.portable_weights().is_file()
            && self.portable_description().is_file()
    }

    /// Reads the run's configuration.
    pub fn read_config(&self) -> Result<RunConfig> {
        RunConfig::read(&self.config())
    }

    /// Takes the lock of the run directory (created if missing) for `what` (e.g.
    /// "training"), or fails naming the process that holds it. Taking it removes the
    /// temporary files of a killed writer (and says how many) and the checkpoints older than
    /// the newest one that a kill between a checkpoint's write and their removal left.
    pub fn hold(&self, what: &str) -> Result<HeldRun> {
        let lock = stdx::lock::DirLock::acquire(self.path(), what)?;
        if lock.removed_temporaries > 0 {
            eprintln!(
                "{}: removed {} temporary file(s) of an interrupted write",
                self.path().display(),
                lock.removed_temporaries
            );
        }
        if let Some((step, _)) = self.checkpoint_steps()?.pop() {
            self.remove_checkpoints_but(step)?;
        }
        Ok(HeldRun { dir: self.clone(), _lock: lock })
    }

    /// The complete checkpoints of the run (a folder `step-NNNNNNNNN` holding
    /// [`CHECKPOINT_STATE`]), oldest first.
    pub fn checkpoint_steps(&self) -> Result<Vec<(u64, PathBuf)>> {
        let mut out: Vec<(u64, PathBuf)> = self
            .checkpoint_folders()?
            .into_iter()
            .filter(|(_, path)| path.join(CHECKPOINT_STATE).is_file())
            .collect();
        out.sort();
        Ok(out)
    }

    /// The newest complete checkpoint, if any.
    pub fn latest_checkpoint(&self) -> Result<Option<PathBuf>> {
        Ok(self.checkpoint_steps()?.pop().map(|(_, p)| p))
    }

    /// Removes every checkpoint folder but that of step `keep`, complete or not. Each is first
    /// renamed to a temporary name (one atomic step) and then deleted, so a kill midway leaves
    /// whole checkpoints or temporaries (which the next [`RunDir::hold`] removes), never a
    /// half-deleted folder.
    pub fn remove_checkpoints_but(&self, keep: u64) -> Result<()> {
        let root = self.checkpoints();
        for (step, path) in self.checkpoint_folders()? {
            if step == keep {
                continue;
            }
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            let aside = root.join(format!(".{name}.partial-removed-{}", std::process::id()));
            std::fs::rename(&path, &aside).map_err(|e| Error::io(&path, e))?;
            std::fs::remove_dir_all(&aside).map_err(|e| Error::io(&aside, e))?;
        }
        Ok(())
    }

    /// Every folder named like a checkpoint (`step-<n>`), complete or not, in no order.
    fn checkpoint_folders(&self) -> Result<Vec<(u64, PathBuf)>> {
        let root = self.checkpoints();
        let entries = match std::fs::read_dir(&root) {
            Ok(e) => e,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(e) => return Err(Error::io(&root, e)),
        };
        let mut out = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|e| Error::io(&root, e))?;
            let name = entry.file_name().to_string_lossy().into_owned();
            if let Some(step) = name.strip_prefix("step-").and_then(|s| s.parse::<u64>().ok()) {
                out.push((step, entry.path()));
            }
        }
        Ok(out)
    }

    /// The cache of the run (see the module documentation for the order).
    pub fn cache(&self, config: &RunConfig, option: Option<&Path>) -> PathBuf {
        let beside = || self.0.parent().unwrap_or(Path::new(".")).to_path_buf();
        option.map(Path::to_path_buf).or_else(|| config.features.cache_dir.clone()).unwrap_or_else(
            || match self.0.parent().and_then(Path::parent) {
                Some(out) if self.info().is_file() => SweepLayout::new(out).cache(),
                _ => beside().join("cache"),
            },
        )
    }
}

/// The directory of a sweep and its parts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SweepLayout(PathBuf);

impl SweepLayout {
    /// The sweep directory `out` (nothing is created).
    pub fn new(out: impl Into<PathBuf>) -> Self {
        Self(out.into())
    }

    /// The directory itself.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// The generated scenes.
    pub fn scenes(&self) -> PathBuf {
        self.0.join("scenes")
    }

    /// The run directories.
    pub fn runs(&self) -> PathBuf {
        self.0.join("runs")
    }

    /// The cache shared by the sweep's runs.
    pub fn cache(&self) -> PathBuf {
        self.0.join("cache")
    }

    /// The tables (Markdown, LaTeX).
    pub fn tables(&self) -> PathBuf {
        self.0.join("tables")
    }

    /// The figures (PNG).
    pub fn figures(&self) -> PathBuf {
        self.0.join("figures")
    }

    /// The HTML report (`index.html`, run pages and their images).
    pub fn report(&self) -> PathBuf {
        self.0.join("report")
    }

    /// The Slurm submissions (`slurm/sweep.json`, job scripts, task lists, Slurm's logs).
    pub fn slurm(&self) -> PathBuf {
        self.0.join("slurm")
    }
}

/// One row of the training curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CurveRow {
    /// Steps done (1-based: the loss of step `step - 1`).
    pub step: u64,
    /// Training loss of that step.
    pub loss: f32,
    /// Validation loss after that step, when it was measured then.
    #[serde(default)]
    pub val_loss: Option<f32>,
    /// Its learning rate.
    pub lr: f64,
    /// Wall time of the run so far (training, validation and checkpoints, over every resumed
    /// part), seconds.
    pub seconds: f64,
}

/// Writes the curve as CSV: `step,loss,val_loss,lr,wall_seconds` (`val_loss` empty where it
/// was not measured).
pub fn write_curve(path: &Path, rows: &[CurveRow]) -> Result<()> {
    Ok(stdx::fs::write_atomic(path, curve_csv(rows).as_bytes())?)
}

/// The text [`write_curve`] writes.
pub fn curve_csv(rows: &[CurveRow]) -> String {
    let mut s = String::from("step,loss,val_loss,lr,wall_seconds\n");
    for r in rows {
        let val = r.val_loss.map_or(String::new(), |v| format!("{v:e}"));
        s.push_str(&format!("{},{:e},{val},{:e},{:.3}\n", r.step, r.loss, r.lr, r.seconds));
    }
    s
}

/// A kept snapshot of the weights (`snapshots/step-NNNNNNNNN.bpk`), for the run-time curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Steps done.
    pub step: u64,
    /// Wall time of the run at that step, seconds.
    pub seconds: f64,
}

/// `metrics.json`: training figures, and the test metrics once evaluated.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunMetrics {
    /// Steps done.
    pub steps: u64,
    /// Mean loss over the last curve rows (the last 10 % of the run, at least one row).
    pub final_train_loss: f32,
    /// Training samples per second (whole run, including resumed parts).
    pub samples_per_second: f64,
    /// Training wall time (validation and checkpoints included), seconds.
    pub wall_seconds: f64,
    /// Why training stopped (absent in runs of older versions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_reason: Option<crate::plateau::StopReason>,
    /// Best validation loss (gamma-MSE on the held-out training lights).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub best_val_loss: Option<f64>,
    /// The validation loss of the ground-truth BRDF (its noise floor; semi-synthetic scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub val_loss_floor: Option<f64>,
    /// Learning-rate decays of the plateau schedule.
    #[serde(default)]
    pub lr_decays: u32,
    /// Lit training records.
    pub train_records: usize,
    /// Validation records.
    #[serde(default)]
    pub val_records: usize,
    /// The gamma-MSE of predicting f = 0 on all training records: the baseline a fit must
    /// beat (a collapsed model sits here).
    pub zero_prediction_loss: f32,
    /// Model parameters.
    pub parameters: usize,
    /// Weight snapshots kept for the run-time curve.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub snapshots: Vec<Snapshot>,
    /// Test metrics (`eval`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub test: Option<crate::test_metrics::TestMetrics>,
    /// Where the training time went, seconds per phase of the step (absent in runs trained
    /// before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phases: Option<crate::phases::StepPhases>,
    /// The burn backend that trained the run (absent in runs trained before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backend: Option<model_spec::Backend>,
    /// Seconds from the start of the last process's fit to the end of its first step (every
    /// kernel of the step launched, its loss read): reading the scene and its caches, making
    /// the device and its tables, and on a GPU compiling (or loading from the persistent
    /// cache) the step's kernels.
    /// Absent in runs trained before it was recorded, and where the process trained no step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub startup_seconds: Option<f64>,
    /// How the last process's fit computed beyond `config.toml` (the bf16 kernel, the loss
    /// reads; [`crate::ComputeSettings`]). Absent in runs trained before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compute: Option<crate::ComputeSettings>,
}

impl RunMetrics {
    /// Reads `metrics.json`.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        serde_json::from_str(&text).map_err(|e| Error::format(path, e.to_string()))
    }

    /// Writes `metrics.json` atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let json = self.to_json(path)?;
        Ok(stdx::fs::write_atomic(path, json.as_bytes())?)
    }

    /// The text [`RunMetrics::write`] writes to `path` (named in the error).
    pub fn to_json(&self, path: &Path) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| Error::format(path, e.to_string()))
    }
}
