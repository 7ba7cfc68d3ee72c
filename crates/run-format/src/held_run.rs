//! A run directory held by one process ([`HeldRun`]): its lock taken once for all the stages
//! that work in it (a sweep's run holds it from training through evaluation and export), the
//! leftovers of a killed process cleared when it is taken, and the directory's state checked
//! against the configuration a fit is about to train ([`HeldRun::begin_training`]), and the
//! files the stages hand it, serialised, written in an order that a kill anywhere leaves
//! resumable ([`HeldRun::write_trained`], [`HeldRun::write_results`]).
//!
//! A run directory is held with [`RunDir::hold`]. The checkpoints' folders are named, listed
//! and removed by [`RunDir`] ([`RunDir::checkpoint_steps`]); what a checkpoint holds is the
//! trainer's (`experiments::checkpoint`).

use crate::config::RunConfig;
use crate::run_dir::{CurveRow, RunDir, RunMetrics, curve_csv};
use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// A run directory whose lock this process holds (released when dropped).
#[derive(Debug)]
pub struct HeldRun {
    pub(crate) dir: RunDir,
    pub(crate) _lock: stdx::lock::DirLock,
}

impl HeldRun {
    /// The run directory.
    pub fn dir(&self) -> &RunDir {
        &self.dir
    }

    /// Reads what a fit starts from, at once: checks the directory against the configuration
    /// to train and returns it, with its cache directory (`cache` overrides the configured
    /// one), the metrics of a run that already finished training and the newest complete
    /// checkpoint to resume from. `config: None` trains the configuration the directory holds
    /// (a sweep's prepared run); a given one is checked, a new run gets it as its
    /// `config.toml`, and an existing run must hold the same.
    pub fn begin_training(
        &self,
        config: Option<&RunConfig>,
        cache: Option<&Path>,
    ) -> Result<TrainingStart> {
        let path = self.dir.config();
        let config = match config {
            None => self.dir.read_config()?,
            Some(given) if path.is_file() => {
                given.validate()?;
                let existing = RunConfig::read(&path)?;
                if existing != *given {
                    let keys = existing.differing_keys(given);
                    return Err(Error::format(
                        &path,
                        format!(
                            "the run directory holds a different configuration (keys {}); use \
                             a new run directory",
                            keys.join(", ")
                        ),
                    ));
                }
                existing
            }
            Some(given) => {
                given.validate()?;
                stdx::fs::write_atomic(&path, given.to_toml()?.as_bytes())?;
                given.clone()
            }
        };
        config.validate()?;
        let finished =
            if self.dir.is_trained() { Some(RunMetrics::read(&self.dir.metrics())?) } else { None };
        let cache = self.dir.cache(&config, cache);
        let checkpoint = self.dir.latest_checkpoint()?;
        Ok(TrainingStart { config, cache, finished, checkpoint })
    }
}

/// What [`HeldRun::begin_training`] read: all a fit needs from its run directory before it
/// trains.
#[derive(Debug)]
pub struct TrainingStart {
    /// The configuration to train.
    pub config: RunConfig,
    /// The eigenpair and feature cache directory.
    pub cache: PathBuf,
    /// The metrics of a run that already finished training (`None`: it trains).
    pub finished: Option<RunMetrics>,
    /// The newest complete checkpoint, which training resumes from.
    pub checkpoint: Option<PathBuf>,
}

impl HeldRun {
    /// Writes what marks the run trained, in the order a kill anywhere between leaves
    /// resumable: the curve of the last checkpoint again (a kill between that checkpoint and
    /// its curve leaves the previous one's, and a run resumed from its last checkpoint trains
    /// no further step that would write it: the kill torture found such a run), the weights
    /// (`weights`: the bytes of their file), and last `metrics.json`, so that a kill before it
    /// redoes them all. Each file is written atomically, and all of them are serialised before
    /// the first is written.
    pub fn write_trained(
        &self,
        curve: &[CurveRow],
        weights: &[u8],
        metrics: &RunMetrics,
    ) -> Result<()> {
        let metrics_path = self.dir.metrics();
        let (curve, metrics) = (curve_csv(curve), metrics.to_json(&metrics_path)?);
        stdx::fs::write_atomic(&self.dir.curve(), curve.as_bytes())?;
        stdx::fs::write_atomic(&self.dir.weights(), weights)?;
        stdx::fs::write_atomic(&metrics_path, metrics.as_bytes())?;
        Ok(())
    }
}

/// A run's evaluation, serialised for its directory: `metrics.json` with its test record and
/// the probe's bytes (`None`: no probe).
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// The run's metrics with the test record.
    pub metrics: RunMetrics,
    /// `probe.bin`'s bytes.
    pub probe: Option<Vec<u8>>,
}

/// A fitted model's files for other tools, serialised: `model.safetensors` and `model.json`
/// ([`RunDir::portable_weights`], [`RunDir::portable_description`]).
#[derive(Clone, Debug)]
pub struct PortableFiles {
    /// `model.safetensors`.
    pub weights: Vec<u8>,
    /// `model.json`.
    pub description: Vec<u8>,
}

