//! Line plots as PNG, drawn with plotters: one curve per series with markers, distinct
//! colours, a legend, axis ticks and labels, an optional log-scaled x axis (the run-time against
//! error curves) and dashed horizontal reference lines (the noise ceiling).
//!
//! Colours are matplotlib's "tab10" cycle ([`PALETTE`]), markers cycle through five shapes, so
//! series stay distinguishable in grey print. Points with a non-finite coordinate (or x <= 0 on
//! a log axis) are skipped; a plot without any point draws its axes and "no data".

use crate::error::Result;
use crate::font::{ensure_registered, font};
use crate::raster::{Raster, Rgb, draw_error};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::ops::Range;

/// matplotlib's tab10 colours, the colour of series i being `PALETTE[i % 10]`.
pub const PALETTE: [Rgb; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

/// Colour of the reference lines.
pub const REFERENCE: Rgb = [64, 64, 64];

/// One curve: its legend label and (x, y) points (drawn in order of increasing x).
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// The points.
    pub points: Vec<(f64, f64)>,
}

/// A line plot.
#[derive(Clone, Debug, PartialEq)]
pub struct LinePlot {
    /// Title above the plot.
    pub title: String,
    /// x axis label.
    pub x_label: String,
    /// y axis label (drawn vertically).
    pub y_label: String,
    /// Log-scaled x axis (default true).
    pub log_x: bool,
    /// The curves.
    pub series: Vec<Series>,
    /// Horizontal reference lines (label, y), drawn dashed in dark grey (the noise ceiling).
    pub references: Vec<(String, f64)>,
    /// Image width in pixels (default 960).
    pub width: u32,
    /// Image height in pixels (default 600).
    pub height: u32,
    /// Text size in pixels (default 16).
    pub font_px: u32,
    /// A marker on every k-th point of a curve (default 1: every point; 0: none), so that
    /// densely sampled curves stay lines.
    pub marker_every: usize,
    /// Corner of the legend (default lower right).
    pub legend: LegendCorner,
}

/// Where a plot's legend goes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LegendCorner {
    /// Upper left.
    UpperLeft,
    /// Upper right.
    UpperRight,
    /// Lower left.
    LowerLeft,
    /// Lower right.
    #[default]
    LowerRight,
}

impl LinePlot {
    /// A 960 x 600 plot with a log x axis, 16 px text and no series.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        LinePlot {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: true,
            series: Vec::new(),
            references: Vec::new(),
            width: 960,
            height: 600,
            font_px: 16,
            marker_every: 1,
            legend: LegendCorner::LowerRight,
        }
    }
}

/// The colour of series `i`.
pub fn series_color(i: usize) -> Rgb {
    PALETTE[i % PALETTE.len()]
}

fn rgb(c: Rgb) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// The plot as PNG bytes of `plot.width` x `plot.height` pixels.
pub fn line_plot_png(plot: &LinePlot) -> Result<Vec<u8>> {
    draw_line_plot(plot)?.to_png()
}

/// The series' drawable points, sorted by x.
fn finite_points(plot: &LinePlot) -> Vec<Vec<(f64, f64)>> {
    plot.series
        .iter()
        .map(|s| {
            let mut p: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite() && (!plot.log_x || *x > 0.0))
                .collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            p
        })
        .collect()
}

/// The range of `values` with 5 % room on both sides (0..1 without values, +-0.5 around a
/// single value).
fn padded_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) =
        values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { (lo.abs() * 0.05).max(0.5) };
    lo - pad..hi + pad
}

/// Whole decades around the positive `values` (1..10 without values).
fn decade_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) =
        values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return 1.0..10.0;
    }
    let (a, b) = (lo.log10().floor().max(-300.0), hi.log10().ceil().min(300.0));
    10f64.powf(a)..10f64.powf(b.max(a + 1.0))
}

/// A tick label: up to three decimals without trailing zeros, scientific outside 1e-3..1e5.
fn tick_label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

