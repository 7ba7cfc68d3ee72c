//! The paper's figures assembled from records and images: the run-time against error curves
//! ([`runtime_plot`], drawn by [`super::plot::line_plot_png`]) and the qualitative comparison
//! grid ([`qualitative_grid`], drawn by [`super::grid::image_grid_png`]).
//!
//! The diffuse / specular / albedo split figures are plain [`ImageGrid`]s: one row per test
//! image, columns such as "GT", "render", "diffuse", "specular", "albedo", built with
//! [`ImageGrid::from_images`].

use super::average::average;
use super::grid::{GridCell, GridRow, ImageGrid, RgbImage};
use super::plot::{LinePlot, Series};
use super::record::{Dataset, MetricKind, RunOptions, RunRecord};
use super::table::Cell;
use brdf_neural::ModelKind;
use metrics::aggregate::Score;

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

/// The qualitative comparison: one row per test image with the ground truth, then each model's
/// render captioned with its PSNR; a row whose renders carry FLIP maps is followed by a FLIP row
/// (an empty ground-truth slot, then each map captioned with the mean FLIP). Column headers
/// come from the first row's model names.
pub fn qualitative_grid(title: &str, rows: &[QualitativeRow]) -> ImageGrid {
    let mut headers = vec!["GT".to_string()];
    if let Some(first) = rows.first() {
        headers.extend(first.renders.iter().map(|r| r.model.clone()));
    }
    let mut grid_rows = Vec::new();
    for row in rows {
        let mut cells = vec![GridCell { image: Some(row.reference.clone()), caption: "GT".into() }];
        cells.extend(row.renders.iter().map(|r| GridCell {
            image: Some(r.render.clone()),
            caption: match r.psnr_db {
                Score::Value(v) => format!("{} {v:.2} dB", r.model),
                Score::Unavailable(_) => format!("{} n/a", r.model),
            },
        }));
        grid_rows.push(GridRow { label: row.label.clone(), cells });
        if row.renders.iter().any(|r| r.flip.is_some()) {
            let mut cells = vec![GridCell { image: None, caption: String::new() }];
            cells.extend(row.renders.iter().map(|r| match &r.flip {
                Some((map, score)) => GridCell {
                    image: Some(map.clone()),
                    caption: match score {
                        Score::Value(v) => format!("FLIP {v:.3}"),
                        Score::Unavailable(_) => "FLIP n/a".into(),
                    },
                },
                None => GridCell { image: None, caption: "FLIP n/a".into() },
            }));
            grid_rows.push(GridRow { label: "FLIP".into(), cells });
        }
    }
    ImageGrid {
        title: title.to_string(),
        column_headers: headers,
        rows: grid_rows,
        font_px: 16,
        padding: 8,
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
    fn qualitative_grid_with_flip_rows() {
        let img = RgbImage::filled(8, 8, BLACK);
        let render = |model: &str, flip| ModelRender {
            model: model.into(),
            render: img.clone(),
            psnr_db: Score::Value(31.578),
            flip,
        };
        let rows = vec![
            QualitativeRow {
                label: "view 0".into(),
                reference: img.clone(),
                renders: vec![
                    render("Disney", Some((img.clone(), Score::Value(0.1234)))),
                    render("RP", None),
                ],
            },
            QualitativeRow {
                label: "view 1".into(),
                reference: img.clone(),
                renders: vec![render("Disney", None), render("RP", None)],
            },
        ];
        let g = qualitative_grid("Qualitative", &rows);
        assert_eq!(g.column_headers, ["GT", "Disney", "RP"]);
        assert_eq!(g.rows.len(), 3);
        assert_eq!(g.rows[0].cells[1].caption, "Disney 31.58 dB");
        assert_eq!(g.rows[1].cells[1].caption, "FLIP 0.123");
        assert_eq!(g.rows[1].cells[2].caption, "FLIP n/a");
        assert!(g.rows[1].cells[0].image.is_none());
        assert!(image_grid_png(&g).is_ok());
    }
}
