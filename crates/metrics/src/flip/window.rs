//! The part of a frame HDR-FLIP needs: a rectangle around the pixels of interest, grown by how
//! far FLIP's filters reach, so that a test image whose object covers a quarter of the frame is
//! filtered on about half of it instead of all of it.
//!
//! A FLIP value at pixel p depends only on the inputs within [`reach`] pixels of p (the CSF
//! and feature filters are the only spatial steps; their borders replicate the frame's edge).
//! So for a [`FlipWindow`] built around a set S of pixels:
//!
//! 1. at every pixel of S, HDR-FLIP of the cropped images equals the whole frame's, bit for
//!    bit: its filter windows lie inside the crop, or reach the frame's edge exactly where the
//!    crop's edge is the frame's (same taps, same order, same values);
//! 2. for two images that are both 0 outside S, every pixel of the crop equals the whole
//!    frame's too (what a filter sees beyond the crop's edge is 0 there, as the replicated edge
//!    pixel is), and every pixel outside the crop is exactly 0 in the whole frame's map (both
//!    images filter to the same values there, and equal inputs have no colour difference).
//!    [`FlipWindow::embed`] puts the crop's map back into a frame of zeros: the whole frame's
//!    map, bit for bit.
//!
//! The exposure range is not a spatial step: take it from the whole frame
//! ([`super::exposure_range`]) and prepare the crops at it.

use super::filter::{Feature, csf_radius, feature_kernel};
use crate::error::{Error, Result};
use crate::image::Image;

/// How far (pixels) a FLIP value reaches into its inputs at `ppd` pixels per degree: the
/// largest radius of the CSF and feature filters (10 at [`super::DEFAULT_PPD`]).
pub fn reach(ppd: f64) -> usize {
    let features = [Feature::Edge, Feature::Point].map(|f| feature_kernel(ppd, f).radius);
    csf_radius(ppd).max(features[0]).max(features[1])
}

/// A rectangle of a `frame` (width, height): columns `x0..x0 + width`, rows `y0..y0 + height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FlipWindow {
    frame: (usize, usize),
    x0: usize,
    y0: usize,
    width: usize,
    height: usize,
}

impl FlipWindow {
    /// The smallest rectangle of a `width` x `height` frame holding every pixel of `pixels`
    /// (row-major indices) and everything within [`reach`]`(ppd)` of them; `None` when
    /// `pixels` is empty.
    ///
    /// # Errors
    /// A pixel index outside the frame.
    pub fn around(
        (width, height): (usize, usize),
        ppd: f64,
        pixels: impl IntoIterator<Item = usize>,
    ) -> Result<Option<FlipWindow>> {
        let mut bounds: Option<(usize, usize, usize, usize)> = None;
        for p in pixels {
            if p >= width * height {
                return Err(Error::Config(format!(
                    "HDR-FLIP window: pixel {p} outside a {width} x {height} frame"
                )));
            }
            let (x, y) = (p % width, p / width);
            bounds = Some(match bounds {
                None => (x, y, x, y),
                Some((a, b, c, d)) => (a.min(x), b.min(y), c.max(x), d.max(y)),
            });
        }
        let Some((x_lo, y_lo, x_hi, y_hi)) = bounds else { return Ok(None) };
        let r = reach(ppd);
        let (x0, y0) = (x_lo.saturating_sub(r), y_lo.saturating_sub(r));
        let (x1, y1) = ((x_hi + r).min(width - 1), (y_hi + r).min(height - 1));
        Ok(Some(FlipWindow {
            frame: (width, height),
            x0,
            y0,
            width: x1 - x0 + 1,
            height: y1 - y0 + 1,
        }))
    }

    /// Pixels inside the window.
    pub fn pixels(&self) -> usize {
        self.width * self.height
    }

    /// The window's part of `image`.
    ///
    /// # Errors
    /// An image of another size than the frame.
    pub fn crop(&self, image: &Image) -> Result<Image> {
        if (image.width(), image.height()) != self.frame {
            return Err(Error::SizeMismatch {
                test: (image.width(), image.height()),
                reference: self.frame,
            });
        }
        let data = self.rows(image.data(), 3).flatten().copied().collect();
        Image::new(self.width, self.height, data)
    }

    /// The window's part of a frame's `mask`.
    ///
    /// # Errors
    /// A mask of another length than the frame.
    pub fn crop_mask(&self, mask: &[bool]) -> Result<Vec<bool>> {
        if mask.len() != self.frame.0 * self.frame.1 {
            return Err(Error::MaskSize { mask: mask.len(), pixels: self.frame.0 * self.frame.1 });
        }
        Ok(self.rows(mask, 1).flatten().copied().collect())
    }

