//! Every transcribed cell of `crates/report/data/paper/` against the paper's LaTeX source
//! (`../shared/docs/paper/neural-brdfs-wacv2025.tex`): this test reads each table's `tabular`
//! from the source on its own, with its own reading of the row labels, the column headers and
//! the printed numbers, and requires the same cells with the same values as the data files. A
//! slip in a data file (a wrong digit, a swapped row or column, a missing or extra cell) fails
//! it. Under `CI=true` a missing source fails it too.

use model_spec::ModelKind;
use report::paper::data::{self, PaperValue, VARIANTS};
use report::{Dataset, MetricKind, RunOptions};

const TEX: &str = "paper/neural-brdfs-wacv2025.tex";

/// One cell as the source prints it: data set, object, model, variant name, metric, value.
type TexCell = (Dataset, Option<String>, ModelKind, &'static str, MetricKind, PaperValue);

/// The `tabular` body of the table or figure labelled `label`: the last one that ends before
/// the label, comments removed.
fn tabular(tex: &str, label: &str) -> String {
    let at = tex.find(&format!("\\label{{{label}}}")).unwrap_or_else(|| panic!("no {label}"));
    let end = tex[..at].rfind("\\end{tabular}").expect("a tabular before the label");
    let begin = tex[..end].rfind("\\begin{tabular}").expect("its begin");
    let body = &tex[begin..end];
    // The column specification after \begin{tabular}.
    let body = &body[body.find('\n').unwrap_or(0)..];
    body.lines().map(strip_comment).collect::<Vec<_>>().join("\n")
}

/// `line` without its comment (an unescaped `%` and what follows).
fn strip_comment(line: &str) -> &str {
    let b = line.as_bytes();
    for i in 0..b.len() {
        if b[i] == b'%' && (i == 0 || b[i - 1] != b'\\') {
            return &line[..i];
        }
    }
    line
}

/// `s` without the macros that only colour or emphasise: `\textcolor{c}`, `\cellcolor{c}`, the
/// highlight macros and braces.
fn plain(s: &str) -> String {
    let mut s = s.to_string();
    for m in ["\\textcolor{", "\\cellcolor{"] {
        while let Some(i) = s.find(m) {
            let j = i + s[i..].find('}').unwrap() + 1;
            s.replace_range(i..j, "");
        }
    }
    for m in ["\\hlBest", "\\hlSecondBest", "\\hlThirdBest", "\\textbf", "{", "}"] {
        s = s.replace(m, "");
    }
    s.trim().to_string()
}

/// The value a cell prints: a decimal, `a\cdot 10^{b}`, `x\%`, "none" (0) or "all valid".
fn value(cell: &str) -> PaperValue {
    let p = plain(cell).replace('$', "").replace("\\%", "");
    let p = p.trim();
    if p == "none" {
        return PaperValue::Printed(0.0);
    }
    if p == "all valid" {
        return PaperValue::NoNumber;
    }
    let text = match p.split_once("\\cdot") {
        Some((a, b)) => {
            let exp = b.trim().strip_prefix("10^").unwrap_or_else(|| panic!("power in {cell:?}"));
            format!("{}e{}", a.trim(), exp.trim())
        }
        None => p.to_string(),
    };
    PaperValue::Printed(text.parse().unwrap_or_else(|e| panic!("{cell:?} ({text:?}): {e}")))
}

/// The model a row label (or a column header) names.
fn model(label: &str) -> ModelKind {
    let l = plain(label);
    let enhanced = l.contains("enhanced") || l.contains("enh.");
    if l.contains("\\rp") {
        ModelKind::Rp
    } else if l.contains("\\ts") {
        ModelKind::Ts
    } else if l.contains("\\fmbrdf") {
        ModelKind::Fmbrdf
    } else if l.contains("\\disney") {
        ModelKind::Disney
    } else if l.contains("Single MLP") {
        ModelKind::SingleMlp
    } else if l.contains("Sep") {
        if enhanced { ModelKind::AdditiveSeparateEnhanced } else { ModelKind::AdditiveSeparate }
    } else if l.contains("Shared") {
        if enhanced { ModelKind::AdditiveSharedEnhanced } else { ModelKind::AdditiveShared }
    } else {
        panic!("no model in {label:?}")
    }
}

/// The variant a row label names, by the data files' names.
fn variant(label: &str) -> &'static str {
    let rules = [
        ("NOL", "nol"),
        ("rnd. in-swap", "swap"),
        ("(ours)", "mapping"),
        ("(view-light)", "view-light"),
        ("albedo clamp", "albedo-clamp"),
        ("scalar spec", "scalar-specular"),
    ];
    rules.iter().find(|(k, _)| label.contains(k)).map_or("none", |r| r.1)
}

