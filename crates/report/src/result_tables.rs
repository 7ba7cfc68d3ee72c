//! The paper's result tables with rows of models (or objects) and absolute values: Table 1
//! (image metrics), reciprocity RMSE, energy conservation, and the per-object tables.
//!
//! Every builder takes all records, keeps each run's last evaluation
//! ([`final_records`]), averages per object then over objects ([`average`]) and states the
//! data, the profile and, for image metrics, the [`Protocol`] in its caption. Column groups
//! are the data sets present, in the order MERL-derived (NBRDF), DiLiGenT-MV, DiLiGenT, others.

use super::average::{average, datasets, final_records, objects, per_object};
use super::record::{Dataset, MetricKind, RunOptions, RunRecord};
use super::table::{Cell, Column, ColumnGroup, Marking, Row, Table};
use metrics::aggregate::{PerObjectMean, Score};
use model_spec::{ModelKind, Reciprocity};
use std::collections::BTreeMap;

/// How the image metrics of a table were computed. Every run is scored both ways; each
/// table's caption names its protocol.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Protocol {
    /// Ours: the object's pixels only, against the observed (noisy) test images, beside the
    /// data's noise ceiling.
    Ours,
    /// The paper's: the whole frame, background included, against the noise-free test renders
    /// (a capture has none: its observations with the background set to 0).
    Paper,
    /// The paper's whole frame against the observed (noisy) test images with their background
    /// set to 0: the other reading of the paper's protocol (it does not name its reference).
    PaperObserved,
}

impl Protocol {
    /// The phrase every caption of the protocol starts with.
    pub fn caption(self) -> &'static str {
        match self {
            Protocol::Ours => {
                "Our protocol: the object mask, against the observed (noisy) test images, \
                 beside the noise ceiling."
            }
            Protocol::Paper => {
                "The paper's protocol: the whole frame, background included, against the \
                 noise-free test renders (captures: the observations with the background set \
                 to 0); sRGB clamped to [0, 1], data range 1."
            }
            Protocol::PaperObserved => {
                "The paper's protocol against the observations: the whole frame, background \
                 included, against the observed (noisy) test images with their background set \
                 to 0; sRGB clamped to [0, 1], data range 1."
            }
        }
    }

    /// A short name for file names and headings ("ours", "paper").
    pub fn name(self) -> &'static str {
        match self {
            Protocol::Ours => "ours",
            Protocol::Paper => "paper",
            Protocol::PaperObserved => "paper-observed",
        }
    }
}

/// "`title` Data: `labels`. Profile: `profile`."
/// Real captures among `data` add a sentence saying which columns they are.
pub(crate) fn caption(title: &str, data: &[Dataset], profile: &str) -> String {
    let labels: Vec<&str> = data.iter().map(Dataset::label).collect();
    let real: Vec<&str> =
        data.iter().filter(|d| !d.has_brdf_ground_truth()).map(Dataset::label).collect();
    let list = if labels.is_empty() { "none".to_string() } else { labels.join(", ") };
    let mut s = format!("{title} Data: {list}. Profile: {profile}.");
    if !real.is_empty() {
        s += &format!(
            " Real captures (the real-world columns): {}; photographs, so no ground-truth \
             BRDF (no RMSE∛) and no noise-free image (no noise ceiling).",
            real.join(", ")
        );
    }
    s
}

/// The image metrics of `dataset`: PSNR, DSSIM, LPIPS, FLIP, and RMSE∛ where a ground-truth
/// BRDF exists.
pub(crate) fn image_metrics(dataset: &Dataset) -> Vec<MetricKind> {
    let mut m = MetricKind::IMAGE.to_vec();
    if dataset.has_brdf_ground_truth() {
        m.push(MetricKind::CubeRootRmse);
    }
    m
}

/// What a column of a model table shows.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    /// A metric of the runs with these options.
    Metric(RunOptions, MetricKind),
    /// How far the model's PSNR is below the noise ceiling (dB, per object then averaged).
    CeilingGap,
}

/// A column of a model table: its header and what it shows.
type ColumnSpec = (Column, Source);

/// The metric columns of `metrics` with default options.
fn metric_columns(metrics: impl IntoIterator<Item = MetricKind>) -> Vec<ColumnSpec> {
    metrics
        .into_iter()
        .map(|m| (Column::metric(m), Source::Metric(RunOptions::DEFAULT, m)))
        .collect()
}

