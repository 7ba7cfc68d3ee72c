//! Training records on the CPU: spatial features, local-frame directions, the rendering
//! weight E cos(theta_l) and the gamma-encoded observation of every lit sample, and the
//! gathering of a batch from random indices.
//!
//! Only lit samples reach this point ([`dataset_merl::SceneDataset::samples`] leaves out
//! shadowed and back-facing ones: they carry no information about the BRDF); samples whose
//! cosine is not positive are dropped here as well.

use crate::config::{FeatureConfig, SpatialKind};
use crate::loss::srgb_oetf;
use crate::{Error, Result};
use angles::Frame;
use dataset_merl::{SampleSet, SceneDataset};
use mesh_encoding::{EigenSettings, LboEncoding, cached_eigenpairs};
use std::path::Path;

/// Samples ready for batching, struct of arrays.
#[derive(Clone, Debug, Default)]
pub struct TrainingData {
    /// Spatial features, row-major `[n, spatial_dim]`.
    pub spatial: Vec<f32>,
    /// Width of a spatial row.
    pub spatial_dim: usize,
    /// Direction to the light, local frame (normal on +z).
    pub l: Vec<[f32; 3]>,
    /// Direction to the viewer, local frame.
    pub v: Vec<[f32; 3]>,
    /// E cos(theta_l), RGB: the rendering is L = f * weight.
    pub weight: Vec<[f32; 3]>,
    /// Observed radiance, linear RGB.
    pub observed: Vec<[f32; 3]>,
    /// sRGB OETF of the observation (negatives clamped to 0, no clamp above 1).
    pub observed_gamma: Vec<[f32; 3]>,
    /// Index of each record in the source [`SampleSet`].
    pub source: Vec<usize>,
}

/// A gathered batch on the CPU.
#[derive(Clone, Debug, Default)]
pub struct CpuBatch {
    /// `[batch, spatial_dim]`.
    pub spatial: Vec<f32>,
    /// Local light directions.
    pub l: Vec<[f32; 3]>,
    /// Local view directions.
    pub v: Vec<[f32; 3]>,
    /// `[batch, 3]` flattened.
    pub weight: Vec<f32>,
    /// `[batch, 3]` flattened, gamma-encoded observation.
    pub target_gamma: Vec<f32>,
}

impl TrainingData {
    /// Number of records.
    pub fn len(&self) -> usize {
        self.l.len()
    }

    /// Whether there is no record.
    pub fn is_empty(&self) -> bool {
        self.l.is_empty()
    }

    /// Builds the records from `samples` with per-sample spatial features `spatial`
    /// (`[samples.len(), spatial_dim]`).
    pub fn new(samples: &SampleSet, spatial: &[f32], spatial_dim: usize) -> Self {
        let mut d = TrainingData { spatial_dim, ..Default::default() };
        for i in 0..samples.len() {
            let n = samples.normal[i];
            let (lw, vw) = (samples.l[i], samples.v[i]);
            let cos = n[0] * lw[0] + n[1] * lw[1] + n[2] * lw[2];
            if cos.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let frame = Frame::from_normal(n);
            d.l.push(frame.to_local(lw));
            d.v.push(frame.to_local(vw));
            let e = samples.irradiance[i];
            d.weight.push([e[0] * cos, e[1] * cos, e[2] * cos]);
            let o = samples.observed[i];
            d.observed.push(o);
            d.observed_gamma.push(o.map(srgb_oetf));
            d.spatial.extend_from_slice(&spatial[i * spatial_dim..(i + 1) * spatial_dim]);
            d.source.push(i);
        }
        d
    }

    /// The gamma-MSE of predicting f = 0 everywhere: mean of gamma(L_obs)^2.
    pub fn zero_prediction_loss(&self) -> f32 {
        let sum: f64 =
            self.observed_gamma.iter().flatten().map(|&g| g as f64 * g as f64).sum::<f64>();
        (sum / (3 * self.len().max(1)) as f64) as f32
    }

    /// Gathers the records at `indices`.
    pub fn gather(&self, indices: &[usize]) -> CpuBatch {
        let k = self.spatial_dim;
        let mut b = CpuBatch {
            spatial: Vec::with_capacity(indices.len() * k),
            l: Vec::with_capacity(indices.len()),
            v: Vec::with_capacity(indices.len()),
            weight: Vec::with_capacity(indices.len() * 3),
            target_gamma: Vec::with_capacity(indices.len() * 3),
        };
        for &i in indices {
            b.spatial.extend_from_slice(&self.spatial[i * k..(i + 1) * k]);
            b.l.push(self.l[i]);
            b.v.push(self.v[i]);
            b.weight.extend_from_slice(&self.weight[i]);
            b.target_gamma.extend_from_slice(&self.observed_gamma[i]);
        }
        b
    }
}