/// Draws the plot into a raster of its size.
pub fn draw_line_plot(plot: &LinePlot) -> Result<Raster> {
    ensure_registered()?;
    let mut raster = Raster::new(plot.width, plot.height)?;
    let points = finite_points(plot);
    let refs: Vec<&(String, f64)> = plot.references.iter().filter(|r| r.1.is_finite()).collect();
    let y = padded_range(points.iter().flatten().map(|p| p.1).chain(refs.iter().map(|r| r.1)));
    {
        let root = BitMapBackend::with_buffer(&mut raster.bytes, (plot.width, plot.height))
            .into_drawing_area();
        if plot.log_x {
            let x = decade_range(points.iter().flatten().map(|p| p.0));
            draw_chart(&root, plot, x.clone().log_scale(), (x, y), &points, &refs)?;
        } else {
            let x = padded_range(points.iter().flatten().map(|p| p.0));
            draw_chart(&root, plot, x.clone(), (x, y), &points, &refs)?;
        }
        root.present().map_err(draw_error)?;
    }
    Ok(raster)
}

/// The chart on `root` with the x axis `x_axis` over `ranges.0` and y over `ranges.1`.
fn draw_chart<XR>(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    plot: &LinePlot,
    x_axis: XR,
    (x, y): (Range<f64>, Range<f64>),
    points: &[Vec<(f64, f64)>],
    refs: &[&(String, f64)],
) -> Result<()>
where
    XR: AsRangedCoord<Value = f64>,
    XR::CoordDescType: ValueFormatter<f64>,
{
    let px = plot.font_px.clamp(6, 128);
    let mut chart = ChartBuilder::on(root)
        .caption(&plot.title, font(px + px / 4))
        .margin(px / 2 + 4)
        .x_label_area_size(px * 3)
        .y_label_area_size(px * 4)
        .build_cartesian_2d(x_axis, y.clone())
        .map_err(draw_error)?;
    chart
        .configure_mesh()
        .x_desc(plot.x_label.as_str())
        .y_desc(plot.y_label.as_str())
        .label_style(font(px))
        .axis_desc_style(font(px))
        .bold_line_style(RGBColor(220, 220, 220))
        .light_line_style(RGBColor(242, 242, 242))
        .x_label_formatter(&|v: &f64| tick_label(*v))
        .y_label_formatter(&|v: &f64| tick_label(*v))
        .draw()
        .map_err(draw_error)?;
    let stroke = (px / 8).max(2);
    for r in refs {
        let style = rgb(REFERENCE).stroke_width(stroke);
        let line = DashedLineSeries::new([(x.start, r.1), (x.end, r.1)], px, px / 2, style);
        chart
            .draw_series(line)
            .map_err(draw_error)?
            .label(r.0.as_str())
            .legend(move |(lx, ly)| PathElement::new([(lx, ly), (lx + 2 * px as i32, ly)], style));
    }
    let radius = (px / 4).max(3) as i32;
    for (i, (s, pts)) in plot.series.iter().zip(points).enumerate() {
        let c = rgb(series_color(i));
        let style = c.stroke_width(stroke);
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), style))
            .map_err(draw_error)?
            .label(s.label.as_str())
            .legend(move |(lx, ly)| {
                EmptyElement::at((lx, ly))
                    + PathElement::new([(0, 0), (2 * px as i32, 0)], style)
                    + marker(i, (px as i32, 0), radius, c)
            });
        if plot.marker_every > 0 {
            let marked = pts.iter().step_by(plot.marker_every);
            chart
                .draw_series(marked.map(|&p| EmptyElement::at(p) + marker(i, (0, 0), radius, c)))
                .map_err(draw_error)?;
        }
    }
    if !plot.series.is_empty() || !refs.is_empty() {
        chart
            .configure_series_labels()
            .label_font(font(px))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(legend_position(plot.legend))
            .draw()
            .map_err(draw_error)?;
    }
    if points.iter().all(Vec::is_empty) {
        let style = TextStyle::from(font(px)).pos(Pos::new(HPos::Center, VPos::Center));
        let (w, h) = root.dim_in_pixel();
        root.draw_text("no data", &style, ((w / 2) as i32, (h / 2) as i32)).map_err(draw_error)?;
    }
    Ok(())
}