/// Rows of models, one group per data set with one column per spec; with the noise ceiling's
/// records, a last "Ground truth (noise ceiling)" reference row.
fn model_table(
    records: &[&RunRecord],
    ceiling: &[&RunRecord],
    data: &[Dataset],
    columns: impl Fn(&Dataset) -> Vec<ColumnSpec>,
) -> (Vec<ColumnGroup>, Vec<Row>) {
    let specs: Vec<(Dataset, Vec<ColumnSpec>)> =
        data.iter().map(|d| (d.clone(), columns(d))).collect();
    let groups = specs
        .iter()
        .map(|(d, cols)| ColumnGroup {
            title: d.label().to_string(),
            columns: cols.iter().map(|c| c.0.clone()).collect(),
        })
        .collect();
    let mut rows: Vec<Row> = ModelKind::ALL
        .iter()
        .map(|&model| {
            let cells = specs
                .iter()
                .flat_map(|(d, cols)| {
                    cols.iter().map(move |(_, source)| match *source {
                        Source::Metric(options, metric) => {
                            average(records, model, options, d, metric)
                        }
                        Source::CeilingGap => ceiling_gap(records, ceiling, model, d),
                    })
                })
                .collect();
            Row::new(model.paper_name(), cells)
        })
        .collect();
    if specs.iter().any(|(d, _)| ceiling.iter().any(|r| &r.dataset == d)) {
        let cells = specs
            .iter()
            .flat_map(|(d, cols)| {
                cols.iter().map(move |(_, source)| match *source {
                    Source::Metric(_, m) if MetricKind::IMAGE.contains(&m) => {
                        reference_average(ceiling, d, m)
                    }
                    _ => Cell::NotRun,
                })
            })
            .collect();
        rows.push(Row::reference(CEILING_LABEL, cells));
    }
    (groups, rows)
}

/// The row label of the noise ceiling.
pub const CEILING_LABEL: &str = "Ground truth (noise ceiling)";

/// Table 1: the nine models with default options; per data set PSNR↑, DSSIM↓, LPIPS↓, FLIP↓
/// and, for MERL-derived data, RMSE∛↓ (all but PSNR ×100), then how far each model's PSNR is
/// below the noise ceiling and its training time. `ceiling` holds the noise ceiling's records
/// (one per evaluated run of a semi-synthetic scene): its row closes the table, never ranked.
/// Best / second / third per column.
pub fn table1(records: &[RunRecord], ceiling: &[RunRecord], profile: &str) -> Table {
    let last = final_records(records);
    let ceiling: Vec<&RunRecord> = ceiling.iter().collect();
    let data = datasets(&last);
    let (groups, rows) = model_table(&last, &ceiling, &data, |d| {
        let mut cols = metric_columns(image_metrics(d));
        if ceiling.iter().any(|r| &r.dataset == d) {
            cols.push((ceiling_gap_column(), Source::CeilingGap));
        }
        let time = Column::metric(MetricKind::TrainingSeconds);
        let time = Column { direction: super::record::Direction::Neutral, ..time };
        cols.push((time, Source::Metric(RunOptions::DEFAULT, MetricKind::TrainingSeconds)));
        cols
    });
    Table {
        caption: caption(
            "Table 1. Our protocol: the object mask, against the observed (noisy) test images, \
             beside the noise ceiling. Image metrics of the models with default options, \
             averaged per object, then over objects; DSSIM, LPIPS, FLIP \
             and RMSE∛ ×100 (RMSE∛ only where a ground-truth BRDF exists). The ground truth's \
             own noise-free renders score the noise ceiling, the best any model can; \
             'below ceiling' is its PSNR minus the model's; time is the training wall time \
             per run (runs trained side by side, `--jobs` > 1, shared the machine's cores).",
            &data,
            profile,
        ),
        stub_header: "Model".into(),
        groups,
        rows,
        marking: Marking::RankColumns,
        notes: vec![],
    }
}

