//! A fitted model over surface points: its predictions on records, the inputs it keeps on the
//! device, and the model as a [`brdf_analytic::SurfaceBrdf`], the one interface validation,
//! evaluation, export, the metrics and the probes take.
//!
//! Records are (point, l, v) triples whose points index rows of spatial features
//! ([`PointRows`]). On a CPU a pass gathers each record's row; on a GPU the rows of every
//! point live on the device ([`device_table`]) and a pass selects them there, so that a pass
//! uploads only indices and directions. Training keeps its records there too
//! ([`crate::training_inputs`]).

use crate::products::Products;
use crate::{BrdfBatch, BrdfModel, Error, ModelConfig, Result, Samples, SpatialTable};
use burn::tensor::{Device, Tensor};

/// Spatial rows of surface points, row-major `[points, dim]`, and the point of each record.
#[derive(Clone, Copy, Debug)]
pub struct PointRows<'a> {
    /// The rows, `dim` floats a point.
    pub spatial: &'a [f32],
    /// Features a point (0: the model takes none).
    pub dim: usize,
    /// Each record's point: record `i` has row `point[i]`.
    pub point: &'a [u32],
}

impl<'a> PointRows<'a> {
    /// The spatial row of record `i`.
    pub fn row(&self, i: usize) -> &'a [f32] {
        let (p, k) = (self.point[i] as usize, self.dim);
        &self.spatial[p * k..(p + 1) * k]
    }

    /// The spatial rows of `records`, row-major (the input of a batch).
    pub fn rows(&self, records: std::ops::Range<usize>) -> Vec<f32> {
        let mut out = Vec::with_capacity(records.len() * self.dim);
        for i in records {
            out.extend_from_slice(self.row(i));
        }
        out
    }
}

/// Records to evaluate a model on: their points and local directions.
#[derive(Clone, Copy, Debug)]
pub struct Records<'a> {
    /// The records' points and the points' spatial rows.
    pub points: PointRows<'a>,
    /// Directions to the light, local frame.
    pub l: &'a [[f32; 3]],
    /// Directions to the viewer, local frame.
    pub v: &'a [[f32; 3]],
}

impl Records<'_> {
    /// The number of records.
    pub fn len(&self) -> usize {
        self.l.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.l.is_empty()
    }
}

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
        .map_err(|e| Error::Readback(format!("{what} output is not f32: {e:?}")))?;
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
    let gpu = !crate::device::is_cpu_device(device);
    let rows = pass_rows(samples.l.len(), gpu);
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
    let gpu = !crate::device::is_cpu_device(device);
    let rows = pass_rows(l.len(), gpu);
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
    // On a GPU, the training loop's parts of 512 rows (`products::gpu_parts`): every pass of
    // an evaluation then meets the matrix-product shapes that training tuned.
    let products = Products::inference(!crate::device::is_cpu_device(device), padded_n);
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
    let out = model.forward(&batch.with_products(products));
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

/// Evaluates `model` on every record (with the additive parts when `parts`); on a GPU the
/// records' spatial rows are selected on the device ([`predict_on`] with a table of their
/// points, [`device_table`]).
pub fn predict(
    model: &BrdfModel,
    config: &ModelConfig,
    records: Records,
    device: &Device,
    parts: bool,
) -> Result<Prediction> {
    let gpu = !crate::device::is_cpu_device(device);
    let table = device_table(config, records.points, gpu, device)?;
    predict_on(model, config, records, table.as_ref(), device, parts)
}

