//! The ablation tables: a variant's metrics minus the baseline's, per model.
//!
//! * [`nol_deltas`]: the NOL ablation of the purely neural models.
//! * [`reciprocity_deltas`]: random swap and the mapping Θ against no reciprocity option.
//! * [`parametrization_deltas`]: view-light angles against Rusinkiewicz angles.
//! * [`nerfactor_deltas`]: NeRFactor's albedo clamp and scalar specular on the additive models.
//!
//! Δ = variant − baseline on table-scaled values (DSSIM, LPIPS, FLIP, RMSE∛ ×100), averaged
//! over the objects run in both settings ([`paired_delta`]). A positive ΔPSNR and a negative
//! ΔDSSIM, ΔLPIPS, ΔFLIP or ΔRMSE∛ mean the variant is better. These tables mark improvements
//! ([`Marking::Improvement`]) rather than best / second / third: a row compares a model with
//! itself, and ranking deltas of different models against each other says little.

use super::average::{datasets, final_records, paired_delta};
use super::record::{RunOptions, RunRecord};
use super::result_tables::{caption, image_metrics};
use super::table::{Column, ColumnGroup, Marking, Row, Table};
use model_spec::{AngleParametrization, ModelKind, Reciprocity};

/// One setting compared with the baseline.
#[derive(Clone, Debug, PartialEq)]
pub struct Variant {
    /// Its name in headers and captions ("NOL", "swap").
    pub label: String,
    /// Its options.
    pub options: RunOptions,
}

impl Variant {
    /// A variant named `label` with `options`.
    pub fn new(label: impl Into<String>, options: RunOptions) -> Self {
        Variant { label: label.into(), options }
    }
}

/// The purely neural models (no analytic BRDF): Single MLP and the four additive models.
pub fn neural_models() -> Vec<ModelKind> {
    ModelKind::ALL.into_iter().filter(|k| k.analytic().is_none()).collect()
}

/// The additive split models.
pub fn additive_models() -> Vec<ModelKind> {
    ModelKind::ALL.into_iter().filter(|k| k.is_additive()).collect()
}

/// A delta table: rows `models`, one column group per (data set, variant) with the data set's
/// image metrics, each cell `metric(variant) − metric(baseline)`.
pub fn delta_table(
    records: &[RunRecord],
    title: &str,
    profile: &str,
    models: &[ModelKind],
    baseline: &Variant,
    variants: &[Variant],
) -> Table {
    let last: Vec<&RunRecord> =
        final_records(records).into_iter().filter(|r| models.contains(&r.model)).collect();
    let data = datasets(&last);
    let mut groups = Vec::new();
    let mut specs = Vec::new();
    for d in &data {
        for v in variants {
            let metrics = image_metrics(d);
            let title = if variants.len() > 1 {
                format!("{} − {}, {}", v.label, baseline.label, d.label())
            } else {
                d.label().to_string()
            };
            groups.push(ColumnGroup {
                title,
                columns: metrics.iter().map(|&m| Column::delta(m)).collect(),
            });
            specs.extend(metrics.into_iter().map(|m| (d.clone(), v.options, m)));
        }
    }
    let rows = models
        .iter()
        .map(|&model| Row {
            label: model.paper_name().to_string(),
            cells: specs
                .iter()
                .map(|(d, options, m)| {
                    paired_delta(&last, model, *options, baseline.options, d, *m)
                })
                .collect(),
            reference: false,
        })
        .collect();
    let names: Vec<&str> = variants.iter().map(|v| v.label.as_str()).collect();
    let text = format!(
        "{title}: Δ = ({}) − {} per model, averaged over the objects run in both settings, on \
         table-scaled values (DSSIM, LPIPS, FLIP, RMSE∛ ×100). Positive ΔPSNR and negative \
         ΔDSSIM, ΔLPIPS, ΔFLIP, ΔRMSE∛ mean the variant is better.",
        names.join(", "),
        baseline.label
    );
    Table {
        caption: caption(&text, &data, profile),
        stub_header: "Model".into(),
        groups,
        rows,
        marking: Marking::Improvement,
        notes: vec![],
    }
}

fn default_variant() -> Variant {
    Variant::new("default", RunOptions::DEFAULT)
}

/// NOL ablation − default for each purely neural model.
pub fn nol_deltas(records: &[RunRecord], profile: &str) -> Table {
    let nol = Variant::new("NOL", RunOptions { nol: true, ..RunOptions::DEFAULT });
    delta_table(records, "NOL ablation", profile, &neural_models(), &default_variant(), &[nol])
}

