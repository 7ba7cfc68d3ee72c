//! `<out>/report/`: the HTML report `collect` writes beside the tables and figures, to be opened
//! from the file system (inline CSS, no script, no network):
//!
//! ```text
//! report/index.html              profile and data, Table 1 in both protocols (ours with the
//!                                noise ceiling, the paper's), the paper beside ours, every
//!                                ablation and per-object table, run time, the figures (the
//!                                qualitative grids, the BRDF plots), the runs
//! report/runs/<run>.html         one run: training curve, the first test renders beside the
//!                                observation and the FLIP map, how each score was computed
//!                                in each protocol (`test.settings`, `test.paper.settings`),
//!                                metrics.json and config.toml
//! report/runs/<run>-curve-{steps,seconds}.png   training and validation loss against each
//! report/observed/<object>-<stem>.png   observed test images (sRGB), shared by the run pages
//! ```
//!
//! Images of the sweep (figures, the runs' renders and FLIP maps) are linked where they are,
//! by relative paths; every link of every page is checked to exist before `collect` returns.

use crate::collected::{CollectSummary, CollectedRun};
use experiments::{Error, Result};
use report::html::{Page, check_well_formed, links};
use report::paper::PaperComparison;
use report::{LinePlot, Series, Table};
use run_format::run_dir::{RunDir, SweepLayout};
use std::path::{Component, Path, PathBuf};

/// Test images shown per run page.
const IMAGES_PER_RUN: usize = 4;

/// `to` relative to the directory `from` (both made absolute), with `/` separators.
pub fn relative(from: &Path, to: &Path) -> String {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let norm = |p: PathBuf| -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for c in p.components() {
            match c {
                Component::ParentDir => {
                    out.pop();
                }
                Component::Normal(s) => out.push(s.to_string_lossy().into_owned()),
                _ => {}
            }
        }
        out
    };
    let (f, t) = (norm(abs(from)), norm(abs(to)));
    let common = f.iter().zip(&t).take_while(|(a, b)| a == b).count();
    let mut parts: Vec<String> = vec!["..".to_string(); f.len() - common];
    parts.extend(t[common..].iter().cloned());
    parts.join("/")
}

/// The page name of a run.
fn run_page(run: &CollectedRun) -> String {
    let id = run.dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    format!("{id}.html")
}

/// The tables of the report: every result table, and the comparison with the paper.
pub struct Tables<'a> {
    /// (file stem, table), as written under `tables/`.
    pub all: &'a [(String, Table)],
    /// The paper beside ours (absent without Table 1 runs).
    pub paper: Option<&'a PaperComparison>,
}

/// The index's sections: (heading, anchor, table stems in order).
const SECTIONS: [(&str, &str, &[&str]); 4] = [
    (
        "Table 1",
        "table1",
        &["table1", "table1-paper", "table1-paper-observed", "table1-noise-free"],
    ),
    (
        "Ablations and analyses",
        "ablations",
        &["nol", "reciprocity", "reciprocity-deltas", "angles", "nerfactor", "energy"],
    ),
    ("Per object", "per-object", &["per-object-"]),
    ("Run time against accuracy", "runtime", &["runtime"]),
];

