//! The paper's published values, compiled in from `crates/report/data/paper/` (see its
//! README): every table of the paper and the per-render PSNRs of its figure
//! `fig:evaluation_renderings`. Values are kept as printed (PSNR in dB, the other image metrics
//! and RMSE∛ ×100, the reciprocity RMSE unscaled, the energy share in %).
//!
//! A file is a header and one line a row. The header's first fields are lead columns, in this
//! order and each optional but `model`: `dataset`, `object`, `model`, `variant`; then one field
//! a printed column, `DATASET:METRIC` (`merl:PSNR`) or, in a file with a `dataset` lead column,
//! `METRIC`. A variant is one of [`VARIANTS`]. A cell is a number, `-` where the paper prints a
//! word instead ("all valid": no energy above 1 to take a median of), or empty where not
//! transcribed.

use crate::record::{Dataset, MetricKind, RunOptions};
use model_spec::{AngleParametrization, ModelKind, Reciprocity};

/// A printed cell of one of the paper's tables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PaperValue {
    /// A number, as printed.
    Printed(f64),
    /// The paper prints a word, no number ("all valid").
    NoNumber,
    /// Not transcribed.
    NotTranscribed,
}

/// Where a cell sits: the data set, object, model, options and metric it reports.
#[derive(Clone, Debug, PartialEq)]
pub struct CellKey {
    /// The data set of its column.
    pub dataset: Dataset,
    /// The object (per-object tables and the figure only).
    pub object: Option<String>,
    /// The model of its row.
    pub model: ModelKind,
    /// The variant of its row (the default options in Table 1 and the energy table).
    pub options: RunOptions,
    /// The metric of its column.
    pub metric: MetricKind,
}

/// One of the paper's tables, flattened to its cells in the file's order (row by row).
#[derive(Clone, Debug, PartialEq)]
pub struct PaperTable {
    /// The data file it came from (for errors and captions).
    pub file: &'static str,
    /// The LaTeX label of the table (or figure) it transcribes.
    pub label: &'static str,
    /// Its cells.
    pub cells: Vec<(CellKey, PaperValue)>,
}

impl PaperTable {
    /// The printed value of `metric` for `model` with `options` on `dataset` (on `object` in a
    /// per-object table), if the paper prints a number there.
    pub fn value(
        &self,
        dataset: &Dataset,
        model: ModelKind,
        options: RunOptions,
        object: Option<&str>,
        metric: MetricKind,
    ) -> Option<f64> {
        self.cells.iter().find_map(|(k, v)| match v {
            PaperValue::Printed(x)
                if &k.dataset == dataset
                    && k.model == model
                    && k.options == options
                    && k.object.as_deref() == object
                    && k.metric == metric =>
            {
                Some(*x)
            }
            _ => None,
        })
    }

    /// The data sets of its columns, in the file's order.
    pub fn datasets(&self) -> Vec<Dataset> {
        unique(self.cells.iter().map(|(k, _)| k.dataset.clone()))
    }

    /// The metrics printed for `dataset`, in the file's order.
    pub fn metrics(&self, dataset: &Dataset) -> Vec<MetricKind> {
        unique(self.cells.iter().filter(|(k, _)| &k.dataset == dataset).map(|(k, _)| k.metric))
    }

    /// The rows: (model, options), in the file's order.
    pub fn rows(&self) -> Vec<(ModelKind, RunOptions)> {
        unique(self.cells.iter().map(|(k, _)| (k.model, k.options)))
    }

    /// The objects of a per-object table, in the file's order.
    pub fn objects(&self) -> Vec<String> {
        unique(self.cells.iter().filter_map(|(k, _)| k.object.clone()))
    }

    /// The table restricted to the columns of `dataset`.
    pub fn only(&self, dataset: &Dataset) -> PaperTable {
        let cells = self.cells.iter().filter(|(k, _)| &k.dataset == dataset).cloned().collect();
        PaperTable { cells, ..self.clone() }
    }

    /// How many cells are transcribed (a number or a printed word).
    pub fn transcribed(&self) -> usize {
        self.cells.iter().filter(|(_, v)| *v != PaperValue::NotTranscribed).count()
    }

    /// How many cells the table has.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// Whether the table has no cell.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }
}

