//! The paper's findings, each checked on our runs: holds, does not hold, or not checked (no
//! runs to check it on), with the numbers behind the verdict. Image scores are the paper's
//! protocol's; the BRDF-space analyses (RMSE∛, reciprocity, energy) have one protocol.

use super::compare::ours as mean_of;
use super::data::ModelGroup;
use crate::average::{datasets, final_records};
use crate::record::{Dataset, MetricKind, RunRecord};
use model_spec::ModelKind;

/// One of the paper's findings and whether our runs show it.
#[derive(Clone, Debug, PartialEq)]
pub struct Finding {
    /// The finding, as the paper states it.
    pub claim: &'static str,
    /// `Some(true)` holds, `Some(false)` does not, `None` not checked.
    pub holds: Option<bool>,
    /// The rule applied and the numbers.
    pub evidence: String,
}

impl Finding {
    /// "holds", "does not hold" or "not checked".
    pub fn verdict(&self) -> &'static str {
        match self.holds {
            Some(true) => "holds",
            Some(false) => "does not hold",
            None => "not checked",
        }
    }
}

fn unchecked(claim: &'static str, why: &str) -> Finding {
    Finding { claim, holds: None, evidence: why.to_string() }
}

/// Every finding, in the paper's order: `paper` holds the runs' scores under the paper's
/// protocol (with RMSE∛), `ours` the records with the reciprocity and energy analyses.
pub fn findings(paper: &[RunRecord], ours: &[RunRecord]) -> Vec<Finding> {
    let paper = final_records(paper);
    let ours = final_records(ours);
    let merl = Dataset::MerlNbrdf;
    let value = |r: &[&RunRecord], m: ModelKind, d: &Dataset, k: MetricKind| mean_of(r, m, d, k);
    let group =
        |r: &[&RunRecord], g: ModelGroup, d: &Dataset, k: MetricKind| -> Vec<(ModelKind, f64)> {
            g.models().into_iter().filter_map(|m| value(r, m, d, k).map(|v| (m, v))).collect()
        };
    let mut out = Vec::new();

    // 1. Purely neural above parametric on MERL-type data.
    let claim = "Purely neural models score above every parametric model on MERL-type data";
    let (n, p) = (
        group(&paper, ModelGroup::PurelyNeural, &merl, MetricKind::Psnr),
        group(&paper, ModelGroup::Parametric, &merl, MetricKind::Psnr),
    );
    let (nr, pr) = (
        group(&paper, ModelGroup::PurelyNeural, &merl, MetricKind::CubeRootRmse),
        group(&paper, ModelGroup::Parametric, &merl, MetricKind::CubeRootRmse),
    );
    out.push(if n.is_empty() || p.is_empty() {
        unchecked(claim, "no MERL-derived runs of both groups")
    } else {
        let (nmin, pmax) = (min(&n), max(&p));
        let mut holds = nmin.1 > pmax.1;
        let mut evidence = format!(
            "lowest purely neural PSNR {:.2} dB ({}) against the highest parametric {:.2} dB \
             ({})",
            nmin.1,
            nmin.0.paper_name(),
            pmax.1,
            pmax.0.paper_name()
        );
        if !nr.is_empty() && !pr.is_empty() {
            let (nmax, pmin) = (max(&nr), min(&pr));
            holds &= nmax.1 < pmin.1;
            evidence += &format!(
                "; highest purely neural RMSE∛ {:.2} ({}) against the lowest parametric {:.2} \
                 ({}), ×100",
                100.0 * nmax.1,
                nmax.0.paper_name(),
                100.0 * pmin.1,
                pmin.0.paper_name()
            );
        }
        Finding { claim, holds: Some(holds), evidence }
    });

    // 2. The enhanced split no worse than the vanilla one.
    let claim = "The enhanced additive split is no worse than its vanilla version";
    let pairs = [
        (ModelKind::AdditiveSeparateEnhanced, ModelKind::AdditiveSeparate),
        (ModelKind::AdditiveSharedEnhanced, ModelKind::AdditiveShared),
    ];
    let mut parts = Vec::new();
    let mut holds = true;
    for (enhanced, vanilla) in pairs {
        for (metric, higher) in [(MetricKind::Psnr, true), (MetricKind::CubeRootRmse, false)] {
            let (Some(e), Some(v)) =
                (value(&paper, enhanced, &merl, metric), value(&paper, vanilla, &merl, metric))
            else {
                continue;
            };
            holds &= if higher { e >= v } else { e <= v };
            let f = if metric == MetricKind::Psnr { 1.0 } else { 100.0 };
            parts.push(format!(
                "{} {} {:.2} against {:.2} ({:+.2})",
                enhanced.paper_name(),
                metric.label(),
                f * e,
                f * v,
                f * (e - v)
            ));
        }
    }
    out.push(if parts.is_empty() {
        unchecked(claim, "no MERL-derived runs of both splits")
    } else {
        let rule = "rule: enhanced PSNR ≥ vanilla and RMSE∛ ≤ vanilla (×100), MERL-derived";
        Finding { claim, holds: Some(holds), evidence: format!("{}; {rule}", parts.join("; ")) }
    });

    // 3. RP last.
    let claim = "RP is last";
    let all: Vec<(ModelKind, f64)> = ModelKind::ALL
        .into_iter()
        .filter_map(|m| value(&paper, m, &merl, MetricKind::Psnr).map(|v| (m, v)))
        .collect();
    out.push(match all.iter().find(|(m, _)| *m == ModelKind::Rp) {
        Some(&(_, rp)) if all.len() > 1 => {
            let others: Vec<(ModelKind, f64)> =
                all.iter().copied().filter(|(m, _)| *m != ModelKind::Rp).collect();
            let next = min(&others);
            Finding {
                claim,
                holds: Some(rp < next.1),
                evidence: format!(
                    "RP {rp:.2} dB, the lowest of the other {} models {:.2} dB ({}); MERL-derived \
                     PSNR",
                    others.len(),
                    next.1,
                    next.0.paper_name()
                ),
            }
        }
        _ => unchecked(claim, "no MERL-derived RP run beside another model"),
    });

    // 4. Reciprocity: orders of magnitude between the purely neural and the symmetric models.
    let claim = "Purely neural models violate reciprocity by orders of magnitude more than the \
                 symmetric parametric models (RP, TS, Disney)";
    let recip = |g: &[ModelKind]| -> Vec<(ModelKind, f64)> {
        let mut v = Vec::new();
        for d in datasets(&ours) {
            for &m in g {
                if let Some(x) = value(&ours, m, &d, MetricKind::ReciprocityRmse) {
                    v.push((m, x));
                }
            }
        }
        v
    };
    let neural = recip(&ModelGroup::PurelyNeural.models());
    let symmetric = recip(&[ModelKind::Rp, ModelKind::Ts, ModelKind::Disney]);
    out.push(if neural.is_empty() || symmetric.is_empty() {
        unchecked(claim, "no reciprocity RMSE of both groups")
    } else {
        let (nmin, smax) = (min(&neural), max(&symmetric));
        Finding {
            claim,
            holds: Some(nmin.1 >= 100.0 * smax.1),
            evidence: format!(
                "lowest purely neural reciprocity RMSE {} ({}) against the highest symmetric {} \
                 ({}); rule: at least 100 times",
                scientific(nmin.1),
                nmin.0.paper_name(),
                scientific(smax.1),
                smax.0.paper_name()
            ),
        }
    });

    // 5. Energy violations below 0.05 % on MERL-type data.
    let claim = "Purely neural models put less than 0.05 % of (x, l) pairs above an albedo of 1 \
                 on MERL-type data";
    let e = group(&ours, ModelGroup::PurelyNeural, &merl, MetricKind::EnergyPercentAbove1);
    out.push(if e.is_empty() {
        unchecked(claim, "no energy analysis of a MERL-derived purely neural run")
    } else {
        let worst = max(&e);
        let parametric =
            group(&ours, ModelGroup::Parametric, &merl, MetricKind::EnergyPercentAbove1);
        let p = parametric
            .iter()
            .map(|(m, v)| format!("{} {v:.3} %", m.paper_name()))
            .collect::<Vec<_>>()
            .join(", ");
        Finding {
            claim,
            holds: Some(worst.1 < 0.05),
            evidence: format!(
                "highest {:.3} % ({}); the parametric models for comparison: {}",
                worst.1,
                worst.0.paper_name(),
                if p.is_empty() { "not run".into() } else { p }
            ),
        }
    });

    // 6. Neural and parametric close on real captures.
    let claim = "On real captures the purely neural and the parametric models are close";
    let gap = |d: &Dataset| -> Option<f64> {
        let n = group(&paper, ModelGroup::PurelyNeural, d, MetricKind::Psnr);
        let p = group(&paper, ModelGroup::Parametric, d, MetricKind::Psnr);
        (!n.is_empty() && !p.is_empty()).then(|| mean(&n) - mean(&p))
    };
    let real: Vec<Dataset> =
        datasets(&paper).into_iter().filter(|d| !d.has_brdf_ground_truth()).collect();
    let real_gaps: Vec<(Dataset, f64)> =
        real.iter().filter_map(|d| gap(d).map(|g| (d.clone(), g))).collect();
    out.push(match (real_gaps.is_empty(), gap(&merl)) {
        (true, _) => unchecked(
            claim,
            "no real-capture runs of both groups (`cargo xtask reproduce-tables --profile real`)",
        ),
        (false, None) => unchecked(claim, "no MERL-derived runs to compare the gap with"),
        (false, Some(merl_gap)) => {
            let holds = real_gaps.iter().all(|(_, g)| *g < merl_gap / 2.0);
            let gaps = real_gaps
                .iter()
                .map(|(d, g)| format!("{g:+.2} dB on {}", d.label()))
                .collect::<Vec<_>>()
                .join(", ");
            Finding {
                claim,
                holds: Some(holds),
                evidence: format!(
                    "mean purely neural minus mean parametric PSNR: {gaps}, against \
                     {merl_gap:+.2} dB on MERL-derived data; rule: less than half the MERL gap"
                ),
            }
        }
    });
    out
}

