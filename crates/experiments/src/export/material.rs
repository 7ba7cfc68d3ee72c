//! The parameters of a parametric fit (Disney or Torrance-Sparrow) at every mesh vertex: the
//! material every renderer export writes, and the analytic BRDF they stand for.
//!
//! The fit's MLP is evaluated at each vertex's spatial features; a renderer interpolates the
//! vertex values barycentrically over each triangle (vertex colours), where the fit evaluated
//! the MLP at the interpolated features. The two agree exactly for a spatially uniform fit
//! (`features.spatial = "uniform"`) and approximately otherwise ([`super::round_trip`]
//! measures by how much).
//!
//! Values are stored in a flat table, one row per vertex, columns as [`MaterialKind::columns`]
//! names them. Disney base colours are stored linear: a fit with `gamma_base_color` gets
//! c^2.2 here, which is what its BRDF uses.

use super::vertex_features;
use crate::fitted::FittedRun;
use crate::{Error, Result};
use brdf_analytic::{Brdf, Disney, DisneyParams, TorranceSparrow, TorranceSparrowParams};
use brdf_neural::{BrdfBatch, BrdfModel, BrdfParams, Samples};
use burn::tensor::Tensor;

/// Which analytic model a material's rows parametrise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialKind {
    /// Isotropic Disney (Burley 2012).
    Disney,
    /// Torrance-Sparrow with GGX (alpha = r^2), Lambertian diffuse and Schlick F0.
    TorranceSparrow,
}

/// Disney columns, in row order.
const DISNEY_COLUMNS: [&str; 12] = [
    "base_color_r",
    "base_color_g",
    "base_color_b",
    "metallic",
    "subsurface",
    "specular",
    "roughness",
    "specular_tint",
    "sheen",
    "sheen_tint",
    "clearcoat",
    "clearcoat_gloss",
];

/// Torrance-Sparrow columns, in row order.
const TS_COLUMNS: [&str; 7] =
    ["roughness", "diffuse_r", "diffuse_g", "diffuse_b", "f0_r", "f0_g", "f0_b"];

impl MaterialKind {
    /// Column names of a row.
    pub fn columns(self) -> &'static [&'static str] {
        match self {
            MaterialKind::Disney => &DISNEY_COLUMNS,
            MaterialKind::TorranceSparrow => &TS_COLUMNS,
        }
    }

    /// Row width.
    pub fn width(self) -> usize {
        self.columns().len()
    }
}

/// Per-vertex material parameters, see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportedMaterial {
    /// The model.
    pub kind: MaterialKind,
    /// `[vertices, kind.width()]`.
    pub values: Vec<f32>,
}

/// One point's analytic BRDF.
#[derive(Clone, Copy, Debug)]
pub enum PointBrdf {
    /// Disney.
    Disney(Disney<f32>),
    /// Torrance-Sparrow.
    TorranceSparrow(TorranceSparrow<f32>),
}

impl PointBrdf {
    /// f_r(l, v) in the local frame.
    pub fn eval(&self, l: [f32; 3], v: [f32; 3]) -> [f32; 3] {
        match self {
            PointBrdf::Disney(b) => b.eval(l, v),
            PointBrdf::TorranceSparrow(b) => b.eval(l, v),
        }
    }
}

/// Column `name` of a row of `kind`.
pub fn column(kind: MaterialKind, row: &[f32], name: &str) -> f32 {
    let i = kind.columns().iter().position(|c| *c == name).expect("known column");
    row[i]
}

impl ExportedMaterial {
    /// Evaluates a finished parametric run at every vertex of its mesh.
    ///
    /// # Errors
    /// [`Error::Run`] (a configuration error) for a model that is not Disney or Torrance-Sparrow (their parameters
    /// have no renderer counterpart: use `export-merl`), or a non-finite parameter.
    pub fn from_run(fitted: &FittedRun) -> Result<Self> {
        let BrdfModel::Parametric(model) = &fitted.model else {
            return Err(Error::config(
                "model.kind",
                format!(
                    "{:?} is a neural model: renderer materials exist for the Disney and \
                     Torrance-Sparrow fits only; use `experiments export-merl` for a table",
                    fitted.config.model.kind
                ),
            ));
        };
        let (table, dim) = vertex_features(&fitted.dataset, &fitted.config, &fitted.cache)?;
        let n = fitted.dataset.mesh.positions.len();
        let mut values = Vec::new();
        let mut kind = None;
        const CHUNK: usize = 1 << 15;
        for start in (0..n).step_by(CHUNK) {
            let end = (start + CHUNK).min(n);
            let dirs = vec![[0.0, 0.0, 1.0f32]; end - start];
            let samples = Samples { spatial: &table[start * dim..end * dim], l: &dirs, v: &dirs };
            let batch = BrdfBatch::new(&fitted.config.model, &samples, None, &fitted.device)
                .map_err(|e| Error::config("model", e.to_string()))?;
            let (k, cols) = match model.params(batch.spatial) {
                BrdfParams::Disney(p) => {
                    let base = if p.gamma_base_color {
                        p.base_color.powf_scalar(2.2)
                    } else {
                        p.base_color
                    };
                    let cols = vec![
                        base,
                        p.metallic,
                        p.subsurface,
                        p.specular,
                        p.roughness,
                        p.specular_tint,
                        p.sheen,
                        p.sheen_tint,
                        p.clearcoat,
                        p.clearcoat_gloss,
                    ];
                    (MaterialKind::Disney, cols)
                }
                BrdfParams::TorranceSparrow(p) => {
                    (MaterialKind::TorranceSparrow, vec![p.roughness, p.diffuse, p.f0])
                }
                _ => {
                    return Err(Error::config(
                        "model.kind",
                        format!(
                            "{:?}: renderer materials exist for the Disney and Torrance-Sparrow \
                             fits only (Realistic Phong and FMBRDF have no counterpart in glTF, \
                             Mitsuba or pbrt); use `experiments export-merl` for a table",
                            fitted.config.model.kind
                        ),
                    ));
                }
            };
            kind = Some(k);
            let rows: Vec<f32> = Tensor::cat(cols, 1)
                .into_data()
                .try_to_vec::<f32>()
                .map_err(|e| Error::config("model", format!("parameters are not f32: {e:?}")))?;
            values.extend(rows);
        }
        let kind =
            kind.ok_or_else(|| Error::format(&fitted.dataset.dir, "mesh has no vertices"))?;
        let m = ExportedMaterial { kind, values };
        m.check()?;
        Ok(m)
    }

