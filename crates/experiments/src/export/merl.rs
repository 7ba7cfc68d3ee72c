//! `export-merl`: a fitted model as a MERL-format table (90 x 90 x 180 bins, the real binary
//! format of [`dataset_merl::MerlBrdf`]) at one surface point, so that any renderer that reads
//! MERL files (Mitsuba's `merl` plugin, pbrt-v4's `measured` material after conversion, the
//! Disney BRDF Explorer) can render the fitted material.
//!
//! Every bin is evaluated at its lower edge, the convention of the reference readers'
//! inverse ([`dataset_merl::merl::lookup::bin_lower_edges`]): (theta_h, theta_d, phi_d) ->
//! (l, v) in the local frame with phi_h = 0. Bins whose directions fall below the horizon
//! (theta_h + theta_d beyond 90 degrees, never queried by a renderer) are written as 0. The
//! surface point is a mesh vertex; by default the one whose spatial features are closest
//! (Euclidean) to the mean over all vertices, i.e. the most "average" point of the object.

use super::{SurfacePoint, representative_row, vertex_features};
use crate::data::RecordSet;
use crate::fitted::FittedRun;
use crate::{Error, Result};
use angles::Rusinkiewicz;
use brdf_analytic::SurfaceBrdf;
use brdf_neural::fitted::NeuralSurface;
use dataset_merl::MerlBrdf;
use dataset_merl::merl::format::TABLE_LEN;
use dataset_merl::merl::lookup::bin_lower_edges;
use std::path::Path;

/// What [`export_merl`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct MerlExport {
    /// The vertex the table was evaluated at.
    pub vertex: usize,
    /// Its position (normalised mesh coordinates).
    pub position: [f32; 3],
    /// Bins below the horizon, written as 0.
    pub below_horizon: usize,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Tabulates `brdf` at surface point `point` over every MERL bin; returns the table and the
/// number of below-horizon bins (written as 0).
pub fn tabulate_merl(
    brdf: &impl SurfaceBrdf,
    point: u32,
    progress: bool,
) -> Result<(MerlBrdf, usize)> {
    let mut values = vec![[0.0f64; 3]; TABLE_LEN];
    let (mut idx, mut ls, mut vs) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..TABLE_LEN {
        let (ih, id, ip) = (i / (90 * 180), (i / 180) % 90, i % 180);
        let (theta_h, theta_d, phi_d) = bin_lower_edges(ih, id, ip);
        let (l, v) = Rusinkiewicz { theta_h, theta_d, phi_d }.to_local();
        if l[2] > 0.0 && v[2] > 0.0 {
            idx.push(i);
            ls.push(l.map(|x| x as f32));
            vs.push(v.map(|x| x as f32));
        }
    }
    let below_horizon = TABLE_LEN - idx.len();
    let batch = brdf.preferred_batch().max(1);
    let bar = stdx::progress::bar(idx.len() as u64, "bins", "export", progress);
    let points = vec![point; batch];
    let mut out = vec![[0.0f32; 3]; batch];
    for start in (0..idx.len()).step_by(batch) {
        let end = (start + batch).min(idx.len());
        let n = end - start;
        brdf.eval_points(&points[..n], &ls[start..end], &vs[start..end], &mut out[..n]);
        for (k, f) in out[..n].iter().enumerate() {
            if f.iter().any(|x| !x.is_finite()) {
                let (l, v) = (ls[start + k], vs[start + k]);
                return Err(Error::config(
                    "model",
                    format!("non-finite BRDF {f:?} at l = {l:?}, v = {v:?}"),
                ));
            }
            values[idx[start + k]] = f.map(f64::from);
        }
        bar.inc(n as u64);
    }
    bar.finish_and_clear();
    Ok((MerlBrdf::from_bin_values(&values, "exported model")?, below_horizon))
}

