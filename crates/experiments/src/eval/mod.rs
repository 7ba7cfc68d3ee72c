//! `eval`: renders the test images of a finished run and computes every metric of the paper
//! (spec section 7).
//!
//! * [`images`]: test renders, PSNR / DSSIM / HDR-FLIP / LPIPS in both protocols (ours: the
//!   object mask against the observed images; the paper's: the whole frame against the
//!   noise-free renders), FLIP error maps and the additive models' diffuse / specular / albedo
//!   figures.
//! * [`metric_settings`] (run-format's): the exact settings of each protocol, written beside
//!   the scores.
//! * [`analyses`]: energy conservation and the reciprocity RMSE on the test records.
//! * [`probe`]: the model on the BRDF plots' fixed directions (lit sphere, slices, albedo
//!   against angle, validity maps), stored as `<run>/probe.bin` when images are written and
//!   the run's `[eval] probe` is not off.
//! * [`run_format::eval_config`]: the `[eval]` table of the run configuration.
//!
//! The cube-root RMSE runs over the lit test samples with theta_l, theta_v <= 80 degrees, not
//! saturated and with a valid ground truth (captured data has none: the RMSE is then absent).
//! LPIPS needs its weights file (see [`metrics::lpips`]); without it the value is absent and
//! `lpips_unavailable` says why. Results go into `<run>/metrics.json` under `test`.

pub mod analyses;
pub mod images;
pub mod probe;

pub use crate::fitted::FittedRun;
pub use brdf_neural::fitted::Prediction;

use crate::Result;
use crate::data::RecordSet;
use crate::places::Places;
use brdf_neural::fitted::{NeuralSurface, device_table, predict, predict_on};
use metrics::rmse::{CubeRootRmse, RmseConfig};
use run_format::held_run::{Evaluation, RunResults};
use run_format::metric_settings;
use run_format::phases::EvalPhases;
use run_format::run_dir::{RunDir, RunMetrics, Snapshot};
use run_format::{CurvePoint, EnergyEstimator, EnergySummary, ImageMetrics, TestMetrics};
use scene::SampleSet;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Only the energy analysis of a finished run, with `estimator` and `pairs` overriding the
/// run's `[eval]` settings (for comparing the two estimators on one model).
pub fn energy_of_run(
    run: &Path,
    estimator: EnergyEstimator,
    pairs: Option<usize>,
    cache: Option<&Path>,
    progress: bool,
) -> Result<Option<EnergySummary>> {
    let run = FittedRun::open(run, None, cache)?;
    let mut eval = run.config.eval.clone();
    eval.energy_estimator = Some(estimator);
    if pairs.is_some() {
        eval.energy_pairs = pairs;
    }
    eval.validate()?;
    // The energy analysis reads no LPIPS weights: no place of them is needed.
    let settings = eval.resolve(run.config.train.profile, Path::new(""));
    let (_, data) = run.test_records()?;
    let config = &run.config;
    let brdf = NeuralSurface::new(&run.model, &config.model, data.points(), &run.device)?;
    analyses::energy(&brdf, &data, &settings, config.seed, progress)
}

/// The cube-root RMSE of the predictions `f` (one per record of `data`) over the samples with
/// a valid ground truth, and the number of samples kept.
pub fn cube_root_rmse(
    samples: &SampleSet,
    data: &RecordSet,
    f: &[[f32; 3]],
) -> Result<(Option<f64>, usize)> {
    let mut rmse = CubeRootRmse::new(RmseConfig::default());
    for (r, &i) in data.source.iter().enumerate() {
        // Samples without a valid ground truth (invalid MERL bins, captured data) are left out.
        if samples.gt_valid[i] {
            let (lz, vz) = (data.l[r][2], data.v[r][2]);
            rmse.push(f[r], samples.gt_brdf[i], lz, vz, samples.saturated[i]);
        }
    }
    let value = if rmse.kept > 0 { Some(rmse.value()?) } else { None };
    Ok((value, rmse.kept))
}

/// The noise ceiling of a scene, computed by the first evaluation of a run on it and kept in
/// the cache directory: `ceiling-<key>.json`, the key hashing the scene's manifest checksum,
/// whether LPIPS was scored and the code's results version.
///
/// One writer at a time: evaluations side by side (a sweep's `--jobs`, a cluster's tasks on a
/// shared file system) that all miss the cache each compute the ceiling, but only the one that
/// holds `ceiling-<key>.lock` ([`CeilingCache::claim`]) writes it.
struct CeilingCache(std::path::PathBuf);

impl CeilingCache {
    fn new(cache: &Path, scene: &scene::SceneDataset, lpips: bool) -> Self {
        let key = format!("{}\n{lpips}\n{}", scene.manifest.checksum, run_format::CODE_VERSION);
        let hash = xxhash_rust::xxh3::xxh3_64(key.as_bytes());
        CeilingCache(cache.join(format!("ceiling-{hash:016x}.json")))
    }

