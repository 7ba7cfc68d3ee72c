//! The paper beside ours: its published Table 1 as data ([`data`]), our runs under its
//! protocol cell by cell with the differences ([`mod@compare`]), the ranking agreement per metric
//! (Kendall's τ-b, [`agreement`]), and a checklist of its findings on our runs ([`findings`]).
//! [`PaperComparison`] gathers them; `collect` writes it as `tables/paper-vs-ours.md` and as
//! a section of the HTML report.

pub mod agreement;
pub mod compare;
pub mod data;
pub mod findings;

pub use compare::{Agreement, LevelCheck, Verdict};
pub use data::{DataError, ModelGroup, PaperRange, PaperTable};
pub use findings::Finding;

use crate::markdown::to_markdown;
use crate::record::{Dataset, RunRecord};
use crate::result_tables::Protocol;
use crate::table::Table;

/// Everything `tables/paper-vs-ours.md` shows.
#[derive(Clone, Debug)]
pub struct PaperComparison {
    /// The profile the runs came from.
    pub profile: String,
    /// Transcribed cells of the paper's tables, and all of them (see the data README).
    pub transcribed: (usize, usize),
    /// Our level of each group of rows against the paper's, under its protocol (against the
    /// noise-free renders).
    pub level: Vec<LevelCheck>,
    /// The same under its reading against the observations (background set to 0).
    pub level_observed: Vec<LevelCheck>,
    /// Ours beside the paper's Table 1, one table per data set we ran that the paper has.
    pub tables: Vec<(String, Table)>,
    /// The ranking agreement of each column of Table 1's MERL half.
    pub agreement: Vec<Agreement>,
    /// The paper's findings on our runs.
    pub findings: Vec<Finding>,
    /// The paper's data sets we have no runs of, with how to get them.
    pub missing: Vec<String>,
}

/// The comparison of our runs with the paper: `paper` holds the records under the paper's
/// protocol (with RMSE∛), `observed` under its reading against the observations, `ours` those
/// under ours (with the reciprocity and energy analyses).
pub fn compare(
    paper: &[RunRecord],
    observed: &[RunRecord],
    ours: &[RunRecord],
    profile: &str,
) -> Result<PaperComparison, DataError> {
    let merl = data::table1_merl()?;
    let mv = data::table1_diligent_mv()?;
    let per_object = data::per_object_diligent_mv()?;
    let transcribed = [&merl, &mv, &per_object]
        .iter()
        .fold((0, 0), |(t, n), x| (t + x.transcribed(), n + x.cells()));
    let has = |d: &Dataset| paper.iter().any(|r| &r.dataset == d);
    let mut tables = Vec::new();
    let mut missing = Vec::new();
    for (name, table, fetch) in [
        ("paper-vs-ours-merl", &merl, "any MERL-derived profile (the default)"),
        (
            "paper-vs-ours-diligent-mv",
            &mv,
            "`cargo xtask fetch-data diligent-mv`, then `cargo xtask reproduce-tables --profile \
             real`",
        ),
    ] {
        if has(&table.dataset) {
            tables.push((name.to_string(), compare::side_by_side(paper, table, profile)));
        } else {
            missing.push(format!("{}: no runs ({fetch})", table.dataset.label()));
        }
    }
    Ok(PaperComparison {
        profile: profile.to_string(),
        transcribed,
        level: compare::level(paper, &data::ranges()?, &merl),
        level_observed: compare::level(observed, &data::ranges()?, &merl),
        tables,
        agreement: compare::agreement(paper, &merl),
        findings: findings::findings(paper, ours),
        missing,
    })
}

impl PaperComparison {
    /// The paragraph on where the paper's values come from.
    pub fn source_note(&self) -> String {
        let (t, n) = self.transcribed;
        let mut s = format!(
            "The paper: Hofherr, Haefner, Cremers, \"On Neural BRDFs: A Thorough Comparison of \
             State-of-the-Art Approaches\", WACV 2025, Table 1 and its supplement \
             (crates/report/data/paper/). {t} of its {n} cells are transcribed."
        );
        if t < n {
            s += " The others print n/a (not transcribed) and stay out of the ranking \
                  agreement; the level check below uses the ranges of Table 1 quoted in the \
                  data's README.";
        }
        s
    }

