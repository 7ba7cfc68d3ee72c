//! The export round trip: the test views re-rendered from an exported material with
//! `brdf-analytic` (per-vertex parameters interpolated over each triangle, as a renderer does
//! with vertex attributes), scored against the fit's own renders of the same records.
//!
//! For a spatially uniform fit the exported BRDF is the fitted one, so what remains is the
//! difference between the network's f32 tensor twin of the analytic model and the scalar
//! library. For a spatially varying fit the renderer interpolates parameters where the fit
//! interpolated features, which the score then shows.

use super::material::ExportedMaterial;
use crate::eval::images::psnr_between;
use crate::fitted::FittedRun;
use crate::{Error, Result};
use brdf_neural::fitted::predict;
use serde::{Deserialize, Serialize};

/// The round trip's scores over the test pairs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoundTrip {
    /// Test images compared.
    pub images: usize,
    /// Lowest PSNR over the images, dB ("inf" in JSON when every image agrees exactly).
    #[serde(with = "run_format::serde_inf")]
    pub min_psnr_db: f64,
    /// Mean PSNR, dB ("inf" when every image agrees exactly).
    #[serde(with = "run_format::serde_inf")]
    pub mean_psnr_db: f64,
    /// Largest relative difference of a BRDF value (|a - b| / max(|b|, 1e-3), any channel).
    pub max_relative_brdf_difference: f64,
}

/// The exported BRDF at every test record of `fitted`.
pub fn exported_brdf(fitted: &FittedRun, material: &ExportedMaterial) -> Result<Vec<[f32; 3]>> {
    let (samples, data) = fitted.test_records()?;
    let tris = &fitted.dataset.mesh.triangles;
    if material.len() != fitted.dataset.mesh.positions.len() {
        return Err(Error::config(
            "material",
            format!(
                "{} rows for a mesh of {} vertices",
                material.len(),
                fitted.dataset.mesh.positions.len()
            ),
        ));
    }
    Ok(data
        .source
        .iter()
        .enumerate()
        .map(|(r, &s)| {
            let row =
                material.interpolate(tris[samples.triangle[s] as usize], samples.barycentric[s]);
            ExportedMaterial::brdf(material.kind, &row).eval(data.l[r], data.v[r])
        })
        .collect())
}

/// Scores `material` (read back from an export) against the fit's renders.
pub fn round_trip(fitted: &FittedRun, material: &ExportedMaterial) -> Result<RoundTrip> {
    let (samples, data) = fitted.test_records()?;
    let records = data.records();
    let fit = predict(&fitted.model, &fitted.config.model, records, &fitted.device, false)?.f;
    let ours = exported_brdf(fitted, material)?;
    let mut worst = 0.0f64;
    for (a, b) in ours.iter().zip(&fit) {
        for c in 0..3 {
            let d = (a[c] as f64 - b[c] as f64).abs() / (b[c] as f64).abs().max(1e-3);
            worst = worst.max(d);
        }
    }
    let psnr = psnr_between(&fitted.dataset, &samples, &data, &ours, &fit)?;
    let n = psnr.len();
    Ok(RoundTrip {
        images: n,
        min_psnr_db: psnr.iter().copied().fold(f64::INFINITY, f64::min),
        mean_psnr_db: psnr.iter().sum::<f64>() / n.max(1) as f64,
        max_relative_brdf_difference: worst,
    })
}
