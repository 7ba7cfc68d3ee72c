//! Selecting records and averaging them the paper's way: first per object, then over objects
//! ([`metrics::aggregate::PerObjectMean`]); differences of two settings over the objects run in
//! both.

use super::record::{Dataset, MetricKind, RunOptions, RunRecord};
use super::table::Cell;
use metrics::aggregate::{PerObjectMean, Score};
use model_spec::ModelKind;
use std::collections::BTreeMap;

/// Each run's last evaluation: of the records sharing model, options, data set and object,
/// those with the most training steps (`None`, the final weights, counts as the most).
/// Several records with the same key and steps (seeds, repeated runs) are all kept and are
/// averaged within their object.
pub fn final_records(records: &[RunRecord]) -> Vec<&RunRecord> {
    let last = |r: &RunRecord| -> u128 { r.steps.map_or(u128::MAX, u128::from) };
    records
        .iter()
        .filter(|r| {
            !records.iter().any(|o| {
                o.model == r.model
                    && o.options == r.options
                    && o.dataset == r.dataset
                    && o.object == r.object
                    && last(o) > last(r)
            })
        })
        .collect()
}

/// The data sets present in `records`, in table order.
pub fn datasets(records: &[&RunRecord]) -> Vec<Dataset> {
    let mut d: Vec<Dataset> = records.iter().map(|r| r.dataset.clone()).collect();
    d.sort();
    d.dedup();
    d
}

/// The objects present in `records` for `dataset`, sorted.
pub fn objects(records: &[&RunRecord], dataset: &Dataset) -> Vec<String> {
    let mut o: Vec<String> =
        records.iter().filter(|r| &r.dataset == dataset).map(|r| r.object.clone()).collect();
    o.sort();
    o.dedup();
    o
}

/// Per-object means of `metric` over the records of (model, options, dataset).
///
/// `None` when no such record carries the metric (not run). A record lacking the metric while
/// others have it makes its object unavailable ("not measured on every run").
pub fn per_object(
    records: &[&RunRecord],
    model: ModelKind,
    options: RunOptions,
    dataset: &Dataset,
    metric: MetricKind,
) -> Option<BTreeMap<String, Score>> {
    let matching: Vec<&&RunRecord> = records
        .iter()
        .filter(|r| r.model == model && r.options == options && &r.dataset == dataset)
        .collect();
    if !matching.iter().any(|r| r.metric(metric).is_some()) {
        return None;
    }
    let mut mean = PerObjectMean::new();
    for r in matching {
        let score = r
            .metric(metric)
            .cloned()
            .unwrap_or_else(|| Score::Unavailable("not measured on every run".into()));
        mean.push(&r.object, score);
    }
    Some(mean.per_object())
}

/// The table value of `metric` for (model, options, dataset): the mean over objects of the
/// per-object means, [`Cell::NotRun`] when nothing was measured, and [`Cell::Partial`] when
/// the records hold objects of `dataset` that (model, options) was not measured on: such a mean
/// is not comparable with the other rows'.
pub fn average(
    records: &[&RunRecord],
    model: ModelKind,
    options: RunOptions,
    dataset: &Dataset,
    metric: MetricKind,
) -> Cell {
    match per_object(records, model, options, dataset, metric) {
        None => Cell::NotRun,
        Some(measured) => {
            let mut mean = PerObjectMean::new();
            for (object, score) in &measured {
                mean.push(object, score.clone());
            }
            let missing: Vec<String> = objects(records, dataset)
                .into_iter()
                .filter(|o| !measured.contains_key(o))
                .collect();
            if missing.is_empty() {
                Cell::Score(mean.overall())
            } else {
                Cell::Partial(mean.overall(), missing)
            }
        }
    }
}

