//! Every training record's direction inputs on the device, computed once.
//!
//! A training step draws a batch of records. Without this table the host gathers the batch's
//! directions every step, encodes them (the angle features of the purely neural models) or
//! computes their geometry terms (the parametric models), and uploads the result: on a GPU the
//! device then waits for the host every step. The records never change, so [`RecordTable`]
//! computes those inputs once for every record, with the same functions
//! ([`crate::AngleConfig::encode_batch`], [`Geometry::new`]), and a batch selects its rows on
//! the device from one uploaded index ([`BrdfBatch::from_records`]), together with its spatial
//! rows ([`SpatialTable`]). The values are the ones the per-step path computes, to the
//! bit; tests compare batches, and a whole training run on the CPU.
//!
//! With the random-swap reciprocity option the angle table holds every record twice, as (l, v)
//! and as (v, l); a batch's swap mask picks the row. The geometry terms of the parametric models
//! ignore the swap, as the per-step path does.
//!
//! Memory: `records x (angle_dim x (1 + swap) + 1)` floats for the purely neural models,
//! `records x 17` for the parametric ones (32 for FMBRDF), the point included only with spatial
//! features ([`RecordTable::bytes`]).

use crate::batch::SpatialTable;
use crate::tensor_brdf::Geometry;
use crate::{BrdfBatch, Error, ModelConfig, ModelKind, Reciprocity, Result};
use burn::tensor::{Device, Int, Tensor, TensorData};

/// The direction inputs of a set of records on the device ([`RecordTable::new`]).
#[derive(Clone, Debug)]
pub struct RecordTable {
    /// Number of records.
    records: usize,
    /// Each record's point (row of the spatial table), when the model has spatial features.
    point: Option<Tensor<1, Int>>,
    /// Encoded angles `[records, angle_dim]`, then the swapped pairs' rows when `swaps`.
    angles: Option<Tensor<2>>,
    /// Whether `angles` holds the swapped pairs too.
    swaps: bool,
    /// The geometry terms of every record (parametric models).
    geometry: Option<Geometry>,
}

/// A batch's records, uploaded once: for [`BrdfBatch::from_records`] and for the
/// caller's own per-record tensors (weights, targets: select their rows with `rows`).
#[derive(Clone, Debug)]
pub struct RecordIndex {
    /// The records, `[batch]`.
    pub rows: Tensor<1, Int>,
    /// The rows of the angle table (`rows`, shifted past the unswapped rows where swapped).
    angle_rows: Option<Tensor<1, Int>>,
    /// The records on the host (FMBRDF's segment search reads its terms there).
    host: Vec<u32>,
}

impl RecordTable {
    /// Number of records.
    pub fn records(&self) -> usize {
        self.records
    }

    /// Uploads the index of a batch of records; `swap[i]` swaps record i's directions in its
    /// angle features (an error unless the model's reciprocity option is the random swap and
    /// the table holds the swapped rows; the geometry terms ignore it).
    pub fn index(
        &self,
        records: &[u32],
        swap: Option<&[bool]>,
        device: &Device,
    ) -> Result<RecordIndex> {
        let n = records.len();
        if let Some(&r) = records.iter().find(|&&r| r as usize >= self.records) {
            return Err(Error::BatchShape(format!(
                "record {r} outside a table of {} records",
                self.records
            )));
        }
        if swap.is_some_and(|m| m.len() != n) {
            return Err(Error::BatchShape("swap mask length differs from the batch".into()));
        }
        if swap.is_some_and(|m| m.contains(&true)) && self.angles.is_some() && !self.swaps {
            return Err(Error::BatchShape(
                "a swap mask for a record table without swapped rows (the reciprocity option is \
                 not the random swap)"
                    .into(),
            ));
        }
        let upload = |v: Vec<i32>| Tensor::<1, Int>::from_data(TensorData::new(v, [n]), device);
        let rows = upload(records.iter().map(|&r| r as i32).collect());
        let angle_rows = match swap {
            Some(mask) if self.swaps && self.angles.is_some() => {
                let shift = |(&r, &s): (&u32, &bool)| r as usize + usize::from(s) * self.records;
                Some(upload(records.iter().zip(mask).map(|p| shift(p) as i32).collect()))
            }
            _ => None,
        };
        Ok(RecordIndex { rows, angle_rows, host: records.to_vec() })
    }
}

