//! The paper's figures assembled from records and images: the run-time against error curves
//! ([`runtime_plot`], drawn by [`super::plot::line_plot_png`]) and the qualitative comparison
//! grid ([`qualitative_grid`]: models in rows, render, FLIP map and a zoom on the highlight
//! beside the ground truth's, drawn by [`super::grid::image_grid_png`]).
//!
//! The diffuse / specular / albedo split figures are plain [`ImageGrid`]s: one row per test
//! image, columns such as "GT", "render", "diffuse", "specular", "albedo", built with
//! [`ImageGrid::from_images`].

use super::average::average;
use super::grid::{GridCell, GridRow, ImageGrid, RgbImage};
use super::plot::{LinePlot, Series};
use super::record::{Dataset, MetricKind, RunOptions, RunRecord};
use super::table::Cell;
use metrics::aggregate::Score;
use model_spec::ModelKind;

/// `metric` against training time on `dataset`, one curve per model (default options).
///
/// Each point is one snapshot step (the records of a model sharing `steps`): x is the mean
/// wall time of the runs at that step and y the mean metric, both averaged per object then
/// over objects; y is table-scaled (RMSE∛ ×100). Steps lacking either value are skipped,
/// models without any point are left out. The x axis is log-scaled; `ceiling` (raw units)
/// draws the noise ceiling as a dashed horizontal line.
pub fn runtime_plot(
    records: &[RunRecord],
    dataset: &Dataset,
    metric: MetricKind,
    ceiling: Option<f64>,
    profile: &str,
) -> LinePlot {
    let mut plot = LinePlot::new(
        format!("{} vs time - {}, profile {profile}", ascii(metric), dataset.label()),
        "training wall time (s, log)",
        y_label(metric),
    );
    if let Some(c) = ceiling {
        plot.references.push(("noise ceiling".into(), c * metric.factor()));
    }
    for model in ModelKind::ALL {
        let mine: Vec<&RunRecord> = records
            .iter()
            .filter(|r| {
                r.model == model && r.options == RunOptions::DEFAULT && &r.dataset == dataset
            })
            .collect();
        let mut budgets: Vec<Option<u64>> = mine.iter().map(|r| r.steps).collect();
        budgets.sort();
        budgets.dedup();
        let mut points = Vec::new();
        for steps in budgets {
            let at: Vec<&RunRecord> = mine.iter().copied().filter(|r| r.steps == steps).collect();
            let value = |m: MetricKind| match average(&at, model, RunOptions::DEFAULT, dataset, m) {
                Cell::Score(Score::Value(v)) if v.is_finite() => Some(v),
                _ => None,
            };
            if let (Some(x), Some(y)) = (value(MetricKind::TrainingSeconds), value(metric)) {
                points.push((x, y * metric.factor()));
            }
        }
        if !points.is_empty() {
            plot.series.push(Series { label: model.paper_name().to_string(), points });
        }
    }
    plot
}

fn ascii(metric: MetricKind) -> &'static str {
    match metric {
        MetricKind::CubeRootRmse => "RMSE of cube roots",
        m => m.label(),
    }
}

fn y_label(metric: MetricKind) -> String {
    match metric {
        MetricKind::Psnr => "PSNR (dB)".into(),
        m if m.factor() != 1.0 => format!("{} (x100)", ascii(m)),
        m => ascii(m).into(),
    }
}

/// One model's render of a test image for [`qualitative_grid`].
#[derive(Clone, Debug, PartialEq)]
pub struct ModelRender {
    /// The model's name in headers and captions (a paper row name).
    pub model: String,
    /// The render (sRGB).
    pub render: RgbImage,
    /// Its PSNR in dB (the caption reads "Disney 31.58 dB", or "Disney n/a").
    pub psnr_db: Score,
    /// Its FLIP map ([`RgbImage::error_map`]) and mean FLIP, for the optional FLIP row.
    pub flip: Option<(RgbImage, Score)>,
}

/// One test image of [`qualitative_grid`].
#[derive(Clone, Debug, PartialEq)]
pub struct QualitativeRow {
    /// Row label ("view 3, light 7").
    pub label: String,
    /// The ground truth (sRGB).
    pub reference: RgbImage,
    /// Each model's render, in column order.
    pub renders: Vec<ModelRender>,
}

/// Longest side, in pixels, of every image of [`qualitative_grid`] (renders are enlarged by
/// whole factors, nearest neighbour, up to it).
pub const QUALITATIVE_SIDE: u32 = 384;

/// The square window around the brightest ground-truth pixel (the highlight), side a quarter
/// of the shorter image side (at least 8 pixels): `(x, y, side)`.
pub fn highlight_window(reference: &RgbImage) -> (u32, u32, u32) {
    let (w, h) = (reference.width(), reference.height());
    let side = (w.min(h) / 4).max(8).min(w.min(h));
    let brightest = reference
        .pixels()
        .iter()
        .enumerate()
        .max_by_key(|(_, p)| p[0] as u32 + p[1] as u32 + p[2] as u32)
        .map_or(0, |(i, _)| i as u32);
    let (cx, cy) = (brightest % w.max(1), brightest / w.max(1));
    let x = cx.saturating_sub(side / 2).min(w - side);
    let y = cy.saturating_sub(side / 2).min(h - side);
    (x, y, side)
}