/// Table 1's models scored against the noise-free test renders instead of the observed
/// images, on the object mask (semi-synthetic data only: the records carry the metrics against
/// the noise-free renders). The ground truth would score ∞ dB here and is left out.
pub fn table1_noise_free(records: &[RunRecord], profile: &str) -> Table {
    let last = final_records(records);
    let data = datasets(&last);
    let (groups, rows) =
        model_table(&last, &[], &data, |_| metric_columns(MetricKind::IMAGE.to_vec()));
    Table {
        caption: caption(
            "Table 1 against the noise-free test renders, on the object mask (our protocol's \
             pixels, the paper's reference): the models' renders scored against the ground \
             truth's noise-free images instead of the noisy observations, averaged per \
             object, then over objects; DSSIM, LPIPS and FLIP ×100. The ground truth scores \
             ∞ dB here.",
            &data,
            profile,
        ),
        stub_header: "Model".into(),
        groups,
        rows,
        marking: Marking::RankColumns,
        notes: vec![],
    }
}

/// Table 1 under the paper's protocol ([`Protocol::Paper`], or its reading against the
/// observations, [`Protocol::PaperObserved`]): `records` carry the scores of the whole frame
/// (and RMSE∛, which no protocol changes). Per data set PSNR↑, DSSIM↓, LPIPS↓, FLIP↓ and,
/// where a ground-truth BRDF exists, RMSE∛↓, as the paper's Table 1; no noise ceiling and no
/// time.
pub fn table1_paper(records: &[RunRecord], protocol: Protocol, profile: &str) -> Table {
    let last = final_records(records);
    let data = datasets(&last);
    let (groups, rows) = model_table(&last, &[], &data, |d| metric_columns(image_metrics(d)));
    Table {
        caption: caption(
            &format!(
                "Table 1. {} Image metrics of the models with default options, averaged per \
                 image, then per object, then over objects; DSSIM, LPIPS, FLIP and RMSE∛ ×100 \
                 (RMSE∛, in BRDF space, is the same in every protocol).{}",
                protocol.caption(),
                if protocol == Protocol::Paper && data.iter().any(Dataset::has_brdf_ground_truth) {
                    " An exact model scores ∞ dB here on generated scenes."
                } else {
                    ""
                }
            ),
            &data,
            profile,
        ),
        stub_header: "Model".into(),
        groups,
        rows,
        marking: Marking::RankColumns,
        notes: vec![],
    }
}

/// The column of [`Source::CeilingGap`].
fn ceiling_gap_column() -> Column {
    Column::metric(MetricKind::Psnr).labelled("below ceiling (dB)").with_direction_lower()
}

/// Mean over objects of the per-object means of `metric` over every record of `dataset`
/// (the noise ceiling's records: any model, any options).
fn reference_average(records: &[&RunRecord], dataset: &Dataset, metric: MetricKind) -> Cell {
    let mut mean = PerObjectMean::new();
    let mut any = false;
    for r in records.iter().filter(|r| &r.dataset == dataset) {
        if let Some(score) = r.metric(metric) {
            mean.push(&r.object, score.clone());
            any = true;
        }
    }
    if any { Cell::Score(mean.overall()) } else { Cell::NotRun }
}

/// Ceiling PSNR minus the model's, per object (objects with both), then averaged.
fn ceiling_gap(
    records: &[&RunRecord],
    ceiling: &[&RunRecord],
    model: ModelKind,
    dataset: &Dataset,
) -> Cell {
    let Some(ours) = per_object(records, model, RunOptions::DEFAULT, dataset, MetricKind::Psnr)
    else {
        return Cell::NotRun;
    };
    let mut mean = PerObjectMean::new();
    let missing: Vec<String> =
        objects(records, dataset).into_iter().filter(|o| !ours.contains_key(o)).collect();
    for (object, score) in ours {
        let mine: Vec<&RunRecord> =
            ceiling.iter().copied().filter(|r| r.object == object).collect();
        let Cell::Score(Score::Value(c)) = reference_average(&mine, dataset, MetricKind::Psnr)
        else {
            continue;
        };
        mean.push(&object, score.value().map_or(score.clone(), |v| Score::Value(c - v)));
    }
    match (mean.per_object().is_empty(), missing.is_empty()) {
        (true, _) => Cell::NotRun,
        (false, true) => Cell::Score(mean.overall()),
        (false, false) => Cell::Partial(mean.overall(), missing),
    }
}

