//! Our Table 1 beside the paper's, under the paper's protocol: each cell as ours / paper / Δ,
//! the ranking agreement per metric (Kendall's τ-b over the nine models), and the level of
//! each group of rows against the paper's.

use super::agreement::kendall_tau_b;
use super::data::{ModelGroup, PaperRange, PaperTable};
use crate::average::{average, final_records};
use crate::record::{Dataset, Direction, MetricKind, RunOptions, RunRecord};
use crate::result_tables::{Protocol, caption};
use crate::table::{Cell, Column, ColumnGroup, Marking, Row, Table};
use metrics::aggregate::Score;
use model_spec::ModelKind;

/// Why a paper cell is empty.
const NOT_TRANSCRIBED: &str = "not transcribed";

/// Our mean of `metric` for `model` on `dataset` (raw, per object then over objects); `None`
/// when not run, not computable, or over fewer objects than the other rows (not comparable).
pub(crate) fn ours(
    records: &[&RunRecord],
    model: ModelKind,
    d: &Dataset,
    m: MetricKind,
) -> Option<f64> {
    match average(records, model, RunOptions::DEFAULT, d, m) {
        Cell::Score(Score::Value(v)) => Some(v),
        _ => None,
    }
}

/// The paper's table `paper` with ours beside it: per metric three columns, ours, the paper's
/// and ours minus the paper's (raw units; the columns print them scaled as the paper does).
pub fn side_by_side(records: &[RunRecord], paper: &PaperTable, profile: &str) -> Table {
    let last = final_records(records);
    let d = &paper.dataset;
    let groups = paper
        .columns
        .iter()
        .map(|&m| ColumnGroup {
            title: m.label().to_string(),
            columns: vec![
                Column::metric(m).labelled("ours"),
                Column::metric(m).labelled("paper"),
                Column { direction: Direction::Neutral, ..Column::delta(m).labelled("Δ") },
            ],
        })
        .collect();
    let rows = ModelKind::ALL
        .iter()
        .map(|&model| {
            let cells = paper
                .columns
                .iter()
                .flat_map(|&m| {
                    let ours = ours(&last, model, d, m);
                    let theirs = paper.value(model, None, m).map(|v| v / m.factor());
                    // A mean over fewer objects than the others' shows with its dagger and
                    // gets no difference.
                    let mine = average(&last, model, RunOptions::DEFAULT, d, m);
                    let theirs_cell = theirs.map_or_else(
                        || Cell::Score(Score::Unavailable(NOT_TRANSCRIBED.into())),
                        Cell::value,
                    );
                    let delta = match (ours, theirs) {
                        (Some(a), Some(b)) => Cell::value(a - b),
                        (None, _) => Cell::NotRun,
                        (_, None) => Cell::Score(Score::Unavailable(NOT_TRANSCRIBED.into())),
                    };
                    [mine, theirs_cell, delta]
                })
                .collect();
            Row::new(model.paper_name(), cells)
        })
        .collect();
    Table {
        caption: caption(
            &format!(
                "Ours beside the paper's Table 1 ({}, {}). {} Per metric: ours, the paper's \
                 value as printed, and ours minus the paper's; DSSIM, LPIPS, FLIP and RMSE∛ \
                 ×100. Ours are averaged per object, then over this profile's objects; the \
                 paper averages 25 materials on 9 meshes (MERL) or 5 objects (DiLiGenT-MV).",
                d.label(),
                paper.file,
                Protocol::Paper.caption()
            ),
            std::slice::from_ref(d),
            profile,
        ),
        stub_header: "Model".into(),
        groups,
        rows,
        marking: Marking::None,
        notes: vec![],
    }
}

/// The ranking agreement of one metric.
#[derive(Clone, Debug, PartialEq)]
pub struct Agreement {
    /// The metric.
    pub metric: MetricKind,
    /// Kendall's τ-b over the models with both values; `None` when fewer than two.
    pub tau: Option<f64>,
    /// How many models entered.
    pub models: usize,
}