/// `metric(variant) - metric(baseline)` for `model` on `dataset`, averaged over the objects
/// measured in both settings (equal to the difference of the two averages on those objects).
///
/// [`Cell::NotRun`] when no object was measured in both; unavailable when either setting is
/// unavailable on a shared object.
pub fn paired_delta(
    records: &[&RunRecord],
    model: ModelKind,
    variant: RunOptions,
    baseline: RunOptions,
    dataset: &Dataset,
    metric: MetricKind,
) -> Cell {
    let (Some(v), Some(b)) = (
        per_object(records, model, variant, dataset, metric),
        per_object(records, model, baseline, dataset, metric),
    ) else {
        return Cell::NotRun;
    };
    let mut mean = PerObjectMean::new();
    for (object, vs) in &v {
        let Some(bs) = b.get(object) else { continue };
        let delta = match (vs, bs) {
            (Score::Value(x), Score::Value(y)) => Score::Value(x - y),
            (Score::Unavailable(why), _) | (_, Score::Unavailable(why)) => {
                Score::Unavailable(why.clone())
            }
        };
        mean.push(object, delta);
    }
    if mean.per_object().is_empty() { Cell::NotRun } else { Cell::Score(mean.overall()) }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(model: ModelKind, object: &str, psnr: f64) -> RunRecord {
        RunRecord::new(model, Dataset::MerlNbrdf, object).with_value(MetricKind::Psnr, psnr)
    }

    #[test]
    fn a_mean_over_fewer_objects_than_the_others_is_partial() {
        let records = [
            rec(ModelKind::Disney, "bear", 30.0),
            rec(ModelKind::Disney, "cow", 20.0),
            rec(ModelKind::Rp, "cow", 99.0),
        ];
        let all: Vec<&RunRecord> = records.iter().collect();
        let d = Dataset::MerlNbrdf;
        let o = RunOptions::DEFAULT;
        assert_eq!(average(&all, ModelKind::Disney, o, &d, MetricKind::Psnr), Cell::value(25.0));
        assert_eq!(
            average(&all, ModelKind::Rp, o, &d, MetricKind::Psnr),
            Cell::Partial(Score::Value(99.0), vec!["bear".into()])
        );
    }

    #[test]
    fn averages_per_object_then_over_objects() {
        // bear has two runs (30, 34 -> 32), cow one (20): the table shows (32 + 20) / 2 = 26,
        // not the flat mean 28.
        let records = [
            rec(ModelKind::Disney, "bear", 30.0),
            rec(ModelKind::Disney, "bear", 34.0),
            rec(ModelKind::Disney, "cow", 20.0),
            rec(ModelKind::Rp, "cow", 99.0),
        ];
        let all: Vec<&RunRecord> = records.iter().collect();
        let d = Dataset::MerlNbrdf;
        let cell = average(&all, ModelKind::Disney, RunOptions::DEFAULT, &d, MetricKind::Psnr);
        assert_eq!(cell, Cell::Score(Score::Value(26.0)));
        let none = average(&all, ModelKind::Ts, RunOptions::DEFAULT, &d, MetricKind::Psnr);
        assert_eq!(none, Cell::NotRun);
        let unmeasured = average(&all, ModelKind::Rp, RunOptions::DEFAULT, &d, MetricKind::Flip);
        assert_eq!(unmeasured, Cell::NotRun);
    }

    #[test]
    fn unavailable_and_partly_measured() {
        let records = [
            rec(ModelKind::Disney, "bear", 30.0)
                .with(MetricKind::Lpips, Score::Unavailable("weights missing".into())),
            rec(ModelKind::Disney, "cow", 20.0).with_value(MetricKind::Flip, 0.1),
        ];
        let all: Vec<&RunRecord> = records.iter().collect();
        let d = Dataset::MerlNbrdf;
        let lpips = average(&all, ModelKind::Disney, RunOptions::DEFAULT, &d, MetricKind::Lpips);
        assert_eq!(lpips, Cell::Score(Score::Unavailable("weights missing".into())));
        let flip = average(&all, ModelKind::Disney, RunOptions::DEFAULT, &d, MetricKind::Flip);
        assert!(matches!(flip, Cell::Score(Score::Unavailable(_))));
    }

    #[test]
    fn final_records_keep_the_last_evaluation() {
        let records = [
            rec(ModelKind::Disney, "bear", 10.0).at_steps(100),
            rec(ModelKind::Disney, "bear", 20.0).at_steps(200),
            rec(ModelKind::Disney, "cow", 15.0).at_steps(100),
            rec(ModelKind::Disney, "cow", 25.0),
            rec(ModelKind::Rp, "bear", 5.0).at_steps(100),
        ];
        let last = final_records(&records);
        let psnr: Vec<f64> =
            last.iter().filter_map(|r| r.metric(MetricKind::Psnr)?.value()).collect();
        assert_eq!(psnr, vec![20.0, 25.0, 5.0]);
    }

    #[test]
    fn deltas_use_shared_objects() {
        let nol = RunOptions { nol: true, ..RunOptions::DEFAULT };
        let records = [
            rec(ModelKind::SingleMlp, "bear", 30.0),
            rec(ModelKind::SingleMlp, "cow", 20.0),
            rec(ModelKind::SingleMlp, "pot", 50.0),
            rec(ModelKind::SingleMlp, "bear", 31.0).with_options(nol),
            rec(ModelKind::SingleMlp, "cow", 17.0).with_options(nol),
        ];
        let all: Vec<&RunRecord> = records.iter().collect();
        let d = Dataset::MerlNbrdf;
        let base = RunOptions::DEFAULT;
        let cell = paired_delta(&all, ModelKind::SingleMlp, nol, base, &d, MetricKind::Psnr);
        // (+1 - 3) / 2; pot (default only) is left out.
        assert_eq!(cell, Cell::Score(Score::Value(-1.0)));
        let none = paired_delta(&all, ModelKind::Rp, nol, base, &d, MetricKind::Psnr);
        assert_eq!(none, Cell::NotRun);
    }
}
