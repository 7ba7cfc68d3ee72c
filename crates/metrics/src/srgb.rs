//! The sRGB OETF (spec section 6), used for PSNR, SSIM and LPIPS on [0, 1]-clamped values.

use crate::image::Image;

/// gamma(c) = 12.92 c for c <= 0.0031308, else 1.055 c^(1/2.4) - 0.055 (no clamping).
#[inline]
pub fn oetf(c: f32) -> f32 {
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// The OETF of `c` clamped to [0, 1] first (so the result lies in [0, 1]).
#[inline]
pub fn oetf_clamped(c: f32) -> f32 {
    oetf(c.clamp(0.0, 1.0)).clamp(0.0, 1.0)
}

/// A linear image converted to display sRGB in [0, 1], as the image metrics use it.
pub fn to_srgb_clamped(linear: &Image) -> Image {
    linear.map(oetf_clamped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oetf_known_values() {
        assert_eq!(oetf(0.0), 0.0);
        assert!((oetf(1.0) - 1.0).abs() < 1e-6);
        assert!((oetf(0.002) - 0.02584).abs() < 1e-7);
        // 1.055 * 0.5^(1/2.4) - 0.055 = 0.735356...
        assert!((oetf(0.5) - 0.735_357).abs() < 1e-6);
        assert!((oetf_clamped(7.0) - 1.0).abs() < 1e-6);
        assert_eq!(oetf_clamped(-1.0), 0.0);
    }
}