fn unique<T: PartialEq>(items: impl Iterator<Item = T>) -> Vec<T> {
    let mut out: Vec<T> = Vec::new();
    for x in items {
        if !out.contains(&x) {
            out.push(x);
        }
    }
    out
}

/// A group of Table 1's rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelGroup {
    /// RP, TS, FMBRDF and Disney: an MLP predicting an analytic model's parameters.
    Parametric,
    /// Single MLP and the four additive splits.
    PurelyNeural,
}

impl ModelGroup {
    /// The group a model belongs to.
    pub fn of(model: ModelKind) -> ModelGroup {
        if model.analytic().is_some() { ModelGroup::Parametric } else { ModelGroup::PurelyNeural }
    }

    /// Its models, in table order.
    pub fn models(self) -> Vec<ModelKind> {
        ModelKind::ALL.into_iter().filter(|&m| ModelGroup::of(m) == self).collect()
    }

    /// The group's name as the comparison writes it.
    pub fn label(self) -> &'static str {
        match self {
            ModelGroup::Parametric => "parametric",
            ModelGroup::PurelyNeural => "purely neural",
        }
    }
}

/// An error in a compiled-in data file: the file, the line (1-based) and the fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("crates/report/data/paper/{file}, line {line}: {fault}")]
pub struct DataError {
    /// The file.
    pub file: &'static str,
    /// The line.
    pub line: usize,
    /// What is wrong.
    pub fault: String,
}

/// The variants of the ablation tables' rows, as the data files name them, with their options.
pub const VARIANTS: [(&str, RunOptions); 7] = [
    ("none", RunOptions::DEFAULT),
    ("nol", RunOptions { nol: true, ..RunOptions::DEFAULT }),
    ("swap", RunOptions { reciprocity: Reciprocity::RandomSwap, ..RunOptions::DEFAULT }),
    ("mapping", RunOptions { reciprocity: Reciprocity::Mapping, ..RunOptions::DEFAULT }),
    (
        "view-light",
        RunOptions { parametrization: AngleParametrization::ViewLight, ..RunOptions::DEFAULT },
    ),
    ("albedo-clamp", RunOptions { albedo_clamp: true, ..RunOptions::DEFAULT }),
    ("scalar-specular", RunOptions { scalar_specular: true, ..RunOptions::DEFAULT }),
];

/// The name of `options` in [`VARIANTS`], if it is one of them.
pub fn variant_name(options: RunOptions) -> Option<&'static str> {
    VARIANTS.iter().find(|(_, o)| *o == options).map(|(n, _)| *n)
}

/// Every data file: (file, the label it transcribes, its text).
pub const FILES: [(&str, &str, &str); 9] = [
    ("table1.csv", "tab:quantitative", include_str!("../../data/paper/table1.csv")),
    (
        "per-object-diligent-mv.csv",
        "tab:supp:diligent_quantitative",
        include_str!("../../data/paper/per-object-diligent-mv.csv"),
    ),
    ("nol.csv", "tab:changes_quantitative_NOL", include_str!("../../data/paper/nol.csv")),
    (
        "reciprocity-rmse.csv",
        "tab:reciprocity",
        include_str!("../../data/paper/reciprocity-rmse.csv"),
    ),
    ("energy.csv", "tab:energy", include_str!("../../data/paper/energy.csv")),
    (
        "reciprocity-quality.csv",
        "tab:changes_quantitative_reci",
        include_str!("../../data/paper/reciprocity-quality.csv"),
    ),
    (
        "view-light.csv",
        "tab:changes_quantitative_view_light",
        include_str!("../../data/paper/view-light.csv"),
    ),
    (
        "nerfactor.csv",
        "tab:supp:changes_quantitative_nerfactor",
        include_str!("../../data/paper/nerfactor.csv"),
    ),
    (
        "evaluation-renderings.csv",
        "fig:evaluation_renderings",
        include_str!("../../data/paper/evaluation-renderings.csv"),
    ),
];

/// The table of `file` (one of [`FILES`]).
pub fn table(file: &str) -> Result<PaperTable, DataError> {
    let &(file, label, text) = FILES.iter().find(|f| f.0 == file).ok_or(DataError {
        file: "README.md",
        line: 0,
        fault: format!("no data file {file}"),
    })?;
    parse(file, label, text)
}

/// Every table of [`FILES`].
pub fn all_tables() -> Result<Vec<PaperTable>, DataError> {
    FILES.iter().map(|&(f, l, t)| parse(f, l, t)).collect()
}

