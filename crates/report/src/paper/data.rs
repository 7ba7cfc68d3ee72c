//! The paper's published values, compiled in from `crates/report/data/paper/` (see its
//! README): Table 1's MERL and DiLiGenT-MV halves, the supplement's per-object DiLiGenT-MV
//! table, and the ranges of Table 1 known second-hand. Values are kept as printed (PSNR in dB,
//! the other image metrics and RMSE∛ ×100); an empty cell is a value not transcribed.

use crate::record::{Dataset, MetricKind};
use model_spec::ModelKind;

/// One of the paper's tables.
#[derive(Clone, Debug, PartialEq)]
pub struct PaperTable {
    /// The data file it came from (for errors and captions).
    pub file: &'static str,
    /// The data set of its rows.
    pub dataset: Dataset,
    /// Its metric columns, in the paper's order.
    pub columns: Vec<MetricKind>,
    /// Its rows, in the paper's order.
    pub rows: Vec<PaperRow>,
}

/// A row of a paper table: a model (and, per object, its object) and one value a column.
#[derive(Clone, Debug, PartialEq)]
pub struct PaperRow {
    /// The object (per-object tables only).
    pub object: Option<String>,
    /// The model.
    pub model: ModelKind,
    /// The printed values, `None` where not transcribed.
    pub values: Vec<Option<f64>>,
}

impl PaperTable {
    /// The printed value of `metric` for `model` (on `object` in a per-object table).
    pub fn value(&self, model: ModelKind, object: Option<&str>, metric: MetricKind) -> Option<f64> {
        let c = self.columns.iter().position(|&m| m == metric)?;
        self.rows
            .iter()
            .find(|r| r.model == model && r.object.as_deref() == object)
            .and_then(|r| r.values[c])
    }

    /// How many cells hold a value.
    pub fn transcribed(&self) -> usize {
        self.rows.iter().map(|r| r.values.iter().flatten().count()).sum()
    }

    /// How many cells the table has.
    pub fn cells(&self) -> usize {
        self.rows.len() * self.columns.len()
    }
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

    /// The group's name as the data files and the comparison write it.
    pub fn label(self) -> &'static str {
        match self {
            ModelGroup::Parametric => "parametric",
            ModelGroup::PurelyNeural => "purely neural",
        }
    }
}

/// The range of one column over a group of the paper's rows, as printed.
#[derive(Clone, Debug, PartialEq)]
pub struct PaperRange {
    /// The data set.
    pub dataset: Dataset,
    /// The rows.
    pub group: ModelGroup,
    /// The column.
    pub metric: MetricKind,
    /// The smallest printed value of the group.
    pub min: f64,
    /// The largest.
    pub max: f64,
    /// Where the range is quoted from.
    pub source: String,
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

const TABLE1_MERL: (&str, &str) =
    ("table1-merl.csv", include_str!("../../data/paper/table1-merl.csv"));
const TABLE1_DILIGENT_MV: (&str, &str) =
    ("table1-diligent-mv.csv", include_str!("../../data/paper/table1-diligent-mv.csv"));
const PER_OBJECT_DILIGENT_MV: (&str, &str) =
    ("per-object-diligent-mv.csv", include_str!("../../data/paper/per-object-diligent-mv.csv"));
const RANGES: (&str, &str) = ("ranges.csv", include_str!("../../data/paper/ranges.csv"));

/// Table 1, MERL half: 9 models x PSNR, DSSIM, LPIPS, FLIP, RMSE∛.
pub fn table1_merl() -> Result<PaperTable, DataError> {
    parse_table(TABLE1_MERL, Dataset::MerlNbrdf, false)
}

/// Table 1, DiLiGenT-MV half: 9 models x PSNR, DSSIM, LPIPS, FLIP.
pub fn table1_diligent_mv() -> Result<PaperTable, DataError> {
    parse_table(TABLE1_DILIGENT_MV, Dataset::DiligentMv, false)
}

/// The supplement's DiLiGenT-MV table: 5 objects x 9 models x PSNR, DSSIM, LPIPS, FLIP.
pub fn per_object_diligent_mv() -> Result<PaperTable, DataError> {
    parse_table(PER_OBJECT_DILIGENT_MV, Dataset::DiligentMv, true)
}

/// The ranges of Table 1 known second-hand (see the data README).
pub fn ranges() -> Result<Vec<PaperRange>, DataError> {
    let (file, text) = RANGES;
    let err = |line: usize, fault: String| DataError { file, line, fault };
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1).filter(|(_, l)| !l.trim().is_empty()) {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        let [dataset, rows, metric, min, max, source] = f[..] else {
            return Err(err(i + 1, format!("{} fields, expected 6", f.len())));
        };
        let group = match rows {
            "parametric" => ModelGroup::Parametric,
            "purely neural" => ModelGroup::PurelyNeural,
            other => return Err(err(i + 1, format!("unknown rows {other:?}"))),
        };
        let number = |s: &str| s.parse::<f64>().map_err(|e| err(i + 1, format!("{s:?}: {e}")));
        out.push(PaperRange {
            dataset: Dataset::from_label(dataset),
            group,
            metric: metric_of(metric).ok_or_else(|| err(i + 1, format!("metric {metric:?}")))?,
            min: number(min)?,
            max: number(max)?,
            source: source.to_string(),
        });
    }
    Ok(out)
}

fn metric_of(label: &str) -> Option<MetricKind> {
    MetricKind::ALL.into_iter().find(|m| m.label() == label)
}

