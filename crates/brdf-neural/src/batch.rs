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

use crate::tensor_brdf::Geometry;
use crate::{Error, ModelConfig, ModelKind, Result};
use burn::tensor::{Device, Tensor, TensorData};

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
}

impl ModelConfig {
    /// Uploads a batch for this model. `swap[i]` swaps l and v in the network input of sample
    /// i (training with [`crate::Reciprocity::RandomSwap`]; see
    /// [`crate::AngleConfig::swap_mask`]); the geometry of parametric models always uses the
    /// true directions.
    pub fn batch(&self, s: &Samples, swap: Option<&[bool]>, device: &Device) -> Result<BrdfBatch> {
        self.batch_owned(s.spatial.to_vec(), s.l, s.v, swap, device)
    }

    /// [`ModelConfig::batch`] for spatial features the caller hands over (a freshly gathered
    /// training batch): they are sanitised in place and become the tensor's storage, with no
    /// copy. The same values as `batch` with `Samples { spatial: &spatial, l, v }`.
    pub fn batch_owned(
        &self,
        mut spatial: Vec<f32>,
        l: &[[f32; 3]],
        v: &[[f32; 3]],
        swap: Option<&[bool]>,
        device: &Device,
    ) -> Result<BrdfBatch> {
        let n = l.len();
        if v.len() != n || spatial.len() != n * self.spatial_dim {
            return Err(Error::BatchShape(format!(
                "{} light and {} view directions, {} spatial values for spatial_dim {}",
                n,
                v.len(),
                spatial.len(),
                self.spatial_dim
            )));
        }
        if swap.is_some_and(|m| m.len() != n) {
            return Err(Error::BatchShape("swap mask length differs from the batch".into()));
        }
        {
            use rayon::prelude::*;
            spatial.par_iter_mut().with_min_len(1 << 14).for_each(|x| {
                *x = if x.is_nan() { 0.0 } else { x.clamp(-SPATIAL_LIMIT, SPATIAL_LIMIT) }
            });
        }
        let spatial = Tensor::from_data(TensorData::new(spatial, [n, self.spatial_dim]), device);
        let angles = self.uses_angle_features().then(|| {
            let d = self.angles.dim();
            let a = self.angles.encode_batch(l, v, swap);
            Tensor::from_data(TensorData::new(a, [n, d]), device)
        });
        let geometry = (!self.uses_angle_features())
            .then(|| Geometry::new(l, v, self.kind == ModelKind::Fmbrdf, device));
        Ok(BrdfBatch { spatial, angles, geometry })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ModelConfig, ModelKind};

    /// `batch_owned` (the training path, sanitising in place) gives the tensors `batch` gives
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
            let a = config.batch(&s, Some(&swap), &device).unwrap();
            let b = config.batch_owned(spatial.clone(), &l, &v, Some(&swap), &device).unwrap();
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
        assert!(config.batch_owned(vec![0.0; 6], &l, &l, None, &device).is_err(), "short rows");
        assert!(config.batch_owned(vec![0.0; 7], &l, &l, Some(&[]), &device).is_err(), "mask");
    }
}