/// Reciprocity RMSE (not scaled) of every model under each reciprocity option: none, random
/// swap and the mapping Θ (the options apply to the purely neural models; the parametric ones
/// run with none only). Lower is better, ranked per column.
pub fn reciprocity_table(records: &[RunRecord], profile: &str) -> Table {
    let last = final_records(records);
    let data = datasets(&last);
    let (groups, rows) = model_table(&last, &[], &data, |_| {
        [
            ("none", Reciprocity::None),
            ("swap", Reciprocity::RandomSwap),
            ("mapping", Reciprocity::Mapping),
        ]
        .into_iter()
        .map(|(label, reciprocity)| {
            let options = RunOptions { reciprocity, ..RunOptions::DEFAULT };
            let m = MetricKind::ReciprocityRmse;
            (Column::metric(m).labelled(label), Source::Metric(options, m))
        })
        .collect()
    });
    Table {
        caption: caption(
            "Reciprocity RMSE between f(x, l, v) and f(x, v, l) per model and reciprocity \
             option (not scaled).",
            &data,
            profile,
        ),
        stub_header: "Model".into(),
        groups,
        rows,
        marking: Marking::RankColumns,
        notes: vec![],
    }
}

/// Energy conservation with default options: the percentage of (x, l) pairs whose
/// directional albedo exceeds 1, and the median albedo of those pairs. Lower is better.
pub fn energy_table(records: &[RunRecord], profile: &str) -> Table {
    let last = final_records(records);
    let data = datasets(&last);
    let (groups, rows) = model_table(&last, &[], &data, |_| {
        metric_columns([MetricKind::EnergyPercentAbove1, MetricKind::EnergyMedianAbove1])
    });
    Table {
        caption: caption(
            "Energy conservation: percentage of (x, l) pairs with directional albedo E > 1 and \
             the median E of those pairs (default options).",
            &data,
            profile,
        ),
        stub_header: "Model".into(),
        groups,
        rows,
        marking: Marking::RankColumns,
        notes: vec![],
    }
}

/// `metric` per object (rows, plus a final "Mean" row) and model (columns, default options) on
/// `dataset`; the best / second / third model of each row is marked. For an image metric, the
/// noise ceiling's records add a last reference column (never ranked), and the caption names
/// the `protocol` the records were scored under.
pub fn per_object_table(
    records: &[RunRecord],
    ceiling: &[RunRecord],
    dataset: &Dataset,
    metric: MetricKind,
    protocol: Protocol,
    profile: &str,
) -> Table {
    let last = final_records(records);
    let names = objects(&last, dataset);
    let mut per_column: Vec<Option<BTreeMap<String, Score>>> = ModelKind::ALL
        .iter()
        .map(|&m| per_object(&last, m, RunOptions::DEFAULT, dataset, metric))
        .collect();
    let mut columns: Vec<Column> =
        ModelKind::ALL.iter().map(|m| Column::metric(metric).labelled(m.paper_name())).collect();
    let ceiling: Vec<&RunRecord> = ceiling.iter().filter(|r| &r.dataset == dataset).collect();
    if MetricKind::IMAGE.contains(&metric) && !ceiling.is_empty() {
        let mut mean = PerObjectMean::new();
        for r in &ceiling {
            if let Some(score) = r.metric(metric) {
                mean.push(&r.object, score.clone());
            }
        }
        per_column.push(Some(mean.per_object()));
        columns.push(Column::metric(metric).labelled(CEILING_LABEL).as_reference());
    }
    let mut rows: Vec<Row> = names
        .iter()
        .map(|object| {
            let cells = per_column
                .iter()
                .map(|p| {
                    p.as_ref()
                        .and_then(|p| p.get(object))
                        .map_or(Cell::NotRun, |s| Cell::Score(s.clone()))
                })
                .collect();
            Row::new(object.clone(), cells)
        })
        .collect();
    let means = per_column
        .iter()
        .map(|p| match p {
            None => Cell::NotRun,
            Some(p) => {
                let mut mean = PerObjectMean::new();
                for (object, score) in p {
                    mean.push(object, score.clone());
                }
                // A column that lacks objects of the others has a mean over fewer objects.
                let missing: Vec<String> =
                    names.iter().filter(|o| !p.contains_key(*o)).cloned().collect();
                if missing.is_empty() {
                    Cell::Score(mean.overall())
                } else {
                    Cell::Partial(mean.overall(), missing)
                }
            }
        })
        .collect();
    rows.push(Row::new("Mean", means));
    let scale = if metric.factor() == 1.0 { String::new() } else { " (×100)".to_string() };
    let mut title = format!("{}{scale} per object and model (default options).", metric.label());
    if MetricKind::IMAGE.contains(&metric) {
        title = format!("{title} {}", protocol.caption());
    }
    Table {
        caption: caption(&title, std::slice::from_ref(dataset), profile),
        stub_header: "Object".into(),
        groups: vec![ColumnGroup { title: dataset.label().to_string(), columns }],
        rows,
        marking: Marking::RankRows,
        notes: vec![],
    }
}