    /// The cached ceiling; a missing or unreadable file is a miss (it is recomputed).
    fn read(&self) -> Option<ImageMetrics> {
        serde_json::from_str(&std::fs::read_to_string(&self.0).ok()?).ok()
    }

    /// The writer's lock (`None`: another evaluation holds it, and will write the ceiling),
    /// held until the returned file drops.
    fn claim(&self) -> Option<std::fs::File> {
        let path = self.0.with_extension("lock");
        std::fs::create_dir_all(self.0.parent()?).ok()?;
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .ok()?;
        file.try_lock().ok().map(|()| file)
    }

    fn write(&self, ceiling: &ImageMetrics) -> Result<()> {
        let text = serde_json::to_string_pretty(ceiling)
            .map_err(|e| crate::Error::format(&self.0, e.to_string()))?;
        Ok(stdx::fs::write_atomic(&self.0, text.as_bytes())?)
    }
}

/// Test PSNR and cube-root RMSE of every weight snapshot of the run.
fn snapshot_curve(
    fitted: &FittedRun,
    run: &RunDir,
    snapshots: &[Snapshot],
    (samples, data): (&SampleSet, &RecordSet),
) -> Result<Vec<CurvePoint>> {
    let mut out = Vec::with_capacity(snapshots.len());
    let gpu = !brdf_neural::device::is_cpu_device(&fitted.device);
    let table = device_table(&fitted.config.model, data.points(), gpu, &fitted.device)?;
    for s in snapshots {
        let model = fitted.load_weights_file(&run.snapshot(s.step))?;
        let config = &fitted.config.model;
        let records = data.records();
        let pred = predict_on(&model, config, records, table.as_ref(), &fitted.device, false)?;
        let psnr = images::mean_psnr(&fitted.dataset, samples, data, &pred.f)?;
        let (rmse_cbrt, _) = cube_root_rmse(samples, data, &pred.f)?;
        out.push(CurvePoint { step: s.step, seconds: s.seconds, psnr, rmse_cbrt });
    }
    Ok(out)
}

/// Evaluates the finished run in `run` and writes its results with its export (as a sweep's
/// run does: [`crate::portable::fitted_files`]), holding its lock; `scene` overrides the
/// config's scene directory.
pub fn eval(
    run: &Path,
    scene: Option<&Path>,
    cache: Option<&Path>,
    backend: brdf_neural::device::Backend,
    options: &EvalOptions,
) -> Result<TestMetrics> {
    let start = Instant::now();
    let held = RunDir::new(run).hold("evaluating")?;
    let fitted = FittedRun::open_on(run, scene, cache, backend)?;
    let trained = RunMetrics::read(&held.metrics())?;
    let evaluation = evaluate(&fitted, &held, trained, options, start)?;
    let test = evaluation.metrics.test.clone();
    let portable = Some(crate::portable::fitted_files(&fitted)?);
    held.write_results(&RunResults { evaluation: Some(evaluation), portable })?;
    test.ok_or_else(|| crate::Error::format(held.metrics(), "evaluation wrote no test record"))
}

/// How a process evaluates, beyond the run's configuration.
#[derive(Clone, Debug)]
pub struct EvalOptions {
    /// Show progress bars.
    pub progress: bool,
    /// The LPIPS weight file when the run's `[eval]` names none: the process's place
    /// ([`crate::places::Places::lpips_weights`]).
    pub lpips_weights: PathBuf,
}

impl Default for EvalOptions {
    /// No progress bars, the default places' LPIPS file.
    fn default() -> Self {
        EvalOptions { progress: false, lpips_weights: Places::default().lpips_weights() }
    }
}

/// Evaluates an opened (or just trained) run in the directory `run`, whose training wrote
/// `trained` (its `metrics.json`, handed on by the fit of the same process or read by
/// [`eval`]); `start` is when the evaluation began (its wall time is recorded). Writes the
/// test images (when the run's `[eval]` asks for them) and returns the rest for the run's
/// holder to write ([`run_format::held_run::HeldRun::write_results`]): `metrics.json` with its test record and the
/// probe.
pub fn evaluate(
    fitted: &FittedRun,
    run: &RunDir,
    trained: RunMetrics,
    options: &EvalOptions,
    start: Instant,
) -> Result<Evaluation> {
    let mut all = trained;
    let (config, device, model, dataset) =
        (&fitted.config, &fitted.device, &fitted.model, &fitted.dataset);
    let settings = config.eval.resolve(config.train.profile, &options.lpips_weights);
    let progress = options.progress;
    let mut phases = EvalPhases::default();
    let mut lap = Instant::now();
    let mut charge = |phase: &mut f64| {
        *phase += lap.elapsed().as_secs_f64();
        lap = Instant::now();
    };
    let (samples, data) = fitted.test_records()?;
    charge(&mut phases.records);
    let parts = config.model.kind.is_additive() && settings.images;
    let pred = predict(model, &config.model, data.records(), device, parts)?;
    let (rmse_cbrt, rmse_samples) = cube_root_rmse(&samples, &data, &pred.f)?;
    charge(&mut phases.predict);

    let (scores, lpips_unavailable) =
        render_and_score(fitted, run, (&samples, &data), &pred, &settings, progress)?;
    charge(&mut phases.images);
    let brdf = NeuralSurface::new(model, &config.model, data.points(), device)?;
    let reciprocity_rmse = analyses::reciprocity(&brdf, &data, &settings)?;
    charge(&mut phases.reciprocity);
    let energy = analyses::energy(&brdf, &data, &settings, config.seed, progress)?;
    charge(&mut phases.energy);
    let probe =
        if settings.probe { probe::probe_fitted(&brdf, dataset, &samples, &data) } else { None };
    charge(&mut phases.probe);
    let curve = snapshot_curve(fitted, run, &all.snapshots, (&samples, &data))?;
    charge(&mut phases.curve);
    let analyses = Analyses { rmse: (rmse_cbrt, rmse_samples), reciprocity_rmse, energy, curve };
    let test = test_metrics(scores, lpips_unavailable, analyses, dataset, (start, phases));
    all.test = Some(test);
    Ok(Evaluation { metrics: all, probe: probe.as_ref().map(probe::encode) })
}