/// `v` as 6.04e-4, and 0 as 0.
fn scientific(v: f64) -> String {
    if v == 0.0 { "0".into() } else { format!("{v:.2e}") }
}

fn min(v: &[(ModelKind, f64)]) -> (ModelKind, f64) {
    *v.iter().min_by(|a, b| a.1.total_cmp(&b.1)).expect("non-empty")
}

fn max(v: &[(ModelKind, f64)]) -> (ModelKind, f64) {
    *v.iter().max_by(|a, b| a.1.total_cmp(&b.1)).expect("non-empty")
}

fn mean(v: &[(ModelKind, f64)]) -> f64 {
    v.iter().map(|x| x.1).sum::<f64>() / v.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(model: ModelKind, d: Dataset, psnr: f64, rmse: f64) -> RunRecord {
        RunRecord::new(model, d, "obj")
            .with_value(MetricKind::Psnr, psnr)
            .with_value(MetricKind::CubeRootRmse, rmse)
    }

    /// The paper's story: neural 52 dB, parametric 45 (RP 44) on MERL; close on DiLiGenT-MV.
    fn story() -> (Vec<RunRecord>, Vec<RunRecord>) {
        let mut paper = Vec::new();
        let mut ours = Vec::new();
        for m in ModelKind::ALL {
            let neural = ModelGroup::of(m) == ModelGroup::PurelyNeural;
            let psnr = if neural {
                52.0
            } else if m == ModelKind::Rp {
                44.0
            } else {
                45.0
            };
            let psnr = psnr + if m.is_enhanced() { 0.1 } else { 0.0 };
            paper.push(rec(m, Dataset::MerlNbrdf, psnr, if neural { 0.005 } else { 0.02 }));
            let real = if neural { 40.5 } else { 40.0 };
            paper.push(
                RunRecord::new(m, Dataset::DiligentMv, "bear").with_value(MetricKind::Psnr, real),
            );
            let recip = if neural { 2e-3 } else { 0.0 };
            let energy = if neural { 0.0 } else { 0.3 };
            ours.push(
                RunRecord::new(m, Dataset::MerlNbrdf, "obj")
                    .with_value(MetricKind::ReciprocityRmse, recip)
                    .with_value(MetricKind::EnergyPercentAbove1, energy),
            );
        }
        (paper, ours)
    }

    #[test]
    fn every_finding_holds_on_the_papers_story() {
        let (paper, ours) = story();
        let f = findings(&paper, &ours);
        assert_eq!(f.len(), 6);
        for x in &f {
            assert_eq!(x.holds, Some(true), "{}: {}", x.claim, x.evidence);
        }
        assert!(f[5].evidence.contains("+0.50 dB on DiLiGenT-MV"), "{}", f[5].evidence);
    }

    #[test]
    fn each_finding_can_fail() {
        let (paper, ours) = story();
        // The record of (model, data set) replaced by one holding only `k` = `v`, on the same
        // object.
        let with = |recs: &[RunRecord], m: ModelKind, d: Dataset, k: MetricKind, v: f64| {
            let mut r = recs.to_vec();
            let i = r.iter().position(|x| x.model == m && x.dataset == d).unwrap();
            let object = r.remove(i).object;
            r.push(RunRecord::new(m, d, object).with_value(k, v));
            r
        };
        // A parametric model above a neural one.
        let p = with(&paper, ModelKind::Disney, Dataset::MerlNbrdf, MetricKind::Psnr, 53.0);
        assert_eq!(findings(&p, &ours)[0].holds, Some(false));
        // An enhanced split below its vanilla version.
        let p = with(
            &paper,
            ModelKind::AdditiveSharedEnhanced,
            Dataset::MerlNbrdf,
            MetricKind::Psnr,
            51.0,
        );
        assert_eq!(findings(&p, &ours)[1].holds, Some(false));
        // RP not last.
        let p = with(&paper, ModelKind::Rp, Dataset::MerlNbrdf, MetricKind::Psnr, 46.0);
        assert_eq!(findings(&p, &ours)[2].holds, Some(false));
        // A symmetric model with a reciprocity error near the neural ones.
        let o = with(&ours, ModelKind::Ts, Dataset::MerlNbrdf, MetricKind::ReciprocityRmse, 1e-4);
        assert_eq!(findings(&paper, &o)[3].holds, Some(false));
        // A neural model with energy violations.
        let o = with(
            &ours,
            ModelKind::SingleMlp,
            Dataset::MerlNbrdf,
            MetricKind::EnergyPercentAbove1,
            0.2,
        );
        assert_eq!(findings(&paper, &o)[4].holds, Some(false));
        // A wide gap on real data.
        let p = with(&paper, ModelKind::Disney, Dataset::DiligentMv, MetricKind::Psnr, 20.0);
        assert_eq!(findings(&p, &ours)[5].holds, Some(false));
        // No real data: not checked, saying how to get it.
        let p: Vec<RunRecord> =
            paper.iter().filter(|r| r.dataset == Dataset::MerlNbrdf).cloned().collect();
        let f = findings(&p, &ours);
        assert_eq!(f[5].holds, None);
        assert!(f[5].evidence.contains("--profile real"));
    }
}