/// The qualitative comparison of one test image, laid out to be read: one row per model (the
/// ground truth first), columns render (captioned with its PSNR), FLIP map (with its mean), and
/// a zoom on the highlight of the ground truth and of the render side by side (the ground
/// truth repeated in every row, so each model's highlight sits next to the one it should
/// match). Images are enlarged to [`QUALITATIVE_SIDE`] by whole factors; text is 22 px.
pub fn qualitative_grid(title: &str, row: &QualitativeRow) -> ImageGrid {
    let side = |im: &RgbImage| im.width().max(im.height()).max(1);
    let full = (QUALITATIVE_SIDE / side(&row.reference)).max(1);
    let (x, y, win) = highlight_window(&row.reference);
    let zoom = (QUALITATIVE_SIDE / win.max(1)).max(1);
    let crop = |im: &RgbImage| GridCell {
        image: Some(im.crop(x, y, win, win).scaled(zoom)),
        caption: format!("highlight, {zoom}x"),
    };
    let gt_crop = crop(&row.reference);
    let headers = ["render", "HDR-FLIP", "ground truth (zoom)", "model (zoom)"];
    let mut rows = vec![GridRow {
        label: "Ground truth".into(),
        cells: vec![
            GridCell { image: Some(row.reference.scaled(full)), caption: row.label.clone() },
            GridCell { image: None, caption: String::new() },
            gt_crop.clone(),
            GridCell { image: None, caption: String::new() },
        ],
    }];
    for r in &row.renders {
        let psnr = match r.psnr_db {
            Score::Value(v) => format!("PSNR {v:.2} dB"),
            Score::Unavailable(_) => "PSNR n/a".into(),
        };
        let flip = match &r.flip {
            Some((map, score)) => GridCell {
                image: Some(map.scaled(full)),
                caption: match score {
                    Score::Value(v) => format!("mean {v:.3}"),
                    Score::Unavailable(_) => "n/a".into(),
                },
            },
            None => GridCell { image: None, caption: "no FLIP map".into() },
        };
        rows.push(GridRow {
            label: r.model.clone(),
            cells: vec![
                GridCell { image: Some(r.render.scaled(full)), caption: psnr },
                flip,
                gt_crop.clone(),
                crop(&r.render),
            ],
        });
    }
    ImageGrid {
        title: title.to_string(),
        column_headers: headers.map(String::from).to_vec(),
        rows,
        font_px: 22,
        padding: 10,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::image_grid_png;
    use crate::plot::line_plot_png;
    use crate::raster::BLACK;

    #[test]
    fn runtime_curves_per_model_and_budget() {
        let d = Dataset::MerlNbrdf;
        let rec = |model, object: &str, steps, secs, psnr| {
            RunRecord::new(model, d.clone(), object)
                .at_steps(steps)
                .with_value(MetricKind::TrainingSeconds, secs)
                .with_value(MetricKind::Psnr, psnr)
        };
        let records = vec![
            rec(ModelKind::Disney, "a", 100, 10.0, 20.0),
            rec(ModelKind::Disney, "b", 100, 20.0, 24.0),
            rec(ModelKind::Disney, "a", 1000, 100.0, 30.0),
            rec(ModelKind::SingleMlp, "a", 1000, 50.0, 28.0),
            RunRecord::new(ModelKind::Rp, d.clone(), "a").with_value(MetricKind::Psnr, 1.0),
        ];
        let p = runtime_plot(&records, &d, MetricKind::Psnr, Some(40.0), "quick");
        let labels: Vec<&str> = p.series.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(labels, ["Disney", "Single MLP"]);
        assert_eq!(p.series[0].points, vec![(15.0, 22.0), (100.0, 30.0)]);
        assert!(p.log_x);
        assert!(p.title.contains("MERL-derived (NBRDF), profile quick"));
        assert!(line_plot_png(&p).is_ok());
        let r = runtime_plot(&records, &d, MetricKind::CubeRootRmse, None, "quick");
        assert!(r.series.is_empty());
        assert_eq!(r.y_label, "RMSE of cube roots (x100)");
    }

    #[test]
    fn qualitative_grid_puts_models_in_rows_with_highlight_zooms() {
        // A 64 x 48 ground truth with its highlight at (50, 10).
        let mut px = vec![[10u8, 10, 10]; 64 * 48];
        px[10 * 64 + 50] = [255, 250, 240];
        let gt = RgbImage::new(64, 48, px).unwrap();
        assert_eq!(highlight_window(&gt), (44, 4, 12));
        let render = |model: &str, flip| ModelRender {
            model: model.into(),
            render: RgbImage::filled(64, 48, BLACK),
            psnr_db: Score::Value(31.578),
            flip,
        };
        let row = QualitativeRow {
            label: "view 0, light 3".into(),
            reference: gt,
            renders: vec![
                render("Disney", Some((RgbImage::filled(64, 48, BLACK), Score::Value(0.1234)))),
                render("RP", None),
            ],
        };
        let g = qualitative_grid("Qualitative", &row);
        assert_eq!(g.column_headers.len(), 4);
        let labels: Vec<&str> = g.rows.iter().map(|r| r.label.as_str()).collect();
        assert_eq!(labels, ["Ground truth", "Disney", "RP"]);
        // Enlarged 6x (384 / 64) and the 12-pixel highlight window 32x, nearest neighbour.
        let full = g.rows[1].cells[0].image.as_ref().unwrap();
        assert_eq!((full.width(), full.height()), (384, 288));
        let zoom = g.rows[0].cells[2].image.as_ref().unwrap();
        assert_eq!((zoom.width(), zoom.height()), (384, 384));
        assert_eq!(zoom.pixels()[(6 * 32) * 384 + 6 * 32], [255, 250, 240]);
        assert_eq!(g.rows[1].cells[0].caption, "PSNR 31.58 dB");
        assert_eq!(g.rows[1].cells[1].caption, "mean 0.123");
        assert_eq!(g.rows[2].cells[1].caption, "no FLIP map");
        assert_eq!(g.rows[2].cells[2], g.rows[0].cells[2], "ground-truth zoom in every row");
        assert!(image_grid_png(&g).is_ok());
    }
}
