//! The BRDF-space analyses of a fitted model on its test records (spec section 7): energy
//! conservation (directional albedo of random (x, l) pairs) and the reciprocity RMSE.

use crate::Result;
use crate::data::RecordSet;
use brdf_analytic::SurfaceBrdf;
use metrics::energy::{EnergyConfig, EnergyPair, energy_conservation, sample_pairs};
use run_format::EnergySummary;
use run_format::eval_config::EvalSettings;

/// Runs the configured energy analysis of `brdf` on `pairs` random records of `data` (point `i`
/// of `brdf` is record `i`; `None` when off).
pub fn energy(
    brdf: &impl SurfaceBrdf,
    data: &RecordSet,
    settings: &EvalSettings,
    seed: u64,
    progress: bool,
) -> Result<Option<EnergySummary>> {
    let Some(estimator) = settings.energy else { return Ok(None) };
    if data.is_empty() {
        return Ok(None);
    }
    let pairs: Vec<EnergyPair> = sample_pairs(data.len(), settings.energy_pairs, seed)
        .into_iter()
        .map(|i| EnergyPair { point: i as u32, l: data.l[i] })
        .collect();
    let report = energy_conservation(brdf, &pairs, &EnergyConfig { estimator, seed, progress })?;
    let se: f64 = report.pairs.iter().flat_map(|p| p.std_error).sum();
    Ok(Some(EnergySummary {
        estimator: settings.energy_name.into(),
        pairs: pairs.len(),
        percent_above_one: report.percent_above_one,
        median_above_one: report.median_above_one,
        mean_std_error: se / (3 * report.pairs.len()).max(1) as f64,
        evaluations: report.evaluations,
        seconds: report.seconds,
    }))
}

/// The reciprocity RMSE of `brdf` over `settings.reciprocity_pairs` records of `data` spread
/// over the whole set (every k-th; point `i` of `brdf` is record `i`), `None` when off.
pub fn reciprocity(
    brdf: &impl SurfaceBrdf,
    data: &RecordSet,
    settings: &EvalSettings,
) -> Result<Option<f64>> {
    let n = settings.reciprocity_pairs.min(data.len());
    if n == 0 {
        return Ok(None);
    }
    let stride = data.len() / n;
    let idx: Vec<usize> = (0..n).map(|i| i * stride).collect();
    let points: Vec<u32> = idx.iter().map(|&i| i as u32).collect();
    let l: Vec<[f32; 3]> = idx.iter().map(|&i| data.l[i]).collect();
    let v: Vec<[f32; 3]> = idx.iter().map(|&i| data.v[i]).collect();
    Ok(Some(metrics::reciprocity::reciprocity_rmse(brdf, &points, &l, &v)?))
}