/// Kendall's τ-b between our and the paper's values of every column of `paper`, over the
/// models with both.
pub fn agreement(records: &[RunRecord], paper: &PaperTable) -> Vec<Agreement> {
    let last = final_records(records);
    paper
        .columns
        .iter()
        .map(|&metric| {
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for model in ModelKind::ALL {
                let theirs = paper.value(model, None, metric).map(|v| v / metric.factor());
                if let (Some(x), Some(y)) = (ours(&last, model, &paper.dataset, metric), theirs) {
                    a.push(x);
                    b.push(y);
                }
            }
            Agreement { metric, tau: kendall_tau_b(&a, &b), models: a.len() }
        })
        .collect()
}

/// Whether our level of a group of rows matches the paper's.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// Within the tolerance of the paper's group mean, for certain.
    Within,
    /// Within the tolerance of the paper's range, but the paper's mean is not known well
    /// enough to decide.
    Undecided,
    /// Further than the tolerance from any value the paper's mean can take.
    Outside,
    /// We have no runs of the group on the data set.
    NotRun,
}

/// Our mean of one column over a group of rows against the paper's.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelCheck {
    /// The paper's range (or the group's transcribed values, when complete).
    pub range: PaperRange,
    /// Whether the paper's mean is known exactly (every cell of the group transcribed): then
    /// `range.min == range.max` is that mean.
    pub exact: bool,
    /// Our per-model means, (model, value), printed scale.
    pub ours: Vec<(ModelKind, f64)>,
    /// The tolerance, printed units.
    pub tolerance: f64,
    /// The verdict.
    pub verdict: Verdict,
}

impl LevelCheck {
    /// Our group mean (printed scale), if any model ran.
    pub fn our_mean(&self) -> Option<f64> {
        (!self.ours.is_empty())
            .then(|| self.ours.iter().map(|(_, v)| v).sum::<f64>() / self.ours.len() as f64)
    }
}

/// The tolerance of the level check of `group` (the issue that set the protocol up: ±1.5 dB
/// for the purely neural rows, ±2.5 dB for the parametric ones).
pub fn tolerance(group: ModelGroup) -> f64 {
    match group {
        ModelGroup::PurelyNeural => 1.5,
        ModelGroup::Parametric => 2.5,
    }
}

