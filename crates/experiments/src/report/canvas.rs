//! An 8-bit RGB raster that figures are drawn on: clipped pixels, rectangles, lines, bitmap
//! text, image blits and PNG encoding. Every drawing call accepts any coordinates (off-canvas
//! parts are clipped), so drawing never fails; only [`Canvas::new`] checks its size.

use super::font::{GLYPH_SIZE, pixel, text_width};
use crate::{Error, Result};
use image::ImageEncoder;
use image::codecs::png::PngEncoder;

/// An sRGB colour.
pub type Rgb = [u8; 3];

/// White.
pub const WHITE: Rgb = [255, 255, 255];
/// Black.
pub const BLACK: Rgb = [0, 0, 0];

/// Largest accepted width or height, in pixels.
pub const MAX_SIDE: u32 = 16_384;

/// A width x height RGB raster, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Canvas {
    width: u32,
    height: u32,
    pixels: Vec<Rgb>,
}

impl Canvas {
    /// A canvas filled with `background`; both sides must be in 1..=[`MAX_SIDE`].
    pub fn new(width: u32, height: u32, background: Rgb) -> Result<Self> {
        if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
            return Err(Error::config(
                "report.figure",
                format!("size {width} x {height} px outside 1..={MAX_SIDE} per side"),
            ));
        }
        Ok(Canvas { width, height, pixels: vec![background; (width * height) as usize] })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pixels, row-major.
    pub fn pixels(&self) -> &[Rgb] {
        &self.pixels
    }

    fn index(&self, x: i64, y: i64) -> Option<usize> {
        let inside =
            (0..i64::from(self.width)).contains(&x) && (0..i64::from(self.height)).contains(&y);
        inside.then(|| (y as usize) * (self.width as usize) + x as usize)
    }

    /// The pixel at (x, y), `None` outside.
    pub fn get(&self, x: i64, y: i64) -> Option<Rgb> {
        self.index(x, y).map(|i| self.pixels[i])
    }

    /// Sets the pixel at (x, y) (ignored outside).
    pub fn set(&mut self, x: i64, y: i64, c: Rgb) {
        if let Some(i) = self.index(x, y) {
            self.pixels[i] = c;
        }
    }

    /// Fills the rectangle with top-left (x, y) and size w x h (clipped).
    pub fn fill_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: Rgb) {
        let x0 = x.clamp(0, i64::from(self.width));
        let y0 = y.clamp(0, i64::from(self.height));
        let x1 = x.saturating_add(w.max(0)).clamp(0, i64::from(self.width));
        let y1 = y.saturating_add(h.max(0)).clamp(0, i64::from(self.height));
        for yy in y0..y1 {
            for xx in x0..x1 {
                self.set(xx, yy, c);
            }
        }
    }

    /// Draws the one-pixel outline of the rectangle (x, y, w, h).
    pub fn stroke_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: Rgb) {
        if w <= 0 || h <= 0 {
            return;
        }
        self.fill_rect(x, y, w, 1, c);
        self.fill_rect(x, y.saturating_add(h - 1), w, 1, c);
        self.fill_rect(x, y, 1, h, c);
        self.fill_rect(x.saturating_add(w - 1), y, 1, h, c);
    }

    /// Draws a line from (x0, y0) to (x1, y1) with a square brush `thickness` pixels wide.
    /// Non-finite endpoints draw nothing; the segment is clipped to the canvas first, so far-off
    /// endpoints cost nothing.
    pub fn line(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, c: Rgb, thickness: u32) {
        let t = f64::from(thickness.max(1));
        let bounds = (-t, -t, f64::from(self.width) + t, f64::from(self.height) + t);
        let Some((x0, y0, x1, y1)) = clip(x0, y0, x1, y1, bounds) else { return };
        let (mut x, mut y) = (x0.round() as i64, y0.round() as i64);
        let (xe, ye) = (x1.round() as i64, y1.round() as i64);
        let (dx, dy) = ((xe - x).abs(), -(ye - y).abs());
        let (sx, sy) = (if x < xe { 1 } else { -1 }, if y < ye { 1 } else { -1 });
        let (half, w) = (i64::from(thickness.max(1) - 1) / 2, i64::from(thickness.max(1)));
        let mut err = dx + dy;
        loop {
            self.fill_rect(x - half, y - half, w, w, c);
            if x == xe && y == ye {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x += sx;
            }
            if e2 <= dx {
                err += dx;
                y += sy;
            }
        }
    }

    /// Draws `text` with its top-left corner at (x, y), each font pixel `scale` x `scale`.
    pub fn text(&mut self, x: i64, y: i64, text: &str, scale: u32, c: Rgb) {
        let s = i64::from(scale.max(1));
        let advance = i64::from(GLYPH_SIZE) * s;
        for (i, ch) in text.chars().enumerate() {
            let ox = x.saturating_add((i as i64).saturating_mul(advance));
            if ox >= i64::from(self.width) {
                break;
            }
            for gy in 0..GLYPH_SIZE {
                for gx in 0..GLYPH_SIZE {
                    if pixel(ch, gx, gy) {
                        let px = ox + i64::from(gx) * s;
                        self.fill_rect(px, y.saturating_add(i64::from(gy) * s), s, s, c);
                    }
                }
            }
        }
    }

    /// Draws `text` rotated a quarter turn counter-clockwise (reading bottom to top), with the
    /// bottom-left corner of its first glyph at (x, y).
    pub fn text_vertical(&mut self, x: i64, y: i64, text: &str, scale: u32, c: Rgb) {
        let s = i64::from(scale.max(1));
        let advance = i64::from(GLYPH_SIZE) * s;
        for (i, ch) in text.chars().enumerate() {
            let base = y.saturating_sub((i as i64).saturating_mul(advance));
            if base < 0 {
                break;
            }
            for gy in 0..GLYPH_SIZE {
                for gx in 0..GLYPH_SIZE {
                    if pixel(ch, gx, gy) {
                        // Glyph column gx runs up the canvas, glyph row gy runs right.
                        let px = x.saturating_add(i64::from(gy) * s);
                        let py = base - (i64::from(gx) + 1) * s;
                        self.fill_rect(px, py, s, s, c);
                    }
                }
            }
        }
    }

    /// Draws `text` centred horizontally on `cx` with its top at `y`.
    pub fn text_centered(&mut self, cx: i64, y: i64, text: &str, scale: u32, c: Rgb) {
        let w = i64::from(text_width(text, scale.max(1)));
        self.text(cx.saturating_sub(w / 2), y, text, scale, c);
    }

    /// Copies a w x h row-major image with its top-left corner at (x, y) (clipped; a buffer
    /// shorter than w x h copies what it has).
    pub fn blit(&mut self, x: i64, y: i64, w: u32, h: u32, pixels: &[Rgb]) {
        for (i, &p) in pixels.iter().take(w as usize * h as usize).enumerate() {
            let (px, py) = ((i % w as usize) as i64, (i / w as usize) as i64);
            self.set(x.saturating_add(px), y.saturating_add(py), p);
        }
    }

    /// The canvas as PNG bytes (8-bit RGB).
    pub fn to_png(&self) -> Result<Vec<u8>> {
        let bytes: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        let mut out = Vec::new();
        PngEncoder::new(&mut out)
            .write_image(&bytes, self.width, self.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| Error::config("report.figure", format!("PNG encoding failed: {e}")))?;
        Ok(out)
    }
}

