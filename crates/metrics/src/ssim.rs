//! SSIM (Wang et al. 2004) and DSSIM = (1 - SSIM) / 2, on display values in [0, 1].
//!
//! **Parity.** Without a mask, [`ssim`] equals scikit-image's
//! `structural_similarity(x, y, channel_axis=-1, data_range=1, gaussian_weights=True, sigma=1.5,
//! use_sample_covariance=False)` (K1 = 0.01, K2 = 0.03): local means, variances and covariance
//! come from a separable Gaussian filter with sigma 1.5 truncated at 3.5 sigma (radius
//! int(3.5 * 1.5 + 0.5) = 5, an 11 x 11 window) as `scipy.ndimage.gaussian_filter` computes it,
//! with mode `reflect` (half-sample symmetric: `d c b a | a b c d | d c b a`) at the borders;
//! the SSIM map
//!
//! S = ((2 mu_x mu_y + C1)(2 s_xy + C2)) / ((mu_x^2 + mu_y^2 + C1)(s_x^2 + s_y^2 + C2)),
//! C1 = (K1 L)^2, C2 = (K2 L)^2, L = 1,
//!
//! is cropped by (11 - 1) / 2 = 5 pixels on every side and averaged, then averaged over RGB.
//! Computed in f64.
//!
//! **Mask.** With a mask the map (the same map as without one: filtering still sees every pixel)
//! is averaged over the masked pixels inside the cropped region and over channels.

use crate::error::{Error, Result};
use crate::image::{Image, check_pair, selected};
use crate::srgb::to_srgb_clamped;

/// SSIM settings (defaults: the standard Wang et al. values).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SsimConfig {
    /// Gaussian sigma in pixels (default 1.5).
    pub sigma: f64,
    /// Truncation of the Gaussian in sigmas (default 3.5, scipy's value in skimage).
    pub truncate: f64,
    /// K1 (default 0.01).
    pub k1: f64,
    /// K2 (default 0.03).
    pub k2: f64,
    /// Data range L (default 1).
    pub data_range: f64,
}

impl Default for SsimConfig {
    fn default() -> Self {
        Self { sigma: 1.5, truncate: 3.5, k1: 0.01, k2: 0.03, data_range: 1.0 }
    }
}

impl SsimConfig {
    /// Window radius int(truncate * sigma + 0.5) (5 by default).
    pub fn radius(&self) -> usize {
        (self.truncate * self.sigma + 0.5) as usize
    }

    /// Normalised 1D Gaussian weights over [-radius, radius].
    fn kernel(&self) -> Vec<f64> {
        let r = self.radius() as i64;
        let w: Vec<f64> =
            (-r..=r).map(|x| (-0.5 * (x * x) as f64 / (self.sigma * self.sigma)).exp()).collect();
        let s: f64 = w.iter().sum();
        w.into_iter().map(|v| v / s).collect()
    }
}

/// scipy's `reflect` index for a position possibly outside [0, n).
#[inline]
fn reflect(i: i64, n: i64) -> usize {
    let period = 2 * n;
    let mut m = i.rem_euclid(period);
    if m >= n {
        m = period - 1 - m;
    }
    m as usize
}

/// Separable Gaussian filter with reflect borders of a planar row-major image.
///
/// Row at a time and tap by tap (the inner loop vectorises over pixels) on a border-extended
/// line; every output sums its taps in the direct loop's order, so the values are the direct
/// filter's bit for bit (`filter_equals_direct_loop`), on AVX2's wider vectors where the CPU
/// has them ([`stdx::simd::with_avx2`]: the same operations, so the same bits).
fn gaussian_filter(src: &[f64], w: usize, h: usize, k: &[f64]) -> Vec<f64> {
    stdx::simd::with_avx2(|| gaussian_filter_rows(src, w, h, k))
}

