//! PSNR on display values with data range 1: 10 log10(1 / MSE), MSE over the masked pixels and
//! all three channels (spec section 7).

use crate::error::Result;
use crate::image::{Image, check_pair, selected};
use crate::srgb::to_srgb_clamped;

/// Mean squared error over the masked pixels and channels.
pub fn mse(test: &Image, reference: &Image, mask: Option<&[bool]>) -> Result<f64> {
    check_pair(test, reference, mask)?;
    let (mut sum, mut n) = (0.0f64, 0usize);
    for p in 0..test.pixels() {
        if selected(mask, p) {
            for c in 0..3 {
                let d = test.data()[3 * p + c] as f64 - reference.data()[3 * p + c] as f64;
                sum += d * d;
            }
            n += 3;
        }
    }
    Ok(sum / n as f64)
}

/// PSNR in dB of images already in display space (data range 1); `+inf` for identical images.
pub fn psnr(test: &Image, reference: &Image, mask: Option<&[bool]>) -> Result<f64> {
    let m = mse(test, reference, mask)?;
    Ok(if m == 0.0 { f64::INFINITY } else { -10.0 * m.log10() })
}

/// PSNR of linear renders: both are converted with [`to_srgb_clamped`] first.
pub fn psnr_linear(test: &Image, reference: &Image, mask: Option<&[bool]>) -> Result<f64> {
    psnr(&to_srgb_clamped(test), &to_srgb_clamped(reference), mask)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_computed() {
        // Every value differs by 0.1: MSE = 0.01, PSNR = 20 dB.
        let a = Image::from_fn(4, 3, |x, y| [0.1 * x as f32, 0.05 * y as f32, 0.3]);
        let b = a.map(|v| v + 0.1);
        assert!((psnr(&b, &a, None).unwrap() - 20.0).abs() < 1e-5);
        // Only pixel 0 differs, by 0.5 in one channel; masked to pixels {0, 1}:
        // MSE = 0.25 / 6, PSNR = 10 log10(24).
        let mut d = a.data().to_vec();
        d[0] += 0.5;
        let c = Image::new(4, 3, d).unwrap();
        let mut mask = vec![false; 12];
        mask[0] = true;
        mask[1] = true;
        let want = 10.0 * 24f64.log10();
        assert!((psnr(&c, &a, Some(&mask)).unwrap() - want).abs() < 1e-5);
        assert_eq!(psnr(&a, &a, None).unwrap(), f64::INFINITY);
    }

    #[test]
    fn linear_variant_converts() {
        let a = Image::from_fn(2, 2, |_, _| [0.5, 0.5, 0.5]);
        let b = Image::from_fn(2, 2, |_, _| [2.0, 2.0, 2.0]);
        // sRGB(0.5) = 0.7353556, sRGB(2) clamps to 1.
        let d = 1.0 - 0.735_357f64;
        let want = -10.0 * (d * d).log10();
        assert!((psnr_linear(&b, &a, None).unwrap() - want).abs() < 1e-4);
    }
}
