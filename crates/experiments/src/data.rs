//! Training records on the CPU: spatial features, local-frame directions, the rendering
//! weight E cos(theta_l) and the gamma-encoded observation of every lit sample, and the
//! gathering of a batch from random indices.
//!
//! Only lit samples reach this point ([`scene::SceneDataset::samples`] leaves out
//! shadowed and back-facing ones: they carry no information about the BRDF); samples whose
//! cosine is not positive are dropped here as well.

use crate::loss::srgb_oetf;
use crate::{Error, Result};
use angles::Frame;
use mesh_encoding::lbo::block_selection;
use mesh_encoding::{EigenSettings, LboEncoding, LboEncodingConfig, cached_eigenpairs};
use rand::SeedableRng;
use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use run_format::config::{FeatureConfig, RunConfig, SpatialKind};
use scene::Split;
use scene::shading::light_weight;
use scene::{SampleSet, SceneDataset};
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

/// The lit records of one split (training, validation or test), struct of arrays: what a
/// fit batches from and what evaluation scores.
#[derive(Clone, Debug, Default)]
pub struct RecordSet {
    /// Spatial features of the distinct surface points, row-major `[points, spatial_dim]`,
    /// shared between the training and validation records (a pixel's records under all its
    /// lights are one point: 42x less memory than a row per record, which at 512 px would not
    /// fit in memory).
    pub spatial: Arc<Vec<f32>>,
    /// Width of a spatial row.
    pub spatial_dim: usize,
    /// The point (row of `spatial`) of each record.
    pub point: Vec<u32>,
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
    /// The sensor's clip level of the scene (semi-synthetic scenes; see
    /// [`crate::data::clip_level`]): renders are compared after clipping there.
    pub clip: Option<f32>,
}

/// Records a thread gathers at a time.
const GATHER_ROWS: usize = 512;

/// How many records ahead a gather asks for the rows it will read ([`stdx::prefetch`]).
const PREFETCH_AHEAD: usize = 8;

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

impl RecordSet {
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
    pub fn new(samples: &SampleSet, spatial: &SpatialFeatures) -> Self {
        Self::from_indices(samples, spatial, 0..samples.len())
    }

    /// Builds the records of the samples at `indices` (into `samples` and the rows of
    /// `spatial`), in that order.
    pub fn from_indices(
        samples: &SampleSet,
        spatial: &SpatialFeatures,
        indices: impl IntoIterator<Item = usize>,
    ) -> Self {
        let mut d = RecordSet {
            spatial: spatial.table.clone(),
            spatial_dim: spatial.dim,
            ..Default::default()
        };
        for i in indices {
            let n = samples.normal[i];
            let (lw, vw) = (samples.l[i], samples.v[i]);
            // The generator's own weight (bit for bit), so that the ground truth renders the
            // scene's noise-free images exactly.
            let Some(weight) = light_weight(samples.irradiance[i], n, lw) else { continue };
            let frame = Frame::from_normal(n);
            d.l.push(frame.to_local(lw));
            d.v.push(frame.to_local(vw));
            d.weight.push(weight);
            let o = samples.observed[i];
            d.observed.push(o);
            d.observed_gamma.push(o.map(srgb_oetf));
            d.point.push(spatial.point[i]);
            d.source.push(i);
        }
        d
    }

    /// The spatial features of record `i`.
    pub fn spatial_row(&self, i: usize) -> &[f32] {
        self.points().row(i)
    }

    /// The spatial rows of `records`, row-major (the input of a batch).
    pub fn spatial_rows(&self, records: std::ops::Range<usize>) -> Vec<f32> {
        self.points().rows(records)
    }