#[cfg(test)]
mod tests {
    use super::super::latex::to_latex;
    use super::super::markdown::to_markdown;
    use super::*;
    use metrics::aggregate::Score;

    fn rec(model: ModelKind, object: &str, psnr: f64, dssim: f64) -> RunRecord {
        RunRecord::new(model, Dataset::DiligentMv, object)
            .with_value(MetricKind::Psnr, psnr)
            .with_value(MetricKind::Dssim, dssim)
            .with(MetricKind::Lpips, Score::Unavailable("weights missing".into()))
            .with_value(MetricKind::Flip, 0.1)
    }

    #[test]
    fn table1_layout_and_averaging() {
        let records = vec![
            rec(ModelKind::Disney, "bear", 30.0, 0.01),
            rec(ModelKind::Disney, "bear", 34.0, 0.03),
            rec(ModelKind::Disney, "cow", 20.0, 0.02),
            rec(ModelKind::Rp, "bear", 25.0, 0.05),
            RunRecord::new(ModelKind::Rp, Dataset::MerlNbrdf, "spot")
                .with_value(MetricKind::CubeRootRmse, 0.1),
        ];
        let t = table1(&records, &[], "quick");
        assert_eq!(t.rows.len(), 9);
        assert_eq!(t.groups[0].title, "MERL-derived (NBRDF)");
        // The image metrics, RMSE∛ for MERL-derived data, and the training time.
        assert_eq!(t.groups[0].columns.len(), 6);
        assert_eq!(t.groups[1].title, "DiLiGenT-MV");
        assert_eq!(t.groups[1].columns.len(), 5);
        assert!(t.caption.contains("Data: MERL-derived (NBRDF), DiLiGenT-MV. Profile: quick."));
        assert!(t.caption.contains("Real captures (the real-world columns): DiLiGenT-MV"));
        // Disney row (index 3), DiLiGenT-MV PSNR: (32 + 20) / 2.
        assert_eq!(t.rows[3].label, "Disney");
        assert_eq!(t.cell_text(3, 6), "26.00");
        assert_eq!(t.cell_text(3, 8), "n/a");
        assert_eq!(t.cell_text(0, 4), "10.00");
        assert_eq!(t.cell_text(1, 6), "–");
        let md = to_markdown(&t);
        assert!(md.contains("n/a not computable (weights missing)"), "{md}");
        assert!(to_latex(&t).contains("\\multicolumn{5}{c}{DiLiGenT-MV}"));
    }

    #[test]
    fn the_noise_ceiling_closes_table1_unranked_with_each_models_gap() {
        let d = Dataset::MerlNbrdf;
        let run = |model, object: &str, psnr: f64| {
            RunRecord::new(model, d.clone(), object)
                .with_value(MetricKind::Psnr, psnr)
                .with_value(MetricKind::TrainingSeconds, 60.0)
        };
        let records = vec![
            run(ModelKind::Ts, "a", 40.0),
            run(ModelKind::Ts, "b", 30.0),
            run(ModelKind::SingleMlp, "a", 44.0),
            run(ModelKind::Disney, "a", 20.0),
            run(ModelKind::Disney, "b", 20.0),
        ];
        // The ceiling as every run of an object reports it (identical per object).
        let ceiling: Vec<RunRecord> = [("a", 45.0), ("a", 45.0), ("b", 41.0)]
            .iter()
            .map(|&(o, p)| {
                RunRecord::new(ModelKind::Ts, d.clone(), o).with_value(MetricKind::Psnr, p)
            })
            .collect();
        let t = table1(&records, &ceiling, "quick");
        let last = t.rows.len() - 1;
        assert_eq!(t.rows[last].label, CEILING_LABEL);
        assert!(t.rows[last].reference);
        let labels: Vec<&str> = t.columns().iter().map(|c| c.label.as_str()).collect();
        let gap = labels.iter().position(|l| l.contains("below ceiling")).unwrap();
        // Ceiling PSNR: (45 + 41) / 2; TS gap: ((45 - 40) + (41 - 30)) / 2; Single MLP: 45 - 44.
        assert_eq!(t.cell_text(last, 0), "43.00");
        assert_eq!(t.cell_text(1, gap), "8.00");
        // Single MLP ran on one of the two objects: its mean and gap are partial, unmarked.
        assert_eq!(t.cell_text(4, 0), "44.00†");
        assert_eq!(t.cell_text(4, gap), "1.00†");
        assert_eq!(t.cell_text(last, gap), "–");
        // Never ranked: neither the partial row nor the ceiling, though both are higher than
        // TS, which is best.
        use super::super::rank::Mark;
        assert_eq!(
            (t.marks()[1][0], t.marks()[3][0], t.marks()[4][0]),
            (Mark::First, Mark::Second, Mark::None)
        );
        assert_eq!(t.marks()[last][0], Mark::None);
        assert!(to_markdown(&t).contains("Single MLP without b"));
        // The per-object table gets the ceiling as a last, unranked column.
        let p = per_object_table(&records, &ceiling, &d, MetricKind::Psnr, Protocol::Ours, "quick");
        assert_eq!(p.columns().last().unwrap().label, CEILING_LABEL);
        assert_eq!(p.cell_text(0, 9), "45.00");
        assert_eq!(p.marks()[0][4], super::super::rank::Mark::First);
    }

