//! The run directory and its files, all written atomically (temporary file in the same
//! directory, then rename).
//!
//! ```text
//! <run>/config.toml        the resolved configuration
//! <run>/metrics.json       steps, why training stopped, wall time, losses (eval adds test metrics)
//! <run>/curve.csv          step,loss,val_loss,lr,wall_seconds
//! <run>/snapshots/         weights at geometrically spaced steps (`train.snapshots`)
//! <run>/weights.bpk        final model weights (burnpack)
//! <run>/checkpoints/step-NNNNNNNNN/{model.bpk, optim.bpk, state.json}
//! <run>/renders/           eval: per test image EXR + sRGB PNG
//! ```

use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The resolved configuration.
pub const CONFIG_FILE: &str = "config.toml";
/// Metrics of the run.
pub const METRICS_FILE: &str = "metrics.json";
/// Training curve.
pub const CURVE_FILE: &str = "curve.csv";
/// Final weights.
pub const WEIGHTS_FILE: &str = "weights.bpk";
/// Checkpoint folder.
pub const CHECKPOINTS_DIR: &str = "checkpoints";
/// Folder of the weight snapshots of the run-time curve.
pub const SNAPSHOTS_DIR: &str = "snapshots";

/// Writes `bytes` to `path` atomically (temporary file beside it, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let tmp = temp_path(path);
    std::fs::write(&tmp, bytes).map_err(|e| Error::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
}

/// A temporary sibling of `path` (same directory, so a rename is atomic).
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    // Keeps the extension: burn's writers may append theirs to a name without it.
    path.with_file_name(format!(".tmp-{}-{name}", std::process::id()))
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
    let mut s = String::from("step,loss,val_loss,lr,wall_seconds\n");
    for r in rows {
        let val = r.val_loss.map_or(String::new(), |v| format!("{v:e}"));
        s.push_str(&format!("{},{:e},{val},{:e},{:.3}\n", r.step, r.loss, r.lr, r.seconds));
    }
    write_atomic(path, s.as_bytes())
}

/// A kept snapshot of the weights (`snapshots/step-NNNNNNNNN.bpk`), for the run-time curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Steps done.
    pub step: u64,
    /// Wall time of the run at that step, seconds.
    pub seconds: f64,
}

/// The file of the snapshot after `step` steps.
pub fn snapshot_path(run: &Path, step: u64) -> PathBuf {
    run.join(SNAPSHOTS_DIR).join(format!("step-{step:09}.bpk"))
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
    pub test: Option<crate::eval::TestMetrics>,
}

impl RunMetrics {
    /// Reads `metrics.json`.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        serde_json::from_str(&text).map_err(|e| Error::format(path, e.to_string()))
    }

    /// Writes `metrics.json` atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let text =
            serde_json::to_string_pretty(self).map_err(|e| Error::format(path, e.to_string()))?;
        write_atomic(path, text.as_bytes())
    }
}