    /// The records' points and the points' spatial rows, as a model evaluates them.
    pub fn points(&self) -> brdf_neural::fitted::PointRows<'_> {
        brdf_neural::fitted::PointRows {
            spatial: &self.spatial,
            dim: self.spatial_dim,
            point: &self.point,
        }
    }

    /// The records (points and directions), as a model evaluates them.
    pub fn records(&self) -> brdf_neural::fitted::Records<'_> {
        brdf_neural::fitted::Records { points: self.points(), l: &self.l, v: &self.v }
    }

    /// The least-squares constant BRDF of the records, per channel: the f minimising
    /// sum (f E cos - L_obs)^2, i.e. sum(L_obs E cos) / sum((E cos)^2), clamped to >= 0
    /// (zero without records). What `output_init = "data"` starts the models at.
    pub fn mean_brdf(&self) -> [f32; 3] {
        let mut num = [0.0_f64; 3];
        let mut den = [0.0_f64; 3];
        for (o, w) in self.observed.iter().zip(&self.weight) {
            for c in 0..3 {
                num[c] += o[c] as f64 * w[c] as f64;
                den[c] += w[c] as f64 * w[c] as f64;
            }
        }
        std::array::from_fn(|c| if den[c] > 0.0 { (num[c] / den[c]).max(0.0) as f32 } else { 0.0 })
    }

    /// The gamma-MSE of predicting f = 0 everywhere: mean of gamma(L_obs)^2.
    pub fn zero_prediction_loss(&self) -> f32 {
        let sum: f64 =
            self.observed_gamma.iter().flatten().map(|&g| g as f64 * g as f64).sum::<f64>();
        (sum / (3 * self.len().max(1)) as f64) as f32
    }

    /// Gathers the records at `indices`.
    pub fn gather(&self, indices: &[usize]) -> CpuBatch {
        use rayon::prelude::*;
        let (n, k) = (indices.len(), self.spatial_dim);
        // Random reads: chunks of records on every thread, first the spatial rows (most of the
        // bytes), then the per-record fields (the same values on any thread count). The rows
        // are written into the vector's spare capacity: zeroing it first would be one more pass
        // over the batch's largest buffer.
        let mut spatial: Vec<f32> = Vec::with_capacity(n * k);
        if k > 0 {
            let rows = &mut spatial.spare_capacity_mut()[..n * k];
            rows.par_chunks_mut(GATHER_ROWS * k).zip(indices.par_chunks(GATHER_ROWS)).for_each(
                |(dst, idx)| {
                    for (r, (d, &i)) in dst.chunks_exact_mut(k).zip(idx).enumerate() {
                        // Rows are random, so each one waits on memory: ask for a later row
                        // (and, before it, its point) while this one is copied.
                        if let Some(&far) = idx.get(r + 2 * PREFETCH_AHEAD) {
                            stdx::prefetch::read(&self.point[far]);
                        }
                        if let Some(&near) = idx.get(r + PREFETCH_AHEAD) {
                            stdx::prefetch::slice(self.spatial_row(near));
                        }
                        for (o, &x) in d.iter_mut().zip(self.spatial_row(i)) {
                            o.write(x);
                        }
                    }
                },
            );
        }
        // SAFETY: the loop above wrote all n * k values: n rows (one per index, the chunks of
        // `indices` and of the rows in step) of k values each (`spatial_row` is k long).
        unsafe { spatial.set_len(n * k) };
        CpuBatch { spatial, ..self.gather_fields(indices) }
    }

    /// The points (rows of [`RecordSet::spatial`]) of the records at `indices`: with
    /// [`RecordSet::gather_fields`], a batch whose spatial rows are selected elsewhere (on
    /// the device, from a `brdf_neural::SpatialTable`).
    pub fn points_of(&self, indices: &[usize]) -> Vec<u32> {
        indices.iter().map(|&i| self.point[i]).collect()
    }

    /// [`RecordSet::gather`] without the spatial rows (`spatial` left empty).
    pub fn gather_fields(&self, indices: &[usize]) -> CpuBatch {
        use rayon::prelude::*;
        const ROWS: usize = GATHER_ROWS;
        let n = indices.len();
        let mut b = CpuBatch {
            spatial: Vec::new(),
            l: vec![[0.0; 3]; n],
            v: vec![[0.0; 3]; n],
            weight: vec![0.0; n * 3],
            target_gamma: vec![0.0; n * 3],
        };
        (
            b.l.par_chunks_mut(ROWS),
            b.v.par_chunks_mut(ROWS),
            b.weight.par_chunks_mut(3 * ROWS),
            b.target_gamma.par_chunks_mut(3 * ROWS),
            indices.par_chunks(ROWS),
        )
            .into_par_iter()
            .for_each(|(l, v, w, t, idx)| {
                for (r, &i) in idx.iter().enumerate() {
                    if let Some(&ahead) = idx.get(r + PREFETCH_AHEAD) {
                        stdx::prefetch::read(&self.l[ahead]);
                        stdx::prefetch::read(&self.v[ahead]);
                        stdx::prefetch::read(&self.weight[ahead]);
                        stdx::prefetch::read(&self.observed_gamma[ahead]);
                    }
                    (l[r], v[r]) = (self.l[i], self.v[i]);
                    w[3 * r..3 * r + 3].copy_from_slice(&self.weight[i]);
                    t[3 * r..3 * r + 3].copy_from_slice(&self.observed_gamma[i]);
                }
            });
        b
    }
}

