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
        let n = s.l.len();
        if s.v.len() != n || s.spatial.len() != n * self.spatial_dim {
            return Err(Error::BatchShape(format!(
                "{} light and {} view directions, {} spatial values for spatial_dim {}",
                n,
                s.v.len(),
                s.spatial.len(),
                self.spatial_dim
            )));
        }
        if swap.is_some_and(|m| m.len() != n) {
            return Err(Error::BatchShape("swap mask length differs from the batch".into()));
        }
        let spatial: Vec<f32> = {
            use rayon::prelude::*;
            s.spatial
                .par_iter()
                .with_min_len(1 << 14)
                .map(|&x| if x.is_nan() { 0.0 } else { x.clamp(-SPATIAL_LIMIT, SPATIAL_LIMIT) })
                .collect()
        };
        let spatial = Tensor::from_data(TensorData::new(spatial, [n, self.spatial_dim]), device);
        let angles = self.uses_angle_features().then(|| {
            let d = self.angles.dim();
            let a = self.angles.encode_batch(s.l, s.v, swap);
            Tensor::from_data(TensorData::new(a, [n, d]), device)
        });
        let geometry = (!self.uses_angle_features())
            .then(|| Geometry::new(s.l, s.v, self.kind == ModelKind::Fmbrdf, device));
        Ok(BrdfBatch { spatial, angles, geometry })
    }
}
