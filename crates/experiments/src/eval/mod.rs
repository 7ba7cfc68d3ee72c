//! `eval`: renders the test images of a finished run and computes every metric of the paper
//! (spec section 7).
//!
//! * [`images`]: test renders, PSNR / DSSIM / HDR-FLIP / LPIPS on the object mask, FLIP error
//!   maps and the additive models' diffuse / specular / albedo figures.
//! * [`analyses`]: energy conservation and the reciprocity RMSE on the test records.
//! * [`predict`]: the model on CPU records, and as a [`metrics::BatchBrdf`].
//! * [`fitted`]: a finished run opened for analysis (config, model, scene).
//! * [`settings`]: the `[eval]` table of the run configuration.
//!
//! The cube-root RMSE runs over the lit test samples with theta_l, theta_v <= 80 degrees, not
//! saturated and with a valid ground truth (captured data has none: the RMSE is then absent).
//! LPIPS needs its weights file (see [`metrics::lpips`]); without it the value is absent and
//! `lpips_unavailable` says why. Results go into `<run>/metrics.json` under `test`.

pub mod analyses;
pub mod fitted;
pub mod images;
pub mod predict;
pub mod settings;

pub use analyses::EnergySummary;
pub use fitted::FittedRun;
pub use predict::{ModelBrdf, Prediction, predict};
pub use settings::{EnergyEstimator, EvalConfig, EvalSettings};

use crate::Result;
use crate::run_dir::{METRICS_FILE, RunMetrics};
use metrics::rmse::{CubeRootRmse, RmseConfig};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// Test metrics of a run (spec 7), raw values (not table-scaled).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TestMetrics {
    /// Mean PSNR over the test images (dB, sRGB clamped, object mask).
    pub psnr: f64,
    /// Mean DSSIM over the test images.
    pub dssim: f64,
    /// Mean HDR-FLIP over the test images.
    pub flip: f64,
    /// Mean LPIPS over the test images (absent without weights).
    #[serde(default)]
    pub lpips: Option<f64>,
    /// Why LPIPS is absent ("weights missing").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lpips_unavailable: Option<String>,
    /// Cube-root RMSE of the BRDF on the test samples (absent without ground truth).
    #[serde(default)]
    pub rmse_cbrt: Option<f64>,
    /// Samples that entered the RMSE.
    pub rmse_samples: usize,
    /// Test images evaluated.
    pub images: usize,
    /// RMSE between f(x, l, v) and f(x, v, l) over test records.
    #[serde(default)]
    pub reciprocity_rmse: Option<f64>,
    /// Energy conservation.
    #[serde(default)]
    pub energy: Option<EnergySummary>,
    /// Wall-clock seconds of the whole evaluation.
    #[serde(default)]
    pub seconds: f64,
}

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
    let settings = eval.resolve(run.config.train.profile);
    let (_, data) = run.test_records()?;
    let config = &run.config;
    let brdf =
        ModelBrdf { model: &run.model, config: &config.model, data: &data, device: &run.device };
    analyses::energy(&brdf, &settings, config.seed, progress)
}

/// Evaluates the finished run in `run`; `scene` overrides the config's scene directory.
pub fn eval(
    run: &Path,
    scene: Option<&Path>,
    cache: Option<&Path>,
    progress: bool,
) -> Result<TestMetrics> {
    let start = Instant::now();
    let fitted = FittedRun::open(run, scene, cache)?;
    let (config, device, model, dataset) =
        (&fitted.config, &fitted.device, &fitted.model, &fitted.dataset);
    let settings = config.eval.resolve(config.train.profile);
    let (samples, data) = fitted.test_records()?;
    let parts = config.model.kind.is_additive() && settings.images;
    let pred = predict(model, &config.model, &data, device, parts)?;

    let mut rmse = CubeRootRmse::new(RmseConfig::default());
    for (r, &i) in data.source.iter().enumerate() {
        // Samples without a valid ground truth (invalid MERL bins, captured data) are left out.
        if samples.gt_valid[i] {
            let (lz, vz) = (data.l[r][2], data.v[r][2]);
            rmse.push(pred.f[r], samples.gt_brdf[i], lz, vz, samples.saturated[i]);
        }
    }
    let rmse_cbrt = if rmse.kept > 0 { Some(rmse.value()?) } else { None };

    let (lpips, lpips_unavailable) = if settings.lpips_weights.is_file() {
        (Some(metrics::lpips::Lpips::load(&settings.lpips_weights, device)?), None)
    } else {
        (None, Some("weights missing".to_string()))
    };
    let scores = images::render_and_score(
        dataset,
        &samples,
        &data,
        &pred,
        run,
        settings.images,
        lpips.as_ref(),
        progress,
    )?;
    let brdf = ModelBrdf { model, config: &config.model, data: &data, device };
    let reciprocity_rmse = analyses::reciprocity(&brdf, &settings)?;
    let energy = analyses::energy(&brdf, &settings, config.seed, progress)?;
    let test = TestMetrics {
        psnr: scores.psnr,
        dssim: scores.dssim,
        flip: scores.flip,
        lpips: scores.lpips,
        lpips_unavailable,
        rmse_cbrt,
        rmse_samples: rmse.kept,
        images: scores.images,
        reciprocity_rmse,
        energy,
        seconds: start.elapsed().as_secs_f64(),
    };
    let path = run.join(METRICS_FILE);
    let mut all = RunMetrics::read(&path)?;
    all.test = Some(test.clone());
    all.write(&path)?;
    Ok(test)
}
