//! What `collect` reads and writes: one evaluated run as it is read from its directory
//! ([`CollectedRun`], found by [`find_runs`], read by [`read_run`]), the name of a test image
//! ([`parse_stem`]) and the summary of what was written ([`CollectSummary`]). The tables, the
//! BRDF plots and the HTML report all take their runs from here.

use crate::plan::{self, Purpose};
use experiments::Result;
use metrics::aggregate::Score;
use report::{Dataset, MetricKind, RunOptions, RunRecord};
use run_format::config::RunConfig;
use run_format::plateau::StopReason;
use run_format::run_dir::{RunDir, RunMetrics};
use run_format::{ImageMetrics, TestMetrics};
use std::path::{Path, PathBuf};

/// One collected run.
#[derive(Clone, Debug)]
pub struct CollectedRun {
    /// Its directory.
    pub dir: PathBuf,
    /// Its configuration.
    pub config: RunConfig,
    /// Why it ran.
    pub purposes: Vec<Purpose>,
    /// The record of its final weights (scored against the observed images).
    pub record: RunRecord,
    /// The same scored against the noise-free test renders (semi-synthetic scenes).
    pub noise_free: Option<RunRecord>,
    /// The noise ceiling of its scene (semi-synthetic scenes).
    pub ceiling: Option<RunRecord>,
    /// The same run under the paper's protocol: the whole frame against the noise-free
    /// renders (with its RMSE∛, which no protocol changes).
    pub paper: Option<RunRecord>,
    /// The paper's whole frame against the observations, background set to 0 (generated
    /// scenes; a capture's `paper` already is this).
    pub paper_observed: Option<RunRecord>,
    /// Its run-time curve: the snapshots' scores and the final weights' (runs with
    /// snapshots).
    pub curve: Vec<RunRecord>,
    /// Why its training stopped (absent for runs of older versions).
    pub stop_reason: Option<StopReason>,
    /// Its training's wall-clock seconds.
    pub train_seconds: f64,
    /// Its evaluation's wall-clock seconds.
    pub eval_seconds: f64,
}

impl CollectedRun {
    /// Whether its training is known to have converged (the plateau rule stopped it).
    pub fn converged(&self) -> bool {
        self.stop_reason.is_some_and(StopReason::converged)
    }
}

/// Every run directory below `paths` (a directory holding `config.toml` and `metrics.json`).
pub fn find_runs(paths: &[PathBuf]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack: Vec<PathBuf> = paths.to_vec();
    while let Some(p) = stack.pop() {
        let run = RunDir::new(&p);
        if run.config().is_file() && run.metrics().is_file() {
            out.push(p);
            continue;
        }
        if let Ok(entries) = std::fs::read_dir(&p) {
            for e in entries.flatten() {
                if e.file_type().is_ok_and(|t| t.is_dir()) {
                    stack.push(e.path());
                }
            }
        }
    }
    out.sort();
    out
}

/// The record of an evaluated run (`None` when it has no test metrics yet).
pub fn read_run(dir: &Path) -> Result<Option<CollectedRun>> {
    let run = RunDir::new(dir);
    let config = run.read_config()?;
    let m = RunMetrics::read(&run.metrics())?;
    let Some(t) = m.test.as_ref() else { return Ok(None) };
    let (object, dataset, purposes) = run_identity(&run, &config);
    let opt = |v: Option<f64>, why: &str| match v {
        Some(x) => Score::Value(x),
        None => Score::Unavailable(why.into()),
    };
    let base = RunRecord::new(config.model.kind, dataset, object)
        .with_options(RunOptions::of(&config.model));
    let why_no_lpips = t.lpips_unavailable.as_deref().unwrap_or("not computed");
    let images = |r: RunRecord, m: &ImageMetrics| {
        r.with_value(MetricKind::Psnr, m.psnr)
            .with_value(MetricKind::Dssim, m.dssim)
            .with_value(MetricKind::Flip, m.flip)
            .with(MetricKind::Lpips, opt(m.lpips, why_no_lpips))
    };
    let observed = ImageMetrics { psnr: t.psnr, dssim: t.dssim, flip: t.flip, lpips: t.lpips };
    let mut r =
        images(base.clone(), &observed).with_value(MetricKind::TrainingSeconds, m.wall_seconds);
    if let Some(v) = t.rmse_cbrt {
        r = r.with_value(MetricKind::CubeRootRmse, v);
    }
    if let Some(v) = t.reciprocity_rmse {
        r = r.with_value(MetricKind::ReciprocityRmse, v);
    }
    if let Some(e) = &t.energy {
        r = r.with_value(MetricKind::EnergyPercentAbove1, e.percent_above_one);
        r = r.with(MetricKind::EnergyMedianAbove1, opt(e.median_above_one, "no pair above 1"));
    }
    let noise_free = t.clean.as_ref().map(|c| images(base.clone(), c));
    let with_rmse = |m: &ImageMetrics| {
        let r = images(base.clone(), m);
        match t.rmse_cbrt {
            Some(v) => r.with_value(MetricKind::CubeRootRmse, v),
            None => r,
        }
    };
    let paper = t.paper.as_ref().map(|p| with_rmse(&p.scores));
    // A capture's paper scores already are against its observations; a generated scene
    // evaluated before the reading against the observations existed has none.
    let paper_observed = t.paper.as_ref().and_then(|p| match (&p.observed, &t.clean) {
        (Some(o), _) => Some(with_rmse(o)),
        (None, None) => Some(with_rmse(&p.scores)),
        (None, Some(_)) => None,
    });
    let ceiling = t.ceiling.as_ref().map(|c| images(base.clone(), c));
    let curve = curve_records(&base, &m, t);
    Ok(Some(CollectedRun {
        dir: dir.to_path_buf(),
        config,
        purposes,
        record: r,
        noise_free,
        ceiling,
        paper,
        paper_observed,
        curve,
        stop_reason: m.stop_reason,
        train_seconds: m.wall_seconds,
        eval_seconds: t.seconds,
    }))
}

