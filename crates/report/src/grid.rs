//! Image grids as PNG: rows of images with column headers, row labels and a caption under each
//! image. Used for the qualitative comparisons (ground truth, then each model's render, with
//! optional FLIP-map rows) and for the diffuse / specular / albedo split figures.
//!
//! Layout: every slot is as wide as the widest image or caption and as tall as the tallest
//! image; each image is centred in its slot, its caption centred below. [`grid_geometry`]
//! returns the positions, so callers (and tests) can find any cell. Images are copied into the
//! raster as they are; text is drawn by plotters with the embedded font.

use crate::error::{Error, Result};
use crate::font::{ensure_registered, font, text_size};
use crate::raster::{BLACK, Raster, Rgb, draw_error};
use metrics::colormap::error_map_rgb8;
use metrics::srgb::oetf_clamped;
use plotters::coord::Shift;
use plotters::prelude::{BitMapBackend, DrawingArea, IntoDrawingArea, RGBColor};
use plotters::style::TextStyle;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// An 8-bit sRGB image, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    width: u32,
    height: u32,
    pixels: Vec<Rgb>,
}

impl RgbImage {
    /// Wraps `width * height` pixels.
    pub fn new(width: u32, height: u32, pixels: Vec<Rgb>) -> Result<Self> {
        if (width as usize).checked_mul(height as usize) != Some(pixels.len()) {
            return Err(Error::figure(
                "report.image",
                format!("{} pixels for a {width} x {height} image", pixels.len()),
            ));
        }
        Ok(RgbImage { width, height, pixels })
    }

    /// A `width` x `height` image of colour `c`.
    pub fn filled(width: u32, height: u32, c: Rgb) -> Self {
        RgbImage { width, height, pixels: vec![c; width as usize * height as usize] }
    }

    /// A linear HDR render shown in sRGB (clamped OETF, as the metrics see it).
    pub fn from_linear(image: &metrics::Image) -> Self {
        Self::convert(image, oetf_clamped)
    }

    /// A display image with values in [0, 1] (clamped).
    pub fn from_display(image: &metrics::Image) -> Self {
        Self::convert(image, |v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) })
    }

    fn convert(image: &metrics::Image, f: impl Fn(f32) -> f32) -> Self {
        let to8 = |v: f32| (f(v) * 255.0).round().clamp(0.0, 255.0) as u8;
        let pixels =
            image.data().chunks_exact(3).map(|c| [to8(c[0]), to8(c[1]), to8(c[2])]).collect();
        let side = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        RgbImage { width: side(image.width()), height: side(image.height()), pixels }
    }

    /// A FLIP error map (values in [0, 1], row-major) in magma, pixels outside `mask` grey
    /// ([`metrics::colormap::error_map_rgb8`]).
    pub fn error_map(
        values: &[f32],
        mask: Option<&[bool]>,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        Self::new(width, height, error_map_rgb8(values, mask))
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

    /// The `w` x `h` region with top-left corner `(x, y)`, clipped to the image.
    pub fn crop(&self, x: u32, y: u32, w: u32, h: u32) -> RgbImage {
        let (x, y) = (x.min(self.width), y.min(self.height));
        let (w, h) = (w.min(self.width - x), h.min(self.height - y));
        let mut pixels = Vec::with_capacity(w as usize * h as usize);
        for row in y..y + h {
            let start = (row * self.width + x) as usize;
            pixels.extend_from_slice(&self.pixels[start..start + w as usize]);
        }
        RgbImage { width: w, height: h, pixels }
    }

    /// The image enlarged `factor` times with nearest-neighbour sampling (pixels stay visible
    /// as squares, as a comparison of renders wants).
    pub fn scaled(&self, factor: u32) -> RgbImage {
        let f = factor.max(1);
        let (w, h) = (self.width * f, self.height * f);
        let mut pixels = Vec::with_capacity(w as usize * h as usize);
        for row in 0..h {
            for col in 0..w {
                pixels.push(self.pixels[((row / f) * self.width + col / f) as usize]);
            }
        }
        RgbImage { width: w, height: h, pixels }
    }
}

/// One grid cell: an image (or an empty slot) and its caption ("Disney 31.58 dB").
#[derive(Clone, Debug, PartialEq)]
pub struct GridCell {
    /// The image; `None` leaves the slot empty.
    pub image: Option<RgbImage>,
    /// Caption under the image; may be empty.
    pub caption: String,
}

/// One row of the grid.
#[derive(Clone, Debug, PartialEq)]
pub struct GridRow {
    /// Label left of the row ("view 3, light 7"); may be empty.
    pub label: String,
    /// Cells, left to right.
    pub cells: Vec<GridCell>,
}

/// A grid of images.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageGrid {
    /// Title above the grid; may be empty.
    pub title: String,
    /// Header above each column ("GT", "Disney"); may be shorter than the rows.
    pub column_headers: Vec<String>,
    /// The rows.
    pub rows: Vec<GridRow>,
    /// Text size in pixels (default 16).
    pub font_px: u32,
    /// Gap between slots and around the grid in pixels (default 8).
    pub padding: u32,
}