impl PortableFiles {
    /// Writes both into `dir` (created if needed), each atomically; returns their paths.
    pub fn write_to(&self, dir: &RunDir) -> Result<[PathBuf; 2]> {
        std::fs::create_dir_all(dir.path()).map_err(|e| Error::io(dir.path(), e))?;
        let files = self.files_in(dir);
        for (path, bytes) in &files {
            stdx::fs::write_atomic(path, bytes)?;
        }
        Ok(files.map(|(path, _)| path))
    }

    /// Its two files in `dir`: their paths and bytes.
    fn files_in(&self, dir: &RunDir) -> [(PathBuf, &[u8]); 2] {
        [
            (dir.portable_weights(), &self.weights[..]),
            (dir.portable_description(), &self.description[..]),
        ]
    }
}

/// What evaluation and export leave in a run directory, each part absent when it was not
/// computed (a run evaluated before keeps its evaluation; the `fit` command does not evaluate).
#[derive(Clone, Debug, Default)]
pub struct RunResults {
    /// The evaluation.
    pub evaluation: Option<Evaluation>,
    /// The exported model.
    pub portable: Option<PortableFiles>,
}

impl HeldRun {
    /// Writes a run's results in the order a kill anywhere between leaves a run that evaluates
    /// again: the probe, the portable model, and `metrics.json` (with its test record) last,
    /// so that a run marked evaluated has its export. Everything is serialised before the first
    /// file is written, and each file is written atomically.
    pub fn write_results(&self, results: &RunResults) -> Result<()> {
        let metrics_path = self.dir.metrics();
        let metrics = match &results.evaluation {
            Some(e) => Some(e.metrics.to_json(&metrics_path)?),
            None => None,
        };
        let mut files: Vec<(PathBuf, &[u8])> = Vec::with_capacity(4);
        if let Some(probe) = results.evaluation.as_ref().and_then(|e| e.probe.as_ref()) {
            files.push((self.dir.probe(), probe));
        }
        if let Some(portable) = &results.portable {
            files.extend(portable.files_in(&self.dir));
        }
        if let Some(metrics) = &metrics {
            files.push((metrics_path, metrics.as_bytes()));
        }
        for (path, bytes) in &files {
            stdx::fs::write_atomic(path, bytes)?;
        }
        Ok(())
    }
}

impl std::ops::Deref for HeldRun {
    type Target = RunDir;

    fn deref(&self) -> &RunDir {
        &self.dir
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run_dir::CHECKPOINT_STATE;

    fn checkpoint(dir: &RunDir, step: u64, complete: bool) {
        let path = dir.checkpoint(step);
        std::fs::create_dir_all(&path).unwrap();
        if complete {
            std::fs::write(path.join(CHECKPOINT_STATE), "{}").unwrap();
        }
    }

    fn results() -> RunResults {
        let metrics: RunMetrics = serde_json::from_str(
            r#"{"steps": 1, "final_train_loss": 0.5, "samples_per_second": 1.0,
                "wall_seconds": 1.0, "train_records": 1, "val_records": 0,
                "zero_prediction_loss": 1.0, "parameters": 1}"#,
        )
        .unwrap();
        let evaluation = Evaluation { metrics, probe: Some(b"probe".to_vec()) };
        let portable = PortableFiles { weights: b"st".to_vec(), description: b"{}".to_vec() };
        RunResults { evaluation: Some(evaluation), portable: Some(portable) }
    }

    #[test]
    fn a_run_is_marked_evaluated_only_after_its_export_is_written() {
        let tmp = test_support::TempDir::new("held-run-results");
        let dir = RunDir::new(tmp.0.join("run"));
        let held = dir.hold("evaluating").unwrap();
        // The export cannot be written (a folder where its weights go): nothing marks the run
        // evaluated, so the next start evaluates it again.
        std::fs::create_dir_all(dir.portable_weights().join("in-the-way")).unwrap();
        assert!(held.write_results(&results()).is_err());
        assert!(dir.probe().is_file(), "the probe is written first");
        assert!(!dir.metrics().exists(), "metrics.json is written last");
        std::fs::remove_dir_all(dir.portable_weights()).unwrap();
        held.write_results(&results()).unwrap();
        assert_eq!(std::fs::read(dir.portable_weights()).unwrap(), b"st");
        assert_eq!(std::fs::read(dir.portable_description()).unwrap(), b"{}");
        assert_eq!(RunMetrics::read(&dir.metrics()).unwrap().steps, 1);
    }

    #[test]
    fn taking_a_run_keeps_only_its_newest_checkpoint_and_a_second_taker_is_refused() {
        let tmp = test_support::TempDir::new("held-run");
        let dir = RunDir::new(tmp.0.join("run"));
        checkpoint(&dir, 100, true);
        checkpoint(&dir, 200, true);
        checkpoint(&dir, 300, false);
        let held = dir.hold("training").unwrap();
        let steps: Vec<u64> = held.checkpoint_steps().unwrap().iter().map(|s| s.0).collect();
        assert_eq!(steps, [200], "the newest complete checkpoint stays, the rest go");
        assert!(!dir.checkpoint(300).exists(), "an incomplete newer one goes too");
        let second = dir.hold("evaluating").unwrap_err().to_string();
        assert!(second.contains("in use by") && second.contains("(training)"), "{second}");
        drop(held);
        assert!(dir.hold("evaluating").is_ok(), "free once dropped");
    }
}
