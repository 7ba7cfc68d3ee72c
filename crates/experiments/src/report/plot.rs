//! Line plots as PNG: one curve per series with markers, distinct colours, a legend, axis
//! ticks and labels, and an optional log-scaled x axis (the run-time against error curves).
//!
//! Colours are matplotlib's "tab10" cycle ([`PALETTE`]), markers cycle through five shapes, so
//! series stay distinguishable in grey print. Points with a non-finite coordinate (or x <= 0 on
//! a log axis) are skipped; a plot without any point draws its axes and "no data".

use super::canvas::{BLACK, Canvas, Rgb, WHITE};
use super::font::{GLYPH_SIZE, text_width};
use crate::Result;

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

const GRID: Rgb = [225, 225, 225];

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
    /// Integer scale of the 8 px font (default 2).
    pub font_scale: u32,
}

impl LinePlot {
    /// A 960 x 600 plot with a log x axis, font scale 2 and no series.
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
            font_scale: 2,
        }
    }
}

/// The plotting area inside the axes, in pixels: x in `left..=right`, y in `top..=bottom`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Left edge.
    pub left: i64,
    /// Top edge.
    pub top: i64,
    /// Right edge.
    pub right: i64,
    /// Bottom edge.
    pub bottom: i64,
}

/// The colour of series `i`.
pub fn series_color(i: usize) -> Rgb {
    PALETTE[i % PALETTE.len()]
}

/// The plot as PNG bytes of `plot.width` x `plot.height` pixels.
pub fn line_plot_png(plot: &LinePlot) -> Result<Vec<u8>> {
    draw_line_plot(plot)?.0.to_png()
}

/// An axis: the transformed range and its ticks (position in transformed units, label).
struct Axis {
    lo: f64,
    hi: f64,
    ticks: Vec<(f64, String)>,
    minor: Vec<f64>,
}

fn finite_points(plot: &LinePlot) -> Vec<Vec<(f64, f64)>> {
    plot.series
        .iter()
        .map(|s| {
            let mut p: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite() && (!plot.log_x || *x > 0.0))
                .map(|(x, y)| (if plot.log_x { x.log10() } else { x }, y))
                .collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            p
        })
        .collect()
}

fn log_axis(lo: f64, hi: f64) -> Axis {
    let lo = lo.floor().max(-300.0);
    let hi = hi.ceil().min(300.0).max(lo + 1.0);
    let decades = (hi - lo) as i64;
    let every = (decades / 8).max(1);
    let mut ticks = Vec::new();
    let mut minor = Vec::new();
    for k in (lo as i64)..=(hi as i64) {
        if (k - lo as i64) % every == 0 {
            ticks.push((k as f64, decade_label(k)));
        }
        if decades <= 6 && k < hi as i64 {
            minor.extend((2..10).map(|m| k as f64 + f64::from(m).log10()));
        }
    }
    Axis { lo, hi, ticks, minor }
}

fn decade_label(k: i64) -> String {
    match k {
        -3..=-1 => format!("{:.*}", k.unsigned_abs() as usize, 10f64.powi(k as i32)),
        0..=4 => format!("{}", 10i64.pow(k as u32)),
        _ => format!("1e{k}"),
    }
}

fn linear_axis(lo: f64, hi: f64) -> Axis {
    let (mut lo, mut hi) = (lo, hi);
    if hi - lo <= f64::EPSILON * lo.abs().max(hi.abs()).max(1.0) {
        let pad = (lo.abs() * 0.05).max(0.5);
        lo -= pad;
        hi += pad;
    }
    let raw = (hi - lo) / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let (lo, hi) = ((lo / step).floor() * step, (hi / step).ceil() * step);
    let decimals = (-(step.log10().floor()) + if step / mag == 2.5 { 1.0 } else { 0.0 })
        .clamp(0.0, 6.0) as usize;
    let n = ((hi - lo) / step).round().clamp(1.0, 50.0) as i64;
    let ticks = (0..=n)
        .map(|i| {
            let v = lo + i as f64 * step;
            let mut s = format!("{v:.decimals$}");
            if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
                s.remove(0);
            }
            (v, s)
        })
        .collect();
    Axis { lo, hi, ticks, minor: Vec::new() }
}

fn axis(values: impl Iterator<Item = f64>, log: bool) -> Axis {
    let (lo, hi) =
        values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    match (lo.is_finite(), log) {
        (false, true) => log_axis(0.0, 1.0),
        (false, false) => linear_axis(0.0, 1.0),
        (true, true) => log_axis(lo, hi),
        (true, false) => linear_axis(lo, hi),
    }
}

