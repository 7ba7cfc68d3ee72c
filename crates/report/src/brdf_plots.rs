//! BRDF plots that compare fitted models with the ground-truth material, drawn from a
//! [`BrdfProbe`] of each BRDF (the experiments crate evaluates the probes; this module only
//! draws them):
//!
//! * [`lit_sphere_grid`]: each BRDF on a sphere under the same directional light, one
//!   exposure for all, with the HDR-FLIP map against the ground truth's sphere;
//! * [`polar_slices_png`]: f_r cos(theta_i) in the plane of incidence against the outgoing
//!   angle, one panel per incident angle, every BRDF a curve (linear or log10);
//! * [`albedo_plot_png`]: directional albedo against the incident angle (white furnace), with
//!   the line at 1;
//! * [`validity_grid`]: per-pixel validity on an image of the object: directional albedo for
//!   the viewing direction (grey up to 1, red above) and the relative reciprocity error.
//!
//! Curves show luminance (Rec. 709 weights) for slices and the largest channel for albedo
//! (the channel that decides energy conservation).

use crate::error::{Error, Result};
use crate::grid::{GridCell, GridRow, ImageGrid, RgbImage};
use crate::plot::{LegendCorner, LinePlot, Series, draw_line_plot};
use crate::raster::Rgb;
use metrics::colormap::magma;
use serde::{Deserialize, Serialize};

/// Side in pixels of a probe's lit sphere.
pub const SPHERE_SIZE: u32 = 96;

/// Colour around the lit spheres.
pub const SPHERE_BACKGROUND: Rgb = [72, 72, 72];

/// Colour of the validity maps where no surface point was evaluated (light blue, apart from
/// both the greys of the albedo and the magma of the reciprocity error).
pub const MAP_BACKGROUND: Rgb = [200, 222, 245];

/// A BRDF rendered on a sphere: orthographic camera on +z, `SPHERE_SIZE`^2 pixels row-major
/// (row 0 at the top), radiance L = f_r E cos(theta_l) (linear RGB, E = pi) inside the disk of
/// [`sphere_normal`], 0 outside.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LitSphere {
    /// Unit direction to the light, world frame (the camera looks down -z).
    pub light: [f64; 3],
    /// The radiance of every pixel.
    pub radiance: Vec<[f32; 3]>,
}

/// One slice in the plane of incidence: the light at `theta_i_deg` on the -x side, the viewer
/// swept through the plane (negative angles on the light's side, the mirror direction at
/// `+theta_i_deg`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PolarSlice {
    /// Incident polar angle, degrees.
    pub theta_i_deg: f64,
    /// (outgoing angle in degrees, f_r cos(theta_i) in 1/sr, RGB).
    pub points: Vec<(f64, [f32; 3])>,
}

/// Per-pixel validity of a fitted model on one test view of the object.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ValidityMaps {
    /// Which image this is ("test view 7").
    pub view: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Largest channel of the directional albedo for the pixel's viewing direction (NaN where
    /// no surface point was evaluated).
    pub albedo: Vec<f32>,
    /// |f(l, v) - f(v, l)| / (mean of the two), averaged over channels, for the pixel's test
    /// light (NaN where no point was evaluated).
    pub reciprocity: Vec<f32>,
}

/// A point of a directional-albedo curve: (incident angle in degrees, albedo RGB).
pub type AlbedoPoint = (f64, [f32; 3]);

/// What one BRDF shows on the standard probes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BrdfProbe {
    /// Where a spatially varying BRDF was evaluated ("surface point at the centre of test view
    /// 7"); empty for a uniform one.
    pub point: String,
    /// The lit sphere.
    pub sphere: LitSphere,
    /// Slices in the plane of incidence.
    pub slices: Vec<PolarSlice>,
    /// Directional albedo against the incident angle.
    pub albedo: Vec<AlbedoPoint>,
    /// Per-pixel validity on the object (fitted models).
    pub validity: Option<ValidityMaps>,
}