/// The (view, light) pairs held out for validation: in every view, `fraction` of its training
/// lights (at least one when the view has two or more), evenly spaced through the view's
/// training lights in manifest order, the last one included. Test lights are never chosen.
pub fn validation_pairs(scene: &SceneDataset, fraction: f64) -> HashSet<(u16, u16)> {
    let mut out = HashSet::new();
    if fraction <= 0.0 {
        return out;
    }
    for (vi, view) in scene.manifest.views.iter().enumerate() {
        if view.split != Split::Train {
            continue;
        }
        let train: Vec<usize> =
            (0..view.lights.len()).filter(|&li| view.lights[li].split == Split::Train).collect();
        let m = train.len();
        if m < 2 {
            continue;
        }
        let k = ((m as f64 * fraction).round() as usize).clamp(1, m - 1);
        for i in 0..k {
            out.insert((vi as u16, train[(i + 1) * m / k - 1] as u16));
        }
    }
    out
}

/// Splits the training samples into training and validation indices: the samples of the
/// validation pairs ([`validation_pairs`]) go to validation, of which at most `cap` are kept
/// (a subset drawn with `seed`), in sample order.
pub fn split_validation(
    samples: &SampleSet,
    pairs: &HashSet<(u16, u16)>,
    cap: usize,
    seed: u64,
) -> (Vec<usize>, Vec<usize>) {
    let (mut train, mut val) = (Vec::new(), Vec::new());
    for i in 0..samples.len() {
        if pairs.contains(&(samples.view[i], samples.light[i])) {
            val.push(i);
        } else {
            train.push(i);
        }
    }
    if val.len() > cap {
        let mut rng = StdRng::seed_from_u64(seed ^ 0x7A11_DA7E_5EED_0001);
        val.shuffle(&mut rng);
        val.truncate(cap);
        val.sort_unstable();
    }
    (train, val)
}

/// The spatial features of a sample set: one row per distinct surface point and each sample's
/// point. Samples with the same inputs to the features (triangle and barycentrics for LBO,
/// position for positional features), i.e. one pixel under every light, share a row, so the
/// values are exactly those a row per sample would hold.
#[derive(Clone, Debug, Default)]
pub struct SpatialFeatures {
    /// Row-major `[points, dim]`.
    pub table: Arc<Vec<f32>>,
    /// Row width.
    pub dim: usize,
    /// The row of each sample.
    pub point: Vec<u32>,
}