impl ImageGrid {
    /// A grid with default font scale and padding, from rows of (label, [(caption, image)]).
    pub fn from_images(
        title: impl Into<String>,
        column_headers: Vec<String>,
        rows: Vec<(String, Vec<(String, RgbImage)>)>,
    ) -> Self {
        ImageGrid {
            title: title.into(),
            column_headers,
            rows: rows
                .into_iter()
                .map(|(label, cells)| GridRow {
                    label,
                    cells: cells
                        .into_iter()
                        .map(|(caption, image)| GridCell { image: Some(image), caption })
                        .collect(),
                })
                .collect(),
            font_px: 16,
            padding: 8,
        }
    }
}

/// Where everything of a grid goes, in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridGeometry {
    /// Raster width.
    pub width: i64,
    /// Raster height.
    pub height: i64,
    /// Left edge of the first column.
    pub left: i64,
    /// Top edge of the first row's slots.
    pub top: i64,
    /// Slot width (widest image or caption).
    pub slot_width: i64,
    /// Slot height (tallest image).
    pub slot_height: i64,
    /// Horizontal distance between columns.
    pub column_step: i64,
    /// Vertical distance between rows.
    pub row_step: i64,
    /// Number of columns.
    pub columns: usize,
}

impl GridGeometry {
    /// Top-left corner of slot (row, column).
    pub fn slot_origin(&self, row: usize, column: usize) -> (i64, i64) {
        let (r, c) = (row as i64, column as i64);
        (self.left + c * self.column_step, self.top + r * self.row_step)
    }

    /// Top-left corner of a `w` x `h` image placed in slot (row, column) (centred).
    pub fn image_origin(&self, row: usize, column: usize, w: u32, h: u32) -> (i64, i64) {
        let (x, y) = self.slot_origin(row, column);
        (x + (self.slot_width - i64::from(w)) / 2, y + (self.slot_height - i64::from(h)) / 2)
    }
}

/// The layout of `grid`.
pub fn grid_geometry(grid: &ImageGrid) -> Result<GridGeometry> {
    let px = grid.font_px.clamp(6, 128);
    let gh = i64::from(px);
    let pad = i64::from(grid.padding.min(1024));
    let cells = || grid.rows.iter().flat_map(|r| r.cells.iter());
    let img_w = cells().filter_map(|c| c.image.as_ref()).map(|i| i64::from(i.width)).max();
    let img_h = cells().filter_map(|c| c.image.as_ref()).map(|i| i64::from(i.height)).max();
    let text_w = |s: &String| text_size(s, px).map(|(w, _)| i64::from(w));
    let widest = |texts: &mut dyn Iterator<Item = &String>| -> Result<i64> {
        texts.map(text_w).try_fold(0, |m, w| Ok(m.max(w?)))
    };
    let caption_w = widest(&mut cells().map(|c| &c.caption))?;
    let header_w = widest(&mut grid.column_headers.iter())?;
    let slot_width = img_w.unwrap_or(0).max(caption_w).max(header_w).max(1);
    let slot_height = img_h.unwrap_or(0).max(1);
    let has_captions = cells().any(|c| !c.caption.is_empty());
    let label_w = widest(&mut grid.rows.iter().map(|r| &r.label))?;
    let columns =
        grid.rows.iter().map(|r| r.cells.len()).max().unwrap_or(0).max(grid.column_headers.len());
    let title_h = if grid.title.is_empty() { 0 } else { gh + pad };
    let header_h = if grid.column_headers.iter().all(String::is_empty) { 0 } else { gh + pad };
    let left = pad + if label_w > 0 { label_w + pad } else { 0 };
    let top = pad + title_h + header_h;
    let column_step = slot_width + pad;
    let row_step = slot_height + if has_captions { pad / 2 + gh } else { 0 } + pad;
    let title_w = text_w(&grid.title)? + 2 * pad;
    Ok(GridGeometry {
        width: (left + columns as i64 * column_step).max(title_w),
        height: top + grid.rows.len() as i64 * row_step,
        left,
        top,
        slot_width,
        slot_height,
        column_step,
        row_step,
        columns,
    })
}

/// Draws `text` in black at `px` pixels with its top at `y`, anchored at `x` as `h` says.
fn text(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    text: &str,
    (x, y): (i64, i64),
    px: u32,
    h: HPos,
) -> Result<()> {
    if text.is_empty() {
        return Ok(());
    }
    let black = RGBColor(BLACK[0], BLACK[1], BLACK[2]);
    let style = TextStyle::from(font(px)).color(&black).pos(Pos::new(h, VPos::Top));
    let at = |v: i64| v.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
    area.draw_text(text, &style, (at(x), at(y))).map_err(draw_error)
}