    /// A map of the window (row-major, `pixels()` values) in a frame of zeros.
    ///
    /// # Errors
    /// A map of another length than the window.
    pub fn embed(&self, map: &[f32]) -> Result<Vec<f32>> {
        if map.len() != self.pixels() {
            return Err(Error::MaskSize { mask: map.len(), pixels: self.pixels() });
        }
        let mut frame = vec![0.0f32; self.frame.0 * self.frame.1];
        for (row, part) in map.chunks_exact(self.width).enumerate() {
            let start = (self.y0 + row) * self.frame.0 + self.x0;
            frame[start..start + self.width].copy_from_slice(part);
        }
        Ok(frame)
    }

    /// The window's rows of a frame-sized buffer of `channels` values a pixel.
    fn rows<'a, T>(&self, buf: &'a [T], channels: usize) -> impl Iterator<Item = &'a [T]> {
        let (fw, x0, w) = (self.frame.0, self.x0, self.width);
        (self.y0..self.y0 + self.height)
            .map(move |y| &buf[(y * fw + x0) * channels..(y * fw + x0 + w) * channels])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flip::{DEFAULT_PPD, FlipExposures, FlipImage, exposure_range, hdr_flip_prepared};
    use crate::testimg::{ObjectFrame, object_frame};

    #[test]
    fn reach_is_the_csf_radius_at_the_default_ppd() {
        assert_eq!(reach(DEFAULT_PPD), 10);
    }

    #[test]
    fn windows_grow_by_the_reach_within_the_frame() {
        let none = FlipWindow::around((40, 30), DEFAULT_PPD, []).unwrap();
        assert!(none.is_none());
        let w = FlipWindow::around((40, 30), DEFAULT_PPD, [15 * 40 + 20]).unwrap().unwrap();
        assert_eq!((w.x0, w.y0, w.width, w.height), (10, 5, 21, 21));
        let corner = FlipWindow::around((40, 30), DEFAULT_PPD, [0, 39]).unwrap().unwrap();
        assert_eq!((corner.x0, corner.y0, corner.width, corner.height), (0, 0, 40, 11));
        assert!(FlipWindow::around((4, 3), DEFAULT_PPD, [12]).is_err());
    }

    /// The module's two statements, bit for bit: an object (a disc, lit unevenly) in a frame
    /// whose observation has noise everywhere, and a render and a noise-free image that are 0
    /// outside the object.
    #[test]
    fn the_window_gives_the_whole_frames_flip() {
        let (w, h) = (96, 80);
        let ObjectFrame { test, observed, clean, mask } = object_frame(w, h, (52.0, 35.0), 18.0);
        let at = FlipExposures::new(exposure_range(&observed, Some(&mask)).unwrap(), DEFAULT_PPD)
            .unwrap();
        let pixels = (0..w * h).filter(|&p| mask[p]);
        let window = FlipWindow::around((w, h), DEFAULT_PPD, pixels).unwrap().unwrap();
        assert!(window.pixels() < w * h / 2, "a small object, a small window");
        let full = |im: &Image| FlipImage::new(im, &at).unwrap();
        let part = |im: &Image| FlipImage::new(&window.crop(im).unwrap(), &at).unwrap();
        let cropped_mask = window.crop_mask(&mask).unwrap();
        // 1: the object's pixels, against the noisy observation.
        let a = hdr_flip_prepared(&full(&test), &full(&observed), Some(&mask)).unwrap();
        let b = hdr_flip_prepared(&part(&test), &part(&observed), Some(&cropped_mask)).unwrap();
        assert_eq!(a.mean.to_bits(), b.mean.to_bits());
        let b_map = window.embed(&b.map).unwrap();
        for p in (0..w * h).filter(|&p| mask[p]) {
            assert_eq!(a.map[p].to_bits(), b_map[p].to_bits(), "pixel {p}");
        }
        // 2: two images that vanish outside the object: the whole frame's map.
        let a = hdr_flip_prepared(&full(&test), &full(&clean), None).unwrap();
        let b = hdr_flip_prepared(&part(&test), &part(&clean), None).unwrap();
        let b_map = window.embed(&b.map).unwrap();
        assert!(a.map.iter().zip(&b_map).all(|(x, y)| x.to_bits() == y.to_bits()));
        assert!(a.map.iter().filter(|v| **v != 0.0).count() > mask.iter().filter(|m| **m).count());
    }
}
