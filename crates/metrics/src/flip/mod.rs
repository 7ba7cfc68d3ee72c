//! HDR-FLIP (Andersson et al. 2021) on linear HDR images, a port of the math of NVlabs/flip
//! (`src/pytorch/flip_loss.py`, `src/cpp/FLIP.h`), spec section 7.
//!
//! Steps: clamp both images to [0, 65536]; from the reference luminance
//! Y = 0.2126 R + 0.7152 G + 0.0722 B take start = log2(x_max / max Y) and
//! stop = log2(x_max / median Y) with x_max = 2.11887 the ACES input that maps to 0.85;
//! N = max(2, ceil(stop - start)) exposures e_i = start + i (stop - start) / (N - 1); per exposure
//! scale by 2^e_i, ACES tone map (pre-exposure 0.6 folded into the constants), clamp to [0, 1],
//! convert to YCxCz and compute LDR-FLIP (CSF filtering, Hunt-adjusted HyAB colour difference
//! remapped with p_c = 0.4, p_t = 0.95, edge and point feature difference, FLIP = dE_c^(1 - dE_f));
//! the HDR-FLIP map is the per-pixel maximum over exposures and the score its mean.
//!
//! **Parity.** Without a mask, [`hdr_flip`] reproduces NVIDIA's reference (the `flip-evaluator`
//! package, the C++ tool): the median is the element at index n / 2 of the sorted luminances (the
//! C++ `nth_element` convention; the PyTorch file takes the lower middle, which differs only for
//! an even pixel count); every filter is applied as exact separable passes (see
//! [`filter`]). The test `flip_matches_flip_evaluator` holds reference values of the official tool.
//!
//! **Mask.** With a mask only the masked reference pixels enter max Y and median Y, and only the
//! masked pixels enter the mean; the filters still see the whole image, so the map at a masked
//! pixel is the unmasked map's value for the same exposure range.
//!
//! A reference whose (masked) maximum or median luminance is 0 has no exposure range (stop would
//! be infinite: the pitfall of black backgrounds): that is an [`Error::Exposure`] unless the
//! exposures are given in [`FlipConfig`].
//!
//! **Windows.** A FLIP value depends on the inputs within a few pixels of it only, so the
//! comparisons of an object that covers part of the frame can run on a window around it
//! ([`window`], [`FlipWindow`]) with the whole frame's results, bit for bit.

pub mod color;
pub mod filter;
mod ldr;
pub mod window;

pub use window::FlipWindow;

use crate::error::{Error, Result};
use crate::image::{Image, check_pair, selected};
use rayon::prelude::*;

/// The default pixels per degree: a 0.7 m wide 4K monitor at 0.7 m, 3840 / 0.7 * 0.7 * pi / 180.
pub const DEFAULT_PPD: f64 = 0.7 * 3840.0 / 0.7 * std::f64::consts::PI / 180.0;

/// ACES constants with the pre-exposure 0.6 folded in.
const ACES: [f32; 6] = [0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14];

/// HDR-FLIP settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlipConfig {
    /// Observer's pixels per degree (default [`DEFAULT_PPD`] = 67.02).
    pub pixels_per_degree: f64,
    /// Start exposure (log2); `None` derives it from the reference (default).
    pub start_exposure: Option<f64>,
    /// Stop exposure (log2); `None` derives it from the reference (default).
    pub stop_exposure: Option<f64>,
}

impl Default for FlipConfig {
    fn default() -> Self {
        Self { pixels_per_degree: DEFAULT_PPD, start_exposure: None, stop_exposure: None }
    }
}

/// An HDR-FLIP result.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipResult {
    /// Mean of the map over the (masked) pixels, in [0, 1].
    pub mean: f64,
    /// Per-pixel HDR-FLIP, row-major (unmasked pixels too).
    pub map: Vec<f32>,
    /// Start exposure used.
    pub start_exposure: f64,
    /// Stop exposure used.
    pub stop_exposure: f64,
    /// Number of exposures.
    pub exposures: usize,
}