    #[test]
    fn no_diligent_columns_without_records() {
        let records = vec![
            RunRecord::new(ModelKind::Rp, Dataset::MerlNbrdf, "spot")
                .with_value(MetricKind::Psnr, 30.0),
        ];
        let t = table1(&records, &[], "cpu");
        assert_eq!(t.groups.len(), 1);
        assert!(table1(&[], &[], "cpu").caption.contains("Data: none."));
    }

    #[test]
    fn reciprocity_and_energy_tables() {
        let d = Dataset::MerlNbrdf;
        let mapping = RunOptions { reciprocity: Reciprocity::Mapping, ..RunOptions::DEFAULT };
        let records = vec![
            RunRecord::new(ModelKind::SingleMlp, d.clone(), "spot")
                .with_value(MetricKind::ReciprocityRmse, 0.25)
                .with_value(MetricKind::EnergyPercentAbove1, 12.5)
                .with_value(MetricKind::EnergyMedianAbove1, 1.25),
            RunRecord::new(ModelKind::SingleMlp, d.clone(), "spot")
                .with_options(mapping)
                .with_value(MetricKind::ReciprocityRmse, 0.0),
        ];
        let t = reciprocity_table(&records, "quick");
        let labels: Vec<&str> = t.columns().iter().map(|c| c.label.as_str()).collect();
        assert_eq!(labels, ["none", "swap", "mapping"]);
        assert_eq!(t.cell_text(4, 0), "0.2500");
        assert_eq!(t.cell_text(4, 1), "–");
        assert_eq!(t.cell_text(4, 2), "0.0000");
        let e = energy_table(&records, "quick");
        assert_eq!(e.cell_text(4, 0), "12.50");
        assert_eq!(e.cell_text(4, 1), "1.250");
    }

    #[test]
    fn per_object_rows() {
        let records = vec![
            rec(ModelKind::Disney, "bear", 30.0, 0.01),
            rec(ModelKind::Rp, "bear", 25.0, 0.05),
            rec(ModelKind::Rp, "cow", 21.0, 0.05),
        ];
        let t = per_object_table(
            &records,
            &[],
            &Dataset::DiligentMv,
            MetricKind::Psnr,
            Protocol::Paper,
            "quick",
        );
        assert!(t.caption.contains("The paper's protocol"), "{}", t.caption);
        let labels: Vec<&str> = t.rows.iter().map(|r| r.label.as_str()).collect();
        assert_eq!(labels, ["bear", "cow", "Mean"]);
        assert_eq!(t.columns().len(), 9);
        assert_eq!(t.cell_text(1, 0), "21.00");
        assert_eq!(t.cell_text(1, 3), "–");
        assert_eq!(t.cell_text(2, 0), "23.00");
        let marks = t.marks();
        assert_eq!(marks[0][3], super::super::rank::Mark::First);
        assert_eq!(marks[0][0], super::super::rank::Mark::Second);
    }
}
