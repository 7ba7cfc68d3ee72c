//! The paper's result tables with rows of models (or objects) and absolute values: Table 1
//! (image metrics), reciprocity RMSE, energy conservation, and the per-object tables.
//!
//! Every builder takes all records, keeps each run's last evaluation
//! ([`final_records`]), averages per object then over objects ([`average`]) and states the
//! data and the profile in its caption. Column groups are the data sets present, in the order
//! MERL-derived (NBRDF), DiLiGenT-MV, DiLiGenT, others.

use super::average::{average, datasets, final_records, objects, per_object};
use super::record::{Dataset, MetricKind, RunOptions, RunRecord};
use super::table::{Cell, Column, ColumnGroup, Marking, Row, Table};
use brdf_neural::{ModelKind, Reciprocity};
use metrics::aggregate::PerObjectMean;

/// "`title` Data: `labels`. Profile: `profile`."
pub(crate) fn caption(title: &str, data: &[Dataset], profile: &str) -> String {
    let labels: Vec<&str> = data.iter().map(Dataset::label).collect();
    let data = if labels.is_empty() { "none".to_string() } else { labels.join(", ") };
    format!("{title} Data: {data}. Profile: {profile}.")
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

/// A column of a model table: its header, the options and the metric it shows.
type ColumnSpec = (Column, RunOptions, MetricKind);

/// Rows of models, one group per data set with one column per (label, options, metric).
fn model_table(
    records: &[&RunRecord],
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
    let rows = ModelKind::ALL
        .iter()
        .map(|&model| Row {
            label: model.paper_name().to_string(),
            cells: specs
                .iter()
                .flat_map(|(d, cols)| {
                    cols.iter().map(move |(_, options, metric)| {
                        average(records, model, *options, d, *metric)
                    })
                })
                .collect(),
        })
        .collect();
    (groups, rows)
}

/// Table 1: the nine models with default options; per data set PSNR↑, DSSIM↓, LPIPS↓, FLIP↓
/// and, for MERL-derived data, RMSE∛↓ (all but PSNR ×100). Best / second / third per column.
pub fn table1(records: &[RunRecord], profile: &str) -> Table {
    let last = final_records(records);
    let data = datasets(&last);
    let (groups, rows) = model_table(&last, &data, |d| {
        image_metrics(d).into_iter().map(|m| (Column::metric(m), RunOptions::DEFAULT, m)).collect()
    });
    Table {
        caption: caption(
            "Table 1: image metrics of the models with default options, averaged per object, \
             then over objects; DSSIM, LPIPS, FLIP and RMSE∛ ×100 (RMSE∛ only where a \
             ground-truth BRDF exists).",
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

/// Reciprocity RMSE (not scaled) of every model under each reciprocity option: none, random
/// swap and the mapping Θ (the options apply to the purely neural models; the parametric ones
/// run with none only). Lower is better, ranked per column.
pub fn reciprocity_table(records: &[RunRecord], profile: &str) -> Table {
    let last = final_records(records);
    let data = datasets(&last);
    let (groups, rows) = model_table(&last, &data, |_| {
        [
            ("none", Reciprocity::None),
            ("swap", Reciprocity::RandomSwap),
            ("mapping", Reciprocity::Mapping),
        ]
        .into_iter()
        .map(|(label, reciprocity)| {
            let options = RunOptions { reciprocity, ..RunOptions::DEFAULT };
            let m = MetricKind::ReciprocityRmse;
            (Column::metric(m).labelled(label), options, m)
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
    let (groups, rows) = model_table(&last, &data, |_| {
        [MetricKind::EnergyPercentAbove1, MetricKind::EnergyMedianAbove1]
            .into_iter()
            .map(|m| (Column::metric(m), RunOptions::DEFAULT, m))
            .collect()
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
/// `dataset`; the best / second / third model of each row is marked.
pub fn per_object_table(
    records: &[RunRecord],
    dataset: &Dataset,
    metric: MetricKind,
    profile: &str,
) -> Table {
    let last = final_records(records);
    let names = objects(&last, dataset);
    let per_model: Vec<_> = ModelKind::ALL
        .iter()
        .map(|&m| per_object(&last, m, RunOptions::DEFAULT, dataset, metric))
        .collect();
    let mut rows: Vec<Row> = names
        .iter()
        .map(|object| Row {
            label: object.clone(),
            cells: per_model
                .iter()
                .map(|p| {
                    p.as_ref()
                        .and_then(|p| p.get(object))
                        .map_or(Cell::NotRun, |s| Cell::Score(s.clone()))
                })
                .collect(),
        })
        .collect();
    rows.push(Row {
        label: "Mean".into(),
        cells: per_model
            .iter()
            .map(|p| match p {
                None => Cell::NotRun,
                Some(p) => {
                    let mut mean = PerObjectMean::new();
                    for (object, score) in p {
                        mean.push(object, score.clone());
                    }
                    Cell::Score(mean.overall())
                }
            })
            .collect(),
    });
    let scale = if metric.factor() == 1.0 { String::new() } else { " (×100)".to_string() };
    Table {
        caption: caption(
            &format!("{}{scale} per object and model (default options).", metric.label()),
            std::slice::from_ref(dataset),
            profile,
        ),
        stub_header: "Object".into(),
        groups: vec![ColumnGroup {
            title: dataset.label().to_string(),
            columns: ModelKind::ALL
                .iter()
                .map(|m| Column::metric(metric).labelled(m.paper_name()))
                .collect(),
        }],
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
        let t = table1(&records, "quick");
        assert_eq!(t.rows.len(), 9);
        assert_eq!(t.groups[0].title, "MERL-derived (NBRDF)");
        assert_eq!(t.groups[0].columns.len(), 5);
        assert_eq!(t.groups[1].title, "DiLiGenT-MV");
        assert_eq!(t.groups[1].columns.len(), 4);
        assert!(t.caption.contains("Data: MERL-derived (NBRDF), DiLiGenT-MV. Profile: quick."));
        // Disney row (index 3), DiLiGenT-MV PSNR: (32 + 20) / 2.
        assert_eq!(t.rows[3].label, "Disney");
        assert_eq!(t.cell_text(3, 5), "26.00");
        assert_eq!(t.cell_text(3, 7), "n/a");
        assert_eq!(t.cell_text(0, 4), "10.00");
        assert_eq!(t.cell_text(1, 5), "–");
        let md = to_markdown(&t);
        assert!(md.contains("n/a not computable (weights missing)"), "{md}");
        assert!(to_latex(&t).contains("\\multicolumn{4}{c}{DiLiGenT-MV}"));
    }

    #[test]
    fn no_diligent_columns_without_records() {
        let records = vec![
            RunRecord::new(ModelKind::Rp, Dataset::MerlNbrdf, "spot")
                .with_value(MetricKind::Psnr, 30.0),
        ];
        let t = table1(&records, "cpu");
        assert_eq!(t.groups.len(), 1);
        assert!(table1(&[], "cpu").caption.contains("Data: none."));
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
        let t = per_object_table(&records, &Dataset::DiligentMv, MetricKind::Psnr, "quick");
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