#[inline(always)]
fn gaussian_filter_rows(src: &[f64], w: usize, h: usize, k: &[f64]) -> Vec<f64> {
    let r = (k.len() / 2) as i64;
    let mut tmp = vec![0.0; src.len()];
    let mut out = vec![0.0; src.len()];
    if w == 0 || h == 0 {
        return out;
    }
    let mut padded = vec![0.0; w + k.len()];
    for (row, dst) in src.chunks_exact(w).zip(tmp.chunks_exact_mut(w)) {
        for (i, p) in padded.iter_mut().enumerate() {
            *p = row[reflect(i as i64 - r, w as i64)];
        }
        for (j, kj) in k.iter().enumerate() {
            for (t, v) in dst.iter_mut().zip(&padded[j..j + w]) {
                *t += kj * v;
            }
        }
    }
    for (y, dst) in out.chunks_exact_mut(w).enumerate() {
        for (j, kj) in k.iter().enumerate() {
            let yi = reflect(y as i64 + j as i64 - r, h as i64);
            for (o, v) in dst.iter_mut().zip(&tmp[yi * w..(yi + 1) * w]) {
                *o += kj * v;
            }
        }
    }
    out
}

/// The SSIM map of one channel (planar, row-major), uncropped.
fn ssim_map_channel(x: &[f64], y: &[f64], w: usize, h: usize, cfg: &SsimConfig) -> Vec<f64> {
    let k = cfg.kernel();
    let prod = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).collect::<Vec<_>>();
    let ux = gaussian_filter(x, w, h, &k);
    let uy = gaussian_filter(y, w, h, &k);
    let uxx = gaussian_filter(&prod(x, x), w, h, &k);
    let uyy = gaussian_filter(&prod(y, y), w, h, &k);
    let uxy = gaussian_filter(&prod(x, y), w, h, &k);
    let c1 = (cfg.k1 * cfg.data_range).powi(2);
    let c2 = (cfg.k2 * cfg.data_range).powi(2);
    (0..w * h)
        .map(|i| {
            let (mx, my) = (ux[i], uy[i]);
            let vx = uxx[i] - mx * mx;
            let vy = uyy[i] - my * my;
            let vxy = uxy[i] - mx * my;
            let a1 = 2.0 * mx * my + c1;
            let a2 = 2.0 * vxy + c2;
            let b1 = mx * mx + my * my + c1;
            let b2 = vx + vy + c2;
            (a1 * a2) / (b1 * b2)
        })
        .collect()
}

/// Mean SSIM of two display-space images (see the module doc for the definition and the mask).
pub fn ssim_with(
    test: &Image,
    reference: &Image,
    mask: Option<&[bool]>,
    cfg: &SsimConfig,
) -> Result<f64> {
    check_pair(test, reference, mask)?;
    if !(cfg.sigma > 0.0 && cfg.truncate >= 0.0 && cfg.data_range > 0.0) {
        return Err(Error::Config(format!("SSIM: {cfg:?}")));
    }
    let (w, h) = (test.width(), test.height());
    let win = 2 * cfg.radius() + 1;
    if w < win || h < win {
        return Err(Error::TooSmall { metric: "SSIM", width: w, height: h, window: win });
    }
    let pad = (win - 1) / 2;
    let (mut sum, mut n) = (0.0, 0usize);
    for c in 0..3 {
        let map = ssim_map_channel(&test.channel_f64(c), &reference.channel_f64(c), w, h, cfg);
        for y in pad..h - pad {
            for x in pad..w - pad {
                if selected(mask, y * w + x) {
                    sum += map[y * w + x];
                    n += 1;
                }
            }
        }
    }
    if n == 0 {
        return Err(Error::Empty("SSIM: mask inside the 5-pixel border crop"));
    }
    Ok(sum / n as f64)
}

/// [`ssim_with`] with the default (standard) settings.
pub fn ssim(test: &Image, reference: &Image, mask: Option<&[bool]>) -> Result<f64> {
    ssim_with(test, reference, mask, &SsimConfig::default())
}

/// DSSIM = (1 - SSIM) / 2 of display-space images.
pub fn dssim(test: &Image, reference: &Image, mask: Option<&[bool]>) -> Result<f64> {
    Ok((1.0 - ssim(test, reference, mask)?) / 2.0)
}