/// Spatial features of every sample of `samples`, `[n, dim]` row-major, and `dim`.
///
/// `lbo`: the mesh's LBO encoding (eigenpairs from `cache_dir`, computed and cached on a
/// miss) interpolated at each hit; `position`: the hit's xyz.
pub fn spatial_features(
    scene: &SceneDataset,
    samples: &SampleSet,
    features: &FeatureConfig,
    cache_dir: &Path,
) -> Result<(Vec<f32>, usize)> {
    match features.spatial {
        SpatialKind::Position => {
            Ok((samples.position.iter().flat_map(|p| p.iter().copied()).collect(), 3))
        }
        SpatialKind::Lbo => {
            let (table, dim) = lbo_table(scene, features, cache_dir)?;
            let mut out = vec![0.0; samples.len() * dim];
            let tris = &scene.mesh.triangles;
            for (i, row) in out.chunks_mut(dim).enumerate() {
                let t = samples.triangle[i] as usize;
                let [b1, b2] = samples.barycentric[i];
                let tri = *tris.get(t).ok_or_else(|| {
                    Error::format(&scene.dir, format!("sample {i} names triangle {t}"))
                })?;
                let b = [1.0 - b1 - b2, b1, b2];
                for (k, &v) in tri.iter().enumerate() {
                    let src = &table[v as usize * dim..(v as usize + 1) * dim];
                    for (o, s) in row.iter_mut().zip(src) {
                        *o += b[k] * s;
                    }
                }
            }
            Ok((out, dim))
        }
    }
}

/// The per-vertex LBO feature table `[vertices, dim]` of the scene's mesh, from
/// `<cache_dir>/lbo-table-<mesh and solver key>-<selection>.f32` or computed (then cached).
pub fn lbo_table(
    scene: &SceneDataset,
    features: &FeatureConfig,
    cache_dir: &Path,
) -> Result<(Vec<f32>, usize)> {
    let sel = &features.lbo;
    let config = sel.encoding()?;
    let vertices: Vec<[f64; 3]> =
        scene.mesh.positions.iter().map(|p| [p.x as f64, p.y as f64, p.z as f64]).collect();
    let key = mesh_encoding::lbo::cache_key(
        &vertices,
        &scene.mesh.triangles,
        config.required_pairs(),
        &eigen_settings(features),
    );
    let path = cache_dir.join(format!(
        "lbo-table-{key:032x}-{}-{}-{}-{}.f32",
        sel.first, sel.blocks, sel.block_len, sel.k_max
    ));
    let dim = sel.dim();
    if let Ok(bytes) = std::fs::read(&path)
        && bytes.len() == vertices.len() * dim * 4
    {
        let table = bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]));
        return Ok((table.collect(), dim));
    }
    let encoding = lbo_encoding(scene, features, cache_dir)?;
    let table = encoding.as_slice().to_vec();
    let bytes: Vec<u8> = table.iter().flat_map(|v| v.to_le_bytes()).collect();
    crate::run_dir::write_atomic(&path, &bytes)?;
    Ok((table, encoding.dim()))
}

fn eigen_settings(features: &FeatureConfig) -> EigenSettings {
    EigenSettings { max_basis_factor: features.lbo.max_basis_factor, ..EigenSettings::default() }
}

/// The LBO encoding of the scene's mesh with the configured selection, eigenpairs from the
/// content-keyed cache (mesh-encoding picks the dense solver itself for small meshes).
pub fn lbo_encoding(
    scene: &SceneDataset,
    features: &FeatureConfig,
    cache_dir: &Path,
) -> Result<LboEncoding> {
    let config = features.lbo.encoding()?;
    let vertices: Vec<[f64; 3]> =
        scene.mesh.positions.iter().map(|p| [p.x as f64, p.y as f64, p.z as f64]).collect();
    std::fs::create_dir_all(cache_dir).map_err(|e| Error::io(cache_dir, e))?;
    let k = config.required_pairs();
    let settings = eigen_settings(features);
    let (pairs, _) = cached_eigenpairs(&vertices, &scene.mesh.triangles, k, &settings, cache_dir)?;
    Ok(LboEncoding::new(&pairs, &config)?)
}