/// Draws the grid on a white raster.
pub fn draw_image_grid(grid: &ImageGrid) -> Result<Raster> {
    ensure_registered()?;
    let g = grid_geometry(grid)?;
    let side = |v: i64| u32::try_from(v.max(1)).unwrap_or(u32::MAX);
    let mut raster = Raster::new(side(g.width), side(g.height))?;
    for (r, row) in grid.rows.iter().enumerate() {
        for (c, cell) in row.cells.iter().enumerate() {
            if let Some(img) = &cell.image {
                let (ix, iy) = g.image_origin(r, c, img.width, img.height);
                raster.blit(ix, iy, img.width, img.height, &img.pixels);
            }
        }
    }
    let px = grid.font_px.clamp(6, 128);
    let (gh, pad) = (i64::from(px), i64::from(grid.padding.min(1024)));
    let (w, h) = (raster.width, raster.height);
    let area = BitMapBackend::with_buffer(&mut raster.bytes, (w, h)).into_drawing_area();
    text(&area, &grid.title, (g.width / 2, pad), px, HPos::Center)?;
    for (c, header) in grid.column_headers.iter().enumerate() {
        let (x, y) = g.slot_origin(0, c);
        text(&area, header, (x + g.slot_width / 2, y - pad / 2 - gh), px, HPos::Center)?;
    }
    for (r, row) in grid.rows.iter().enumerate() {
        let (_, y) = g.slot_origin(r, 0);
        text(&area, &row.label, (pad, y + g.slot_height / 2 - gh / 2), px, HPos::Left)?;
        for (c, cell) in row.cells.iter().enumerate() {
            let (x, y) = g.slot_origin(r, c);
            let at = (x + g.slot_width / 2, y + g.slot_height + pad / 2);
            text(&area, &cell.caption, at, px, HPos::Center)?;
        }
    }
    area.present().map_err(draw_error)?;
    drop(area);
    Ok(raster)
}

/// The grid as PNG bytes.
pub fn image_grid_png(grid: &ImageGrid) -> Result<Vec<u8>> {
    draw_image_grid(grid)?.to_png()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn colour(r: usize, c: usize) -> Rgb {
        [(40 * r + 10) as u8, (60 * c + 20) as u8, 200]
    }

    #[test]
    fn places_images_where_the_geometry_says() {
        let rows = (0..2)
            .map(|r| {
                let cells = (0..3)
                    .map(|c| {
                        (format!("model {c} 31.58 dB"), RgbImage::filled(24, 16, colour(r, c)))
                    })
                    .collect();
                (format!("view {r}"), cells)
            })
            .collect();
        let headers = vec!["GT".to_string(), "Disney".into(), "RP".into()];
        let grid = ImageGrid::from_images("Qualitative", headers, rows);
        let g = grid_geometry(&grid).unwrap();
        let png = image_grid_png(&grid).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!((i64::from(img.width()), i64::from(img.height())), (g.width, g.height));
        for r in 0..2 {
            for c in 0..3 {
                let (x, y) = g.image_origin(r, c, 24, 16);
                for (dx, dy) in [(0, 0), (23, 15), (12, 8)] {
                    let p = img.get_pixel((x + dx) as u32, (y + dy) as u32).0;
                    assert_eq!(p, colour(r, c), "cell ({r}, {c})");
                }
                // Just outside the image: background or caption, not the image's colour.
                let p = img.get_pixel((x - 1) as u32, y as u32).0;
                assert_ne!(p, colour(r, c));
            }
        }
        // Row 1 lies below row 0, column 2 right of column 1.
        assert!(g.slot_origin(1, 0).1 > g.slot_origin(0, 0).1 + 16);
        assert!(g.slot_origin(0, 2).0 > g.slot_origin(0, 1).0 + 24);
    }

    #[test]
    fn empty_and_ragged_grids() {
        let grid = ImageGrid::from_images("", vec![], vec![]);
        assert!(image_grid_png(&grid).is_ok());
        let mut grid = ImageGrid::from_images(
            "t",
            vec!["a".into(), "b".into(), "c".into()],
            vec![("r".into(), vec![("x".into(), RgbImage::filled(4, 4, BLACK))])],
        );
        grid.rows[0].cells.push(GridCell { image: None, caption: "missing".into() });
        assert_eq!(grid_geometry(&grid).unwrap().columns, 3);
        assert!(image_grid_png(&grid).is_ok());
    }

    #[test]
    fn image_conversions() {
        assert!(RgbImage::new(2, 2, vec![BLACK; 3]).is_err());
        let lin =
            metrics::Image::from_fn(
                2,
                1,
                |x, _| if x == 0 { [0.0; 3] } else { [2.0, 0.5, f32::NAN] },
            );
        let img = RgbImage::from_linear(&lin);
        assert_eq!(img.pixels()[0], [0, 0, 0]);
        assert_eq!(img.pixels()[1][0], 255);
        let flip = RgbImage::error_map(&[0.0, 1.0], Some(&[true, false]), 2, 1).unwrap();
        assert_eq!(flip.pixels()[1], metrics::colormap::OUTSIDE_MASK);
        assert!(RgbImage::error_map(&[0.0], None, 2, 1).is_err());
    }
}