/// Where plotters puts the legend for `corner`.
fn legend_position(corner: LegendCorner) -> SeriesLabelPosition {
    match corner {
        LegendCorner::UpperLeft => SeriesLabelPosition::UpperLeft,
        LegendCorner::UpperRight => SeriesLabelPosition::UpperRight,
        LegendCorner::LowerLeft => SeriesLabelPosition::LowerLeft,
        LegendCorner::LowerRight => SeriesLabelPosition::LowerRight,
    }
}

/// Marker shape `i % 5` (circle, square, triangle, cross, ring) of radius `r` at pixel offset
/// `at` in colour `c`.
fn marker<DB: DrawingBackend>(
    i: usize,
    at: (i32, i32),
    r: i32,
    c: RGBColor,
) -> DynElement<'static, DB, (i32, i32)> {
    match i % 5 {
        0 => Circle::new(at, r, c.filled()).into_dyn(),
        1 => Rectangle::new([(at.0 - r, at.1 - r), (at.0 + r, at.1 + r)], c.filled()).into_dyn(),
        2 => TriangleMarker::new(at, r + 1, c.filled()).into_dyn(),
        3 => Cross::new(at, r, c.stroke_width(2)).into_dyn(),
        _ => Circle::new(at, r, c.stroke_width(2)).into_dyn(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plot(series: usize) -> LinePlot {
        let mut p = LinePlot::new("PSNR against training time", "training time (s)", "PSNR (dB)");
        for i in 0..series {
            let points = (0..4)
                .map(|k| (10f64.powi(k) * (1.0 + i as f64), 20.0 + k as f64 + i as f64))
                .collect();
            p.series.push(Series { label: format!("model {i}"), points });
        }
        p
    }

    fn count(r: &Raster, c: Rgb) -> usize {
        r.bytes.chunks_exact(3).filter(|p| *p == c).count()
    }

    #[test]
    fn png_of_the_stated_size_with_every_curve_colour() {
        let p = plot(9);
        let png = line_plot_png(&p).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (960, 600));
        let r = draw_line_plot(&p).unwrap();
        for i in 0..9 {
            // A curve of 3 segments, its markers and the legend entry: far more than a legend.
            let n = count(&r, series_color(i));
            assert!(n > 400, "series {i} colour {:?}: {n} pixels", series_color(i));
        }
        // Text was drawn: dark pixels that belong to no series.
        assert!(count(&r, [0, 0, 0]) > 500);
    }

    #[test]
    fn reference_lines_are_dashed_across_the_plot() {
        let mut p = plot(1);
        let without = count(&draw_line_plot(&p).unwrap(), REFERENCE);
        p.references.push(("noise ceiling".into(), 21.5));
        let r = draw_line_plot(&p).unwrap();
        // Dashes cover about two thirds of a ~800 px wide plot, 2 px thick.
        assert!(count(&r, REFERENCE) > without + 600, "{without} {}", count(&r, REFERENCE));
    }

    #[test]
    fn degenerate_inputs_draw() {
        let mut p = plot(2);
        p.series[0].points = vec![(f64::NAN, 1.0), (-1.0, 2.0), (0.0, f64::INFINITY)];
        p.series[1].points = vec![(5.0, 3.0)];
        assert!(line_plot_png(&p).is_ok());
        let mut p = plot(0);
        p.width = 120;
        p.height = 90;
        p.log_x = false;
        assert!(line_plot_png(&p).is_ok());
        p.width = 0;
        assert!(line_plot_png(&p).is_err());
    }

    #[test]
    fn ranges_and_tick_labels() {
        assert_eq!(decade_range([2.0, 350.0].into_iter()), 1.0..1000.0);
        assert_eq!(decade_range(std::iter::empty()), 1.0..10.0);
        assert_eq!(decade_range([10.0].into_iter()), 10.0..100.0);
        let r = padded_range([20.0, 30.0].into_iter());
        assert!((r.start - 19.5).abs() < 1e-12 && (r.end - 30.5).abs() < 1e-12);
        let r = padded_range([5.0].into_iter());
        assert!(r.start < 5.0 && r.end > 5.0);
        assert_eq!(tick_label(100.0), "100");
        assert_eq!(tick_label(22.5), "22.5");
        assert_eq!(tick_label(0.01), "0.01");
        assert_eq!(tick_label(1e6), "1e6");
        assert_eq!(tick_label(0.0), "0");
    }
}