/// The run's object, data set and purposes, from its `run.json` or, for a run made outside a
/// sweep, from its scene's folder name (purposes: a table row and an ablation).
fn run_identity(run: &RunDir, config: &RunConfig) -> (String, Dataset, Vec<Purpose>) {
    match plan::read_info(run) {
        Ok(i) => (i.object, Dataset::from_label(&i.dataset), i.purposes),
        Err(_) => {
            let object = config
                .scene
                .as_ref()
                .and_then(|s| s.file_name())
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "unknown".into());
            (
                object,
                scene_dataset(config.scene.as_deref()),
                vec![Purpose::Table, Purpose::Ablation],
            )
        }
    }
}

/// The run-time curve of a run whose profile kept weight snapshots: each snapshot's test
/// scores, then the final weights'.
fn curve_records(base: &RunRecord, m: &RunMetrics, t: &TestMetrics) -> Vec<RunRecord> {
    let point = |steps: u64, seconds: f64, psnr: f64, rmse: Option<f64>| {
        let p = base
            .clone()
            .at_steps(steps)
            .with_value(MetricKind::TrainingSeconds, seconds)
            .with_value(MetricKind::Psnr, psnr);
        match rmse {
            Some(v) => p.with_value(MetricKind::CubeRootRmse, v),
            None => p,
        }
    };
    let mut curve: Vec<RunRecord> =
        t.curve.iter().map(|c| point(c.step, c.seconds, c.psnr, c.rmse_cbrt)).collect();
    if !curve.is_empty() {
        curve.push(point(m.steps, m.wall_seconds, t.psnr, t.rmse_cbrt));
    }
    curve
}

/// The note under the tables when runs stopped before converging, naming them.
pub fn convergence_note(runs: &[&CollectedRun]) -> Option<String> {
    let open: Vec<&&CollectedRun> = runs.iter().filter(|r| !r.converged()).collect();
    if open.is_empty() {
        return None;
    }
    let mut names: Vec<String> = open
        .iter()
        .map(|r| format!("{} on {}", r.record.model.paper_name(), r.record.object))
        .collect();
    if names.len() > 8 {
        let more = names.len() - 6;
        names.truncate(6);
        names.push(format!("{more} more"));
    }
    Some(format!(
        "Not converged: {} of {} runs stopped at their step budget before their validation \
         loss reached a plateau ({}); more training would change their scores. Profiles with \
         a larger budget (the default) train every run to its plateau.",
        open.len(),
        runs.len(),
        names.join(", ")
    ))
}

/// The data set of a scene directory, from its manifest: captured scenes name their benchmark,
/// everything else is MERL-derived.
fn scene_dataset(scene: Option<&Path>) -> Dataset {
    use scene::{MANIFEST_FILE, Manifest, MaterialSpec};
    match scene.and_then(|s| Manifest::read(&s.join(MANIFEST_FILE)).ok()) {
        Some(m) => match m.config.material {
            MaterialSpec::Captured { benchmark, .. } => Dataset::from_label(&benchmark),
            _ => Dataset::MerlNbrdf,
        },
        None => Dataset::MerlNbrdf,
    }
}

/// What [`collect`](crate::collect()) wrote.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CollectSummary {
    /// Evaluated runs collected.
    pub runs: usize,
    /// Run directories without test metrics (not finished), left out.
    pub unfinished: usize,
    /// Files written.
    pub files: Vec<PathBuf>,
}

/// The (view, light) of a test image's stem (`view007_light003`).
pub fn parse_stem(stem: &str) -> Option<(usize, usize)> {
    let rest = stem.strip_prefix("view")?;
    let (v, l) = rest.split_once("_light")?;
    Some((v.parse().ok()?, l.parse().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stems_parse() {
        assert_eq!(parse_stem("view007_light012"), Some((7, 12)));
        assert_eq!(parse_stem("v07_l12"), None);
    }
}