/// Writes `<out>/report/` and checks its links; the files go into `summary`.
pub fn write_report(
    out: &Path,
    profile: &str,
    tables: &Tables<'_>,
    runs: &[CollectedRun],
    summary: &mut CollectSummary,
) -> Result<()> {
    let dir = SweepLayout::new(out).report();
    let run_dir = dir.join("runs");
    let mut pages = Vec::new();
    let mut datasets: Vec<String> =
        runs.iter().map(|r| r.record.dataset.label().to_string()).collect();
    datasets.sort();
    datasets.dedup();
    let mut index = Page::new(&format!("Neural BRDF comparison: profile {profile}"));
    index.paragraph(
        &format!(
            "{} evaluated runs on {} ({}). Tables as in tables/*.md; best values bold on green, \
             second underlined, third italic; the noise ceiling row is a reference, never ranked.",
            runs.len(),
            datasets.join(", "),
            profile
        ),
        true,
    );
    for (heading, anchor, stems) in SECTIONS {
        let chosen: Vec<&Table> = tables
            .all
            .iter()
            .filter(|(name, _)| {
                stems.iter().any(|s| name == s || (s.ends_with('-') && name.starts_with(s)))
            })
            .map(|(_, t)| t)
            .collect();
        if chosen.is_empty() {
            continue;
        }
        index.heading(heading, anchor);
        for t in chosen {
            index.table(t);
        }
        if anchor == "runtime" {
            index.figures(&figures_matching(&dir, summary, "runtime-"));
        }
        if anchor == "table1"
            && let Some(c) = tables.paper
        {
            paper_section(&mut index, c);
        }
    }
    figure_sections(&mut index, &dir, summary);
    let mut sorted: Vec<&CollectedRun> = runs.iter().collect();
    sorted.sort_by(|a, b| {
        (&a.record.object, a.record.model as usize, a.record.options.label()).cmp(&(
            &b.record.object,
            b.record.model as usize,
            b.record.options.label(),
        ))
    });
    index.heading("Runs", "runs");
    let run_links: Vec<(String, String)> =
        sorted.iter().map(|r| (format!("runs/{}", run_page(r)), run_title(r))).collect();
    index.links(&run_links);
    for r in &sorted {
        let page = run_dir.join(run_page(r));
        let html = run_page_html(r, &run_dir, &dir, summary)?;
        pages.push((page, html));
    }
    pages.push((dir.join("index.html"), index.finish()));
    check_pages(&pages)?;
    for (path, html) in pages {
        stdx::fs::write_atomic(&path, html.as_bytes())?;
        summary.files.push(path);
    }
    Ok(())
}

/// The index's figure sections: the qualitative comparison and the BRDF plots.
fn figure_sections(index: &mut Page, dir: &Path, summary: &CollectSummary) {
    let qualitative = figures_matching(dir, summary, "qualitative-");
    let split = figures_matching(dir, summary, "split-");
    if !qualitative.is_empty() || !split.is_empty() {
        index.heading("Qualitative comparison", "qualitative");
        for f in qualitative.into_iter().chain(split) {
            index.figures(&[f]);
        }
    }
    let brdf: Vec<(String, String)> = ["spheres-", "slices-", "albedo-", "validity-"]
        .iter()
        .flat_map(|p| figures_matching(dir, summary, p))
        .collect();
    if !brdf.is_empty() {
        index.heading("BRDF plots", "brdf");
        index.paragraph(
            "Each fitted model and the ground-truth material away from the cameras' \
             directions: lit spheres with their HDR-FLIP error, slices in the plane of \
             incidence (linear and log10), directional albedo against the incident angle \
             (above 1 the BRDF creates energy), and per-pixel validity on a test view.",
            true,
        );
        for f in brdf {
            index.figures(&[f]);
        }
    }
}

/// Checks every page before any is written: well formed, and each link names a file that
/// exists or a page of this report.
fn check_pages(pages: &[(PathBuf, String)]) -> Result<()> {
    let pending: Vec<PathBuf> = pages.iter().map(|(p, _)| lexical(p)).collect();
    for (path, html) in pages {
        check_well_formed(html).map_err(|e| Error::format(path, e))?;
        let base = path.parent().unwrap_or(Path::new("."));
        for link in links(html) {
            let target = lexical(&base.join(&link));
            if !target.exists() && !pending.contains(&target) {
                return Err(Error::format(path, format!("links to {link}, which does not exist")));
            }
        }
    }
    Ok(())
}