/// Our level of each quoted range's group against the paper's. When `paper` holds every cell
/// of the group, its mean replaces the range.
pub fn level(records: &[RunRecord], ranges: &[PaperRange], paper: &PaperTable) -> Vec<LevelCheck> {
    let last = final_records(records);
    ranges
        .iter()
        .map(|r| {
            let models = r.group.models();
            let ours: Vec<(ModelKind, f64)> = models
                .iter()
                .filter_map(|&m| {
                    ours(&last, m, &r.dataset, r.metric).map(|v| (m, v * r.metric.factor()))
                })
                .collect();
            let printed: Vec<f64> = if paper.dataset == r.dataset {
                models.iter().filter_map(|&m| paper.value(m, None, r.metric)).collect()
            } else {
                vec![]
            };
            let mut range = r.clone();
            let exact = printed.len() == models.len();
            if exact {
                let mean = printed.iter().sum::<f64>() / printed.len() as f64;
                (range.min, range.max) = (mean, mean);
            }
            let tolerance = tolerance(r.group);
            let mut check = LevelCheck { range, exact, ours, tolerance, verdict: Verdict::NotRun };
            check.verdict = match check.our_mean() {
                None => Verdict::NotRun,
                Some(m) => {
                    let (lo, hi) = (check.range.min, check.range.max);
                    let worst = (m - lo).abs().max((m - hi).abs());
                    let nearest = if m < lo {
                        lo - m
                    } else if m > hi {
                        m - hi
                    } else {
                        0.0
                    };
                    if worst <= tolerance {
                        Verdict::Within
                    } else if nearest <= tolerance {
                        Verdict::Undecided
                    } else {
                        Verdict::Outside
                    }
                }
            };
            check
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::data::PaperRow;
    use super::*;

    fn paper_with(values: &[(ModelKind, f64)]) -> PaperTable {
        PaperTable {
            file: "test.csv",
            dataset: Dataset::MerlNbrdf,
            columns: vec![MetricKind::Psnr, MetricKind::Dssim],
            rows: ModelKind::ALL
                .iter()
                .map(|&m| PaperRow {
                    object: None,
                    model: m,
                    values: vec![values.iter().find(|v| v.0 == m).map(|v| v.1), None],
                })
                .collect(),
        }
    }

    fn ours_psnr(values: &[(ModelKind, &str, f64)]) -> Vec<RunRecord> {
        values
            .iter()
            .map(|&(m, o, v)| {
                RunRecord::new(m, Dataset::MerlNbrdf, o).with_value(MetricKind::Psnr, v)
            })
            .collect()
    }

    #[test]
    fn cells_are_ours_paper_and_the_difference() {
        let paper = paper_with(&[(ModelKind::Rp, 44.0), (ModelKind::SingleMlp, 52.0)]);
        let ours = ours_psnr(&[
            (ModelKind::Rp, "a", 40.0),
            (ModelKind::Rp, "b", 42.0),
            (ModelKind::Ts, "a", 43.0),
        ]);
        let t = side_by_side(&ours, &paper, "default");
        assert_eq!(t.columns().len(), 6);
        assert_eq!(
            (t.cell_text(0, 0), t.cell_text(0, 1), t.cell_text(0, 2)),
            ("41.00".into(), "44.00".into(), "-3.00".into())
        );
        // TS: ours only, on one of the two objects (a partial mean, no difference); the
        // paper's cell is not transcribed.
        assert_eq!(t.cell_text(1, 0), "43.00†");
        assert_eq!(t.cell_text(1, 2), "–");
        assert_eq!(t.cell_text(1, 1), "n/a");
        // Single MLP: the paper's only.
        assert_eq!((t.cell_text(4, 0), t.cell_text(4, 1)), ("–".into(), "52.00".into()));
        assert!(t.caption.contains("The paper's protocol"), "{}", t.caption);
    }

    #[test]
    fn agreement_over_the_models_with_both() {
        let paper = paper_with(&[
            (ModelKind::Rp, 44.0),
            (ModelKind::Ts, 45.0),
            (ModelKind::SingleMlp, 52.0),
        ]);
        let ours = ours_psnr(&[
            (ModelKind::Rp, "a", 30.0),
            (ModelKind::Ts, "a", 35.0),
            (ModelKind::SingleMlp, "a", 40.0),
            (ModelKind::Disney, "a", 39.0),
        ]);
        let a = agreement(&ours, &paper);
        assert_eq!((a[0].tau, a[0].models), (Some(1.0), 3));
        assert_eq!((a[1].tau, a[1].models), (None, 0));
    }

    #[test]
    fn level_checks_a_range_and_an_exact_mean() {
        let range = |min, max| PaperRange {
            dataset: Dataset::MerlNbrdf,
            group: ModelGroup::PurelyNeural,
            metric: MetricKind::Psnr,
            min,
            max,
            source: "test".into(),
        };
        let neural: Vec<(ModelKind, &str, f64)> =
            ModelGroup::PurelyNeural.models().into_iter().map(|m| (m, "a", 51.0)).collect();
        let ours = ours_psnr(&neural);
        let empty = paper_with(&[]);
        let v = |min, max| level(&ours, &[range(min, max)], &empty)[0].verdict.clone();
        assert_eq!(v(51.4, 52.4), Verdict::Within);
        assert_eq!(v(51.4, 53.0), Verdict::Undecided);
        assert_eq!(v(53.0, 54.0), Verdict::Outside);
        // Every neural cell transcribed: their mean (53.0) decides.
        let all: Vec<(ModelKind, f64)> =
            ModelGroup::PurelyNeural.models().into_iter().map(|m| (m, 53.0)).collect();
        let c = &level(&ours, &[range(40.0, 60.0)], &paper_with(&all))[0];
        assert!(c.exact && c.range.min == 53.0);
        assert_eq!(c.verdict, Verdict::Outside);
        assert_eq!(level(&[], &[range(1.0, 2.0)], &empty)[0].verdict, Verdict::NotRun);
    }
}