/// Liang-Barsky clipping of a segment to `(xmin, ymin, xmax, ymax)`.
fn clip(
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
    (xmin, ymin, xmax, ymax): (f64, f64, f64, f64),
) -> Option<(f64, f64, f64, f64)> {
    if ![x0, y0, x1, y1].iter().all(|v| v.is_finite()) {
        return None;
    }
    let (dx, dy) = (x1 - x0, y1 - y0);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-dx, x0 - xmin), (dx, xmax - x0), (-dy, y0 - ymin), (dy, ymax - y0)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then_some((x0 + t0 * dx, y0 + t0 * dy, x0 + t1 * dx, y0 + t1 * dy))
}

#[cfg(test)]
mod tests {
    use super::*;

    const RED: Rgb = [255, 0, 0];

    #[test]
    fn rejects_bad_sizes() {
        assert!(Canvas::new(0, 10, WHITE).is_err());
        assert!(Canvas::new(10, MAX_SIDE + 1, WHITE).is_err());
    }

    #[test]
    fn lines_are_clipped_and_finite() {
        let mut c = Canvas::new(20, 10, WHITE).unwrap();
        c.line(-1e6, 5.0, 1e6, 5.0, RED, 1);
        assert!((0..20).all(|x| c.get(x, 5) == Some(RED)));
        // Extreme endpoints lose precision in clipping but draw quickly and never panic.
        c.line(-1e300, 7.0, 1e300, 7.0, RED, 1);
        assert_eq!(c.get(0, 4), Some(WHITE));
        c.line(f64::NAN, 0.0, 3.0, 3.0, BLACK, 3);
        c.line(0.0, 0.0, 0.0, 0.0, BLACK, 1);
        assert_eq!(c.get(0, 0), Some(BLACK));
        c.line(-50.0, -50.0, -40.0, -45.0, BLACK, 2);
    }

    #[test]
    fn text_and_blit() {
        let mut c = Canvas::new(40, 40, WHITE).unwrap();
        c.text(0, 0, "I", 2, BLACK);
        // 'I' row 0 is 0x1E: pixels 1..=4 set, scaled by 2.
        assert_eq!(c.get(2, 0), Some(BLACK));
        assert_eq!(c.get(0, 0), Some(WHITE));
        c.text_vertical(20, 39, "I", 1, RED);
        assert!(c.pixels().contains(&RED));
        c.blit(30, 30, 2, 2, &[RED; 4]);
        assert_eq!(c.get(31, 31), Some(RED));
        c.blit(39, 39, 5, 5, &[BLACK; 3]);
        c.text(i64::MAX - 5, i64::MIN, "overflow?", 3, RED);
        let png = c.to_png().unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }
}