/// Rec. 709 luminance.
pub fn luminance(c: [f32; 3]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

/// The world normal of sphere pixel (`x`, `y`) (row 0 at the top), `None` outside the disk.
pub fn sphere_normal(x: u32, y: u32) -> Option<[f64; 3]> {
    let s = SPHERE_SIZE as f64;
    let px = 2.0 * (x as f64 + 0.5) / s - 1.0;
    let py = 1.0 - 2.0 * (y as f64 + 0.5) / s;
    let r2 = px * px + py * py;
    (r2 < 1.0).then(|| [px, py, (1.0 - r2).sqrt()])
}

/// Display scale of the spheres: the median lit luminance of `reference` at 18 % grey.
fn sphere_exposure(reference: &LitSphere) -> f32 {
    let mut lum: Vec<f64> =
        reference.radiance.iter().map(|&c| luminance(c)).filter(|&v| v > 0.0).collect();
    if lum.is_empty() {
        return 1.0;
    }
    let n = lum.len();
    let (_, m, _) = lum.select_nth_unstable_by(n / 2, f64::total_cmp);
    (0.18 / *m) as f32
}

fn sphere_image(s: &LitSphere, scale: f32) -> Result<metrics::Image> {
    let data = s.radiance.iter().flat_map(|c| c.map(|v| v * scale)).collect();
    let side = SPHERE_SIZE as usize;
    metrics::Image::new(side, side, data).map_err(|e| Error::figure("report.sphere", e.to_string()))
}

/// Each BRDF's sphere beside its HDR-FLIP map against the reference (the ground truth's
/// sphere, first row; without it, the first BRDF is the reference). One display exposure for
/// every sphere; images enlarged 3x.
pub fn lit_sphere_grid(
    title: &str,
    reference: Option<&LitSphere>,
    models: &[(String, &LitSphere)],
) -> Result<ImageGrid> {
    let Some(base) = reference.or(models.first().map(|m| m.1)) else {
        return Err(Error::figure("report.sphere", "no sphere to draw"));
    };
    let side = SPHERE_SIZE * SPHERE_SIZE;
    for s in models.iter().map(|m| m.1).chain(reference) {
        if s.radiance.len() != side as usize {
            let fault = format!("{} pixels for a {SPHERE_SIZE}^2 sphere", s.radiance.len());
            return Err(Error::figure("report.sphere", fault));
        }
    }
    let scale = sphere_exposure(base);
    let mask: Vec<bool> =
        (0..side).map(|i| sphere_normal(i % SPHERE_SIZE, i / SPHERE_SIZE).is_some()).collect();
    let base_img = sphere_image(base, 1.0)?;
    // The unlit side is black; the background dark grey, so the outline stays visible.
    let shown = |s: &LitSphere| -> Result<RgbImage> {
        let img = RgbImage::from_linear(&sphere_image(s, scale)?);
        let px = img
            .pixels()
            .iter()
            .zip(&mask)
            .map(|(&p, &inside)| if inside { p } else { SPHERE_BACKGROUND })
            .collect();
        Ok(RgbImage::new(SPHERE_SIZE, SPHERE_SIZE, px)?.scaled(3))
    };
    let empty = || GridCell { image: None, caption: String::new() };
    let mut rows = Vec::new();
    if let Some(r) = reference {
        rows.push(GridRow {
            label: "Ground truth".into(),
            cells: vec![GridCell { image: Some(shown(r)?), caption: String::new() }, empty()],
        });
    }
    for (name, s) in models {
        let flip = metrics::flip::hdr_flip_with(
            &sphere_image(s, 1.0)?,
            &base_img,
            Some(&mask),
            &metrics::flip::FlipConfig::default(),
        );
        let flip = match flip {
            Ok(f) => GridCell {
                image: Some(
                    RgbImage::error_map(&f.map, Some(&mask), SPHERE_SIZE, SPHERE_SIZE)?.scaled(3),
                ),
                caption: format!("mean {:.3}", f.mean),
            },
            Err(e) => GridCell { image: None, caption: format!("FLIP n/a: {e}") },
        };
        rows.push(GridRow {
            label: name.clone(),
            cells: vec![GridCell { image: Some(shown(s)?), caption: String::new() }, flip],
        });
    }
    let against = if reference.is_some() { "ground truth" } else { "first row" };
    Ok(ImageGrid {
        title: title.to_string(),
        column_headers: vec!["lit sphere".into(), format!("HDR-FLIP against {against}")],
        rows,
        font_px: 20,
        padding: 10,
    })
}

/// A line plot's raster as an image for a grid.
fn plot_image(plot: &LinePlot) -> Result<RgbImage> {
    let r = draw_line_plot(plot)?;
    let px = r.bytes.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    RgbImage::new(r.width, r.height, px)
}

/// Smallest value a log10 slice shows (1/sr).
pub const LOG_FLOOR: f64 = 1e-4;

/// The slices of every BRDF, one panel per incident angle (two panels a row): luminance of
/// f_r cos(theta_i) against the outgoing angle, or its log10 (floored at [`LOG_FLOOR`]) with
/// `log`. The slices of each BRDF are matched to the panels by incident angle.
pub fn polar_slices_png(
    title: &str,
    brdfs: &[(String, &[PolarSlice])],
    log: bool,
) -> Result<Vec<u8>> {
    let Some((_, first)) = brdfs.first() else {
        return Err(Error::figure("report.slices", "no BRDF to plot"));
    };
    let y_label = if log {
        "log10 f_r cos(theta_i) (luminance)"
    } else {
        "f_r cos(theta_i) (1/sr, luminance)"
    };
    let mut cells = Vec::new();
    for slice in first.iter() {
        let mut plot = LinePlot::new(
            format!("incident {:.0} deg", slice.theta_i_deg),
            "outgoing angle theta_o (deg; negative: light's side)",
            y_label,
        );
        plot.log_x = false;
        (plot.width, plot.height) = (900, 620);
        plot.marker_every = 15;
        plot.legend = LegendCorner::UpperLeft;
        for (name, slices) in brdfs {
            let Some(s) = slices.iter().find(|s| s.theta_i_deg == slice.theta_i_deg) else {
                continue;
            };
            let y = |c: [f32; 3]| {
                let v = luminance(c);
                if log { v.max(LOG_FLOOR).log10() } else { v }
            };
            plot.series.push(Series {
                label: name.clone(),
                points: s.points.iter().map(|&(t, c)| (t, y(c))).collect(),
            });
        }
        cells.push(GridCell { image: Some(plot_image(&plot)?), caption: String::new() });
    }
    let rows =
        cells.chunks(2).map(|c| GridRow { label: String::new(), cells: c.to_vec() }).collect();
    let scale = if log { "log10" } else { "linear" };
    let grid = ImageGrid {
        title: format!("{title} (slices in the plane of incidence, {scale})"),
        column_headers: Vec::new(),
        rows,
        font_px: 20,
        padding: 8,
    };
    crate::grid::image_grid_png(&grid)
}

/// Directional albedo (largest channel) against the incident angle for every BRDF, with the
/// line at 1 above which a BRDF creates energy.
pub fn albedo_plot_png(title: &str, brdfs: &[(String, &[AlbedoPoint])]) -> Result<Vec<u8>> {
    let mut plot = LinePlot::new(
        format!("{title}: directional albedo (white furnace)"),
        "incident angle theta (deg)",
        "directional albedo (largest channel)",
    );
    plot.log_x = false;
    plot.marker_every = 4;
    plot.legend = LegendCorner::UpperLeft;
    plot.references = vec![("albedo = 1".into(), 1.0)];
    for (name, curve) in brdfs {
        let max = |c: [f32; 3]| c.iter().fold(f32::MIN, |a, &b| a.max(b)) as f64;
        plot.series.push(Series {
            label: name.clone(),
            points: curve.iter().map(|&(t, c)| (t, max(c))).collect(),
        });
    }
    crate::plot::line_plot_png(&plot)
}

/// Directional albedo above which a validity-map pixel is full red.
pub const ALBEDO_RED: f32 = 1.25;

/// Colour of a directional albedo: grey up to 1 (sRGB-encoded), then from pink to full red at
/// [`ALBEDO_RED`]; no value: [`MAP_BACKGROUND`].
pub fn albedo_colour(a: f32) -> Rgb {
    if !a.is_finite() {
        return MAP_BACKGROUND;
    }
    if a <= 1.0 {
        let g = (metrics::srgb::oetf_clamped(a.max(0.0)) * 255.0).round() as u8;
        return [g, g, g];
    }
    let t = ((a - 1.0) / (ALBEDO_RED - 1.0)).clamp(0.0, 1.0);
    let gb = (190.0 * (1.0 - t)).round() as u8;
    [255, gb, gb]
}

/// Colour of a relative reciprocity error: magma over log10 from 1e-4 (black) to 1; no value:
/// [`MAP_BACKGROUND`].
pub fn reciprocity_colour(e: f32) -> Rgb {
    if !e.is_finite() {
        return MAP_BACKGROUND;
    }
    let t = if e <= 0.0 { 0.0 } else { ((e.log10() + 4.0) / 4.0).clamp(0.0, 1.0) };
    magma(t)
}

/// Each model's validity maps in a row: directional albedo (caption: share of pixels above 1
/// and the largest value) and reciprocity error (median and largest), enlarged to about 288 px.
pub fn validity_grid(title: &str, models: &[(String, &ValidityMaps)]) -> Result<ImageGrid> {
    let mut rows = Vec::new();
    for (name, m) in models {
        let n = m.width as usize * m.height as usize;
        if m.albedo.len() != n || m.reciprocity.len() != n {
            let fault =
                format!("maps of {} and {} pixels for {n}", m.albedo.len(), m.reciprocity.len());
            return Err(Error::figure("report.validity", fault));
        }
        let factor = (288 / m.width.max(m.height).max(1)).max(1);
        let image = |values: &[f32], colour: fn(f32) -> Rgb| -> Result<RgbImage> {
            Ok(RgbImage::new(m.width, m.height, values.iter().map(|&v| colour(v)).collect())?
                .scaled(factor))
        };
        let albedo: Vec<f32> = m.albedo.iter().copied().filter(|v| v.is_finite()).collect();
        let above = albedo.iter().filter(|&&v| v > 1.0).count();
        let share = 100.0 * above as f64 / albedo.len().max(1) as f64;
        let amax = albedo.iter().copied().fold(f32::NAN, f32::max);
        let mut recip: Vec<f32> = m.reciprocity.iter().copied().filter(|v| v.is_finite()).collect();
        recip.sort_by(f32::total_cmp);
        let (median, rmax) = match recip.len() {
            0 => (f32::NAN, f32::NAN),
            k => (recip[k / 2], recip[k - 1]),
        };
        rows.push(GridRow {
            label: name.clone(),
            cells: vec![
                GridCell {
                    image: Some(image(&m.albedo, albedo_colour)?),
                    caption: format!("> 1 at {share:.1} % of pixels, max {amax:.3}"),
                },
                GridCell {
                    image: Some(image(&m.reciprocity, reciprocity_colour)?),
                    caption: format!("median {median:.1e}, max {rmax:.1e}"),
                },
            ],
        });
    }
    let view = models.first().map_or(String::new(), |m| format!(", {}", m.1.view));
    Ok(ImageGrid {
        title: format!("{title}: validity on the object{view}"),
        column_headers: vec![
            format!("directional albedo (grey <= 1, red > 1, full red {ALBEDO_RED})"),
            "reciprocity error (magma, log 1e-4 .. 1)".into(),
        ],
        rows,
        font_px: 18,
        padding: 10,
    })
}

#[cfg(test)]
mod tests;