/// ACES filmic tone curve (Narkowicz), clamped to [0, 1].
#[inline]
pub fn aces(x: f32) -> f32 {
    let [k0, k1, k2, k3, k4, k5] = ACES;
    let x2 = x * x;
    let den = k3 * x2 + k4 * x + k5;
    if den.is_infinite() {
        return 1.0;
    }
    ((k0 * x2 + k1 * x + k2) / den).clamp(0.0, 1.0)
}

/// The larger root x of aces(x) = t (2.11887 for t = 0.85).
pub fn aces_inverse(t: f64) -> f64 {
    let k = ACES.map(|v| v as f64);
    let c0 = (k[1] - k[4] * t) / (k[0] - k[3] * t);
    let c1 = (k[2] - k[5] * t) / (k[0] - k[3] * t);
    -0.5 * c0 + ((0.5 * c0).powi(2) - c1).sqrt()
}

/// (start, stop) exposures from the reference's masked luminance.
pub fn exposure_range(reference: &Image, mask: Option<&[bool]>) -> Result<(f64, f64)> {
    let mut lum: Vec<f32> = (0..reference.pixels())
        .filter(|&p| selected(mask, p))
        .map(|p| {
            let [r, g, b] = reference.pixel(p % reference.width(), p / reference.width());
            let [r, g, b] = [r, g, b].map(|v| v.clamp(0.0, 65536.0));
            0.2126 * r + 0.7152 * g + 0.0722 * b
        })
        .collect();
    if lum.is_empty() {
        return Err(Error::Empty("HDR-FLIP exposure range"));
    }
    let n = lum.len();
    let (_, median, _) = lum.select_nth_unstable_by(n / 2, f32::total_cmp);
    let median = *median as f64;
    let max = lum.iter().copied().fold(0.0f32, f32::max) as f64;
    if max <= 0.0 || median <= 0.0 {
        return Err(Error::Exposure(format!(
            "reference luminance has max {max} and median {median}; a zero median (e.g. black \
             background) gives an infinite stop exposure: pass a mask or explicit exposures"
        )));
    }
    let x_max = aces_inverse(0.85);
    Ok(((x_max / max).log2(), (x_max / median).log2()))
}

/// HDR-FLIP of a linear HDR `test` image against `reference` (see the module doc).
pub fn hdr_flip_with(
    test: &Image,
    reference: &Image,
    mask: Option<&[bool]>,
    cfg: &FlipConfig,
) -> Result<FlipResult> {
    check_pair(test, reference, mask)?;
    let exposures = match (cfg.start_exposure, cfg.stop_exposure) {
        (Some(a), Some(b)) => (a, b),
        (a, b) => {
            let (s, t) = exposure_range(reference, mask)?;
            (a.unwrap_or(s), b.unwrap_or(t))
        }
    };
    let at = FlipExposures::new(exposures, cfg.pixels_per_degree)?;
    hdr_flip_prepared(&FlipImage::new(test, &at)?, &FlipImage::new(reference, &at)?, mask)
}

/// The exposures and viewing condition of an HDR-FLIP comparison: what two [`FlipImage`]s must
/// share to be compared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlipExposures {
    start: f64,
    stop: f64,
    pixels_per_degree: f64,
}

impl FlipExposures {
    /// The exposure range `(start, stop)` (log2) seen at `pixels_per_degree`.
    ///
    /// # Errors
    /// A range or a pixels-per-degree value that is not finite (or not positive).
    pub fn new((start, stop): (f64, f64), pixels_per_degree: f64) -> Result<Self> {
        if !(pixels_per_degree > 0.0 && pixels_per_degree.is_finite()) {
            return Err(Error::Config(format!("HDR-FLIP: pixels per degree {pixels_per_degree}")));
        }
        if !(start.is_finite() && stop.is_finite()) {
            return Err(Error::Exposure(format!("exposure range [{start}, {stop}] is not finite")));
        }
        Ok(FlipExposures { start, stop, pixels_per_degree })
    }

    /// The exposures' count, N = max(2, ceil(stop - start)).
    pub fn count(&self) -> usize {
        ((self.stop - self.start).ceil()).max(2.0) as usize
    }

