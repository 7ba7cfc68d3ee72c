//! The model input: spatial features and directions of a batch of samples, uploaded once.
//!
//! Directions are unit vectors in the local shading frame (normal on +z; the caller rotates
//! world directions with `angles::Frame`). Angle features (purely neural models) and the
//! direction-only geometry terms (parametric models) are computed here on the CPU; see
//! [`crate::features`] and [`crate::tensor_brdf::Geometry`].
//!
//! Spatial features are sanitised: NaN becomes 0 and values are clamped into
//! [-[`SPATIAL_LIMIT`], [`SPATIAL_LIMIT`]] (the LBO features lie in [-1, 1]), so that no input
//! can make a model's output overflow.
//!
//! A training loop on a GPU keeps the feature rows of all its surface points on the device
//! ([`SpatialTable`], sanitised once) and selects each batch's rows there
//! ([`BrdfBatch::from_table`]): the same values as gathering them on the CPU and uploading
//! them with every batch ([`BrdfBatch::from_owned`]), without the copy and the transfer.

use crate::products::Products;
use crate::tensor_brdf::Geometry;
use crate::{Error, ModelConfig, ModelKind, Result};
use burn::tensor::{Device, Int, Tensor, TensorData};

/// Bound on the magnitude of a spatial feature value.
pub const SPATIAL_LIMIT: f32 = 1e3;

/// Samples on the CPU.
#[derive(Clone, Copy, Debug)]
pub struct Samples<'a> {
    /// Spatial features, row-major `[n, spatial_dim]`.
    pub spatial: &'a [f32],
    /// Directions to the light, local frame, `n` unit vectors.
    pub l: &'a [[f32; 3]],
    /// Directions to the viewer, local frame, `n` unit vectors.
    pub v: &'a [[f32; 3]],
}

/// A batch on the device.
#[derive(Clone, Debug)]
pub struct BrdfBatch {
    /// Spatial features, `[batch, spatial_dim]`.
    pub spatial: Tensor<2>,
    /// Encoded direction features, `[batch, angle_dim]` (purely neural models).
    pub angles: Option<Tensor<2>>,
    /// Direction-only BRDF terms (parametric models).
    pub geometry: Option<Geometry>,
    /// How the model's linear layers compute their products on this batch: plain f32 unless
    /// set ([`BrdfBatch::with_products`]; a training step's batches carry the run's).
    pub products: Products,
}

/// The spatial feature rows of a set of surface points on the device, sanitised, for
/// [`BrdfBatch::from_table`].
#[derive(Clone, Debug)]
pub struct SpatialTable {
    /// `[points, spatial_dim]`.
    rows: Tensor<2>,
    /// Number of rows.
    points: usize,
}

impl SpatialTable {
    /// Number of points (rows).
    pub fn points(&self) -> usize {
        self.points
    }

    /// Width of a row (the model's `spatial_dim`).
    pub fn width(&self) -> usize {
        self.rows.dims()[1]
    }

    /// The rows `points`, `[points.len(), width]`.
    pub(crate) fn select(&self, points: Tensor<1, Int>) -> Tensor<2> {
        self.rows.clone().select(0, points)
    }
}

/// NaN to 0 and every value into [-[`SPATIAL_LIMIT`], [`SPATIAL_LIMIT`]], on every thread.
fn sanitise(values: &mut [f32]) {
    use rayon::prelude::*;
    values
        .par_iter_mut()
        .with_min_len(1 << 14)
        .for_each(|x| *x = if x.is_nan() { 0.0 } else { x.clamp(-SPATIAL_LIMIT, SPATIAL_LIMIT) });
}

impl SpatialTable {
    /// Uploads the feature rows of a set of points (row-major `[points, spatial_dim]` of
    /// `config`), sanitised, for [`BrdfBatch::from_table`].
    pub fn new(config: &ModelConfig, rows: &[f32], device: &Device) -> Result<SpatialTable> {
        let k = config.spatial_dim;
        if k == 0 || !rows.len().is_multiple_of(k) {
            return Err(Error::BatchShape(format!(
                "a spatial table of {} values for spatial_dim {k}",
                rows.len()
            )));
        }
        let points = rows.len() / k;
        let mut rows = rows.to_vec();
        sanitise(&mut rows);
        let rows = Tensor::from_data(TensorData::new(rows, [points, k]), device);
        Ok(SpatialTable { rows, points })
    }
}

impl BrdfBatch {
    /// Uploads a batch for the model of `config`. `swap[i]` swaps l and v in the network input
    /// of sample i (training with [`crate::Reciprocity::RandomSwap`]; see
    /// [`crate::AngleConfig::swap_mask`]); the geometry of parametric models always uses the
    /// true directions.
    pub fn new(
        config: &ModelConfig,
        s: &Samples,
        swap: Option<&[bool]>,
        device: &Device,
    ) -> Result<BrdfBatch> {
        Self::from_owned(config, s.spatial.to_vec(), s.l, s.v, swap, device)
    }