/// DSSIM of linear renders, converted with [`to_srgb_clamped`] first.
pub fn dssim_linear(test: &Image, reference: &Image, mask: Option<&[bool]>) -> Result<f64> {
    dssim(&to_srgb_clamped(test), &to_srgb_clamped(reference), mask)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(w: usize, h: usize, seed: u32) -> Image {
        // A deterministic pseudo-random image in [0, 1].
        let mut s = seed.wrapping_mul(2_654_435_761).wrapping_add(1);
        Image::from_fn(w, h, |_, _| {
            let mut next = || {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                (s >> 8) as f32 / (1u32 << 24) as f32
            };
            [next(), next(), next()]
        })
    }

    #[test]
    fn identical_images_give_one() {
        let a = pattern(16, 13, 1);
        assert!((ssim(&a, &a, None).unwrap() - 1.0).abs() < 1e-12);
        assert!(dssim(&a, &a, None).unwrap().abs() < 1e-12);
    }

    #[test]
    fn constant_images_closed_form() {
        // Constants a and b: variances and covariance vanish, so
        // S = (2ab + C1) / (a^2 + b^2 + C1) at every pixel.
        let (a, b) = (0.3f64, 0.7f64);
        let x = Image::from_fn(12, 12, |_, _| [a as f32; 3]);
        let y = Image::from_fn(12, 12, |_, _| [b as f32; 3]);
        let (a, b) = (a as f32 as f64, b as f32 as f64);
        let c1 = 1e-4;
        let want = (2.0 * a * b + c1) / (a * a + b * b + c1);
        assert!((ssim(&x, &y, None).unwrap() - want).abs() < 1e-12);
    }

    #[test]
    fn reflect_matches_scipy() {
        // scipy 'reflect' of [0, 1, 2] extended by 3 on each side: 2 1 0 | 0 1 2 | 2 1 0.
        let got: Vec<usize> = (-3..6).map(|i| reflect(i, 3)).collect();
        assert_eq!(got, vec![2, 1, 0, 0, 1, 2, 2, 1, 0]);
    }

    /// The row-at-a-time filter equals the direct per-pixel loop bit for bit.
    #[test]
    fn filter_equals_direct_loop() {
        let (w, h) = (23, 9);
        let src: Vec<f64> = (0..w * h).map(|i| ((i * 7919) % 101) as f64 / 37.0).collect();
        let k = SsimConfig::default().kernel();
        let r = (k.len() / 2) as i64;
        let mut tmp = vec![0.0; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut s = 0.0;
                for (j, kj) in k.iter().enumerate() {
                    s += kj * src[y * w + reflect(x as i64 + j as i64 - r, w as i64)];
                }
                tmp[y * w + x] = s;
            }
        }
        let got = gaussian_filter(&src, w, h, &k);
        for y in 0..h {
            for x in 0..w {
                let mut s = 0.0;
                for (j, kj) in k.iter().enumerate() {
                    s += kj * tmp[reflect(y as i64 + j as i64 - r, h as i64) * w + x];
                }
                assert_eq!(got[y * w + x].to_bits(), s.to_bits(), "({x}, {y})");
            }
        }
    }

    #[test]
    fn window_too_large_is_an_error() {
        let a = pattern(10, 20, 2);
        assert!(matches!(ssim(&a, &a, None), Err(Error::TooSmall { .. })));
    }

    /// Reference values of scikit-image 0.26.0, obtained with `devtools/reference_values.py`:
    /// `structural_similarity(test, ref, channel_axis=-1, data_range=1.0, gaussian_weights=True,
    /// sigma=1.5, use_sample_covariance=False)` on float64 copies of the same f32 images, and the
    /// mean of its `full=True` map over the mask (x + 2y) % 3 != 0 inside the 5-pixel crop.
    #[test]
    fn matches_scikit_image() {
        let cases = [
            ((24, 17, 3), 0.967_838_324_440_172_9, 0.967_829_252_152_923_6),
            ((32, 32, 11), 0.964_735_934_028_131_3, 0.964_729_447_666_857_2),
        ];
        for ((w, h, seed), want, want_masked) in cases {
            let (r, t) = crate::testimg::ldr_pair(w, h, seed);
            let got = ssim(&t, &r, None).unwrap();
            assert!((got - want).abs() < 1e-9, "{w}x{h}: {got} vs skimage {want}");
            let mask: Vec<bool> = (0..w * h).map(|p| (p % w + 2 * (p / w)) % 3 != 0).collect();
            let got = ssim(&t, &r, Some(&mask)).unwrap();
            assert!((got - want_masked).abs() < 1e-9, "{w}x{h} masked: {got} vs {want_masked}");
        }
    }
}
