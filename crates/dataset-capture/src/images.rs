//! A capture's images and masks: EXR (linear) or 8/16-bit PNG through the stated response,
//! decoded to linear radiance with a saturation flag per pixel.

use crate::config::{ImageSettings, Response};
use crate::error::{Error, Result};
use std::path::Path;
use stdx::Limits;

/// A decoded image: linear radiance (after `scale`) and which pixels have a saturated channel.
pub struct Decoded {
    /// Width and height.
    pub size: (u32, u32),
    /// Radiance, row-major.
    pub radiance: Vec<[f32; 3]>,
    /// A channel at or above the saturation level.
    pub saturated: Vec<bool>,
}

fn is_exr(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// The inverse of the sRGB transfer function.
fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}

/// What a reader of a capture's image of `size` accepts: no more pixels than its camera
/// declares (so a header that disagrees is refused before the decoder allocates), and the
/// user's allocation bound.
fn within_size(size: (u32, u32), limits: &Limits) -> Limits {
    Limits { max_image_pixels: u64::from(size.0) * u64::from(size.1), ..*limits }
}

/// Decodes an image of the capture, expecting `size`, within `limits`.
pub fn decode(
    path: &Path,
    size: (u32, u32),
    s: &ImageSettings,
    limits: &Limits,
) -> Result<Decoded> {
    if !path.exists() {
        return Err(Error::input(path, "the image is missing"));
    }
    let limits = within_size(size, limits);
    let (w, h, linear, saturation) = if is_exr(path) {
        let (w, h, px) = scene::images::read_exr_rgb(path, &limits)?;
        (w as u32, h as u32, px, s.saturation.unwrap_or(f32::INFINITY))
    } else {
        let img = scene::images::decode_within(path, &limits)
            .map_err(|e| Error::input(path, format!("cannot decode the image: {e}")))?;
        let (w, h) = (img.width(), img.height());
        let rgb = img.into_rgb16();
        let px = rgb
            .pixels()
            .map(|p| {
                p.0.map(|c| {
                    let v = f32::from(c) / 65535.0;
                    match s.response {
                        Response::Linear => v,
                        Response::Srgb => srgb_to_linear(v),
                        Response::Gamma => v.powf(s.gamma),
                    }
                })
            })
            .collect();
        (w, h, px, s.saturation.unwrap_or(1.0))
    };
    if (w, h) != size {
        return Err(Error::input(
            path,
            format!("the image is {w} x {h}, its camera says {} x {}", size.0, size.1),
        ));
    }
    if let Some(i) = linear.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(Error::input(
            path,
            format!("non-finite value at pixel ({}, {})", i % w as usize, i / w as usize),
        ));
    }
    let saturated = linear.iter().map(|p| p.iter().any(|&c| c >= saturation)).collect();
    let radiance = linear.into_iter().map(|p| p.map(|c| c * s.scale)).collect();
    Ok(Decoded { size: (w, h), radiance, saturated })
}

/// Reads a mask PNG of `size` within `limits`: true where the mask is non-zero (its alpha where
/// it has one).
pub fn decode_mask(path: &Path, size: (u32, u32), limits: &Limits) -> Result<Vec<bool>> {
    if !path.exists() {
        return Err(Error::input(path, "the mask is missing"));
    }
    let img = scene::images::decode_within(path, &within_size(size, limits))
        .map_err(|e| Error::input(path, format!("cannot decode the mask: {e}")))?;
    if (img.width(), img.height()) != size {
        return Err(Error::input(
            path,
            format!(
                "the mask is {} x {}, its image {} x {}",
                img.width(),
                img.height(),
                size.0,
                size.1
            ),
        ));
    }
    let alpha = img.color().has_alpha();
    Ok(img
        .into_rgba16()
        .pixels()
        .map(|p| if alpha { p.0[3] > 0 } else { p.0[..3].iter().any(|&c| c > 0) })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_inverse_is_monotone_and_fixes_the_ends() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.5) - 0.21404).abs() < 1e-4);
    }

    #[test]
    fn png_codes_decode_through_the_response_and_saturate_at_the_top() {
        let dir = std::env::temp_dir().join(format!("capture-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.png");
        let img = image::RgbImage::from_raw(2, 1, vec![0, 128, 255, 255, 255, 255]).unwrap();
        img.save(&p).unwrap();
        let s = ImageSettings {
            response: Response::Gamma,
            gamma: 2.0,
            scale: 2.0,
            ..Default::default()
        };
        let d = decode(&p, (2, 1), &s, &Limits::DEFAULT).unwrap();
        assert_eq!(d.radiance[0][0], 0.0);
        assert!((d.radiance[0][1] - 2.0 * (128.0_f32 / 255.0).powi(2)).abs() < 1e-5);
        assert_eq!(d.saturated, vec![true, true]);
        let e = decode(&p, (3, 1), &s, &Limits::DEFAULT).err().unwrap().to_string();
        assert!(e.contains("a.png") && e.contains("2 x 1"), "{e}");
        let e = decode(&dir.join("b.png"), (2, 1), &s, &Limits::DEFAULT).err().unwrap().to_string();
        assert!(e.contains("b.png") && e.contains("missing"), "{e}");
        // A header larger than its camera is refused before the decoder allocates.
        let e = decode(&p, (1, 1), &s, &Limits::DEFAULT).err().unwrap().to_string();
        assert!(e.contains("a.png") && e.contains("declares 2 x 1 pixels"), "{e}");
        let e = decode_mask(&p, (1, 1), &Limits::DEFAULT).err().unwrap().to_string();
        assert!(e.contains("a.png") && e.contains("at most 1"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
