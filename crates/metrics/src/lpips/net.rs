//! The LPIPS network on burn: AlexNet's five conv layers, per-layer unit normalisation, squared
//! difference, the 1x1 `lin` layers and the spatial mean.

use super::weights::{Tensors, read};
use crate::error::{Error, Result};
use crate::image::{Image, check_pair};
use burn::tensor::activation::relu;
use burn::tensor::module::{conv2d, max_pool2d};
use burn::tensor::ops::{ConvOptions, MaxPoolOptions};
use burn::tensor::{Device, Tensor, TensorData};
use std::path::Path;

/// (stride, padding) of AlexNet's conv1..conv5, and whether a 3/2 max-pool precedes the layer.
const LAYERS: [(usize, usize, bool); 5] =
    [(4, 2, false), (1, 2, true), (1, 1, true), (1, 1, false), (1, 1, false)];
const SHIFT: [f32; 3] = [-0.030, -0.088, -0.188];
const SCALE: [f32; 3] = [0.458, 0.448, 0.450];

/// LPIPS with loaded weights (any channel counts; the official file has 64, 192, 384, 256, 256).
#[derive(Debug)]
pub struct Lpips {
    conv: Vec<(Tensor<4>, Tensor<1>)>,
    lin: Vec<Tensor<4>>,
    device: Device,
}

impl Lpips {
    /// Loads the weight file at `path` (format in [`super::weights`]).
    pub fn load(path: &Path, device: &Device) -> Result<Self> {
        Self::from_tensors(&read(path)?, device)
            .map_err(|reason| Error::WeightFormat { path: path.into(), reason })
    }

    /// Builds the network from named tensors; the error names the missing or misshaped tensor.
    pub fn from_tensors(t: &Tensors, device: &Device) -> std::result::Result<Self, String> {
        let get =
            |name: &str, rank: usize| -> std::result::Result<&(Vec<usize>, Vec<f32>), String> {
                let v = t.get(name).ok_or(format!("missing tensor {name}"))?;
                if v.0.len() != rank {
                    return Err(format!("{name}: rank {} (want {rank})", v.0.len()));
                }
                Ok(v)
            };
        let mut conv = Vec::new();
        let mut lin = Vec::new();
        let mut in_ch = 3;
        for k in 0..5 {
            let (wd, wv) = get(&format!("conv{}.weight", k + 1), 4)?;
            let (bd, bv) = get(&format!("conv{}.bias", k + 1), 1)?;
            let (ld, lv) = get(&format!("lin{k}.weight"), 4)?;
            if wd[1] != in_ch || bd[0] != wd[0] || ld[..] != [1, wd[0], 1, 1] {
                return Err(format!("layer {k}: shapes {wd:?}, {bd:?}, {ld:?} do not fit"));
            }
            in_ch = wd[0];
            let w = Tensor::from_data(
                TensorData::new(wv.clone(), [wd[0], wd[1], wd[2], wd[3]]),
                device,
            );
            let b = Tensor::from_data(TensorData::new(bv.clone(), [bd[0]]), device);
            conv.push((w, b));
            lin.push(Tensor::from_data(TensorData::new(lv.clone(), [1, ld[1], 1, 1]), device));
        }
        Ok(Self { conv, lin, device: device.clone() })
    }

    /// LPIPS distance of two sRGB images in [0, 1] (values are clamped to [0, 1]).
    pub fn distance(&self, test: &Image, reference: &Image) -> Result<f64> {
        check_pair(test, reference, None)?;
        let fa = self.features(test)?;
        let fb = self.features(reference)?;
        let mut total = 0.0f64;
        for ((a, b), lin) in fa.into_iter().zip(fb).zip(&self.lin) {
            let d = (normalize(a) - normalize(b)).powi_scalar(2);
            let weighted =
                conv2d(d, lin.clone(), None, ConvOptions::new([1, 1], [0, 0], [1, 1], 1));
            let v: Vec<f32> = weighted
                .mean()
                .into_data()
                .try_to_vec::<f32>()
                .map_err(|e| Error::Config(format!("LPIPS: reading a tensor failed: {e:?}")))?;
            total += v[0] as f64;
        }
        Ok(total)
    }

    /// The five ReLU feature maps of an image.
    fn features(&self, img: &Image) -> Result<Vec<Tensor<4>>> {
        let (w, h) = (img.width(), img.height());
        let mut planar = vec![0.0f32; 3 * w * h];
        for (p, px) in img.data().chunks_exact(3).enumerate() {
            for c in 0..3 {
                let x = 2.0 * px[c].clamp(0.0, 1.0) - 1.0;
                planar[c * w * h + p] = (x - SHIFT[c]) / SCALE[c];
            }
        }
        let mut x: Tensor<4> =
            Tensor::from_data(TensorData::new(planar, [1, 3, h, w]), &self.device);
        let mut out = Vec::with_capacity(5);
        for ((stride, pad, pool), (wt, b)) in LAYERS.iter().zip(&self.conv) {
            if *pool {
                x = max_pool2d(x, MaxPoolOptions::new([3, 3]).with_stride([2, 2]));
            }
            let [_, _, hh, ww] = x.dims();
            let k = wt.dims()[2];
            if hh + 2 * pad < k || ww + 2 * pad < k {
                return Err(Error::TooSmall { metric: "LPIPS", width: w, height: h, window: k });
            }
            x = relu(conv2d(
                x,
                wt.clone(),
                Some(b.clone()),
                ConvOptions::new([*stride; 2], [*pad; 2], [1, 1], 1),
            ));
            out.push(x.clone());
        }
        Ok(out)
    }
}

/// x / (||x||_channels + 1e-10) per pixel.
fn normalize(x: Tensor<4>) -> Tensor<4> {
    let norm = x.clone().powi_scalar(2).sum_dim(1).sqrt();
    x / (norm + 1e-10)
}

#[cfg(test)]
mod tests;