/// The metric a column header names.
fn metric(header: &str) -> MetricKind {
    let rules = [
        ("RMSE", MetricKind::CubeRootRmse),
        ("\\psnr", MetricKind::Psnr),
        ("\\dssim", MetricKind::Dssim),
        ("\\lpips", MetricKind::Lpips),
        ("\\flip", MetricKind::Flip),
        ("\\%", MetricKind::EnergyPercentAbove1),
        ("\\mu", MetricKind::EnergyMedianAbove1),
    ];
    rules
        .iter()
        .find(|(k, _)| header.contains(k))
        .map(|r| r.1)
        .unwrap_or_else(|| panic!("no metric in {header:?}"))
}

fn rows(body: &str) -> Vec<Vec<String>> {
    body.split("\\\\")
        .map(|r| r.replace("\\hline", "").replace("[2pt]", "").replace("[-9pt]", ""))
        .map(|r| r.split('&').map(|c| c.trim().to_string()).collect::<Vec<_>>())
        .filter(|r| r.iter().any(|c| !c.is_empty()))
        .collect()
}

/// The data sets of the column groups, one a value column, from the `\multicolumn` row (or a
/// row of plain data-set names).
fn dataset_columns(header: &[String]) -> Vec<Dataset> {
    let mut out = Vec::new();
    for c in &header[1..] {
        let d = if c.contains("\\merlc") { Dataset::MerlNbrdf } else { Dataset::DiligentMv };
        assert!(c.contains("\\merlc") || c.contains("\\diligentc"), "data set {c:?}");
        let n = c
            .strip_prefix("\\multicolumn{")
            .map_or(1, |r| r[..r.find('}').unwrap()].parse::<usize>().unwrap());
        out.extend(std::iter::repeat_n(d, n));
    }
    out
}

/// A table of rows = models (and variants), columns = (data set, metric).
fn model_rows(body: &str, metric_row: bool) -> Vec<TexCell> {
    let rows = rows(body);
    let datasets = dataset_columns(&rows[0]);
    let (metrics, first): (Vec<MetricKind>, usize) = if metric_row {
        (rows[1][1..].iter().map(|h| metric(h)).collect(), 2)
    } else {
        (vec![MetricKind::ReciprocityRmse; datasets.len()], 1)
    };
    assert_eq!(datasets.len(), metrics.len());
    let mut out = Vec::new();
    for r in &rows[first..] {
        assert_eq!(r.len(), 1 + metrics.len(), "row {r:?}");
        let (m, v) = (model(&r[0]), variant(&r[0]));
        for ((d, k), c) in datasets.iter().zip(&metrics).zip(&r[1..]) {
            out.push((d.clone(), None, m, v, *k, value(c)));
        }
    }
    out
}

/// The supplement's per-object table: rows (object, metric), columns = models.
fn per_object(body: &str) -> Vec<TexCell> {
    let rows = rows(body);
    let models: Vec<ModelKind> = rows[0][2..].iter().map(|h| model(h)).collect();
    let mut object = String::new();
    let mut out = Vec::new();
    for r in &rows[1..] {
        if let Some(rest) = r[0].strip_prefix("\\multirow{4}{*}{") {
            object = rest.trim_end_matches('}').to_lowercase();
        }
        assert_eq!(r.len(), 2 + models.len(), "row {r:?}");
        let k = metric(&r[1]);
        for (m, c) in models.iter().zip(&r[2..]) {
            out.push((Dataset::DiligentMv, Some(object.clone()), *m, "none", k, value(c)));
        }
    }
    out
}

