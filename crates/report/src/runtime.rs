//! Run time against accuracy: how long each model takes to reach its own plateau.
//!
//! The records are the test scores of a run's weight snapshots and of its final weights
//! ([`RunRecord::steps`] set, [`MetricKind::TrainingSeconds`] the run's wall time at that
//! step). Per model and object the curve (seconds, PSNR) ends at the run's plateau, its final
//! PSNR; the time to come within `d` dB of it is the earliest snapshot time from which the
//! curve stays within `d` dB of the plateau (a later dip moves it later). Values are averaged
//! per object, then over objects, like every table.

use super::average::objects;
use super::record::{Dataset, Direction, MetricKind, RunOptions, RunRecord};
use super::result_tables::caption;
use super::table::{Cell, Column, ColumnGroup, Marking, Row, Table};
use metrics::aggregate::{PerObjectMean, Score};
use model_spec::ModelKind;

/// One model's curve on one object: (steps, seconds, PSNR, RMSE∛), in step order.
type Curve = Vec<(u64, f64, f64, Option<f64>)>;

fn curve(records: &[RunRecord], model: ModelKind, dataset: &Dataset, object: &str) -> Curve {
    let mut c: Curve = records
        .iter()
        .filter(|r| {
            r.model == model
                && r.options == RunOptions::DEFAULT
                && &r.dataset == dataset
                && r.object == object
        })
        .filter_map(|r| {
            let v = |m| r.metric(m).and_then(Score::value);
            Some((
                r.steps?,
                v(MetricKind::TrainingSeconds)?,
                v(MetricKind::Psnr)?,
                v(MetricKind::CubeRootRmse),
            ))
        })
        .collect();
    c.sort_by_key(|p| p.0);
    c
}

/// The earliest time from which every later point is within `within` dB of the last point.
pub fn seconds_to_plateau(points: &[(f64, f64)], within: f64) -> Option<f64> {
    let &(_, plateau) = points.last()?;
    let mut t = points.last()?.0;
    for &(s, psnr) in points.iter().rev() {
        if psnr < plateau - within {
            break;
        }
        t = s;
    }
    Some(t)
}

/// The quantities of one curve, in column order.
fn row_values(c: &Curve, ceiling: Option<f64>) -> Vec<Option<f64>> {
    let points: Vec<(f64, f64)> = c.iter().map(|p| (p.1, p.2)).collect();
    let last = c.last();
    vec![
        last.map(|p| p.0 as f64),
        last.map(|p| p.1),
        last.map(|p| p.2),
        last.zip(ceiling).map(|(p, c)| c - p.2),
        seconds_to_plateau(&points, 0.5),
        seconds_to_plateau(&points, 0.1),
        last.and_then(|p| p.3),
    ]
}

/// The time-to-accuracy table of the run-time curves in `records`: per model the steps and
/// seconds its runs took, its plateau PSNR, how far below the noise ceiling (`ceiling`'s
/// records) that is, the seconds to come within 0.5 dB and 0.1 dB of its plateau, and the
/// final RMSE∛.
pub fn time_to_accuracy(records: &[RunRecord], ceiling: &[RunRecord], profile: &str) -> Table {
    let dataset = Dataset::MerlNbrdf;
    let refs: Vec<&RunRecord> = records.iter().collect();
    let names = objects(&refs, &dataset);
    let ceiling_of = |object: &str| {
        let v: Vec<f64> = ceiling
            .iter()
            .filter(|r| r.dataset == dataset && r.object == object)
            .filter_map(|r| r.metric(MetricKind::Psnr).and_then(Score::value))
            .collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    let col = |label: &str, direction, decimals| Column {
        direction,
        decimals,
        ..Column::metric(MetricKind::TrainingSeconds).labelled(label)
    };
    let columns = vec![
        col("steps", Direction::Neutral, 0),
        col("time (s)", Direction::LowerIsBetter, 0),
        Column::metric(MetricKind::Psnr).labelled("plateau PSNR"),
        Column::metric(MetricKind::Psnr).labelled("below ceiling (dB)").with_direction_lower(),
        col("s to -0.5 dB", Direction::LowerIsBetter, 0),
        col("s to -0.1 dB", Direction::LowerIsBetter, 0),
        Column::metric(MetricKind::CubeRootRmse),
    ];
    let mut rows = Vec::new();
    for model in ModelKind::ALL {
        let mut means: Vec<PerObjectMean> = columns.iter().map(|_| PerObjectMean::new()).collect();
        let mut any = false;
        for object in &names {
            let c = curve(records, model, &dataset, object);
            if c.is_empty() {
                continue;
            }
            any = true;
            for (mean, v) in means.iter_mut().zip(row_values(&c, ceiling_of(object))) {
                if let Some(v) = v {
                    mean.push(object, Score::Value(v));
                }
            }
        }
        if any {
            let cells = means
                .iter()
                .map(|m| {
                    if m.per_object().is_empty() { Cell::NotRun } else { Cell::Score(m.overall()) }
                })
                .collect();
            rows.push(Row::new(model.paper_name(), cells));
        }
    }
    Table {
        caption: caption(
            "Run time against accuracy: per model, the training steps and wall time of its \
             runs, the test PSNR at its plateau (the final weights), how far that is below \
             the noise ceiling, the seconds until the test PSNR stays within 0.5 dB and 0.1 dB \
             of the plateau, and the final RMSE∛ ×100; averaged per object, then over objects.",
            std::slice::from_ref(&dataset),
            profile,
        ),
        stub_header: "Model".into(),
        groups: vec![ColumnGroup { title: dataset.label().to_string(), columns }],
        rows,
        marking: Marking::RankColumns,
        notes: vec![],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_to_plateau_waits_until_the_curve_stays_close() {
        let pts = [(1.0, 30.0), (2.0, 39.8), (4.0, 39.0), (8.0, 39.95), (16.0, 40.0)];
        assert_eq!(seconds_to_plateau(&pts, 0.5), Some(8.0));
        assert_eq!(seconds_to_plateau(&pts, 1.5), Some(2.0));
        assert_eq!(seconds_to_plateau(&pts, 0.01), Some(16.0));
        assert_eq!(seconds_to_plateau(&[], 0.5), None);
    }

    #[test]
    fn table_reads_the_curves() {
        let d = Dataset::MerlNbrdf;
        let point = |steps: u64, s: f64, psnr: f64| {
            RunRecord::new(ModelKind::SingleMlp, d.clone(), "spot")
                .at_steps(steps)
                .with_value(MetricKind::TrainingSeconds, s)
                .with_value(MetricKind::Psnr, psnr)
        };
        let records = vec![point(100, 10.0, 30.0), point(200, 20.0, 39.7), point(400, 40.0, 40.0)];
        let ceiling = vec![
            RunRecord::new(ModelKind::Ts, d.clone(), "spot").with_value(MetricKind::Psnr, 41.0),
        ];
        let t = time_to_accuracy(&records, &ceiling, "runtime");
        assert_eq!(t.rows.len(), 1);
        assert_eq!(t.rows[0].label, "Single MLP");
        let text: Vec<String> = (0..7).map(|c| t.cell_text(0, c)).collect();
        assert_eq!(text, ["400", "40", "40.00", "1.00", "20", "40", "–"]);
    }
}