/// Spatial features of `samples` under `features` ([`SpatialFeatures`]): LBO eigenfunctions
/// interpolated barycentrically from the mesh's vertex table, or the positions. A solve the
/// cache does not spare may take `lbo_memory` bytes ([`lbo_table`]).
pub fn spatial_features(
    scene: &SceneDataset,
    samples: &SampleSet,
    features: &FeatureConfig,
    (cache_dir, lbo_memory): (&Path, Option<u64>),
) -> Result<SpatialFeatures> {
    // Distinct points by the exact bits of what the features are computed from.
    let key = |i: usize| -> [u32; 3] {
        match features.spatial {
            SpatialKind::Position => samples.position[i].map(f32::to_bits),
            SpatialKind::Uniform => [0; 3],
            SpatialKind::Lbo => {
                let [b1, b2] = samples.barycentric[i];
                [samples.triangle[i], b1.to_bits(), b2.to_bits()]
            }
        }
    };
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut first = Vec::new();
    let mut point = Vec::with_capacity(samples.len());
    for i in 0..samples.len() {
        let next = first.len() as u32;
        let p = *index.entry(key(i)).or_insert_with(|| {
            first.push(i);
            next
        });
        point.push(p);
    }
    let (table, dim) = match features.spatial {
        SpatialKind::Position => {
            (first.iter().flat_map(|&i| samples.position[i].iter().copied()).collect(), 3)
        }
        SpatialKind::Uniform => (vec![1.0; first.len()], 1),
        SpatialKind::Lbo => {
            let (table, dim) = lbo_table(scene, features, cache_dir, lbo_memory)?;
            let mut out = vec![0.0; first.len() * dim];
            let tris = &scene.mesh.triangles;
            for (row, &i) in out.chunks_mut(dim).zip(&first) {
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
            (out, dim)
        }
    };
    Ok(SpatialFeatures { table: Arc::new(table), dim, point })
}

/// The clip level renders get: the saturation of semi-synthetic scenes, none for captures
/// (whose observations are raw values divided by a per-light intensity).
pub fn clip_level(dataset: &SceneDataset) -> Option<f32> {
    use scene::MaterialSpec;
    let c = &dataset.manifest.config;
    (!matches!(c.material, MaterialSpec::Captured { .. })).then_some(c.settings.saturation)
}

/// The per-vertex spatial features `[vertices, dim]` of a scene's mesh under `config`.
pub fn vertex_features(
    scene: &SceneDataset,
    config: &RunConfig,
    cache: &Path,
) -> Result<(Vec<f32>, usize)> {
    match config.features.spatial {
        // Training or the sweep's feature stage solved it (with their budget) and cached it.
        SpatialKind::Lbo => lbo_table(scene, &config.features, cache, None),
        SpatialKind::Position => {
            Ok((scene.mesh.positions.iter().flat_map(|p| p.to_array()).collect(), 3))
        }
        SpatialKind::Uniform => Ok((vec![1.0; scene.mesh.positions.len()], 1)),
    }
}

/// The per-vertex LBO feature table `[vertices, dim]` of the scene's mesh, from
/// `<cache_dir>/lbo-table-<mesh and solver key>-<selection>.bin` (the workspace's checked cache
/// container) or computed (then cached), the solve's factor within `lbo_memory` bytes (`None`:
/// mesh-encoding's default budget, [`EigenSettings::memory_budget`]).
pub fn lbo_table(
    scene: &SceneDataset,
    features: &FeatureConfig,
    cache_dir: &Path,
    lbo_memory: Option<u64>,
) -> Result<(Vec<f32>, usize)> {
    /// Version of the table files; bump when the table's meaning changes.
    const TABLE_VERSION: u32 = 1;
    const MAGIC: &[u8; 8] = b"NBLBOTAB";
    let sel = &features.lbo;
    let config = encoding_config(features)?;
    let vertices: Vec<[f64; 3]> =
        scene.mesh.positions.iter().map(|p| [p.x as f64, p.y as f64, p.z as f64]).collect();
    let key = mesh_encoding::lbo::cache_key(
        &vertices,
        &scene.mesh.triangles,
        config.required_pairs(),
        &eigen_settings(features, lbo_memory),
    );
    let path = cache_dir.join(format!(
        "lbo-table-{key:032x}-{}-{}-{}-{}.bin",
        sel.first, sel.blocks, sel.block_len, sel.k_max
    ));
    let dim = sel.dim();
    if let Ok(bytes) = std::fs::read(&path)
        && let Ok(table) = stdx::cache_file::decode::<Vec<f32>>(&bytes, MAGIC, TABLE_VERSION, key)
        && table.len() == vertices.len() * dim
    {
        return Ok((table, dim));
    }
    let encoding = lbo_encoding(scene, features, cache_dir, lbo_memory)?;
    let table = encoding.as_slice().to_vec();
    stdx::fs::write_atomic(&path, &stdx::cache_file::encode(MAGIC, TABLE_VERSION, key, &table))?;
    Ok((table, encoding.dim()))
}

/// mesh-encoding's configuration of the run's LBO selection (run-format states the selection
/// as data; its indices are mesh-encoding's [`block_selection`]).
fn encoding_config(features: &FeatureConfig) -> Result<LboEncodingConfig> {
    let sel = &features.lbo;
    let selection = block_selection(sel.first, sel.blocks, sel.block_len, sel.k_max)?;
    Ok(LboEncodingConfig { selection, ..LboEncodingConfig::default() })
}

fn eigen_settings(features: &FeatureConfig, memory_budget: Option<u64>) -> EigenSettings {
    EigenSettings {
        max_basis_factor: features.lbo.max_basis_factor,
        memory_budget,
        ..EigenSettings::default()
    }
}

/// The LBO encoding of the scene's mesh with the configured selection, eigenpairs from the
/// content-keyed cache (mesh-encoding picks the dense solver itself for small meshes), a solve
/// within `lbo_memory` bytes ([`lbo_table`]).
pub fn lbo_encoding(
    scene: &SceneDataset,
    features: &FeatureConfig,
    cache_dir: &Path,
    lbo_memory: Option<u64>,
) -> Result<LboEncoding> {
    let config = encoding_config(features)?;
    let vertices: Vec<[f64; 3]> =
        scene.mesh.positions.iter().map(|p| [p.x as f64, p.y as f64, p.z as f64]).collect();
    std::fs::create_dir_all(cache_dir).map_err(|e| Error::io(cache_dir, e))?;
    let k = config.required_pairs();
    let settings = eigen_settings(features, lbo_memory);
    let mesh = scene.dir.join(&scene.manifest.mesh_file);
    let (pairs, _) = cached_eigenpairs(&vertices, &scene.mesh.triangles, k, &settings, cache_dir)
        .map_err(|e| match e {
        // Name the mesh a failed solve (a mesh too large for memory, say) is about.
        mesh_encoding::Error::Lbo { .. } => Error::format(&mesh, e.to_string()),
        e => e.into(),
    })?;
    Ok(LboEncoding::new(&pairs, &config)?)
}

#[cfg(test)]
mod tests {
    /// run-format states the LBO selection and the solver's default as data; they are
    /// mesh-encoding's.
    #[test]
    fn the_run_formats_lbo_defaults_are_the_encodings() {
        use run_format::config::{DEFAULT_MAX_BASIS_FACTOR, FeatureConfig};
        let features = FeatureConfig::default();
        let selection = super::encoding_config(&features).unwrap().selection;
        assert_eq!(selection, mesh_encoding::LboEncodingConfig::default().selection);
        assert_eq!(selection.len(), features.lbo.dim());
        assert_eq!(DEFAULT_MAX_BASIS_FACTOR, super::EigenSettings::default().max_basis_factor);
    }

    use super::*;

    fn records(n: usize, points: usize, k: usize) -> RecordSet {
        let f = |i: usize, c: usize| ((i * 7 + c) as f32 * 0.61).sin();
        RecordSet {
            spatial: Arc::new((0..points * k).map(|i| f(i, 0)).collect()),
            spatial_dim: k,
            point: (0..n).map(|i| ((i * 31) % points) as u32).collect(),
            l: (0..n).map(|i| [f(i, 1), f(i, 2), f(i, 3)]).collect(),
            v: (0..n).map(|i| [f(i, 4), f(i, 5), f(i, 6)]).collect(),
            weight: (0..n).map(|i| [f(i, 7), f(i, 8), f(i, 9)]).collect(),
            observed: vec![[0.0; 3]; n],
            observed_gamma: (0..n).map(|i| [f(i, 10), f(i, 11), f(i, 12)]).collect(),
            source: (0..n).collect(),
            clip: None,
        }
    }

    /// The parallel gather copies exactly what a record-by-record loop copies, for batches
    /// that end inside a chunk, repeat records, or have no spatial features, and on pools of
    /// 1, 2 and 3 threads.
    #[test]
    fn gather_matches_a_sequential_reference_on_any_pool() {
        for (n, points, k, batch) in [(5000, 700, 160, 1300), (50, 9, 3, 0), (40, 1, 0, 777)] {
            let d = records(n, points, k);
            let indices: Vec<usize> = (0..batch).map(|j| (j * 977 + j / 3) % n).collect();
            let mut want = CpuBatch::default();
            for &i in &indices {
                want.spatial.extend_from_slice(d.spatial_row(i));
                want.l.push(d.l[i]);
                want.v.push(d.v[i]);
                want.weight.extend_from_slice(&d.weight[i]);
                want.target_gamma.extend_from_slice(&d.observed_gamma[i]);
            }
            for threads in [1, 2, 3] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                let got = pool.install(|| d.gather(&indices));
                assert_eq!(got.spatial, want.spatial, "spatial, {threads} threads, k = {k}");
                assert_eq!((&got.l, &got.v), (&want.l, &want.v), "directions, {threads} threads");
                assert_eq!(got.weight, want.weight, "weights, {threads} threads");
                assert_eq!(got.target_gamma, want.target_gamma, "targets, {threads} threads");
            }
            // The split a device-side selection uses: the fields, and the points whose rows
            // are the spatial rows.
            let fields = d.gather_fields(&indices);
            assert!(fields.spatial.is_empty());
            assert_eq!((&fields.l, &fields.v, &fields.weight), (&want.l, &want.v, &want.weight));
            assert_eq!(fields.target_gamma, want.target_gamma);
            let rows: Vec<f32> = d
                .points_of(&indices)
                .iter()
                .flat_map(|&p| d.spatial[p as usize * k..(p as usize + 1) * k].to_vec())
                .collect();
            assert_eq!(rows, want.spatial, "rows of points_of, k = {k}");
        }
    }
}
