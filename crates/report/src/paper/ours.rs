//! Our side of the comparison with the paper: a model's mean of one metric, or a variant's
//! difference to the default options, with its spread over objects ([`Estimate`]), so that a
//! difference can be called beyond our own noise or within it.
//!
//! Means are taken the paper's way, per object first, then over objects. A difference is
//! paired: per object, then over the objects measured in both settings.

use crate::average::{average, per_object};
use crate::record::{Dataset, MetricKind, RunOptions, RunRecord};
use crate::table::Cell;
use metrics::aggregate::Score;
use model_spec::ModelKind;

/// How many standard errors a mean must lie from 0 to count as beyond our noise.
pub const NOISE_SE: f64 = 2.0;

/// A mean over objects with its spread.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// The mean over objects (raw units).
    pub mean: f64,
    /// The sample standard deviation over objects (raw units); `None` with one object.
    pub sd: Option<f64>,
    /// How many objects.
    pub objects: usize,
}

impl Estimate {
    /// The estimate of the values `v`, one an object; `None` when empty.
    pub fn of(v: &[f64]) -> Option<Estimate> {
        if v.is_empty() {
            return None;
        }
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let sd = (v.len() > 1)
            .then(|| (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt());
        Some(Estimate { mean, sd, objects: v.len() })
    }

    /// The standard error of the mean, `sd / √n`.
    pub fn se(&self) -> Option<f64> {
        self.sd.map(|s| s / (self.objects as f64).sqrt())
    }

    /// Whether the mean is further than [`NOISE_SE`] standard errors from 0; `None` without a
    /// spread (one object).
    pub fn beyond_noise(&self) -> Option<bool> {
        self.se().map(|se| self.mean.abs() > NOISE_SE * se)
    }
}

/// Per-object values of (model, options) on `dataset`: `None` when not run, when any object's
/// value is unavailable, or when the mean would be over fewer objects than the other rows'.
fn values(
    last: &[&RunRecord],
    model: ModelKind,
    options: RunOptions,
    d: &Dataset,
    m: MetricKind,
) -> Option<Vec<(String, f64)>> {
    if !matches!(average(last, model, options, d, m), Cell::Score(Score::Value(_))) {
        return None;
    }
    let all = measured(last, model, options, d, m)?;
    // Every object measured, none unavailable.
    (all.len() == per_object(last, model, options, d, m)?.len()).then_some(all)
}

/// The per-object values of (model, options) on `d` that are numbers; `None` when not run.
fn measured(
    last: &[&RunRecord],
    model: ModelKind,
    options: RunOptions,
    d: &Dataset,
    m: MetricKind,
) -> Option<Vec<(String, f64)>> {
    let per = per_object(last, model, options, d, m)?;
    Some(
        per.into_iter()
            .filter_map(|(o, s)| match s {
                Score::Value(v) => Some((o, v)),
                Score::Unavailable(_) => None,
            })
            .collect(),
    )
}

/// Our mean of `m` for (model, options) on `d`, with its spread over objects.
pub fn level(
    last: &[&RunRecord],
    model: ModelKind,
    options: RunOptions,
    d: &Dataset,
    m: MetricKind,
) -> Option<Estimate> {
    let v = values(last, model, options, d, m)?;
    Estimate::of(&v.into_iter().map(|x| x.1).collect::<Vec<_>>())
}

/// `a − b` per object, over the objects measured in both, with its spread: a = (model,
/// options) and b likewise.
pub fn paired(
    last: &[&RunRecord],
    a: (ModelKind, RunOptions),
    b: (ModelKind, RunOptions),
    d: &Dataset,
    m: MetricKind,
) -> Option<Estimate> {
    let (va, vb) = (measured(last, a.0, a.1, d, m)?, measured(last, b.0, b.1, d, m)?);
    let diffs: Vec<f64> = va
        .iter()
        .filter_map(|(o, x)| vb.iter().find(|(p, _)| p == o).map(|(_, y)| x - y))
        .collect();
    Estimate::of(&diffs)
}

/// The variant's difference to the default options for `model`: `m(options) − m(default)`.
pub fn delta(
    last: &[&RunRecord],
    model: ModelKind,
    options: RunOptions,
    d: &Dataset,
    m: MetricKind,
) -> Option<Estimate> {
    paired(last, (model, options), (model, RunOptions::DEFAULT), d, m)
}

/// The data set of ours that stands beside the paper's `paper` data set: the same one, or for
/// the paper's DiLiGenT-MV our DiLiGenT runs when we have no DiLiGenT-MV ones (the real-world
/// column of the default run is the DiLiGenT ball).
pub fn stand_in(last: &[&RunRecord], paper: &Dataset) -> Dataset {
    let has = |d: &Dataset| last.iter().any(|r| &r.dataset == d);
    match paper {
        Dataset::DiligentMv if !has(paper) && has(&Dataset::Diligent) => Dataset::Diligent,
        d => d.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimates_and_noise() {
        let e = Estimate::of(&[1.0, 2.0, 3.0]).unwrap();
        assert_eq!((e.mean, e.sd, e.objects), (2.0, Some(1.0), 3));
        assert!((e.se().unwrap() - 1.0 / 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(e.beyond_noise(), Some(true));
        let small = Estimate::of(&[-1.0, 0.5, 1.0]).unwrap();
        assert_eq!(small.beyond_noise(), Some(false));
        assert_eq!(Estimate::of(&[4.0]).unwrap().beyond_noise(), None);
        assert_eq!(Estimate::of(&[]), None);
    }

    #[test]
    fn deltas_pair_objects_and_the_real_column_stands_in() {
        let nol = RunOptions { nol: true, ..RunOptions::DEFAULT };
        let r = |o: &str, options, v| {
            RunRecord::new(ModelKind::SingleMlp, Dataset::MerlNbrdf, o)
                .with_options(options)
                .with_value(MetricKind::Psnr, v)
        };
        let records = [
            r("a", RunOptions::DEFAULT, 40.0),
            r("b", RunOptions::DEFAULT, 42.0),
            r("c", RunOptions::DEFAULT, 50.0),
            r("a", nol, 41.0),
            r("b", nol, 44.0),
        ];
        let last: Vec<&RunRecord> = records.iter().collect();
        let d = delta(&last, ModelKind::SingleMlp, nol, &Dataset::MerlNbrdf, MetricKind::Psnr);
        let d = d.unwrap();
        assert_eq!((d.mean, d.objects), (1.5, 2));
        let l = level(
            &last,
            ModelKind::SingleMlp,
            RunOptions::DEFAULT,
            &Dataset::MerlNbrdf,
            MetricKind::Psnr,
        );
        assert_eq!(l.unwrap().mean, 44.0);
        // The variant lacks object c: its mean is partial, not a level.
        assert_eq!(
            level(&last, ModelKind::SingleMlp, nol, &Dataset::MerlNbrdf, MetricKind::Psnr),
            None
        );
        assert_eq!(stand_in(&last, &Dataset::DiligentMv), Dataset::DiligentMv);
        let ball = RunRecord::new(ModelKind::Rp, Dataset::Diligent, "ball");
        let with_ball: Vec<&RunRecord> = last.iter().copied().chain([&ball]).collect();
        assert_eq!(stand_in(&with_ball, &Dataset::DiligentMv), Dataset::Diligent);
    }
}