/// Exports the finished run `run` as a MERL binary at `out` (written atomically).
pub fn export_merl(
    run: &Path,
    out: &Path,
    point: SurfacePoint,
    scene: Option<&Path>,
    cache: Option<&Path>,
    progress: bool,
) -> Result<MerlExport> {
    let start = std::time::Instant::now();
    let fitted = FittedRun::open(run, scene, cache)?;
    let (config, dataset) = (&fitted.config, &fitted.dataset);
    let (table, dim) = vertex_features(dataset, config, &fitted.cache)?;
    let n = dataset.mesh.positions.len();
    let vertex = match point {
        SurfacePoint::Vertex(v) if v < n => v,
        SurfacePoint::Vertex(v) => {
            return Err(Error::config(
                "vertex",
                format!("{v} is out of range: the mesh has {n} vertices"),
            ));
        }
        SurfacePoint::Representative => representative_row(&table, dim)
            .ok_or_else(|| Error::format(&dataset.dir, "the mesh has no vertices"))?,
    };
    let data = RecordSet {
        spatial: std::sync::Arc::new(table[vertex * dim..(vertex + 1) * dim].to_vec()),
        spatial_dim: dim,
        point: vec![0],
        ..Default::default()
    };
    let brdf = NeuralSurface::new(&fitted.model, &config.model, data.points(), &fitted.device)?;
    let (merl, below_horizon) = tabulate_merl(&brdf, 0, progress)?;
    merl.write(out).map_err(|e| Error::format(out, e.to_string()))?;
    Ok(MerlExport {
        vertex,
        position: dataset.mesh.positions[vertex].to_array(),
        below_horizon,
        seconds: start.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use brdf_analytic::{Brdf, Disney, DisneyParams, TorranceSparrow, TorranceSparrowParams};

    /// A "model" that wraps an analytic BRDF exports exactly that BRDF's MERL table (the
    /// f64 tabulation of the same BRDF), up to f32 evaluation.
    #[test]
    fn wrapped_analytic_brdfs_reproduce_their_tables() {
        let ts = TorranceSparrow::new(TorranceSparrowParams {
            roughness: 0.35,
            diffuse: [0.5, 0.2, 0.1],
            f0: [0.04, 0.5, 0.9],
        });
        let disney = Disney::new(DisneyParams::default());
        let check = |name: &str, ours: MerlBrdf, reference: MerlBrdf| {
            let (a, b) = (ours.raw(), reference.raw());
            let mut worst = 0.0f64;
            for (x, y) in a.iter().zip(b) {
                worst = worst.max((x - y).abs() / y.abs().max(1e-3));
            }
            assert!(worst < 1e-4, "{name}: worst relative difference {worst}");
        };
        let (ours, below) = tabulate_merl(&ts, 0, false).unwrap();
        let reference = MerlBrdf::tabulate("ts", |h, d, p| {
            let (l, v) = Rusinkiewicz { theta_h: h, theta_d: d, phi_d: p }.to_local();
            if l[2] > 0.0 && v[2] > 0.0 {
                let ts64 = TorranceSparrow::new(TorranceSparrowParams {
                    roughness: 0.35,
                    diffuse: [0.5, 0.2, 0.1],
                    f0: [0.04, 0.5, 0.9],
                });
                ts64.eval(l, v)
            } else {
                [0.0; 3]
            }
        })
        .unwrap();
        assert!(below > 0 && below < TABLE_LEN / 2, "{below}");
        check("Torrance-Sparrow", ours, reference);
        let (ours, _) = tabulate_merl(&disney, 0, false).unwrap();
        let reference = MerlBrdf::tabulate("disney", |h, d, p| {
            let (l, v) = Rusinkiewicz { theta_h: h, theta_d: d, phi_d: p }.to_local();
            if l[2] > 0.0 && v[2] > 0.0 {
                Disney::<f64>::new(DisneyParams::default()).eval(l, v)
            } else {
                [0.0; 3]
            }
        })
        .unwrap();
        check("Disney", ours, reference);
    }

    #[test]
    fn representative_row_is_the_closest_to_the_mean() {
        let t = [0.0f32, 0.0, 10.0, 10.0, 4.0, 6.0, 9.0, 0.0];
        assert_eq!(representative_row(&t, 2), Some(2));
        assert_eq!(representative_row(&[], 2), None);
        assert_eq!(representative_row(&t, 0), None);
    }
}