impl RecordTable {
    /// Computes the direction inputs of every record (local-frame `l[i]`, `v[i]`, at surface
    /// point `point[i]`) for the model of `config` and uploads them, for
    /// [`BrdfBatch::from_records`].
    pub fn new(
        config: &ModelConfig,
        l: &[[f32; 3]],
        v: &[[f32; 3]],
        point: &[u32],
        device: &Device,
    ) -> Result<RecordTable> {
        let records = l.len();
        if v.len() != records || point.len() != records {
            return Err(Error::BatchShape(format!(
                "{records} light and {} view directions, {} points",
                v.len(),
                point.len()
            )));
        }
        if records > (i32::MAX / 2) as usize {
            return Err(Error::BatchShape(format!("{records} records: too many for a table")));
        }
        let swaps = config.angles.reciprocity == Reciprocity::RandomSwap;
        let angles = config.uses_angle_features().then(|| {
            let d = config.angles.dim();
            let mut a = config.angles.encode_batch(l, v, None);
            if swaps {
                a.extend(config.angles.encode_batch(v, l, None));
            }
            let rows = a.len() / d;
            Tensor::from_data(TensorData::new(a, [rows, d]), device)
        });
        let geometry = (!config.uses_angle_features())
            .then(|| Geometry::new(l, v, config.kind == ModelKind::Fmbrdf, device));
        let point = (config.spatial_dim > 0).then(|| {
            let p: Vec<i32> = point.iter().map(|&p| p as i32).collect();
            Tensor::<1, Int>::from_data(TensorData::new(p, [records]), device)
        });
        Ok(RecordTable { records, point, angles, swaps, geometry })
    }

    /// Bytes [`RecordTable::new`] puts on the device for `records` records of the model of
    /// `config`.
    pub fn bytes(config: &ModelConfig, records: usize) -> usize {
        let per_record = if config.uses_angle_features() {
            let copies = if config.angles.reciprocity == Reciprocity::RandomSwap { 2 } else { 1 };
            config.angles.dim() * copies
        } else if config.kind == ModelKind::Fmbrdf {
            16 + 9 + 6
        } else {
            16
        };
        records * (per_record + usize::from(config.spatial_dim > 0)) * 4
    }
}