/// Draws the plot; returns the canvas and the plotting area (for tests and overlays).
pub fn draw_line_plot(plot: &LinePlot) -> Result<(Canvas, Frame)> {
    let mut canvas = Canvas::new(plot.width, plot.height, WHITE)?;
    let fs = plot.font_scale.clamp(1, 16);
    let gh = i64::from(GLYPH_SIZE * fs);
    let pad = gh / 2 + 4;
    let points = finite_points(plot);
    let xa = axis(points.iter().flatten().map(|p| p.0), plot.log_x);
    let refs: Vec<&(String, f64)> = plot.references.iter().filter(|r| r.1.is_finite()).collect();
    let ya = axis(points.iter().flatten().map(|p| p.1).chain(refs.iter().map(|r| r.1)), false);
    let y_tick_w = ya.ticks.iter().map(|t| i64::from(text_width(&t.1, fs))).max().unwrap_or(0);
    let labels = plot.series.iter().map(|s| &s.label).chain(refs.iter().map(|r| &r.0));
    let legend_w = labels.clone().map(|l| i64::from(text_width(l, fs))).max().unwrap_or(0);
    let legend_w = if labels.count() == 0 { 0 } else { legend_w + 3 * gh + 3 * pad };
    let (w, h) = (i64::from(plot.width), i64::from(plot.height));
    let frame = Frame {
        left: pad + gh + pad + y_tick_w + 8,
        top: if plot.title.is_empty() { pad } else { gh + 2 * pad },
        right: (w - pad - legend_w).max(0),
        bottom: (h - (8 + pad + gh + pad + gh + pad)).max(0),
    };
    let (pw, ph) =
        ((frame.right - frame.left).max(1) as f64, (frame.bottom - frame.top).max(1) as f64);
    let px = |u: f64| frame.left as f64 + (u - xa.lo) / (xa.hi - xa.lo) * pw;
    let py = |v: f64| frame.bottom as f64 - (v - ya.lo) / (ya.hi - ya.lo) * ph;

    // Grid, ticks and tick labels.
    for &u in &xa.minor {
        let x = px(u);
        canvas.line(x, frame.bottom as f64, x, frame.bottom as f64 + 4.0, BLACK, 1);
    }
    for (u, label) in &xa.ticks {
        let x = px(*u);
        canvas.line(x, frame.top as f64, x, frame.bottom as f64, GRID, 1);
        canvas.line(x, frame.bottom as f64, x, frame.bottom as f64 + 8.0, BLACK, 1);
        canvas.text_centered(x.round() as i64, frame.bottom + 8 + pad / 2, label, fs, BLACK);
    }
    for (v, label) in &ya.ticks {
        let y = py(*v);
        canvas.line(frame.left as f64, y, frame.right as f64, y, GRID, 1);
        canvas.line(frame.left as f64 - 8.0, y, frame.left as f64, y, BLACK, 1);
        let tw = i64::from(text_width(label, fs));
        canvas.text(frame.left - 8 - 4 - tw, y.round() as i64 - gh / 2, label, fs, BLACK);
    }
    canvas.stroke_rect(
        frame.left,
        frame.top,
        frame.right - frame.left + 1,
        frame.bottom - frame.top + 1,
        BLACK,
    );

    // Reference lines (dashed), curves, then markers on top.
    let thickness = fs.max(2);
    for r in &refs {
        dashed_line(&mut canvas, frame.left as f64, frame.right as f64, py(r.1), gh, thickness);
    }
    for (i, pts) in points.iter().enumerate() {
        let c = series_color(i);
        for p in pts.windows(2) {
            canvas.line(px(p[0].0), py(p[0].1), px(p[1].0), py(p[1].1), c, thickness);
        }
    }
    for (i, pts) in points.iter().enumerate() {
        for &(u, v) in pts {
            marker(&mut canvas, px(u), py(v), i, gh / 3 + 1);
        }
    }
    if points.iter().all(Vec::is_empty) {
        let cy = (frame.top + frame.bottom) / 2 - gh / 2;
        canvas.text_centered((frame.left + frame.right) / 2, cy, "no data", fs, BLACK);
    }

    // Title, axis labels, legend.
    // The title shrinks (down to scale 1) to fit the width.
    let title_fs =
        (1..=fs).rev().find(|&s| i64::from(text_width(&plot.title, s)) <= w - 2 * pad).unwrap_or(1);
    canvas.text_centered(w / 2, pad, &plot.title, title_fs, BLACK);
    let x_label_y = frame.bottom + 8 + pad / 2 + gh + pad;
    canvas.text_centered((frame.left + frame.right) / 2, x_label_y, &plot.x_label, fs, BLACK);
    let y_label_w = i64::from(text_width(&plot.y_label, fs));
    canvas.text_vertical(
        pad,
        (frame.top + frame.bottom) / 2 + y_label_w / 2,
        &plot.y_label,
        fs,
        BLACK,
    );
    let lx = frame.right + pad;
    for (i, s) in plot.series.iter().enumerate() {
        let y = frame.top + pad + i as i64 * (gh + pad / 2);
        let c = series_color(i);
        let mid = (y + gh / 2) as f64;
        canvas.line(lx as f64, mid, (lx + 2 * gh) as f64, mid, c, thickness);
        marker(&mut canvas, (lx + gh) as f64, mid, i, gh / 3 + 1);
        canvas.text(lx + 2 * gh + pad / 2, y, &s.label, fs, BLACK);
    }
    for (k, r) in refs.iter().enumerate() {
        let y = frame.top + pad + (plot.series.len() + k) as i64 * (gh + pad / 2);
        let mid = (y + gh / 2) as f64;
        dashed_line(&mut canvas, lx as f64, (lx + 2 * gh) as f64, mid, gh / 2, thickness);
        canvas.text(lx + 2 * gh + pad / 2, y, &r.0, fs, BLACK);
    }
    Ok((canvas, frame))
}