/// The figure: per scene block, the printed PSNRs in the order of the label row's models.
fn figure(body: &str) -> Vec<TexCell> {
    let blocks: Vec<&str> = body.split("\\hline").collect();
    let labels = rows(blocks.last().unwrap());
    let models: Vec<ModelKind> = labels[0][1..]
        .iter()
        .filter(|c| !plain(c).is_empty() && !c.contains("\\gt"))
        .map(|c| model(c))
        .collect();
    let mut out = Vec::new();
    for b in &blocks[..blocks.len() - 1] {
        let (d, object) = if b.contains("\\merlc") && b.contains("grease covered steel") {
            (Dataset::MerlNbrdf, "stanford-bunny__grease-covered-steel")
        } else if b.contains("\\diligentc") && b.contains("cow") {
            (Dataset::DiligentMv, "cow")
        } else {
            panic!("unknown scene block")
        };
        let psnrs: Vec<PaperValue> = b
            .split("PSNR:")
            .skip(1)
            .map(|s| {
                let s = s.trim_start_matches(|c: char| c == '\\' || c.is_whitespace());
                let s = s.trim_start_matches("fontsizePSNR").trim_start();
                let end = s.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap();
                value(&s[..end])
            })
            .collect();
        assert_eq!(psnrs.len(), models.len(), "{object}");
        for (m, v) in models.iter().zip(psnrs) {
            out.push((d.clone(), Some(object.into()), *m, "none", MetricKind::Psnr, v));
        }
    }
    out
}

fn name_of(options: RunOptions) -> &'static str {
    VARIANTS.iter().find(|v| v.1 == options).unwrap().0
}

/// The cells of one data file checked against the source: how many matched, and every fault.
fn check(tex: &str, file: &'static str, label: &'static str, text: &str) -> (usize, Vec<String>) {
    let ours = data::parse(file, label, text).unwrap();
    let body = tabular(tex, label);
    let mut left = match label {
        "tab:reciprocity" => model_rows(&body, false),
        "tab:supp:diligent_quantitative" => per_object(&body),
        "fig:evaluation_renderings" => figure(&body),
        _ => model_rows(&body, true),
    };
    let (mut checked, mut faults) = (0, Vec::new());
    for (k, v) in &ours.cells {
        let key = (&k.dataset, &k.object, k.model, name_of(k.options), k.metric);
        match left.iter().position(|c| (&c.0, &c.1, c.2, c.3, c.4) == key) {
            Some(i) => {
                let c = left.remove(i);
                if c.5 == *v {
                    checked += 1;
                } else {
                    faults.push(format!("{file}: {key:?} is {v:?}, the paper prints {:?}", c.5));
                }
            }
            None => faults.push(format!("{file}: {key:?} is not in {label}")),
        }
    }
    for c in left {
        faults.push(format!("{file}: {label} prints {c:?}, the file lacks it"));
    }
    (checked, faults)
}

fn source() -> Option<String> {
    let docs = test_support::shared_docs_root(TEX)?;
    Some(std::fs::read_to_string(docs.join(TEX)).unwrap())
}

#[test]
fn every_transcribed_cell_matches_the_latex_source() {
    let Some(tex) = source() else { return };
    let mut checked = 0;
    let mut faults = Vec::new();
    for &(file, label, text) in &data::FILES {
        let (n, f) = check(&tex, file, label, text);
        checked += n;
        faults.extend(f);
    }
    assert!(faults.is_empty(), "{} faults:\n{}", faults.len(), faults.join("\n"));
    // Table 1 81, per object 180, NOL 27, reciprocity RMSE 12, energy 28, reciprocity
    // quality 54, view-light 27, NeRFactor 18, the figure 14.
    assert_eq!(checked, 441);
}

/// The check is not blind: a changed digit, two swapped rows, a dropped row and an empty cell
/// are each found.
#[test]
fn a_transcription_slip_is_found() {
    let Some(tex) = source() else { return };
    let (file, label, text) = data::FILES[0];
    assert_eq!(check(&tex, file, label, text), (81, vec![]));
    let lines: Vec<&str> = text.lines().collect();
    let digit = text.replacen("44.05", "44.06", 1);
    // RP's and TS's values under each other's name.
    let swapped = text.replacen("RP,1.632", "X,1.632", 1).replacen("TS,1.216", "RP,1.216", 1);
    let swapped = swapped.replacen("X,1.632", "TS,1.632", 1);
    let dropped: Vec<&str> = lines.iter().copied().filter(|l| !l.starts_with("TS,")).collect();
    let empty = text.replacen(",0.779,", ",,", 1);
    for (slip, faults) in [(digit, 1), (swapped, 18), (dropped.join("\n"), 9), (empty, 1)] {
        let (_, f) = check(&tex, file, label, &slip);
        assert_eq!(f.len(), faults, "{f:?}");
    }
}