/// What evaluation computes beside the images.
struct Analyses {
    rmse: (Option<f64>, usize),
    reciprocity_rmse: Option<f64>,
    energy: Option<EnergySummary>,
    curve: Vec<CurvePoint>,
}

/// Renders and scores the test images with LPIPS where its weights are present (else the
/// reason it is absent), the noise ceiling read from the scene's cache or computed and stored
/// by the one evaluation that claims it.
fn render_and_score(
    fitted: &FittedRun,
    run: &RunDir,
    (samples, data): (&SampleSet, &RecordSet),
    pred: &Prediction,
    settings: &run_format::eval_config::EvalSettings,
    progress: bool,
) -> Result<(images::ImageScores, Option<String>)> {
    let (lpips, lpips_unavailable) = if settings.lpips_weights.is_file() {
        (Some(metrics::lpips::Lpips::load(&settings.lpips_weights, &fitted.device)?), None)
    } else {
        (None, Some("weights missing".to_string()))
    };
    let cached = CeilingCache::new(&fitted.cache, &fitted.dataset, lpips.is_some());
    let known = cached.read();
    let writer = if known.is_none() { cached.claim() } else { None };
    let opts = images::RenderOptions {
        run: run.path(),
        write: settings.images,
        lpips: lpips.as_ref(),
        progress,
        skip_ceiling: known.is_some(),
    };
    let mut scores = images::render_and_score(&fitted.dataset, samples, data, pred, &opts)?;
    match (&known, &scores.ceiling) {
        (Some(c), _) => scores.ceiling = Some(c.clone()),
        (None, Some(c)) if writer.is_some() => cached.write(c)?,
        (None, _) => {}
    }
    Ok((scores, lpips_unavailable))
}

/// The test record of a run from its scores and analyses.
fn test_metrics(
    scores: images::ImageScores,
    lpips_unavailable: Option<String>,
    analyses: Analyses,
    dataset: &scene::SceneDataset,
    (start, phases): (Instant, EvalPhases),
) -> TestMetrics {
    let Analyses { rmse: (rmse_cbrt, rmse_samples), reciprocity_rmse, energy, curve } = analyses;
    TestMetrics {
        psnr: scores.model.psnr,
        dssim: scores.model.dssim,
        flip: scores.model.flip,
        paper: scores.paper.map(|p| run_format::test_metrics::PaperProtocol {
            scores: p,
            observed: scores.paper_observed,
            settings: metric_settings::PaperSettings::current(
                scores.images,
                scores.frame_pixels,
                scores.clean.is_some(),
            ),
        }),
        clean: scores.clean,
        ceiling: scores.ceiling,
        lpips: scores.model.lpips,
        lpips_unavailable,
        rmse_cbrt,
        rmse_samples,
        images: scores.images,
        reciprocity_rmse,
        energy,
        curve,
        settings: Some(metric_settings::MetricSettings::current(
            scores.images,
            scores.pixels,
            crate::data::clip_level(dataset),
        )),
        seconds: start.elapsed().as_secs_f64(),
        phases,
    }
}

#[cfg(test)]
mod tests {
    use super::CeilingCache;

    #[test]
    fn one_evaluation_at_a_time_may_write_a_scenes_ceiling() {
        let dir = test_support::TempDir::new("ceiling-claim");
        let cache = CeilingCache(dir.0.join("cache/ceiling-0123.json"));
        let first = cache.claim().expect("a free lock is claimed (its folder created)");
        assert!(cache.claim().is_none(), "a second claim while the first holds it");
        drop(first);
        assert!(cache.claim().is_some(), "free again");
        assert!(cache.read().is_none(), "claiming writes no ceiling");
    }
}