    /// One line per level check of `checks` (`level` or `level_observed`).
    pub fn level_lines(checks: &[LevelCheck]) -> Vec<String> {
        checks
            .iter()
            .map(|c| {
                let r = &c.range;
                let paper = if c.exact {
                    format!("the paper's mean {:.2}", r.min)
                } else {
                    format!("the paper's range {:.2} to {:.2} ({})", r.min, r.max, r.source)
                };
                let ours = match c.our_mean() {
                    None => "no runs".to_string(),
                    Some(m) => {
                        let lo = c.ours.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
                        let hi = c.ours.iter().map(|x| x.1).fold(f64::NEG_INFINITY, f64::max);
                        format!("ours {lo:.2} to {hi:.2}, mean {m:.2}")
                    }
                };
                let unit = if r.metric == crate::record::MetricKind::Psnr { " dB" } else { "" };
                let tol = format!("±{}{unit}", c.tolerance);
                let verdict = match c.verdict {
                    Verdict::Within => format!("within {tol} of the paper's mean"),
                    Verdict::Undecided => {
                        format!("within {tol} of the paper's range; its mean is needed to decide")
                    }
                    Verdict::Outside => format!("more than {tol} from the paper"),
                    Verdict::NotRun => "not checked".into(),
                };
                format!(
                    "{} rows, {} {}: {ours}; {paper}: **{verdict}**",
                    r.dataset.label(),
                    r.group.label(),
                    r.metric.label()
                )
            })
            .collect()
    }

    /// One line per metric of the ranking agreement.
    pub fn agreement_lines(&self) -> Vec<String> {
        self.agreement
            .iter()
            .map(|a| match a.tau {
                Some(t) => format!("{}: τ = {t:+.3} over {} models", a.metric.label(), a.models),
                None => format!(
                    "{}: n/a ({} models with both values; τ needs two, and values that differ)",
                    a.metric.label(),
                    a.models
                ),
            })
            .collect()
    }

    /// The whole comparison as Markdown.
    pub fn to_markdown(&self) -> String {
        let mut s = format!(
            "# The paper's Table 1 beside ours\n\nProfile: {}. {}\n\n{}\n\n",
            self.profile,
            Protocol::Paper.caption(),
            self.source_note()
        );
        s += "## Level\n\nThe paper's protocol (against the noise-free renders):\n\n";
        for l in Self::level_lines(&self.level) {
            s += &format!("* {l}\n");
        }
        s += &format!("\n{}\n\n", Protocol::PaperObserved.caption());
        for l in Self::level_lines(&self.level_observed) {
            s += &format!("* {l}\n");
        }
        for (_, t) in &self.tables {
            s += "\n";
            s += &to_markdown(t);
        }
        for m in &self.missing {
            s += &format!("\n{m}.\n");
        }
        s += "\n## Ranking agreement (Kendall's τ-b, Table 1's MERL half)\n\n";
        for l in self.agreement_lines() {
            s += &format!("* {l}\n");
        }
        s += "\n## The paper's findings on our runs\n\n";
        for f in &self.findings {
            s += &format!("* **{}**: {}. {}.\n", f.verdict(), f.claim, sentence(&f.evidence));
        }
        s
    }
}

/// `s` with its first letter in upper case.
pub fn sentence(s: &str) -> String {
    let mut c = s.chars();
    c.next().map_or_else(String::new, |f| f.to_uppercase().chain(c).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::MetricKind;
    use model_spec::ModelKind;

    #[test]
    fn the_comparison_names_what_is_missing_and_renders() {
        let paper: Vec<RunRecord> = ModelKind::ALL
            .iter()
            .map(|&m| {
                RunRecord::new(m, Dataset::MerlNbrdf, "spot").with_value(MetricKind::Psnr, 50.0)
            })
            .collect();
        let c = compare(&paper, &paper, &paper, "default").unwrap();
        assert_eq!(c.tables.len(), 1);
        assert!(c.missing[0].contains("DiLiGenT-MV") && c.missing[0].contains("fetch-data"));
        let md = c.to_markdown();
        assert!(md.contains("The paper's protocol"), "{md}");
        assert!(md.contains("## Ranking agreement") && md.contains("## The paper's findings"));
        assert_eq!(c.findings.len(), 6);
        assert_eq!((c.level.len(), c.level_observed.len()), (2, 2));
    }
}