    /// [`BrdfBatch::new`] for spatial features the caller hands over (a freshly gathered
    /// training batch): they are sanitised in place and become the tensor's storage, with no
    /// copy. The same values as `new` with `Samples { spatial: &spatial, l, v }`.
    pub fn from_owned(
        config: &ModelConfig,
        mut spatial: Vec<f32>,
        l: &[[f32; 3]],
        v: &[[f32; 3]],
        swap: Option<&[bool]>,
        device: &Device,
    ) -> Result<BrdfBatch> {
        let n = l.len();
        if v.len() != n || spatial.len() != n * config.spatial_dim {
            return Err(Error::BatchShape(format!(
                "{} light and {} view directions, {} spatial values for spatial_dim {}",
                n,
                v.len(),
                spatial.len(),
                config.spatial_dim
            )));
        }
        sanitise(&mut spatial);
        let spatial = Tensor::from_data(TensorData::new(spatial, [n, config.spatial_dim]), device);
        Self::with_spatial(config, spatial, l, v, swap, device)
    }

    /// [`BrdfBatch::new`] with the spatial features of sample i the row `points[i]` of
    /// `table`, selected on the device: the same values as `new` with those rows gathered on
    /// the CPU.
    pub fn from_table(
        config: &ModelConfig,
        table: &SpatialTable,
        points: &[u32],
        l: &[[f32; 3]],
        v: &[[f32; 3]],
        swap: Option<&[bool]>,
        device: &Device,
    ) -> Result<BrdfBatch> {
        let n = l.len();
        let [_, k] = table.rows.dims();
        if points.len() != n || k != config.spatial_dim {
            return Err(Error::BatchShape(format!(
                "{} points for {n} samples, a table of width {k} for spatial_dim {}",
                points.len(),
                config.spatial_dim
            )));
        }
        if let Some(&p) = points.iter().find(|&&p| p as usize >= table.points) {
            return Err(Error::BatchShape(format!(
                "point {p} outside a spatial table of {} points",
                table.points
            )));
        }
        let index: Vec<i32> = points.iter().map(|&p| p as i32).collect();
        let index = Tensor::<1, Int>::from_data(TensorData::new(index, [n]), device);
        let spatial = table.rows.clone().select(0, index);
        Self::with_spatial(config, spatial, l, v, swap, device)
    }

    /// The batch of the spatial rows `spatial` (on the device) and the directions.
    fn with_spatial(
        config: &ModelConfig,
        spatial: Tensor<2>,
        l: &[[f32; 3]],
        v: &[[f32; 3]],
        swap: Option<&[bool]>,
        device: &Device,
    ) -> Result<BrdfBatch> {
        let n = l.len();
        if v.len() != n {
            return Err(Error::BatchShape(format!("{n} light and {} view directions", v.len())));
        }
        if swap.is_some_and(|m| m.len() != n) {
            return Err(Error::BatchShape("swap mask length differs from the batch".into()));
        }
        let angles = config.uses_angle_features().then(|| {
            let d = config.angles.dim();
            let a = config.angles.encode_batch(l, v, swap);
            Tensor::from_data(TensorData::new(a, [n, d]), device)
        });
        let geometry = (!config.uses_angle_features())
            .then(|| Geometry::new(l, v, config.kind == ModelKind::Fmbrdf, device));
        Ok(BrdfBatch { spatial, angles, geometry, products: Products::F32 })
    }

    /// The same batch, its linear layers' products computed as `products` says.
    pub fn with_products(self, products: Products) -> BrdfBatch {
        BrdfBatch { products, ..self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ModelConfig, ModelKind};

    /// `from_owned` (the training path, sanitising in place) gives the tensors `new` gives
    /// (sanitising a copy), bit for bit, for every kind of input: NaN, infinities, huge values.
    #[test]
    fn owned_and_borrowed_batches_agree_bitwise() {
        let device = crate::device::cpu();
        let n = 3000; // several parallel chunks of the in-place sanitiser
        for kind in [ModelKind::SingleMlp, ModelKind::Disney] {
            let config = ModelConfig { kind, spatial_dim: 7, ..Default::default() };
            let special = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30, 999.0, -0.0];
            let spatial: Vec<f32> = (0..n * 7)
                .map(|i| if i % 11 == 0 { special[i / 11 % 7] } else { (i as f32 * 0.37).sin() })
                .collect();
            let dir = |i: usize, s: f32| {
                let (a, b) = ((i as f32 * 0.1 + s).sin() * 0.5, (i as f32 * 0.07 - s).cos() * 0.5);
                [a, b, (1.0 - a * a - b * b).sqrt()]
            };
            let l: Vec<[f32; 3]> = (0..n).map(|i| dir(i, 0.3)).collect();
            let v: Vec<[f32; 3]> = (0..n).map(|i| dir(i, 1.1)).collect();
            let swap: Vec<bool> = (0..n).map(|i| i % 3 == 0).collect();
            let s = Samples { spatial: &spatial, l: &l, v: &v };
            let a = BrdfBatch::new(&config, &s, Some(&swap), &device).unwrap();
            let b = BrdfBatch::from_owned(&config, spatial.clone(), &l, &v, Some(&swap), &device)
                .unwrap();
            let bits = |t: &Tensor<2>| -> Vec<u32> {
                t.clone()
                    .into_data()
                    .try_to_vec::<f32>()
                    .unwrap()
                    .iter()
                    .map(|x| x.to_bits())
                    .collect()
            };
            assert_eq!(bits(&a.spatial), bits(&b.spatial), "{kind:?} spatial");
            let clean = a.spatial.clone().into_data().try_to_vec::<f32>().unwrap();
            assert!(clean.iter().all(|x| x.abs() <= SPATIAL_LIMIT), "{kind:?}: sanitised");
            assert_eq!(a.angles.is_some(), b.angles.is_some());
            if let (Some(x), Some(y)) = (&a.angles, &b.angles) {
                assert_eq!(bits(x), bits(y), "{kind:?} angles");
            }
            assert_eq!(a.geometry.is_some(), b.geometry.is_some());
        }
        let config = ModelConfig { spatial_dim: 7, ..Default::default() };
        let l = [[0.0, 0.0, 1.0]];
        assert!(
            BrdfBatch::from_owned(&config, vec![0.0; 6], &l, &l, None, &device).is_err(),
            "short rows"
        );
        assert!(
            BrdfBatch::from_owned(&config, vec![0.0; 7], &l, &l, Some(&[]), &device).is_err(),
            "mask"
        );
    }

