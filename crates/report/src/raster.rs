//! The 8-bit RGB buffer every figure is drawn into (by plotters' bitmap backend, and by
//! [`Raster::blit`] for images), and its PNG encoding.

use crate::error::{Error, Result};
use image::ImageEncoder;
use image::codecs::png::PngEncoder;

/// An sRGB colour.
pub type Rgb = [u8; 3];

/// White.
pub const WHITE: Rgb = [255, 255, 255];
/// Black.
pub const BLACK: Rgb = [0, 0, 0];

/// Largest accepted width or height of a figure, in pixels.
pub const MAX_SIDE: u32 = 16_384;

/// A white `width` x `height` RGB buffer, row-major, 3 bytes a pixel.
pub struct Raster {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The bytes, as plotters' `BitMapBackend::with_buffer` takes them.
    pub bytes: Vec<u8>,
}

impl Raster {
    /// A white raster; both sides must be in 1..=[`MAX_SIDE`].
    pub fn new(width: u32, height: u32) -> Result<Self> {
        if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
            return Err(Error::figure(
                "report.figure",
                format!("size {width} x {height} px outside 1..={MAX_SIDE} per side"),
            ));
        }
        Ok(Self { width, height, bytes: vec![255; 3 * width as usize * height as usize] })
    }

    /// Copies a `w` x `h` image (row-major) with its top-left corner at (x, y); the parts
    /// outside the raster are clipped.
    pub fn blit(&mut self, x: i64, y: i64, w: u32, h: u32, pixels: &[Rgb]) {
        for (i, p) in pixels.iter().take(w as usize * h as usize).enumerate() {
            let (px, py) = (x + (i % w as usize) as i64, y + (i / w as usize) as i64);
            if (0..i64::from(self.width)).contains(&px) && (0..i64::from(self.height)).contains(&py)
            {
                let o = 3 * (py as usize * self.width as usize + px as usize);
                self.bytes[o..o + 3].copy_from_slice(p);
            }
        }
    }

    /// The pixel at (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> Rgb {
        let o = 3 * (y as usize * self.width as usize + x as usize);
        [self.bytes[o], self.bytes[o + 1], self.bytes[o + 2]]
    }

    /// The raster as PNG bytes (8-bit RGB).
    pub fn to_png(&self) -> Result<Vec<u8>> {
        let mut out = Vec::new();
        PngEncoder::new(&mut out)
            .write_image(&self.bytes, self.width, self.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| Error::figure("report.figure", format!("PNG encoding failed: {e}")))?;
        Ok(out)
    }
}

/// A plotters drawing error as this crate's error.
pub fn draw_error(e: impl std::fmt::Debug) -> Error {
    Error::figure("report.figure", format!("drawing failed: {e:?}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blits_clip_and_sizes_are_checked() {
        let mut r = Raster::new(4, 3).unwrap();
        r.blit(-1, 1, 2, 2, &[[1, 2, 3]; 4]);
        assert_eq!(r.pixel(0, 1), [1, 2, 3]);
        assert_eq!(r.pixel(1, 1), WHITE);
        assert_eq!(r.pixel(0, 0), WHITE);
        let png = r.to_png().unwrap();
        let back = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(back.get_pixel(0, 2).0, [1, 2, 3]);
        assert!(Raster::new(0, 3).is_err() && Raster::new(3, MAX_SIDE + 1).is_err());
    }
}