    /// A material from rows; checks the width and that every value is finite and in range.
    pub fn new(kind: MaterialKind, values: Vec<f32>) -> Result<Self> {
        let m = ExportedMaterial { kind, values };
        m.check()?;
        Ok(m)
    }

    fn check(&self) -> Result<()> {
        let w = self.kind.width();
        if self.values.is_empty() || !self.values.len().is_multiple_of(w) {
            return Err(Error::config(
                "material",
                format!("{} values do not make rows of {w}", self.values.len()),
            ));
        }
        if let Some(i) = self.values.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
            return Err(Error::config(
                "material",
                format!(
                    "vertex {} {} = {} (not finite or negative)",
                    i / w,
                    self.kind.columns()[i % w],
                    self.values[i]
                ),
            ));
        }
        Ok(())
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.values.len() / self.kind.width()
    }

    /// Whether there are no vertices (never, for a checked material).
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> &[f32] {
        let w = self.kind.width();
        &self.values[i * w..(i + 1) * w]
    }

    /// Whether every row equals the first (bit for bit): a spatially uniform fit.
    pub fn is_uniform(&self) -> bool {
        let first = self.row(0);
        self.values.chunks_exact(self.kind.width()).all(|r| r == first)
    }

    /// The mean row (f64 sums).
    pub fn mean(&self) -> Vec<f32> {
        let w = self.kind.width();
        let mut m = vec![0.0f64; w];
        for r in self.values.chunks_exact(w) {
            for (a, &x) in m.iter_mut().zip(r) {
                *a += x as f64;
            }
        }
        m.iter().map(|a| (a / self.len() as f64) as f32).collect()
    }

    /// The object's one row when uniform, else the mean row: what a format without per-vertex
    /// values gets.
    pub fn uniform_or_mean(&self) -> Vec<f32> {
        if self.is_uniform() { self.row(0).to_vec() } else { self.mean() }
    }

    /// The values of column `name`, one per vertex.
    pub fn column(&self, name: &str) -> Vec<f32> {
        let i = self.kind.columns().iter().position(|c| *c == name).expect("known column");
        self.values.chunks_exact(self.kind.width()).map(|r| r[i]).collect()
    }

    /// The row a renderer sees at barycentric `(b1, b2)` of triangle `tri` (vertex values
    /// interpolated with weights `(1 - b1 - b2, b1, b2)`).
    pub fn interpolate(&self, tri: [u32; 3], [b1, b2]: [f32; 2]) -> Vec<f32> {
        let b = [1.0 - b1 - b2, b1, b2];
        let mut out = vec![0.0f32; self.kind.width()];
        for (k, &v) in tri.iter().enumerate() {
            for (o, &x) in out.iter_mut().zip(self.row(v as usize)) {
                *o += b[k] * x;
            }
        }
        out
    }

    /// The analytic BRDF of a row.
    pub fn brdf(kind: MaterialKind, row: &[f32]) -> PointBrdf {
        match kind {
            MaterialKind::Disney => PointBrdf::Disney(Disney::new(DisneyParams {
                base_color: [row[0], row[1], row[2]],
                metallic: row[3],
                subsurface: row[4],
                specular: row[5],
                roughness: row[6],
                specular_tint: row[7],
                sheen: row[8],
                sheen_tint: row[9],
                clearcoat: row[10],
                clearcoat_gloss: row[11],
                gamma_base_color: false,
            })),
            MaterialKind::TorranceSparrow => {
                PointBrdf::TorranceSparrow(TorranceSparrow::new(TorranceSparrowParams {
                    roughness: row[0],
                    diffuse: [row[1], row[2], row[3]],
                    f0: [row[4], row[5], row[6]],
                }))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_checked_and_interpolated() {
        let ts = |r: f32| vec![r, 0.5, 0.4, 0.3, 0.04, 0.05, 0.06];
        let m = ExportedMaterial::new(
            MaterialKind::TorranceSparrow,
            [ts(0.2), ts(0.4), ts(0.6)].concat(),
        )
        .unwrap();
        assert_eq!(m.len(), 3);
        assert!(!m.is_uniform());
        let p = m.interpolate([0, 1, 2], [0.25, 0.5]);
        assert!((p[0] - (0.25 * 0.2 + 0.25 * 0.4 + 0.5 * 0.6)).abs() < 1e-6);
        assert!((m.mean()[0] - 0.4).abs() < 1e-6);
        assert_eq!(m.column("f0_b"), vec![0.06; 3]);
        let e = ExportedMaterial::new(MaterialKind::TorranceSparrow, vec![0.1; 6]).unwrap_err();
        assert!(e.to_string().contains("rows of 7"), "{e}");
        let mut bad = ts(0.2);
        bad[4] = f32::NAN;
        let e = ExportedMaterial::new(MaterialKind::TorranceSparrow, bad).unwrap_err();
        assert!(e.to_string().contains("vertex 0 f0_r"), "{e}");
    }
}
