//! A run directory held by one process ([`HeldRun`]): its lock taken once for all the stages
//! that work in it (a sweep's run holds it from training through evaluation and export), the
//! leftovers of a killed process cleared when it is taken, and the directory's state checked
//! against the configuration a fit is about to train ([`HeldRun::begin_training`]).
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

impl HeldRun {
    /// Writes what marks the run evaluated: the probe first (`write_probe` writes it,
    /// atomically, to the path it is given; `None`: no probe), `metrics` (with its test
    /// record) last, so that a kill between them leaves a run that evaluates again.
    pub fn write_evaluated<E: From<Error>>(
        &self,
        write_probe: Option<impl FnOnce(&Path) -> std::result::Result<(), E>>,
        metrics: &RunMetrics,
    ) -> std::result::Result<(), E> {
        if let Some(write) = write_probe {
            write(&self.dir.probe())?;
        }
        metrics.write(&self.dir.metrics())?;
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
