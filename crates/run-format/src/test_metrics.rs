//! The scores of a finished run as `metrics.json` keeps them (its `test` record): image
//! metrics in both protocols, the noise ceiling, the BRDF-space analyses and the run-time
//! curve, raw values (tables scale them).
//!
//! `eval` (experiments) computes them; `collect` (sweep) and the Python package read them.

use crate::metric_settings;
use crate::phases::EvalPhases;
use serde::{Deserialize, Serialize};

/// Mean image metrics over the test images, raw (not table-scaled).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ImageMetrics {
    /// Mean PSNR (dB, sRGB clamped, object mask); +inf for identical images.
    #[serde(with = "crate::serde_inf")]
    pub psnr: f64,
    /// Mean DSSIM.
    pub dssim: f64,
    /// Mean HDR-FLIP.
    pub flip: f64,
    /// Mean LPIPS, when its weights were present.
    #[serde(default)]
    pub lpips: Option<f64>,
}

impl ImageMetrics {
    /// Adds `o` to these sums (LPIPS where either has it).
    pub fn add(&mut self, o: &ImageMetrics) {
        self.psnr += o.psnr;
        self.dssim += o.dssim;
        self.flip += o.flip;
        self.lpips = match (self.lpips, o.lpips) {
            (Some(a), Some(b)) => Some(a + b),
            (None, Some(b)) => Some(b),
            (a, None) => a,
        };
    }

    /// These sums divided by `n` (at least 1): the means.
    pub fn divided(mut self, n: usize) -> Self {
        let n = n.max(1) as f64;
        self.psnr /= n;
        self.dssim /= n;
        self.flip /= n;
        self.lpips = self.lpips.map(|l| l / n);
        self
    }
}

/// The energy-conservation result of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnergySummary {
    /// `fast` or `paper`.
    pub estimator: String,
    /// (x, l) pairs analysed.
    pub pairs: usize,
    /// Percentage of pairs with some channel's albedo above 1.
    pub percent_above_one: f64,
    /// Median over violating pairs of their largest channel (`None`: no violation).
    pub median_above_one: Option<f64>,
    /// Mean standard error of the per-pair estimates (all channels).
    pub mean_std_error: f64,
    /// BRDF evaluations spent.
    pub evaluations: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// The scores of a run under the paper's protocol, with its settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PaperProtocol {
    /// Mean scores over the test images (+inf PSNR for an exact render).
    pub scores: ImageMetrics,
    /// The same whole frames scored against the observations with their background set to 0
    /// instead of the noise-free renders: the other reading of the paper's protocol, which
    /// keeps the sensor noise in the reference (generated scenes; a capture's `scores` already
    /// are against its observations).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub observed: Option<ImageMetrics>,
    /// How they were computed.
    pub settings: metric_settings::PaperSettings,
}

/// One point of a run's run-time curve: the test scores of a weight snapshot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CurvePoint {
    /// Training steps of the snapshot.
    pub step: u64,
    /// Wall time of the run at that step, seconds.
    pub seconds: f64,
    /// Mean test PSNR (dB) against the observed images.
    pub psnr: f64,
    /// Cube-root RMSE of the BRDF (absent without ground truth).
    #[serde(default)]
    pub rmse_cbrt: Option<f64>,
}

/// Test metrics of a run (spec 7), raw values (not table-scaled).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TestMetrics {
    /// Mean PSNR over the test images (dB, sRGB clamped, object mask): our protocol, as are
    /// every score up to `lpips` and `settings`.
    pub psnr: f64,
    /// Mean DSSIM over the test images.
    pub dssim: f64,
    /// Mean HDR-FLIP over the test images.
    pub flip: f64,
    /// The model against the noise-free test renders (semi-synthetic scenes only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clean: Option<ImageMetrics>,
    /// The noise ceiling: the noise-free test renders scored against the observed ones, the
    /// best any model can score (semi-synthetic scenes only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ceiling: Option<ImageMetrics>,
    /// The paper's protocol: the whole frame against the noise-free renders, with its
    /// settings (absent in runs evaluated before it was added; the sweep re-evaluates them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paper: Option<PaperProtocol>,
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
    /// Test scores of the weight snapshots, in step order (runs with `train.snapshots`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub curve: Vec<CurvePoint>,
    /// The exact settings of every score (absent in runs evaluated before they were recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settings: Option<metric_settings::MetricSettings>,
    /// Wall-clock seconds of the whole evaluation.
    #[serde(default)]
    pub seconds: f64,
    /// Where those seconds went (absent in older runs).
    #[serde(default)]
    pub phases: EvalPhases,
}