    /// Rows selected from a [`SpatialTable`] on the device give the batch that gathering
    /// the same rows on the CPU gives, bit for bit (the model's output too, so the geometry of
    /// the parametric models agrees as well); bad points and shapes are errors.
    #[test]
    fn table_batches_agree_with_gathered_batches_bitwise() {
        let device = crate::device::cpu();
        let (k, points, n) = (5, 40, 300);
        let special = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -0.0];
        let table: Vec<f32> = (0..points * k)
            .map(|i| if i % 13 == 0 { special[i / 13 % 5] } else { (i as f32 * 0.71).cos() })
            .collect();
        let rows: Vec<u32> = (0..n).map(|i| ((i * 7 + i / 3) % points) as u32).collect();
        let gathered: Vec<f32> = rows
            .iter()
            .flat_map(|&p| table[p as usize * k..(p as usize + 1) * k].to_vec())
            .collect();
        let dir = |i: usize, s: f32| {
            let (a, b) = ((i as f32 * 0.13 + s).sin() * 0.6, (i as f32 * 0.05 - s).cos() * 0.6);
            [a, b, (1.0 - a * a - b * b).max(0.0).sqrt()]
        };
        let l: Vec<[f32; 3]> = (0..n).map(|i| dir(i, 0.2)).collect();
        let v: Vec<[f32; 3]> = (0..n).map(|i| dir(i, 0.9)).collect();
        let swap: Vec<bool> = (0..n).map(|i| i % 4 == 1).collect();
        let bits = |t: Tensor<2>| -> Vec<u32> {
            t.into_data().try_to_vec::<f32>().unwrap().iter().map(|x| x.to_bits()).collect()
        };
        for kind in [ModelKind::SingleMlp, ModelKind::Disney, ModelKind::Fmbrdf] {
            let config = ModelConfig { kind, spatial_dim: k, ..Default::default() };
            let t = SpatialTable::new(&config, &table, &device).unwrap();
            assert_eq!(t.points(), points);
            let a = BrdfBatch::from_owned(&config, gathered.clone(), &l, &v, Some(&swap), &device)
                .unwrap();
            let b =
                BrdfBatch::from_table(&config, &t, &rows, &l, &v, Some(&swap), &device).unwrap();
            assert_eq!(bits(a.spatial.clone()), bits(b.spatial.clone()), "{kind:?} spatial");
            if let (Some(x), Some(y)) = (&a.angles, &b.angles) {
                assert_eq!(bits(x.clone()), bits(y.clone()), "{kind:?} angles");
            }
            assert_eq!(a.angles.is_some(), b.angles.is_some());
            let model = crate::BrdfModel::init(&config, &device).unwrap();
            let (fa, fb) = (model.forward(&a), model.forward(&b));
            assert_eq!(bits(fa.f), bits(fb.f), "{kind:?} output");
        }
        let config = ModelConfig { spatial_dim: k, ..Default::default() };
        let t = SpatialTable::new(&config, &table, &device).unwrap();
        let one = [[0.0, 0.0, 1.0]];
        let far = [points as u32];
        assert!(
            BrdfBatch::from_table(&config, &t, &far, &one, &one, None, &device).is_err(),
            "point"
        );
        assert!(
            BrdfBatch::from_table(&config, &t, &[0, 1], &one, &one, None, &device).is_err(),
            "len"
        );
        assert!(
            BrdfBatch::from_table(&config, &t, &[0], &one, &[], None, &device).is_err(),
            "views"
        );
        assert!(SpatialTable::new(&config, &table[..k + 1], &device).is_err(), "ragged table");
        let wide = ModelConfig { spatial_dim: k + 1, ..Default::default() };
        assert!(
            BrdfBatch::from_table(&wide, &t, &[0], &one, &one, None, &device).is_err(),
            "width"
        );
    }
}