fn model_of(name: &str) -> Option<ModelKind> {
    ModelKind::ALL.into_iter().find(|m| m.paper_name() == name)
}

/// A table file: a header `[object,]model,<metric labels>` and one row a line.
fn parse_table(
    (file, text): (&'static str, &str),
    dataset: Dataset,
    per_object: bool,
) -> Result<PaperTable, DataError> {
    let err = |line: usize, fault: String| DataError { file, line, fault };
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines.next().ok_or_else(|| err(1, "empty file".into()))?;
    let lead = if per_object { 2 } else { 1 };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let expected = if per_object { ["object", "model"].as_slice() } else { ["model"].as_slice() };
    if names.len() <= lead || names[..lead] != *expected {
        return Err(err(1, format!("header {header:?} must start with {}", expected.join(","))));
    }
    let columns = names[lead..]
        .iter()
        .map(|n| metric_of(n).ok_or_else(|| err(1, format!("unknown column {n:?}"))))
        .collect::<Result<Vec<_>, _>>()?;
    let mut rows = Vec::new();
    for (i, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != names.len() {
            return Err(err(i + 1, format!("{} fields, the header has {}", f.len(), names.len())));
        }
        let model = model_of(f[lead - 1])
            .ok_or_else(|| err(i + 1, format!("unknown model {:?}", f[lead - 1])))?;
        let values = f[lead..]
            .iter()
            .map(|v| match *v {
                "" => Ok(None),
                v => v
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .map(Some)
                    .ok_or_else(|| err(i + 1, format!("{v:?} is not a number"))),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let object = per_object.then(|| f[0].to_string());
        rows.push(PaperRow { object, model, values });
    }
    Ok(PaperTable { file, dataset, columns, rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shape of the paper's tables: Table 1 has the nine models in the paper's order, five
    /// columns on MERL (with RMSE∛) and four on DiLiGenT-MV (no BRDF ground truth); the
    /// supplement's table has every model on each of DiLiGenT-MV's five objects.
    #[test]
    fn each_file_has_the_rows_and_columns_of_the_papers_table() {
        let merl = table1_merl().unwrap();
        let models: Vec<ModelKind> = merl.rows.iter().map(|r| r.model).collect();
        assert_eq!(models, ModelKind::ALL);
        use MetricKind::*;
        assert_eq!(merl.columns, [Psnr, Dssim, Lpips, Flip, CubeRootRmse]);
        assert_eq!(merl.cells(), 45);
        let mv = table1_diligent_mv().unwrap();
        assert_eq!(mv.rows.iter().map(|r| r.model).collect::<Vec<_>>(), ModelKind::ALL);
        assert_eq!(mv.columns, [Psnr, Dssim, Lpips, Flip]);
        let per = per_object_diligent_mv().unwrap();
        assert_eq!(per.rows.len(), 45);
        let mut objects: Vec<&str> = per.rows.iter().filter_map(|r| r.object.as_deref()).collect();
        objects.dedup();
        assert_eq!(objects, ["bear", "buddha", "cow", "pot2", "reading"]);
        for o in objects {
            let m: Vec<ModelKind> = per
                .rows
                .iter()
                .filter(|r| r.object.as_deref() == Some(o))
                .map(|r| r.model)
                .collect();
            assert_eq!(m, ModelKind::ALL, "{o}");
        }
        assert_eq!(per.columns, mv.columns);
        // Whatever is transcribed is within each metric's printed range.
        for t in [&merl, &mv, &per] {
            for r in &t.rows {
                for (v, m) in r.values.iter().zip(&t.columns) {
                    if let Some(v) = v {
                        let ok = if *m == Psnr { (10.0..80.0).contains(v) } else { *v >= 0.0 };
                        assert!(ok, "{}: {m:?} {v}", t.file);
                    }
                }
            }
        }
    }

    #[test]
    fn the_quoted_ranges_parse_and_are_ordered() {
        let r = ranges().unwrap();
        assert_eq!(r.len(), 2);
        assert!(r.iter().all(|r| r.min <= r.max && r.metric == MetricKind::Psnr));
        let neural = r.iter().find(|r| r.group == ModelGroup::PurelyNeural).unwrap();
        let parametric = r.iter().find(|r| r.group == ModelGroup::Parametric).unwrap();
        assert!(neural.min > parametric.max, "the paper's neural rows are above the parametric");
    }

    #[test]
    fn bad_files_are_named_with_their_line() {
        let bad = "model,PSNR\nRP,abc\n";
        let e = parse_table(("x.csv", bad), Dataset::MerlNbrdf, false).unwrap_err();
        assert_eq!((e.file, e.line), ("x.csv", 2));
        assert!(e.to_string().contains("\"abc\""), "{e}");
        let e = parse_table(("y.csv", "model,PSNR\nPhong,1\n"), Dataset::MerlNbrdf, false);
        assert!(e.unwrap_err().fault.contains("unknown model"));
        let e = parse_table(("z.csv", "model,PSNR,XYZ\n"), Dataset::MerlNbrdf, false);
        assert!(e.unwrap_err().fault.contains("XYZ"));
    }

    #[test]
    fn groups_split_the_nine_models() {
        assert_eq!(ModelGroup::Parametric.models().len(), 4);
        assert_eq!(ModelGroup::PurelyNeural.models().len(), 5);
        assert_eq!(ModelGroup::of(ModelKind::Fmbrdf), ModelGroup::Parametric);
    }
}