    /// The scale 2^e_i of exposure `i`.
    fn scale(&self, i: usize) -> f32 {
        let step = (self.stop - self.start) / (self.count() - 1) as f64;
        (self.start + i as f64 * step).exp2() as f32
    }
}

/// One image prepared for HDR-FLIP at given exposures: per exposure, its tone-mapped,
/// CSF-filtered colours and its edge and point features. Comparing two prepared images costs
/// only the per-pixel differences, so an image compared several times at the same exposures
/// (an evaluation scores one render against the observation, its background-free copy and the
/// noise-free render, and the noise-free render against the observation) is filtered once; the
/// result is bit for bit that of [`hdr_flip_with`] with the same exposures.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipImage {
    width: usize,
    height: usize,
    at: FlipExposures,
    per_exposure: Vec<ldr::Prepared>,
}

impl FlipImage {
    /// `image` prepared at the exposures `at`.
    ///
    /// # Errors
    /// An image with a NaN pixel.
    pub fn new(image: &Image, at: &FlipExposures) -> Result<FlipImage> {
        image.check_no_nan("HDR-FLIP image")?;
        let (w, h) = (image.width(), image.height());
        let ldr = ldr::LdrFlip::new(at.pixels_per_degree);
        let to_planes = |scale: f32| -> [Vec<f32>; 3] {
            let mut planes = [vec![0.0; w * h], vec![0.0; w * h], vec![0.0; w * h]];
            for (p, px) in image.data().chunks_exact(3).enumerate() {
                let rgb = [px[0], px[1], px[2]].map(|v| aces(scale * v.clamp(0.0, 65536.0)));
                let y = color::linrgb_to_ycxcz(rgb);
                for c in 0..3 {
                    planes[c][p] = y[c];
                }
            }
            planes
        };
        let per_exposure = (0..at.count())
            .into_par_iter()
            .map(|i| ldr.prepare(&to_planes(at.scale(i)), w, h))
            .collect();
        Ok(FlipImage { width: w, height: h, at: *at, per_exposure })
    }
}

/// HDR-FLIP of the prepared `test` against the prepared `reference` (the same size and
/// exposures); `mask` selects the pixels of the mean.
///
/// # Errors
/// Images of different sizes or exposures, or a mask of another length or with no pixel.
pub fn hdr_flip_prepared(
    test: &FlipImage,
    reference: &FlipImage,
    mask: Option<&[bool]>,
) -> Result<FlipResult> {
    let (w, h) = (test.width, test.height);
    if (reference.width, reference.height) != (w, h) {
        return Err(Error::SizeMismatch {
            test: (w, h),
            reference: (reference.width, reference.height),
        });
    }
    if test.at != reference.at {
        return Err(Error::Config(format!(
            "HDR-FLIP: test prepared at {:?}, reference at {:?}",
            test.at, reference.at
        )));
    }
    if let Some(m) = mask
        && m.len() != w * h
    {
        return Err(Error::MaskSize { mask: m.len(), pixels: w * h });
    }
    let ldr = ldr::LdrFlip::new(test.at.pixels_per_degree);
    let maps: Vec<Vec<f32>> = test
        .per_exposure
        .par_iter()
        .zip(&reference.per_exposure)
        .map(|(t, r)| ldr.error_map(t, r))
        .collect();
    let mut map = vec![0.0f32; w * h];
    for m in &maps {
        for (a, b) in map.iter_mut().zip(m) {
            *a = a.max(*b);
        }
    }
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (p, v) in map.iter().enumerate() {
        if selected(mask, p) {
            sum += *v as f64;
            n += 1;
        }
    }
    if n == 0 {
        return Err(Error::Empty("HDR-FLIP mean"));
    }
    Ok(FlipResult {
        mean: sum / n as f64,
        map,
        start_exposure: test.at.start,
        stop_exposure: test.at.stop,
        exposures: test.at.count(),
    })
}

/// [`hdr_flip_with`] with the default viewing condition; returns the mean.
pub fn hdr_flip(test: &Image, reference: &Image, mask: Option<&[bool]>) -> Result<f64> {
    Ok(hdr_flip_with(test, reference, mask, &FlipConfig::default())?.mean)
}

#[cfg(test)]
mod tests;
