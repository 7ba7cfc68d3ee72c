//! Evaluating a fitted model on CPU records: the BRDF and, for additive models, its parts; and
//! the model as a [`metrics::BatchBrdf`] for the BRDF-space analyses (energy, reciprocity).

use crate::data::TrainingData;
use crate::{Error, Result};
use brdf_neural::{BrdfBatch, BrdfModel, ModelConfig, Samples, SpatialTable, split_k};
use burn::tensor::{Device, Tensor};

/// Rows per forward pass.
pub const CHUNK: usize = 1 << 15;

/// The fewest rows a forward pass on a GPU runs (see [`pass_rows`]).
pub const MIN_GPU_ROWS: usize = 1 << 10;

/// The rows a forward pass of `n` samples runs: `n` on a CPU; on a GPU, `n` rounded up to a
/// power of two of at least [`MIN_GPU_ROWS`] (to a multiple of [`CHUNK`] above it), the extra
/// rows padding that is dropped.
///
/// An evaluation's passes come in many sizes (the tail of every chunked pass, the probes'
/// 179-direction slices). On a GPU with autotune, the first product of every new shape
/// benchmarks candidate kernels, compiling each: 2 to 7 s a shape on a fresh H200, and an odd
/// row count also changes the kernels' vector width. Rounded to powers of two and run in the
/// training loop's parts of 512 rows ([`forward_rows`]), every pass reuses the shapes training
/// tuned (benches/README.md, "Why evaluation was slow on a GPU").
pub fn pass_rows(n: usize, gpu: bool) -> usize {
    if !gpu || n == 0 {
        n
    } else if n >= CHUNK {
        n.div_ceil(CHUNK) * CHUNK
    } else {
        n.next_power_of_two().max(MIN_GPU_ROWS)
    }
}

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
    let gpu = !brdf_neural::device::is_cpu_device(device);
    let rows = pass_rows(samples.l.len(), gpu);
    // On a GPU, the training loop's parts of 512 rows (`split_k::gpu_parts`): every pass of
    // an evaluation then meets the matrix-product shapes that training tuned.
    let _split = gpu.then(|| split_k::scope(split_k::gpu_parts(rows)));
    forward_padded(model, config, Spatial::Rows, samples, device, parts, rows)
}

/// [`forward_rows`] with each sample's spatial row selected on the device: row `points[i]`
/// of `table` for sample i (the same values as [`forward_rows`] with those rows gathered on
/// the CPU, without copying a row per sample and uploading it).
#[allow(clippy::too_many_arguments)]
pub fn forward_points(
    model: &BrdfModel,
    config: &ModelConfig,
    table: &SpatialTable,
    points: &[u32],
    l: &[[f32; 3]],
    v: &[[f32; 3]],
    device: &Device,
    parts: bool,
) -> Result<Prediction> {
    let gpu = !brdf_neural::device::is_cpu_device(device);
    let rows = pass_rows(l.len(), gpu);
    let _split = gpu.then(|| split_k::scope(split_k::gpu_parts(rows)));
    let samples = Samples { spatial: &[], l, v };
    forward_padded(model, config, Spatial::Table(table, points), &samples, device, parts, rows)
}

/// Where a pass's spatial rows come from.
#[derive(Clone, Copy)]
enum Spatial<'a> {
    /// The samples' own rows, on the CPU.
    Rows,
    /// Rows of a table on the device, one index a sample.
    Table(&'a SpatialTable, &'a [u32]),
}

