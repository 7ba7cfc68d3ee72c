//! The paper beside ours: its published tables as data ([`data`]), our runs beside each of
//! them cell by cell, with our spread over objects and the differences ([`mod@compare`], on
//! [`ours`]), the ranking agreement per metric (Kendall's τ-b, [`agreement`]), and a checklist
//! of its findings on our runs ([`findings`]). The supplement's per-object DiLiGenT-MV table is
//! data only (this project has no DiLiGenT-MV runs to set beside it yet).
//! [`PaperComparison`] gathers them; `collect` writes it as `tables/paper-vs-ours.md` and as
//! a section of the HTML report.

pub mod agreement;
pub mod compare;
pub mod data;
pub mod findings;
pub mod ours;

pub use compare::{Against, Agreement, LevelCheck, Measure, Verdict};
pub use data::{DataError, ModelGroup, PaperTable, PaperValue};
pub use findings::{Finding, Outcome};

use crate::markdown::to_markdown;
use crate::record::RunRecord;
use crate::result_tables::Protocol;
use crate::table::{Cell, Table};

/// Everything `tables/paper-vs-ours.md` shows.
#[derive(Clone, Debug)]
pub struct PaperComparison {
    /// The profile the runs came from.
    pub profile: String,
    /// Transcribed cells of the paper's tables, and all of them (see the data README).
    pub transcribed: (usize, usize),
    /// Our PSNR level of each group of rows against the paper's, under its protocol (against
    /// the noise-free renders).
    pub level: Vec<LevelCheck>,
    /// The same under its reading against the observations (background set to 0).
    pub level_observed: Vec<LevelCheck>,
    /// Ours beside each of the paper's tables we have runs for: (file stem, table).
    pub tables: Vec<(String, Table)>,
    /// The ranking agreement of each column of Table 1.
    pub agreement: Vec<Agreement>,
    /// The paper's findings on our runs.
    pub findings: Vec<Finding>,
    /// The paper's tables we have no runs for, with how to get them.
    pub missing: Vec<String>,
}

/// The paper's tables set beside ours: (data file, title, our records: image metrics under
/// the paper's protocol or our analyses, measure, comparison, how to get runs).
const BESIDE: [(&str, &str, bool, Measure, Against, &str); 8] = [
    ("table1.csv", "Table 1", true, Measure::Level, Against::Difference, "any profile"),
    (
        "nol.csv",
        "NOL for the directions",
        true,
        Measure::Delta,
        Against::Difference,
        "the ablation `nol`",
    ),
    (
        "reciprocity-rmse.csv",
        "Reciprocity RMSE",
        false,
        Measure::Level,
        Against::Ratio,
        "the ablation `reciprocity`",
    ),
    (
        "energy.csv",
        "Energy conservation",
        false,
        Measure::Level,
        Against::Difference,
        "any profile",
    ),
    (
        "reciprocity-quality.csv",
        "Reciprocity strategies' quality",
        true,
        Measure::Delta,
        Against::Difference,
        "the ablation `reciprocity`",
    ),
    (
        "view-light.csv",
        "View-light angles",
        true,
        Measure::Delta,
        Against::Difference,
        "the ablation `angles`",
    ),
    (
        "nerfactor.csv",
        "NeRFactor changes",
        true,
        Measure::Delta,
        Against::Difference,
        "the ablation `nerfactor`",
    ),
    (
        "evaluation-renderings.csv",
        "Per-render PSNR of fig:evaluation_renderings",
        true,
        Measure::Level,
        Against::Difference,
        "the scene stanford-bunny__grease-covered-steel (`--profile figure`)",
    ),
];

/// The comparison of our runs with the paper: `paper` holds the records under the paper's
/// protocol (with RMSE∛), `observed` under its reading against the observations, `ours` those
/// under ours (with the reciprocity and energy analyses).
pub fn compare(
    paper: &[RunRecord],
    observed: &[RunRecord],
    ours: &[RunRecord],
    profile: &str,
) -> Result<PaperComparison, DataError> {
    let all = data::all_tables()?;
    let transcribed = all.iter().fold((0, 0), |(t, n), x| (t + x.transcribed(), n + x.len()));
    let table1 = data::table1()?;
    let mut tables = Vec::new();
    let mut missing = Vec::new();
    for (file, title, image, measure, against, how) in BESIDE {
        let whole = data::table(file)?;
        let records = if image { paper } else { ours };
        // One table a data set of the paper's: ours on it (or on our stand-in for it).
        for d in whole.datasets() {
            let t = whole.only(&d);
            let last = crate::average::final_records(records);
            let mine = ours::stand_in(&last, &d);
            let on = if mine == d {
                d.label().to_string()
            } else {
                format!("ours {}, the paper's {}", mine.label(), d.label())
            };
            let title = format!("{title}, {on}");
            let beside = compare::beside(records, &t, &title, measure, against, profile);
            // Our cells are the first of each four.
            let any = beside
                .rows
                .iter()
                .any(|r| r.cells.iter().step_by(4).any(|c| !matches!(c, Cell::NotRun)));
            let tag = if d.has_brdf_ground_truth() { "merl" } else { "real" };
            let stem = format!("paper-vs-ours-{}-{tag}", file.trim_end_matches(".csv"));
            if any {
                tables.push((stem, beside));
            } else if d.has_brdf_ground_truth() {
                missing.push(format!("{title} ({}): no runs ({how})", t.label));
            }
        }
    }
    if !paper.iter().any(|r| !r.dataset.has_brdf_ground_truth()) {
        missing.push(
            "Real-world columns: no runs (the DiLiGenT ball: `cargo xtask fetch-data diligent`; \
             DiLiGenT-MV: `cargo xtask fetch-data diligent-mv`, then `--profile real`)"
                .into(),
        );
    }
    Ok(PaperComparison {
        profile: profile.to_string(),
        transcribed,
        level: compare::level(paper, &table1),
        level_observed: compare::level(observed, &table1),
        tables,
        agreement: compare::agreement(paper, &table1),
        findings: findings::findings(paper, ours),
        missing,
    })
}