/// Colour of the reference lines.
pub const REFERENCE: Rgb = [64, 64, 64];

/// A horizontal dashed line from x0 to x1 at y, dashes of `dash` pixels.
fn dashed_line(canvas: &mut Canvas, x0: f64, x1: f64, y: f64, dash: i64, thickness: u32) {
    let dash = dash.max(2) as f64;
    let mut x = x0;
    while x < x1 {
        canvas.line(x, y, (x + dash).min(x1), y, REFERENCE, thickness);
        x += 2.0 * dash;
    }
}

/// Draws marker shape `i % 5` (circle, square, triangle, diamond, cross) of radius `r` at (x, y)
/// in series `i`'s colour.
fn marker(canvas: &mut Canvas, x: f64, y: f64, i: usize, r: i64) {
    if !x.is_finite() || !y.is_finite() {
        return;
    }
    let c = series_color(i);
    let (cx, cy) = (x.round() as i64, y.round() as i64);
    for dy in -r..=r {
        for dx in -r..=r {
            let inside = match i % 5 {
                0 => dx * dx + dy * dy <= r * r,
                1 => dx.abs() * 10 <= r * 8 && dy.abs() * 10 <= r * 8,
                2 => 2 * dx.abs() <= dy + r,
                3 => dx.abs() + dy.abs() <= r,
                _ => (dx.abs() - dy.abs()).abs() <= 1,
            };
            if inside {
                canvas.set(cx + dx, cy + dy, c);
            }
        }
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

    #[test]
    fn png_of_the_stated_size_with_every_curve_colour() {
        let p = plot(9);
        let png = line_plot_png(&p).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (960, 600));
        let (_, frame) = draw_line_plot(&p).unwrap();
        for i in 0..9 {
            let c = series_color(i);
            let found = img.enumerate_pixels().any(|(x, y, px)| {
                let (x, y) = (i64::from(x), i64::from(y));
                px.0 == c && x > frame.left && x < frame.right && y > frame.top && y < frame.bottom
            });
            assert!(found, "series {i} colour {c:?} missing in the plot area");
        }
        assert!(frame.left < frame.right && frame.top < frame.bottom);
    }

    #[test]
    fn reference_lines_are_drawn_inside_the_frame() {
        let mut p = plot(1);
        p.references.push(("noise ceiling".into(), 21.5));
        let png = line_plot_png(&p).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        let (_, frame) = draw_line_plot(&p).unwrap();
        let inside = img.enumerate_pixels().filter(|(x, y, px)| {
            let (x, y) = (i64::from(*x), i64::from(*y));
            px.0 == REFERENCE && x > frame.left && x < frame.right && y > frame.top
        });
        // Dashes cover about half the frame's width, thickness 2.
        assert!(inside.count() as i64 > frame.right - frame.left);
    }

    #[test]
    fn degenerate_inputs_draw() {
        let mut p = plot(2);
        p.series[0].points = vec![(f64::NAN, 1.0), (-1.0, 2.0), (0.0, f64::INFINITY)];
        p.series[1].points = vec![(5.0, 3.0)];
        assert!(line_plot_png(&p).is_ok());
        let mut p = plot(0);
        p.width = 40;
        p.height = 30;
        p.log_x = false;
        assert!(line_plot_png(&p).is_ok());
        p.width = 0;
        assert!(line_plot_png(&p).is_err());
    }

    #[test]
    fn axes() {
        let a = log_axis(0.3, 2.7);
        let labels: Vec<&str> = a.ticks.iter().map(|t| t.1.as_str()).collect();
        assert_eq!(labels, ["1", "10", "100", "1000"]);
        assert_eq!(decade_label(-2), "0.01");
        assert_eq!(decade_label(6), "1e6");
        let a = linear_axis(20.3, 31.7);
        let labels: Vec<&str> = a.ticks.iter().map(|t| t.1.as_str()).collect();
        assert_eq!(labels, ["20.0", "22.5", "25.0", "27.5", "30.0", "32.5"]);
        let a = linear_axis(5.0, 5.0);
        assert!(a.lo < 5.0 && a.hi > 5.0);
    }
}