/// Table 1, both halves: 9 models x (MERL: RMSE∛, PSNR, DSSIM, LPIPS, FLIP; DiLiGenT-MV: PSNR,
/// DSSIM, LPIPS, FLIP).
pub fn table1() -> Result<PaperTable, DataError> {
    table("table1.csv")
}

fn metric_of(label: &str) -> Option<MetricKind> {
    MetricKind::ALL.into_iter().find(|m| m.label() == label)
}

fn model_of(name: &str) -> Option<ModelKind> {
    ModelKind::ALL.into_iter().find(|m| m.paper_name() == name)
}

fn dataset_of(name: &str) -> Option<Dataset> {
    match Dataset::from_label(name) {
        Dataset::Other(_) => None,
        d => Some(d),
    }
}

/// The lead columns a header may start with, in their order.
const LEADS: [&str; 4] = ["dataset", "object", "model", "variant"];

/// A file's text as a table (see the module's documentation for the format).
pub fn parse(file: &'static str, label: &'static str, text: &str) -> Result<PaperTable, DataError> {
    let err = |line: usize, fault: String| DataError { file, line, fault };
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines.next().ok_or_else(|| err(1, "empty file".into()))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let mut leads = Vec::new();
    for lead in LEADS {
        if names.get(leads.len()) == Some(&lead) {
            leads.push(lead);
        }
    }
    if !leads.contains(&"model") {
        return Err(err(1, format!("header {header:?} has no model column")));
    }
    let has_dataset = leads.contains(&"dataset");
    let columns = names[leads.len()..]
        .iter()
        .map(|n| {
            let (dataset, metric) = match n.split_once(':') {
                Some((d, m)) => {
                    let d =
                        dataset_of(d).ok_or_else(|| err(1, format!("unknown data set {d:?}")))?;
                    (Some(d), m)
                }
                None if has_dataset => (None, *n),
                None => return Err(err(1, format!("column {n:?} names no data set (merl:{n}?)"))),
            };
            let metric =
                metric_of(metric).ok_or_else(|| err(1, format!("unknown column {n:?}")))?;
            Ok((dataset, metric))
        })
        .collect::<Result<Vec<_>, _>>()?;
    if columns.is_empty() {
        return Err(err(1, format!("header {header:?} has no value column")));
    }
    let mut cells = Vec::new();
    for (i, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != names.len() {
            return Err(err(i + 1, format!("{} fields, the header has {}", f.len(), names.len())));
        }
        let lead = |name: &str| leads.iter().position(|l| *l == name).map(|p| f[p]);
        let model = lead("model").unwrap_or_default();
        let model =
            model_of(model).ok_or_else(|| err(i + 1, format!("unknown model {model:?}")))?;
        let options = match lead("variant") {
            None => RunOptions::DEFAULT,
            Some(v) => VARIANTS
                .iter()
                .find(|(n, _)| *n == v)
                .map(|(_, o)| *o)
                .ok_or_else(|| err(i + 1, format!("unknown variant {v:?}")))?,
        };
        let row_dataset = match lead("dataset") {
            None => None,
            Some(d) => {
                Some(dataset_of(d).ok_or_else(|| err(i + 1, format!("unknown data set {d:?}")))?)
            }
        };
        let object = lead("object").map(str::to_string);
        for ((dataset, metric), v) in columns.iter().zip(&f[leads.len()..]) {
            let value = match *v {
                "" => PaperValue::NotTranscribed,
                "-" => PaperValue::NoNumber,
                v => v
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .map(PaperValue::Printed)
                    .ok_or_else(|| err(i + 1, format!("{v:?} is not a number")))?,
            };
            let dataset =
                dataset.clone().or_else(|| row_dataset.clone()).unwrap_or(Dataset::MerlNbrdf);
            let key = CellKey { dataset, object: object.clone(), model, options, metric: *metric };
            cells.push((key, value));
        }
    }
    Ok(PaperTable { file, label, cells })
}

#[cfg(test)]
mod tests {
    use super::*;
    use MetricKind::*;

