//! Evaluating a fitted model on CPU records: the BRDF and, for additive models, its parts; and
//! the model as a [`metrics::BatchBrdf`] for the BRDF-space analyses (energy, reciprocity).

use crate::data::TrainingData;
use crate::{Error, Result};
use brdf_neural::{BrdfModel, ModelConfig, Samples};
use burn::tensor::{Device, Tensor};

/// Rows per forward pass.
pub const CHUNK: usize = 1 << 15;

/// A model's outputs on a set of records.
#[derive(Clone, Debug, Default)]
pub struct Prediction {
    /// f_r, linear RGB, 1/sr.
    pub f: Vec<[f32; 3]>,
    /// Additive models: the diffuse part as it enters f ((1 - xi) f_d for the enhanced ones).
    pub diffuse: Option<Vec<[f32; 3]>>,
    /// Additive models: the raw diffuse f_d (albedo / pi), before the enhanced models' 1 - xi.
    pub diffuse_raw: Option<Vec<[f32; 3]>>,
    /// Additive models: the specular part f_s.
    pub specular: Option<Vec<[f32; 3]>>,
}

fn rows(t: Tensor<2>, what: &str) -> Result<Vec<[f32; 3]>> {
    let v: Vec<f32> = t
        .into_data()
        .try_to_vec::<f32>()
        .map_err(|e| Error::config("model", format!("{what} output is not f32: {e:?}")))?;
    Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

/// Evaluates `model` at the given spatial rows (`[n, k]`) and local directions.
pub fn forward_rows(
    model: &BrdfModel,
    config: &ModelConfig,
    samples: &Samples,
    device: &Device,
    parts: bool,
) -> Result<Prediction> {
    let batch = config.batch(samples, None, device)?;
    let out = model.forward(&batch);
    let mut p = Prediction { f: rows(out.f, "f")?, ..Default::default() };
    if parts && let (Some(d), Some(s)) = (out.diffuse, out.specular) {
        let effective = match out.xi {
            Some(xi) => xi.neg().add_scalar(1.0) * d.clone(),
            None => d.clone(),
        };
        p.diffuse = Some(rows(effective, "diffuse")?);
        p.diffuse_raw = Some(rows(d, "diffuse")?);
        p.specular = Some(rows(s, "specular")?);
    }
    Ok(p)
}

/// Evaluates `model` on every record of `data` (with the additive parts when `parts`).
pub fn predict(
    model: &BrdfModel,
    config: &ModelConfig,
    data: &TrainingData,
    device: &Device,
    parts: bool,
) -> Result<Prediction> {
    let mut all = Prediction::default();
    for start in (0..data.len()).step_by(CHUNK) {
        let end = (start + CHUNK).min(data.len());
        let samples = Samples {
            spatial: &data.spatial_rows(start..end),
            l: &data.l[start..end],
            v: &data.v[start..end],
        };
        let p = forward_rows(model, config, &samples, device, parts)?;
        all.f.extend(p.f);
        for (dst, src) in [
            (&mut all.diffuse, p.diffuse),
            (&mut all.diffuse_raw, p.diffuse_raw),
            (&mut all.specular, p.specular),
        ] {
            if let Some(src) = src {
                dst.get_or_insert_with(Vec::new).extend(src);
            }
        }
    }
    Ok(all)
}

/// A fitted model as a [`metrics::BatchBrdf`]: point `i` is record `i` of `data` (its spatial
/// features); directions are the analyses' local-frame ones. Evaluation errors (which cannot
/// happen for a model that loaded) surface as NaN, which the analyses reject.
pub struct ModelBrdf<'a> {
    /// The model.
    pub model: &'a BrdfModel,
    /// Its configuration (feature construction).
    pub config: &'a ModelConfig,
    /// The records whose spatial features the points index.
    pub data: &'a TrainingData,
    /// Device of the model.
    pub device: &'a Device,
}

impl metrics::BatchBrdf for ModelBrdf<'_> {
    fn eval_batch(&self, points: &[u32], l: &[[f32; 3]], v: &[[f32; 3]], out: &mut [[f32; 3]]) {
        let k = self.data.spatial_dim;
        let mut spatial = Vec::with_capacity(points.len() * k);
        for &p in points {
            spatial.extend_from_slice(self.data.spatial_row(p as usize));
        }
        let samples = Samples { spatial: &spatial, l, v };
        match forward_rows(self.model, self.config, &samples, self.device, false) {
            Ok(p) => out.copy_from_slice(&p.f),
            Err(_) => out.fill([f32::NAN; 3]),
        }
    }

    fn preferred_batch(&self) -> usize {
        CHUNK
    }

    /// The backend parallelises each forward pass itself.
    fn parallel(&self) -> bool {
        false
    }
}