/// [`predict`] with the spatial rows of the records' points on the device already (`table`, on
/// `device`), or gathered on the CPU chunk by chunk (`None`).
pub fn predict_on(
    model: &BrdfModel,
    config: &ModelConfig,
    records: Records,
    table: Option<&SpatialTable>,
    device: &Device,
    parts: bool,
) -> Result<Prediction> {
    let mut all = Prediction::default();
    for start in (0..records.len()).step_by(CHUNK) {
        let end = (start + CHUNK).min(records.len());
        let (l, v) = (&records.l[start..end], &records.v[start..end]);
        let p = match table {
            Some(table) => {
                let points = &records.points.point[start..end];
                forward_points(model, config, table, points, l, v, device, parts)?
            }
            None => {
                let samples = Samples { spatial: &records.points.rows(start..end), l, v };
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

/// Largest spatial table [`device_table`] puts on a GPU, in bytes (a 512 px scene of the
/// `full` profile needs at most 0.42 GB: 652,749 training pixels x 160 floats for Spot).
pub const DEVICE_TABLE_MAX_BYTES: usize = 2 << 30;

/// The spatial rows of every point on `device` when `on_device` (the default on a GPU): each
/// pass then selects its rows there, instead of 640 bytes a sample copied on the CPU and
/// uploaded with every pass. `None` otherwise (on the CPU the gather is the selection), without
/// spatial features, or past [`DEVICE_TABLE_MAX_BYTES`]. Not handled yet: a GPU whose largest
/// storage buffer is smaller than the table (Vulkan's `maxStorageBufferRange`, 128 MiB on some
/// integrated GPUs; 4 GiB on NVIDIA's) fails to allocate it.
pub fn device_table(
    config: &ModelConfig,
    points: PointRows,
    on_device: bool,
    device: &Device,
) -> Result<Option<SpatialTable>> {
    let bytes = std::mem::size_of_val(points.spatial);
    if !on_device || points.dim == 0 || bytes > DEVICE_TABLE_MAX_BYTES {
        return Ok(None);
    }
    Ok(Some(SpatialTable::new(config, points.spatial, device)?))
}

/// Rows per pass of [`NeuralSurface`] on a GPU: eight of [`CHUNK`]. The energy analysis then
/// evaluates 13 of the paper's pairs (20,000 samples each) a pass, and the host samples their
/// directions on every core while the device runs (a pair a pass, at [`CHUNK`], left one
/// core sampling and a readback every 20,000 evaluations).
pub const GPU_BATCH: usize = 8 * CHUNK;

/// A fitted model as a [`brdf_analytic::SurfaceBrdf`]: point `i` is record `i` of `points` (its
/// spatial row); directions are the callers' local-frame ones. Evaluation errors (which cannot
/// happen for a model that loaded) surface as NaN, which the analyses reject.
///
/// On a GPU the spatial rows of the points live on the device ([`device_table`]), and each
/// pass selects its rows there: the analyses
/// evaluate a point thousands of times (the paper's energy protocol 20,000 times a pair), and
/// copying its row (160 floats at 512 px) for every evaluation would make the host, not the
/// device, set the pace.
pub struct NeuralSurface<'a> {
    model: &'a BrdfModel,
    config: &'a ModelConfig,
    points: PointRows<'a>,
    device: &'a Device,
    gpu: bool,
    table: Option<SpatialTable>,
}

impl<'a> NeuralSurface<'a> {
    /// The model on the records of `points`, their spatial rows uploaded on a GPU.
    pub fn new(
        model: &'a BrdfModel,
        config: &'a ModelConfig,
        points: PointRows<'a>,
        device: &'a Device,
    ) -> Result<Self> {
        let gpu = !crate::device::is_cpu_device(device);
        let table = device_table(config, points, gpu, device)?;
        Ok(Self { model, config, points, device, gpu, table })
    }

    /// The records whose spatial rows the points index.
    pub fn points(&self) -> PointRows<'a> {
        self.points
    }

    /// Whether the spatial rows are selected on the device.
    pub fn rows_on_device(&self) -> bool {
        self.table.is_some()
    }
}

impl brdf_analytic::SurfaceBrdf for NeuralSurface<'_> {
    fn eval_points(&self, points: &[u32], l: &[[f32; 3]], v: &[[f32; 3]], out: &mut [[f32; 3]]) {
        let p = match &self.table {
            Some(table) => {
                let rows: Vec<u32> =
                    points.iter().map(|&p| self.points.point[p as usize]).collect();
                forward_points(self.model, self.config, table, &rows, l, v, self.device, false)
            }
            None => {
                let mut spatial = Vec::with_capacity(points.len() * self.points.dim);
                for &p in points {
                    spatial.extend_from_slice(self.points.row(p as usize));
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
    use crate::ModelKind;

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
        let device = crate::device::cpu();
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

    /// On a GPU (`cargo test -p brdf-neural --features wgpu`, lavapipe will do), a pass padded
    /// to a power of two and split into parts of 512 rows gives the CPU's values.
    #[cfg(feature = "wgpu")]
    #[test]
    fn gpu_passes_padded_and_split_give_the_cpus_values() {
        use crate::device::{Backend, BackendDevice};
        use burn::module::Module;
        let cpu = crate::device::cpu();
        let gpu = Backend::Wgpu.device().unwrap();
        assert!(!crate::device::is_cpu_device(&gpu));
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

    /// Records whose points repeat: 7 points, 40 records (spatial rows, points, l, v).
    #[allow(clippy::type_complexity)]
    fn records() -> (Vec<f32>, Vec<u32>, Vec<[f32; 3]>, Vec<[f32; 3]>) {
        let (spatial, _, _) = inputs(7);
        let (_, l, v) = inputs(40);
        (spatial, (0..40).map(|i| (i * 3 % 7) as u32).collect(), l, v)
    }

    /// Evaluates records 39, 0, 5, ... through [`brdf_analytic::SurfaceBrdf`].
    fn as_surface(brdf: &NeuralSurface, l: &[[f32; 3]], v: &[[f32; 3]]) -> Vec<[f32; 3]> {
        use brdf_analytic::SurfaceBrdf;
        let records: Vec<u32> = (0..40).map(|i| (39 + 5 * i) % 40).collect();
        let l: Vec<[f32; 3]> = records.iter().map(|&r| l[r as usize]).collect();
        let v: Vec<[f32; 3]> = records.iter().map(|&r| v[r as usize]).collect();
        let mut out = vec![[0.0; 3]; records.len()];
        brdf.eval_points(&records, &l, &v, &mut out);
        out
    }

    #[test]
    fn the_model_as_a_surface_brdf_reads_each_records_point_on_the_cpu() {
        let device = crate::device::cpu();
        let config = ModelConfig { spatial_dim: 4, ..ModelConfig::new(ModelKind::SingleMlp) };
        let model = BrdfModel::init(&config, &device).unwrap();
        let (spatial, point, l, v) = records();
        let points = PointRows { spatial: &spatial, dim: 4, point: &point };
        let brdf = NeuralSurface::new(&model, &config, points, &device).unwrap();
        assert!(!brdf.rows_on_device());
        assert_eq!(brdf_analytic::SurfaceBrdf::preferred_batch(&brdf), CHUNK);
        let got = as_surface(&brdf, &l, &v);
        for (i, g) in got.iter().enumerate() {
            let r = (39 + 5 * i) % 40;
            let samples = Samples { spatial: points.row(r), l: &l[r..r + 1], v: &v[r..r + 1] };
            let want = forward_rows(&model, &config, &samples, &device, false).unwrap().f[0];
            assert_eq!(*g, want, "record {r}");
        }
    }

    /// On a GPU the records' rows are selected from a table on the device: the CPU's values.
    #[cfg(feature = "wgpu")]
    #[test]
    fn the_model_as_a_surface_brdf_selects_rows_on_the_gpu() {
        use crate::device::{Backend, BackendDevice};
        use burn::module::Module;
        let cpu = crate::device::cpu();
        let gpu = Backend::Wgpu.device().unwrap();
        for kind in [ModelKind::SingleMlp, ModelKind::Disney] {
            let config = ModelConfig { spatial_dim: 4, ..ModelConfig::new(kind) };
            let model = BrdfModel::init(&config, &cpu).unwrap();
            let on_gpu = model.clone().fork(&gpu);
            let (spatial, point, l, v) = records();
            let points = PointRows { spatial: &spatial, dim: 4, point: &point };
            let want =
                as_surface(&NeuralSurface::new(&model, &config, points, &cpu).unwrap(), &l, &v);
            let brdf = NeuralSurface::new(&on_gpu, &config, points, &gpu).unwrap();
            assert!(brdf.rows_on_device());
            assert_eq!(brdf_analytic::SurfaceBrdf::preferred_batch(&brdf), GPU_BATCH);
            let got = as_surface(&brdf, &l, &v);
            for (x, y) in want.iter().flatten().zip(got.iter().flatten()) {
                assert!((x - y).abs() <= 1e-4 * x.abs().max(1e-3), "{kind:?}: {x} against {y}");
            }
        }
    }
}