    /// The shape of the paper's tables: Table 1 has the nine models in the paper's order, five
    /// columns on MERL (RMSE∛ first) and four on DiLiGenT-MV (no BRDF ground truth); the
    /// supplement's table has every model on each of DiLiGenT-MV's five objects; the ablations
    /// have the paper's 14 rows a scene.
    #[test]
    fn each_file_has_the_rows_and_columns_of_the_papers_table() {
        let t1 = table1().unwrap();
        let (merl, mv) = (Dataset::MerlNbrdf, Dataset::DiligentMv);
        assert_eq!(t1.rows().iter().map(|r| r.0).collect::<Vec<_>>(), ModelKind::ALL);
        assert_eq!(t1.datasets(), [merl.clone(), mv.clone()]);
        assert_eq!(t1.metrics(&merl), [CubeRootRmse, Psnr, Dssim, Lpips, Flip]);
        assert_eq!(t1.metrics(&mv), [Psnr, Dssim, Lpips, Flip]);
        assert_eq!((t1.len(), t1.transcribed()), (81, 81));
        let per = table("per-object-diligent-mv.csv").unwrap();
        assert_eq!(per.objects(), ["bear", "buddha", "cow", "pot2", "reading"]);
        assert_eq!(per.len(), 5 * 9 * 4);
        let ablation_rows: usize =
            ["nol.csv", "reciprocity-quality.csv", "view-light.csv", "nerfactor.csv"]
                .iter()
                .map(|f| table(f).unwrap().rows().len())
                .sum();
        assert_eq!(ablation_rows, 14);
        let energy = table("energy.csv").unwrap();
        assert_eq!(energy.rows().len(), 7);
        let no_number = energy.cells.iter().filter(|c| c.1 == PaperValue::NoNumber).count();
        assert_eq!(no_number, 2, "RP's medians: all valid");
        // Every number is in its metric's printed range.
        for t in all_tables().unwrap() {
            assert_eq!(t.transcribed(), t.len(), "{}", t.file);
            for (k, v) in &t.cells {
                if let PaperValue::Printed(v) = v {
                    let delta = t.rows().iter().any(|r| r.1 != RunOptions::DEFAULT)
                        && !t.file.starts_with("reciprocity-rmse");
                    let ok = match k.metric {
                        _ if delta => v.abs() < 5.0,
                        Psnr => (10.0..80.0).contains(v),
                        _ => *v >= 0.0,
                    };
                    assert!(ok, "{}: {k:?} {v}", t.file);
                }
            }
        }
    }

    #[test]
    fn values_are_found_by_their_key() {
        let t1 = table1().unwrap();
        let v = t1.value(&Dataset::MerlNbrdf, ModelKind::Rp, RunOptions::DEFAULT, None, Psnr);
        assert_eq!(v, Some(44.05));
        let nol = table("nol.csv").unwrap();
        let o = VARIANTS[1].1;
        let v = nol.value(&Dataset::DiligentMv, ModelKind::AdditiveShared, o, None, Psnr);
        assert_eq!(v, Some(-0.37));
        assert_eq!(variant_name(o), Some("nol"));
    }

    #[test]
    fn bad_files_are_named_with_their_line() {
        let e = parse("x.csv", "t", "model,merl:PSNR\nRP,abc\n").unwrap_err();
        assert_eq!((e.file, e.line), ("x.csv", 2));
        assert!(e.to_string().contains("\"abc\""), "{e}");
        let e = parse("y.csv", "t", "model,merl:PSNR\nPhong,1\n").unwrap_err();
        assert!(e.fault.contains("unknown model"));
        let e = parse("z.csv", "t", "model,merl:XYZ\n").unwrap_err();
        assert!(e.fault.contains("XYZ"));
        let e = parse("w.csv", "t", "model,PSNR\n").unwrap_err();
        assert!(e.fault.contains("names no data set"), "{e}");
        let e = parse("v.csv", "t", "model,variant,merl:PSNR\nRP,twice,1\n").unwrap_err();
        assert!(e.fault.contains("unknown variant"), "{e}");
        let e = parse("u.csv", "t", "model,merl:PSNR\nRP,1,2\n").unwrap_err();
        assert!(e.fault.contains("3 fields"), "{e}");
    }

    #[test]
    fn groups_split_the_nine_models() {
        assert_eq!(ModelGroup::Parametric.models().len(), 4);
        assert_eq!(ModelGroup::PurelyNeural.models().len(), 5);
        assert_eq!(ModelGroup::of(ModelKind::Fmbrdf), ModelGroup::Parametric);
    }
}