/// The section "The paper beside ours": where its values come from, the level of each group of
/// rows, ours beside its Table 1, the ranking agreement and its findings on our runs.
fn paper_section(index: &mut Page, c: &PaperComparison) {
    let plain = |s: &str| s.replace("**", "");
    index.heading("The paper beside ours", "paper");
    index.paragraph(report::Protocol::Paper.caption(), true);
    index.paragraph(&c.source_note(), true);
    for l in PaperComparison::level_lines(&c.level) {
        index.paragraph(&plain(&l), false);
    }
    index.paragraph(report::Protocol::PaperObserved.caption(), true);
    for l in PaperComparison::level_lines(&c.level_observed) {
        index.paragraph(&plain(&l), false);
    }
    for (_, t) in &c.tables {
        index.table(t);
    }
    for m in &c.missing {
        index.paragraph(m, true);
    }
    index.paragraph("Ranking agreement (Kendall's τ-b over the nine models, MERL half):", false);
    for l in c.agreement_lines() {
        index.paragraph(&l, true);
    }
    index.paragraph("The paper's findings on our runs:", false);
    for f in &c.findings {
        let evidence = report::paper::sentence(&f.evidence);
        index.paragraph(&format!("{}: {}. {evidence}.", f.verdict(), f.claim), false);
    }
}

/// `p` made absolute with `.` and `..` resolved lexically.
fn lexical(p: &Path) -> PathBuf {
    let abs = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

/// The figures of the sweep whose file names start with `prefix`, relative to `dir`.
fn figures_matching(dir: &Path, summary: &CollectSummary, prefix: &str) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = summary
        .files
        .iter()
        .filter(|p| {
            p.extension().is_some_and(|e| e == "png")
                && p.file_name().is_some_and(|n| n.to_string_lossy().starts_with(prefix))
        })
        .map(|p| {
            let name = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            (relative(dir, p), name)
        })
        .collect();
    out.sort();
    out.dedup();
    out
}

fn run_title(r: &CollectedRun) -> String {
    format!("{}: {} ({})", r.record.object, r.record.model.paper_name(), r.record.options.label())
}

/// A run's page, writing its curve plot and the observed images it shows.
fn run_page_html(
    r: &CollectedRun,
    run_dir: &Path,
    report_dir: &Path,
    summary: &mut CollectSummary,
) -> Result<String> {
    let run = RunDir::new(&r.dir);
    let mut page = Page::new(&run_title(r));
    page.paragraph(&format!("Run directory: {}", r.dir.display()), true);
    let why = r.stop_reason.map_or("unknown".to_string(), |s| format!("{s:?}"));
    page.paragraph(&format!("Training stopped: {why}. Data: {}.", r.record.dataset.label()), true);
    // The training curve.
    let plots = curve_plots(&run.curve(), &run_title(r))?;
    if !plots.is_empty() {
        let mut cells = Vec::new();
        for (axis, png) in plots {
            let name = format!("{}-curve-{axis}.png", run_page(r).trim_end_matches(".html"));
            let path = run_dir.join(&name);
            stdx::fs::write_atomic(&path, &png)?;
            summary.files.push(path);
            cells.push((name, format!("training and validation loss against {axis}")));
        }
        page.heading("Training curve", "curve");
        page.figures(&cells);
    }
    // The first test images: observation, render, FLIP map.
    let mut stems: Vec<String> = std::fs::read_dir(run.renders())
        .map(|rd| {
            rd.flatten()
                .filter_map(|e| e.file_name().to_str().map(String::from))
                .filter(|n| n.ends_with(".exr"))
                .map(|n| n.trim_end_matches(".exr").to_string())
                .collect()
        })
        .unwrap_or_default();
    stems.sort();
    if !stems.is_empty() {
        page.heading("Test renders", "renders");
    }
    for stem in stems.iter().take(IMAGES_PER_RUN) {
        let mut cells = Vec::new();
        if let Some(obs) = observed_png(r, stem, report_dir, summary)? {
            cells.push((relative(run_dir, &obs), format!("{stem}: observed")));
        }
        let render = run.renders().join(format!("{stem}.png"));
        if render.is_file() {
            cells.push((
                relative(run_dir, &render),
                format!("{stem}: {}", r.record.model.paper_name()),
            ));
        }
        let flip = run.flip().join(format!("{stem}.png"));
        if flip.is_file() {
            cells.push((relative(run_dir, &flip), format!("{stem}: HDR-FLIP error")));
        }
        page.figures(&cells);
    }
    let metrics =
        std::fs::read_to_string(run.metrics()).map_err(|e| Error::io(run.metrics(), e))?;
    let json: serde_json::Value = serde_json::from_str(&metrics).unwrap_or_default();
    for (pointer, heading, anchor) in [
        ("/test/settings", "How the scores were computed (our protocol)", "settings"),
        ("/test/paper/settings", "How the scores were computed (the paper's protocol)", "paper"),
    ] {
        if let Some(settings) = json.pointer(pointer).and_then(|v| v.as_object()) {
            page.heading(heading, anchor);
            for (key, value) in settings {
                let text = value.as_str().map_or_else(|| value.to_string(), String::from);
                page.paragraph(&format!("{key}: {text}"), false);
            }
        }
    }
    page.heading("metrics.json", "metrics");
    page.preformatted(&metrics);
    page.heading("config.toml", "config");
    let config = std::fs::read_to_string(run.config()).map_err(|e| Error::io(run.config(), e))?;
    page.preformatted(&config);
    page.links(&[("../index.html".into(), "back to the report".into())]);
    Ok(page.finish())
}

