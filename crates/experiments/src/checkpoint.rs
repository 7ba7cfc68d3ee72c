//! What training writes as it goes ([`save`]): checkpoints and the weights' snapshots.
//!
//! A checkpoint holds the model weights and Adam state (burnpack, through burn's records, which
//! keep the parameter ids the optimizer state is keyed by), plus the step, the curve so far and
//! the elapsed time. A snapshot (for evaluation's curve of test scores) is the same weights'
//! bytes in `<run>/snapshots/`. The batch RNG needs no state: step `s` draws from a generator seeded with
//! `seed + s`, so a resumed run is identical to an uninterrupted one.
//!
//! A checkpoint is written into a temporary folder and renamed into place; older checkpoints
//! are removed only after the new one is complete, so a crash or a non-finite loss always
//! leaves the last good one. Their folders are named, listed and removed by run-format
//! ([`run_format::held_run`]); `state.json` is written last and marks one complete.

use crate::{Error, Result};
use brdf_neural::BrdfModel;
use burn::module::Module;
use burn::optim::ModuleOptimizer;
use run_format::run_dir::{CurveRow, RunDir, write_curve};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

const MODEL: &str = "model.bpk";
const OPTIM: &str = "optim.bpk";
const STATE: &str = run_format::run_dir::CHECKPOINT_STATE;

/// What a checkpoint holds besides the tensors.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CheckpointState {
    /// Steps done.
    pub step: u64,
    /// The training curve so far.
    pub curve: Vec<CurveRow>,
    /// Training wall time so far, seconds.
    pub seconds: f64,
    /// The plateau rule's state.
    #[serde(default)]
    pub plateau: run_format::plateau::Plateau,
    /// Snapshots kept so far.
    #[serde(default)]
    pub snapshots: Vec<run_format::run_dir::Snapshot>,
    /// Set once training has stopped early (the checkpoint of the last step).
    #[serde(default)]
    pub stopped: Option<run_format::plateau::StopReason>,
    /// Seconds per phase of the step so far.
    #[serde(default)]
    pub phases: run_format::phases::StepPhases,
}

/// What training writes after a step: a snapshot of the weights, a checkpoint, or both.
#[derive(Clone, Copy, Debug)]
pub struct Writes {
    /// The weights' snapshot of this step (`<run>/snapshots/`).
    pub snapshot: bool,
    /// A checkpoint of this step, with the curve so far.
    pub checkpoint: bool,
}

/// Writes what `writes` asks for after `state.step` steps, everything serialised before the
/// first file is written: the snapshot (the same bytes as the checkpoint's weights), then the
/// checkpoint (atomically, the older ones removed after it) and the curve. Returns the
/// checkpoint's folder when one was written.
pub fn save(
    run: &RunDir,
    (model, optim): (&BrdfModel, &ModuleOptimizer),
    state: &CheckpointState,
    writes: Writes,
) -> Result<Option<PathBuf>> {
    let weights = crate::fitted::weight_pack(model)?;
    let checkpoint = match writes.checkpoint {
        true => Some(serialise(optim, state, &run.checkpoint(state.step))?),
        false => None,
    };
    if writes.snapshot {
        stdx::fs::write_atomic(&run.snapshot(state.step), &weights)?;
    }
    let Some((adam, json)) = checkpoint else { return Ok(None) };
    let dir = run.checkpoint(state.step);
    stdx::fs::write_dir_atomic(&dir, &[], |tmp| -> Result<()> {
        for (name, bytes) in [(MODEL, &weights[..]), (OPTIM, &adam), (STATE, json.as_bytes())] {
            std::fs::write(tmp.join(name), bytes).map_err(|e| Error::io(tmp.join(name), e))?;
        }
        Ok(())
    })?;
    run.remove_checkpoints_but(state.step)?;
    write_curve(&run.curve(), &state.curve)?;
    Ok(Some(dir))
}

/// A checkpoint's Adam state and loop state, serialised (`dir` names the checkpoint in errors).
fn serialise(
    optim: &ModuleOptimizer,
    state: &CheckpointState,
    dir: &Path,
) -> Result<(Vec<u8>, String)> {
    let adam = canonical_optimizer_bytes(optim)
        .map_err(|e| Error::format(dir.join(OPTIM), format!("cannot write Adam state: {e}")))?;
    let json =
        serde_json::to_string(state).map_err(|e| Error::format(dir.join(STATE), e.to_string()))?;
    Ok((adam, json))
}

/// Adam's state as a burnpack with its tensors in name order. burn lists them in the order of
/// a `HashMap`, which differs from process to process, so the same state would be written as
/// different bytes and a resumed run's checkpoint would not equal an uninterrupted one's.
fn canonical_optimizer_bytes(optim: &ModuleOptimizer) -> std::result::Result<Vec<u8>, String> {
    let bytes = optim.into_bytes().map_err(|e| format!("{e:?}"))?;
    let reader = burn_pack::Reader::from_bytes(bytes).map_err(|e| format!("{e:?}"))?;
    let (scalars, metadata) = (reader.scalars().clone(), reader.metadata().clone());
    let mut tensors = reader.into_tensors().map_err(|e| format!("{e:?}"))?;
    tensors.sort_by(|a, b| a.name.cmp(&b.name));
    let mut writer = burn_pack::Writer::new(tensors);
    for (key, value) in &scalars {
        writer = writer.with_scalar(key, *value);
    }
    for (key, value) in &metadata {
        writer = writer.with_metadata(key, value);
    }
    Ok(writer.into_bytes().map_err(|e| format!("{e:?}"))?.to_vec())
}

/// Loads a checkpoint into a freshly initialised model and optimizer of the same
/// configuration.
pub fn load(
    dir: &Path,
    model: BrdfModel,
    optim: ModuleOptimizer,
) -> Result<(BrdfModel, ModuleOptimizer, CheckpointState)> {
    let model = model
        .try_load_file(dir.join(MODEL))
        .map_err(|e| Error::format(dir.join(MODEL), format!("cannot load weights: {e:?}")))?;
    let optim = optim
        .load(dir.join(OPTIM))
        .map_err(|e| Error::format(dir.join(OPTIM), format!("cannot load Adam state: {e:?}")))?;
    let path = dir.join(STATE);
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    let state = serde_json::from_str(&text).map_err(|e| Error::format(&path, e.to_string()))?;
    Ok((model, optim, state))
}