impl PaperComparison {
    /// The paragraph on where the paper's values come from.
    pub fn source_note(&self) -> String {
        let (t, n) = self.transcribed;
        format!(
            "The paper: Hofherr, Haefner, Cremers, \"On Neural BRDFs: A Thorough Comparison of \
             State-of-the-Art Approaches\", WACV 2025: every table and the per-render PSNRs of \
             its figure of renderings (crates/report/data/paper/, checked cell by cell against \
             its LaTeX source). {t} of {n} cells transcribed."
        )
    }

    /// One line per level check of `checks` (`level` or `level_observed`).
    pub fn level_lines(checks: &[LevelCheck]) -> Vec<String> {
        checks
            .iter()
            .map(|c| {
                let (lo, hi, mean) = c.paper;
                let ours = match c.our_mean() {
                    None => "no runs".to_string(),
                    Some(m) => {
                        let lo = c.ours.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
                        let hi = c.ours.iter().map(|x| x.1).fold(f64::NEG_INFINITY, f64::max);
                        format!("ours {lo:.2} to {hi:.2}, mean {m:.2}")
                    }
                };
                let unit = if c.metric == crate::record::MetricKind::Psnr { " dB" } else { "" };
                let verdict = match c.verdict {
                    Verdict::Within => format!("within ±{}{unit} of the paper's mean", c.tolerance),
                    Verdict::Outside => {
                        format!("more than ±{}{unit} from the paper's mean", c.tolerance)
                    }
                    Verdict::NotRun => "not checked".into(),
                };
                format!(
                    "{} rows, {} {}: {ours}; the paper's {lo:.2} to {hi:.2}, mean {mean:.2}: \
                     **{verdict}**",
                    c.dataset.label(),
                    c.group.label(),
                    c.metric.label()
                )
            })
            .collect()
    }

    /// One line per metric of the ranking agreement.
    pub fn agreement_lines(&self) -> Vec<String> {
        self.agreement
            .iter()
            .map(|a| {
                let on = if a.ours == a.dataset {
                    a.dataset.label().to_string()
                } else {
                    format!("ours {} against the paper's {}", a.ours.label(), a.dataset.label())
                };
                match a.tau {
                    Some(t) => {
                        format!("{} ({on}): τ = {t:+.3} over {} models", a.metric.label(), a.models)
                    }
                    None => format!(
                        "{} ({on}): n/a ({} models with both values; τ needs two, and values \
                         that differ)",
                        a.metric.label(),
                        a.models
                    ),
                }
            })
            .collect()
    }

    /// The whole comparison as Markdown.
    pub fn to_markdown(&self) -> String {
        let mut s = format!(
            "# The paper beside ours\n\nProfile: {}. {}\n\n{}\n\n",
            self.profile,
            Protocol::Paper.caption(),
            self.source_note()
        );
        s += "## The paper's findings on our runs\n\n";
        for f in &self.findings {
            s += &format!("* **{}**: {}. {}.\n", f.verdict(), f.claim, sentence(&f.evidence));
        }
        s += "\n## Level\n\nThe paper's protocol (against the noise-free renders):\n\n";
        for l in Self::level_lines(&self.level) {
            s += &format!("* {l}\n");
        }
        s += &format!("\n{}\n\n", Protocol::PaperObserved.caption());
        for l in Self::level_lines(&self.level_observed) {
            s += &format!("* {l}\n");
        }
        s += "\n## Ranking agreement (Kendall's τ-b over the nine models of Table 1)\n\n";
        for l in self.agreement_lines() {
            s += &format!("* {l}\n");
        }
        s += "\n## Ours beside the paper's tables\n";
        for (_, t) in &self.tables {
            s += "\n";
            s += &to_markdown(t);
        }
        for m in &self.missing {
            s += &format!("\n{m}.\n");
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
    use crate::record::{Dataset, MetricKind};
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
        assert_eq!(c.transcribed, (441, 441));
        assert_eq!(c.tables.len(), 1, "Table 1's MERL half only");
        assert_eq!(c.tables[0].0, "paper-vs-ours-table1-merl");
        assert!(c.missing.iter().any(|m| m.contains("tab:changes_quantitative_NOL")));
        assert!(c.missing.iter().any(|m| m.contains("fetch-data diligent")));
        let md = c.to_markdown();
        assert!(md.contains("The paper's protocol"), "{md}");
        assert!(md.contains("## Ranking agreement") && md.contains("## The paper's findings"));
        assert_eq!(c.findings.len(), 11);
        assert_eq!((c.level.len(), c.level_observed.len()), (2, 2));
        assert_eq!(c.agreement.len(), 9);
    }
}