impl BrdfBatch {
    /// The batch of the records `index` (made by `table`), selected on the device: the batch
    /// [`BrdfBatch::from_owned`] makes from the same records' rows and directions. `spatial`
    /// holds the points' feature rows (required when the model has spatial features).
    pub fn from_records(
        config: &ModelConfig,
        table: &RecordTable,
        spatial: Option<&SpatialTable>,
        index: &RecordIndex,
        device: &Device,
    ) -> Result<BrdfBatch> {
        let n = index.host.len();
        let spatial = match (config.spatial_dim, spatial, &table.point) {
            (0, _, _) => Tensor::from_data(TensorData::new(Vec::<f32>::new(), [n, 0]), device),
            (k, Some(s), Some(point)) if s.width() == k => {
                let points = point.clone().select(0, index.rows.clone());
                s.select(points)
            }
            (k, s, _) => {
                return Err(Error::BatchShape(format!(
                    "a model with {k} spatial features needs a spatial table of that width \
                     (got {})",
                    s.map_or("none".to_string(), |s| format!("width {}", s.width()))
                )));
            }
        };
        let angles = table.angles.as_ref().map(|a| {
            let rows = index.angle_rows.as_ref().unwrap_or(&index.rows);
            a.clone().select(0, rows.clone())
        });
        let geometry = table.geometry.as_ref().map(|g| g.select(&index.rows, &index.host));
        Ok(BrdfBatch { spatial, angles, geometry, products: crate::products::Products::F32 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A batch selected from a record table equals the batch gathered, encoded and uploaded
    /// from the same records, bit for bit: inputs and the model's output, for angle features
    /// (with random swaps too), the parametric geometry and FMBRDF's, grazing and below-horizon
    /// directions, and records drawn twice; bad indices and tables are errors.
    #[test]
    fn record_batches_agree_with_gathered_batches_bitwise() {
        let device = crate::device::cpu();
        let (points, records, n) = (30, 200, 257);
        let dir = |i: usize, s: f32| {
            let (a, b) = ((i as f32 * 0.13 + s).sin() * 0.6, (i as f32 * 0.05 - s).cos() * 0.6);
            [a, b, (1.0 - a * a - b * b).max(0.0).sqrt()]
        };
        // Grazing and below-horizon directions among them.
        let mut l: Vec<[f32; 3]> = (0..records).map(|i| dir(i, 0.2)).collect();
        let v: Vec<[f32; 3]> = (0..records).map(|i| dir(i, 0.9)).collect();
        l[3] = [1.0, 0.0, 0.0];
        l[4] = [0.6, 0.0, -0.8];
        let point: Vec<u32> = (0..records).map(|i| ((i * 11) % points) as u32).collect();
        let batch: Vec<u32> = (0..n).map(|i| ((i * 37 + i / 5) % records) as u32).collect();
        let swap: Vec<bool> = (0..n).map(|i| i % 3 == 1).collect();
        let bits = |t: Tensor<2>| -> Vec<u32> {
            t.into_data().try_to_vec::<f32>().unwrap().iter().map(|x| x.to_bits()).collect()
        };
        let pick =
            |xs: &[[f32; 3]]| -> Vec<[f32; 3]> { batch.iter().map(|&r| xs[r as usize]).collect() };
        let (bl, bv) = (pick(&l), pick(&v));
        let cases = [
            (ModelKind::SingleMlp, Reciprocity::None, 5),
            (ModelKind::SingleMlp, Reciprocity::RandomSwap, 5),
            (ModelKind::AdditiveShared, Reciprocity::RandomSwap, 3),
            (ModelKind::Disney, Reciprocity::None, 5),
            (ModelKind::Fmbrdf, Reciprocity::None, 5),
            (ModelKind::Rp, Reciprocity::None, 3),
        ];
        for (kind, reciprocity, k) in cases {
            let mut config = ModelConfig { kind, spatial_dim: k, ..Default::default() };
            config.angles.reciprocity = reciprocity;
            config.angles.swap_probability = 0.5;
            let rows: Vec<f32> = (0..points * k).map(|i| (i as f32 * 0.71).cos()).collect();
            let gathered: Vec<f32> = batch
                .iter()
                .flat_map(|&r| {
                    let p = point[r as usize] as usize;
                    rows[p * k..(p + 1) * k].to_vec()
                })
                .collect();
            let spatial = (k > 0).then(|| SpatialTable::new(&config, &rows, &device).unwrap());
            let table = RecordTable::new(&config, &l, &v, &point, &device).unwrap();
            assert_eq!(table.records(), records);
            // A mask only with the random swap, as the trainer draws one.
            let mask = (reciprocity == Reciprocity::RandomSwap).then_some(&swap[..]);
            let index = table.index(&batch, mask, &device).unwrap();
            let a = BrdfBatch::from_owned(&config, gathered, &bl, &bv, mask, &device).unwrap();
            let b = BrdfBatch::from_records(&config, &table, spatial.as_ref(), &index, &device)
                .unwrap();
            let name = format!("{kind:?} {reciprocity:?} k={k}");
            assert_eq!(bits(a.spatial.clone()), bits(b.spatial.clone()), "{name}: spatial");
            assert_eq!(a.angles.is_some(), b.angles.is_some(), "{name}");
            if let (Some(x), Some(y)) = (&a.angles, &b.angles) {
                assert_eq!(bits(x.clone()), bits(y.clone()), "{name}: angles");
            }
            assert_eq!(a.geometry.is_some(), b.geometry.is_some(), "{name}");
            let model = crate::BrdfModel::init(&config, &device).unwrap();
            let (fa, fb) = (model.forward(&a), model.forward(&b));
            assert_eq!(bits(fa.f), bits(fb.f), "{name}: output");
            let bytes = RecordTable::bytes(&config, records);
            assert!(bytes > 0 && bytes.is_multiple_of(4 * records), "{name}: {bytes} bytes");
        }
        let config = ModelConfig { spatial_dim: 5, ..Default::default() };
        let table = RecordTable::new(&config, &l, &v, &point, &device).unwrap();
        assert!(table.index(&[records as u32], None, &device).is_err(), "record outside");
        assert!(table.index(&[0, 1], Some(&[true]), &device).is_err(), "mask length");
        assert!(table.index(&[0], Some(&[true]), &device).is_err(), "a swap without swapped rows");
        assert!(RecordTable::new(&config, &l, &v[1..], &point, &device).is_err(), "lengths");
        let index = table.index(&[0], None, &device).unwrap();
        let no_rows = BrdfBatch::from_records(&config, &table, None, &index, &device);
        assert!(no_rows.is_err(), "spatial features without a spatial table");
    }
}