/// [`forward_rows`] (or [`forward_points`]) run on `padded_n` (at least the samples') rows.
fn forward_padded(
    model: &BrdfModel,
    config: &ModelConfig,
    source: Spatial,
    samples: &Samples,
    device: &Device,
    parts: bool,
    padded_n: usize,
) -> Result<Prediction> {
    let n = samples.l.len();
    let pad = padded_n.saturating_sub(n);
    // Padding rows: zero features (or the table's first row) and a valid (l, v) pair; their
    // outputs are dropped.
    let padded = |d: &[[f32; 3]]| [d, &vec![[0.0, 0.0, 1.0]; pad]].concat();
    let (l, v) = if pad == 0 {
        (std::borrow::Cow::Borrowed(samples.l), std::borrow::Cow::Borrowed(samples.v))
    } else {
        (padded(samples.l).into(), padded(samples.v).into())
    };
    let batch = match source {
        Spatial::Rows => {
            let mut spatial = Vec::with_capacity(samples.spatial.len() + pad * config.spatial_dim);
            spatial.extend_from_slice(samples.spatial);
            spatial.resize(spatial.len() + pad * config.spatial_dim, 0.0);
            BrdfBatch::from_owned(config, spatial, &l, &v, None, device)?
        }
        Spatial::Table(table, points) => {
            let points = if pad == 0 {
                std::borrow::Cow::Borrowed(points)
            } else {
                [points, &vec![0; pad]].concat().into()
            };
            BrdfBatch::from_table(config, table, &points, &l, &v, None, device)?
        }
    };
    let rows = |t: Tensor<2>, what: &str| -> Result<Vec<[f32; 3]>> {
        let mut r = rows(t, what)?;
        r.truncate(n);
        Ok(r)
    };
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

/// Evaluates `model` on every record of `data` (with the additive parts when `parts`); on a
/// GPU the records' spatial rows are selected on the device ([`predict_on`] with a table of
/// `data`'s points, [`crate::trainer::device_table`]).
pub fn predict(
    model: &BrdfModel,
    config: &ModelConfig,
    data: &TrainingData,
    device: &Device,
    parts: bool,
) -> Result<Prediction> {
    let gpu = !brdf_neural::device::is_cpu_device(device);
    let table = crate::trainer::device_table(config, data, gpu, device)?;
    predict_on(model, config, data, table.as_ref(), device, parts)
}

/// [`predict`] with the spatial rows of `data`'s points on the device already (`table`, on
/// `device`), or gathered on the CPU chunk by chunk (`None`).
pub fn predict_on(
    model: &BrdfModel,
    config: &ModelConfig,
    data: &TrainingData,
    table: Option<&SpatialTable>,
    device: &Device,
    parts: bool,
) -> Result<Prediction> {
    let mut all = Prediction::default();
    for start in (0..data.len()).step_by(CHUNK) {
        let end = (start + CHUNK).min(data.len());
        let (l, v) = (&data.l[start..end], &data.v[start..end]);
        let p = match table {
            Some(table) => {
                let points = &data.point[start..end];
                forward_points(model, config, table, points, l, v, device, parts)?
            }
            None => {
                let samples = Samples { spatial: &data.spatial_rows(start..end), l, v };
                forward_rows(model, config, &samples, device, parts)?
            }
        };
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

/// Rows per pass of [`ModelBrdf`] on a GPU: eight of [`CHUNK`]. The energy analysis then
/// evaluates 13 of the paper's pairs (20,000 samples each) a pass, and the host samples their
/// directions on every core while the device runs (a pair a pass, at [`CHUNK`], left one
/// core sampling and a readback every 20,000 evaluations).
pub const GPU_BATCH: usize = 8 * CHUNK;

/// A fitted model as a [`metrics::BatchBrdf`]: point `i` is record `i` of `data` (its spatial
/// features); directions are the analyses' local-frame ones. Evaluation errors (which cannot
/// happen for a model that loaded) surface as NaN, which the analyses reject.
///
/// On a GPU the spatial rows of `data`'s points live on the device
/// ([`crate::trainer::device_table`]), and each pass selects its rows there: the analyses
/// evaluate a point thousands of times (the paper's energy protocol 20,000 times a pair), and
/// copying its row (160 floats at 512 px) for every evaluation would make the host, not the
/// device, set the pace.
pub struct ModelBrdf<'a> {
    model: &'a BrdfModel,
    config: &'a ModelConfig,
    data: &'a TrainingData,
    device: &'a Device,
    gpu: bool,
    table: Option<SpatialTable>,
}

impl<'a> ModelBrdf<'a> {
    /// The model on the records of `data`, their spatial rows uploaded on a GPU.
    pub fn new(
        model: &'a BrdfModel,
        config: &'a ModelConfig,
        data: &'a TrainingData,
        device: &'a Device,
    ) -> Result<Self> {
        let gpu = !brdf_neural::device::is_cpu_device(device);
        let table = crate::trainer::device_table(config, data, gpu, device)?;
        Ok(Self { model, config, data, device, gpu, table })
    }

    /// The records whose spatial features the points index.
    pub fn data(&self) -> &'a TrainingData {
        self.data
    }

    /// Whether the spatial rows are selected on the device.
    pub fn rows_on_device(&self) -> bool {
        self.table.is_some()
    }
}

impl metrics::BatchBrdf for ModelBrdf<'_> {
    fn eval_batch(&self, points: &[u32], l: &[[f32; 3]], v: &[[f32; 3]], out: &mut [[f32; 3]]) {
        let p = match &self.table {
            Some(table) => {
                let rows: Vec<u32> = points.iter().map(|&p| self.data.point[p as usize]).collect();
                forward_points(self.model, self.config, table, &rows, l, v, self.device, false)
            }
            None => {
                let k = self.data.spatial_dim;
                let mut spatial = Vec::with_capacity(points.len() * k);
                for &p in points {
                    spatial.extend_from_slice(self.data.spatial_row(p as usize));
                }
                let samples = Samples { spatial: &spatial, l, v };
                forward_rows(self.model, self.config, &samples, self.device, false)
            }
        };
        match p {
            Ok(p) => out.copy_from_slice(&p.f),
            Err(_) => out.fill([f32::NAN; 3]),
        }
    }

    fn preferred_batch(&self) -> usize {
        if self.gpu { GPU_BATCH } else { CHUNK }
    }

    /// The backend parallelises each forward pass itself.
    fn parallel(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use brdf_neural::ModelKind;

    #[test]
    fn gpu_passes_round_up_to_few_shapes_and_cpu_passes_do_not() {
        assert_eq!(pass_rows(179, false), 179);
        assert_eq!(pass_rows(0, true), 0);
        assert_eq!(pass_rows(179, true), MIN_GPU_ROWS);
        assert_eq!(pass_rows(4_000, true), 4_096);
        assert_eq!(pass_rows(CHUNK, true), CHUNK);
        assert_eq!(pass_rows(CHUNK + 1, true), 2 * CHUNK);
    }

    /// `n` samples of 4 spatial features: (spatial, l, v).
    #[allow(clippy::type_complexity)]
    fn inputs(n: usize) -> (Vec<f32>, Vec<[f32; 3]>, Vec<[f32; 3]>) {
        let spatial: Vec<f32> = (0..n * 4).map(|i| (i as f32 * 0.37).sin()).collect();
        let dirs = |s: f32| -> Vec<[f32; 3]> {
            (0..n)
                .map(|i| {
                    let a = 0.02 * i as f32 + s;
                    [a.sin() * 0.6, a.cos() * 0.6, 0.8]
                })
                .collect()
        };
        (spatial, dirs(0.1), dirs(1.3))
    }

    #[test]
    fn padded_passes_give_the_unpadded_values() {
        let device = brdf_neural::device::cpu();
        for kind in [ModelKind::SingleMlp, ModelKind::AdditiveSharedEnhanced, ModelKind::Disney] {
            let config = ModelConfig { spatial_dim: 4, ..ModelConfig::new(kind) };
            let model = BrdfModel::init(&config, &device).unwrap();
            let n = 37;
            let (spatial, l, v) = inputs(n);
            let samples = Samples { spatial: &spatial, l: &l, v: &v };
            let plain =
                forward_padded(&model, &config, Spatial::Rows, &samples, &device, true, n).unwrap();
            let padded =
                forward_padded(&model, &config, Spatial::Rows, &samples, &device, true, 1024)
                    .unwrap();
            let specular = (plain.specular.as_ref(), padded.specular.as_ref());
            assert_eq!(specular.0.is_some(), kind.is_additive());
            assert_eq!(specular.1.is_some(), kind.is_additive());
            for (a, b) in [(Some(&plain.f), Some(&padded.f)), specular] {
                let (Some(a), Some(b)) = (a, b) else { continue };
                assert_eq!(a.len(), n);
                assert_eq!(b.len(), n);
                for (x, y) in a.iter().flatten().zip(b.iter().flatten()) {
                    assert!((x - y).abs() <= 1e-6 * x.abs().max(1.0), "{kind:?}: {x} against {y}");
                }
            }
        }
    }

    /// On a GPU (`cargo test -p experiments --features wgpu`, lavapipe will do), a pass padded
    /// to a power of two and split into parts of 512 rows gives the CPU's values.
    #[cfg(feature = "wgpu")]
    #[test]
    fn gpu_passes_padded_and_split_give_the_cpus_values() {
        use brdf_neural::device::Backend;
        use burn::module::Module;
        let cpu = brdf_neural::device::cpu();
        let gpu = Backend::Wgpu.device().unwrap();
        assert!(!brdf_neural::device::is_cpu_device(&gpu));
        for kind in [ModelKind::SingleMlp, ModelKind::Disney] {
            let config = ModelConfig { spatial_dim: 4, ..ModelConfig::new(kind) };
            let model = BrdfModel::init(&config, &cpu).unwrap();
            let on_gpu = model.clone().fork(&gpu);
            for n in [37, 1_500] {
                let (spatial, l, v) = inputs(n);
                let samples = Samples { spatial: &spatial, l: &l, v: &v };
                let want = forward_rows(&model, &config, &samples, &cpu, false).unwrap().f;
                let got = forward_rows(&on_gpu, &config, &samples, &gpu, false).unwrap().f;
                assert_eq!(got.len(), n);
                for (x, y) in want.iter().flatten().zip(got.iter().flatten()) {
                    assert!((x - y).abs() <= 1e-4 * x.abs().max(1e-3), "{kind:?}: {x} against {y}");
                }
            }
        }
    }

    /// Records whose points repeat: 7 points, 40 records.
    fn records(config: &ModelConfig) -> TrainingData {
        let (spatial, _, _) = inputs(7);
        let (_, l, v) = inputs(40);
        TrainingData {
            spatial: std::sync::Arc::new(spatial),
            spatial_dim: config.spatial_dim,
            point: (0..40).map(|i| (i * 3 % 7) as u32).collect(),
            l,
            v,
            ..Default::default()
        }
    }

    /// Evaluates records 39, 0, 5, ... of `data` through [`metrics::BatchBrdf`].
    fn as_batch_brdf(brdf: &ModelBrdf, data: &TrainingData) -> Vec<[f32; 3]> {
        use metrics::BatchBrdf;
        let records: Vec<u32> = (0..40).map(|i| (39 + 5 * i) % 40).collect();
        let l: Vec<[f32; 3]> = records.iter().map(|&r| data.l[r as usize]).collect();
        let v: Vec<[f32; 3]> = records.iter().map(|&r| data.v[r as usize]).collect();
        let mut out = vec![[0.0; 3]; records.len()];
        brdf.eval_batch(&records, &l, &v, &mut out);
        out
    }

    #[test]
    fn the_model_as_a_batch_brdf_reads_each_records_point_on_the_cpu() {
        let device = brdf_neural::device::cpu();
        let config = ModelConfig { spatial_dim: 4, ..ModelConfig::new(ModelKind::SingleMlp) };
        let model = BrdfModel::init(&config, &device).unwrap();
        let data = records(&config);
        let brdf = ModelBrdf::new(&model, &config, &data, &device).unwrap();
        assert!(!brdf.rows_on_device());
        assert_eq!(metrics::BatchBrdf::preferred_batch(&brdf), CHUNK);
        let got = as_batch_brdf(&brdf, &data);
        for (i, g) in got.iter().enumerate() {
            let r = (39 + 5 * i) % 40;
            let samples = Samples {
                spatial: data.spatial_row(r),
                l: &data.l[r..r + 1],
                v: &data.v[r..r + 1],
            };
            let want = forward_rows(&model, &config, &samples, &device, false).unwrap().f[0];
            assert_eq!(*g, want, "record {r}");
        }
    }

    /// On a GPU the records' rows are selected from a table on the device: the CPU's values.
    #[cfg(feature = "wgpu")]
    #[test]
    fn the_model_as_a_batch_brdf_selects_rows_on_the_gpu() {
        use brdf_neural::device::Backend;
        use burn::module::Module;
        let cpu = brdf_neural::device::cpu();
        let gpu = Backend::Wgpu.device().unwrap();
        for kind in [ModelKind::SingleMlp, ModelKind::Disney] {
            let config = ModelConfig { spatial_dim: 4, ..ModelConfig::new(kind) };
            let model = BrdfModel::init(&config, &cpu).unwrap();
            let on_gpu = model.clone().fork(&gpu);
            let data = records(&config);
            let want = as_batch_brdf(&ModelBrdf::new(&model, &config, &data, &cpu).unwrap(), &data);
            let brdf = ModelBrdf::new(&on_gpu, &config, &data, &gpu).unwrap();
            assert!(brdf.rows_on_device());
            assert_eq!(metrics::BatchBrdf::preferred_batch(&brdf), GPU_BATCH);
            let got = as_batch_brdf(&brdf, &data);
            for (x, y) in want.iter().flatten().zip(got.iter().flatten()) {
                assert!((x - y).abs() <= 1e-4 * x.abs().max(1e-3), "{kind:?}: {x} against {y}");
            }
        }
    }
}