/// Random swap − none and mapping Θ − none for each purely neural model.
pub fn reciprocity_deltas(records: &[RunRecord], profile: &str) -> Table {
    let with = |reciprocity| RunOptions { reciprocity, ..RunOptions::DEFAULT };
    delta_table(
        records,
        "Reciprocity options",
        profile,
        &neural_models(),
        &Variant::new("none", RunOptions::DEFAULT),
        &[
            Variant::new("swap", with(Reciprocity::RandomSwap)),
            Variant::new("mapping", with(Reciprocity::Mapping)),
        ],
    )
}

/// View-light angles − Rusinkiewicz angles for each purely neural model (the parametric
/// models take no angle features).
pub fn parametrization_deltas(records: &[RunRecord], profile: &str) -> Table {
    let view_light =
        RunOptions { parametrization: AngleParametrization::ViewLight, ..RunOptions::DEFAULT };
    delta_table(
        records,
        "Angle parametrization",
        profile,
        &neural_models(),
        &Variant::new("Rusinkiewicz", RunOptions::DEFAULT),
        &[Variant::new("view-light", view_light)],
    )
}

/// NeRFactor's albedo clamp − default and scalar specular − default for the additive models.
pub fn nerfactor_deltas(records: &[RunRecord], profile: &str) -> Table {
    delta_table(
        records,
        "NeRFactor changes",
        profile,
        &additive_models(),
        &default_variant(),
        &[
            Variant::new("albedo clamp", RunOptions { albedo_clamp: true, ..RunOptions::DEFAULT }),
            Variant::new(
                "scalar specular",
                RunOptions { scalar_specular: true, ..RunOptions::DEFAULT },
            ),
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::super::rank::Mark;
    use super::super::record::{Dataset, MetricKind};
    use super::*;

    fn rec(model: ModelKind, options: RunOptions, psnr: f64, flip: f64) -> RunRecord {
        RunRecord::new(model, Dataset::MerlNbrdf, "spot")
            .with_options(options)
            .with_value(MetricKind::Psnr, psnr)
            .with_value(MetricKind::Flip, flip)
    }

    #[test]
    fn model_sets() {
        assert_eq!(neural_models().len(), 5);
        assert_eq!(neural_models()[0], ModelKind::SingleMlp);
        assert_eq!(additive_models().len(), 4);
    }

    #[test]
    fn nol_deltas_signs_and_marks() {
        let nol = RunOptions { nol: true, ..RunOptions::DEFAULT };
        let records = vec![
            rec(ModelKind::SingleMlp, RunOptions::DEFAULT, 30.0, 0.10),
            rec(ModelKind::SingleMlp, nol, 31.5, 0.12),
            rec(ModelKind::Disney, RunOptions::DEFAULT, 20.0, 0.3),
        ];
        let t = nol_deltas(&records, "quick");
        assert_eq!(t.rows.len(), 5);
        assert_eq!(t.groups.len(), 1);
        assert_eq!(t.groups[0].title, "MERL-derived (NBRDF)");
        assert_eq!(t.cell_text(0, 0), "+1.50");
        assert_eq!(t.cell_text(0, 3), "+2.00");
        assert_eq!(t.cell_text(0, 1), "–");
        assert_eq!(t.cell_text(1, 0), "–");
        let m = t.marks();
        assert_eq!(m[0][0], Mark::Improved);
        assert_eq!(m[0][3], Mark::None);
        assert!(t.caption.contains("(NOL) − default"));
    }

    #[test]
    fn two_variant_groups() {
        let swap = RunOptions { reciprocity: Reciprocity::RandomSwap, ..RunOptions::DEFAULT };
        let records = vec![
            rec(ModelKind::AdditiveShared, RunOptions::DEFAULT, 30.0, 0.10),
            rec(ModelKind::AdditiveShared, swap, 29.0, 0.09),
        ];
        let t = reciprocity_deltas(&records, "quick");
        let titles: Vec<&str> = t.groups.iter().map(|g| g.title.as_str()).collect();
        assert_eq!(
            titles,
            ["swap − none, MERL-derived (NBRDF)", "mapping − none, MERL-derived (NBRDF)"]
        );
        // Add. Shared is row 2 of the neural models; swap FLIP -0.01 ×100.
        assert_eq!(t.cell_text(2, 0), "-1.00");
        assert_eq!(t.cell_text(2, 3), "-1.00");
        assert_eq!(t.marks()[2][3], Mark::Improved);
        assert_eq!(t.cell_text(2, 5), "–");
        let p = parametrization_deltas(&records, "quick");
        assert_eq!(p.rows.len(), 5);
        let n = nerfactor_deltas(&records, "quick");
        assert_eq!(n.rows.len(), 4);
        assert_eq!(n.groups.len(), 2);
    }
}
