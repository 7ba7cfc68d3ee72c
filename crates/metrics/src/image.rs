//! Images as the metrics see them: width x height RGB `f32`, row-major, channels interleaved,
//! and the optional object mask.

use crate::error::{Error, Result};

/// A linear or sRGB image: `data[3 * (y * width + x) + c]` is channel `c` of pixel (x, y).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: usize,
    height: usize,
    data: Vec<f32>,
}

impl Image {
    /// Wraps a buffer of `width * height * 3` floats.
    pub fn new(width: usize, height: usize, data: Vec<f32>) -> Result<Self> {
        if width.checked_mul(height).and_then(|p| p.checked_mul(3)) != Some(data.len()) {
            return Err(Error::BufferLength { what: "Image::new", width, height, len: data.len() });
        }
        Ok(Self { width, height, data })
    }

    /// An image from a function of (x, y) returning RGB.
    pub fn from_fn(
        width: usize,
        height: usize,
        mut f: impl FnMut(usize, usize) -> [f32; 3],
    ) -> Self {
        let mut data = Vec::with_capacity(width * height * 3);
        for y in 0..height {
            for x in 0..width {
                data.extend_from_slice(&f(x, y));
            }
        }
        Self { width, height, data }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Number of pixels.
    pub fn pixels(&self) -> usize {
        self.width * self.height
    }

    /// The interleaved RGB buffer.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The pixel at (x, y).
    ///
    /// # Panics
    /// If (x, y) is outside the image.
    pub fn pixel(&self, x: usize, y: usize) -> [f32; 3] {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside the image");
        let i = 3 * (y * self.width + x);
        [self.data[i], self.data[i + 1], self.data[i + 2]]
    }

    /// Applies `f` to every channel value.
    pub fn map(&self, f: impl Fn(f32) -> f32) -> Image {
        Image {
            width: self.width,
            height: self.height,
            data: self.data.iter().map(|&v| f(v)).collect(),
        }
    }

    /// One channel as a planar `f64` buffer (row-major).
    pub(crate) fn channel_f64(&self, c: usize) -> Vec<f64> {
        self.data.iter().skip(c).step_by(3).map(|&v| v as f64).collect()
    }

    /// Errors on the first NaN, naming the image.
    pub fn check_no_nan(&self, what: &'static str) -> Result<()> {
        match self.data.iter().position(|v| v.is_nan()) {
            None => Ok(()),
            Some(i) => {
                let p = i / 3;
                Err(Error::NaN { what, x: p % self.width, y: p / self.width, channel: i % 3 })
            }
        }
    }
}

/// Validates a (test, reference, mask) triple: same size, mask length, no NaN, and (with a mask)
/// at least one selected pixel.
pub fn check_pair(test: &Image, reference: &Image, mask: Option<&[bool]>) -> Result<()> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(Error::SizeMismatch {
            test: (test.width, test.height),
            reference: (reference.width, reference.height),
        });
    }
    if let Some(m) = mask {
        if m.len() != test.pixels() {
            return Err(Error::MaskSize { mask: m.len(), pixels: test.pixels() });
        }
        if !m.iter().any(|&b| b) {
            return Err(Error::Empty("mask"));
        }
    }
    if test.pixels() == 0 {
        return Err(Error::Empty("image"));
    }
    test.check_no_nan("test image")?;
    reference.check_no_nan("reference image")
}

/// Whether pixel `p` is selected by the mask (always, without one).
#[inline]
pub(crate) fn selected(mask: Option<&[bool]>, p: usize) -> bool {
    mask.is_none_or(|m| m[p])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_checks_length() {
        assert!(Image::new(2, 2, vec![0.0; 12]).is_ok());
        assert!(matches!(Image::new(2, 2, vec![0.0; 11]), Err(Error::BufferLength { .. })));
    }

    #[test]
    fn check_pair_names_faults() {
        let a = Image::new(2, 1, vec![0.0; 6]).unwrap();
        let b = Image::new(1, 2, vec![0.0; 6]).unwrap();
        assert!(matches!(check_pair(&a, &b, None), Err(Error::SizeMismatch { .. })));
        assert!(matches!(check_pair(&a, &a, Some(&[true])), Err(Error::MaskSize { .. })));
        assert!(matches!(check_pair(&a, &a, Some(&[false, false])), Err(Error::Empty(_))));
        let mut d = vec![0.0; 6];
        d[4] = f32::NAN;
        let n = Image::new(2, 1, d).unwrap();
        let e = check_pair(&n, &a, None).unwrap_err();
        assert!(matches!(e, Error::NaN { x: 1, y: 0, channel: 1, .. }), "{e}");
        assert!(e.to_string().contains("test image"));
    }
}