/// The observed test image `stem` of the run's scene as an sRGB PNG under
/// `report/observed/` (written once per object and stem); `None` when the scene is not there.
fn observed_png(
    r: &CollectedRun,
    stem: &str,
    report_dir: &Path,
    summary: &mut CollectSummary,
) -> Result<Option<PathBuf>> {
    let Some(scene) = &r.config.scene else { return Ok(None) };
    let Some((v, l)) = crate::collected::parse_stem(stem) else { return Ok(None) };
    let exr = scene.join(format!("images/{}.exr", scene::sample_stem(v, l)));
    let path = report_dir.join("observed").join(format!("{}-{stem}.png", r.record.object));
    if path.is_file() {
        return Ok(Some(path));
    }
    let Ok((w, h, px)) = scene::images::read_exr_rgb(&exr, &stdx::Limits::DEFAULT) else {
        return Ok(None);
    };
    experiments::eval::images::write_png_srgb_atomic(&path, w as u32, h as u32, &px)?;
    summary.files.push(path.clone());
    Ok(Some(path))
}

/// The loss curves of `curve.csv` as PNGs: log10 training and validation loss against steps
/// and against wall seconds (`("steps", png)`, `("seconds", png)`); empty without a curve.
fn curve_plots(curve: &Path, title: &str) -> Result<Vec<(&'static str, Vec<u8>)>> {
    let Ok(text) = std::fs::read_to_string(curve) else { return Ok(Vec::new()) };
    // (step, seconds, log10 loss) of the training and of the validation loss.
    let (mut train, mut val) = (Vec::new(), Vec::new());
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() < 5 {
            continue;
        }
        let (Ok(step), Ok(secs)) = (f[0].parse::<f64>(), f[4].parse::<f64>()) else { continue };
        if let Ok(loss) = f[1].parse::<f64>()
            && loss > 0.0
        {
            train.push((step, secs, loss.log10()));
        }
        if let Ok(v) = f[2].parse::<f64>()
            && v > 0.0
        {
            val.push((step, secs, v.log10()));
        }
    }
    if train.is_empty() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    for (axis, x_label) in [("steps", "step"), ("seconds", "wall time (s)")] {
        let pick = |pts: &[(f64, f64, f64)]| -> Vec<(f64, f64)> {
            pts.iter().map(|&(st, se, y)| (if axis == "steps" { st } else { se }, y)).collect()
        };
        let mut plot = LinePlot::new(format!("{title}: loss"), x_label, "log10 loss (gamma-MSE)");
        plot.log_x = false;
        plot.series = vec![
            Series { label: "training loss".into(), points: pick(&train) },
            Series { label: "validation loss".into(), points: pick(&val) },
        ];
        out.push((axis, report::line_plot_png(&plot)?));
    }
    Ok(out)
}
