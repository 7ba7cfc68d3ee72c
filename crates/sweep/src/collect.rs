//! `collect`: the tables and figures of any set of evaluated run directories.
//!
//! Each run directory (found recursively below the given paths) contributes a
//! [`RunRecord`] from its `config.toml`, `metrics.json` and `run.json` (runs made outside a
//! sweep, without `run.json`, count as Table 1 / ablation runs on the object named by their
//! scene directory). Written, atomically, under `<out>/`:
//!
//! ```text
//! tables/table1.{md,tex}           Table 1 (every data set present) under our protocol (the
//!                                  object mask, against the observations), with the noise
//!                                  ceiling
//! tables/table1-paper.*            Table 1 under the paper's protocol (the whole frame,
//!                                  against the noise-free renders)
//! tables/table1-paper-observed.*   the same frames against the observations (background 0)
//! tables/table1-noise-free.*       Table 1 against the noise-free renders, on the mask
//! tables/nol.{md,tex}              NOL deltas            tables/reciprocity.{md,tex}
//! tables/reciprocity-deltas.*      swap / mapping deltas tables/angles.{md,tex}
//! tables/nerfactor.{md,tex}        NeRFactor changes     tables/energy.{md,tex}
//! tables/per-object-psnr.*         per object (ours)     tables/per-object-rmse.*
//! tables/per-object-psnr-paper.*   per object, the paper's protocol
//! tables/runtime.{md,tex}         run time against accuracy (seconds to each plateau)
//! tables/paper-vs-ours.md          the paper's Table 1 beside ours (its protocol), the ranking
//!                                  agreement and its findings checked (`report::paper`)
//! tables/all.md                    every table in one file
//! figures/qualitative-<object>.png GT and every model's render with its PSNR, FLIP maps
//! figures/split-<object>.png       additive models: render, diffuse, specular, albedo
//! figures/runtime-psnr.png, runtime-rmse.png
//! figures/{spheres,slices,slices-log,albedo,validity}-<object>.png   BRDF plots (see
//!                                  [`super::brdf_figures`])
//! report/index.html               the HTML report (see [`super::html_report`])
//! ```

use crate::collected::{
    CollectSummary, CollectedRun, convergence_note, find_runs, parse_stem, read_run,
};
use crate::plan::Purpose;
use experiments::{Error, Result};
use metrics::aggregate::Score;
use report::{
    self, Dataset, MetricKind, ModelRender, Protocol, QualitativeRow, RgbImage, RunOptions,
    RunRecord, Table,
};
use run_format::run_dir::{RunDir, SweepLayout};
use scene::flag;
use std::path::{Path, PathBuf};

/// Writes one output of a sweep (a table or a figure) to `path`, atomically.
fn write(path: PathBuf, bytes: &[u8], summary: &mut CollectSummary) -> Result<()> {
    stdx::fs::write_atomic(&path, bytes)?;
    summary.files.push(path);
    Ok(())
}

/// Builds every table and figure of the runs below `paths` into `out`.
pub fn collect(paths: &[PathBuf], out: &Path, profile: &str) -> Result<CollectSummary> {
    let mut summary = CollectSummary::default();
    let mut runs = Vec::new();
    for dir in find_runs(paths) {
        match read_run(&dir)? {
            Some(r) => runs.push(r),
            None => summary.unfinished += 1,
        }
    }
    summary.runs = runs.len();
    if runs.is_empty() {
        return Err(Error::format(
            paths.first().map(PathBuf::as_path).unwrap_or(Path::new(".")),
            "no evaluated run found",
        ));
    }
    let table_runs: Vec<&CollectedRun> =
        runs.iter().filter(|r| r.purposes.iter().any(|p| *p != Purpose::Runtime)).collect();
    let ceiling: Vec<RunRecord> = runs.iter().filter_map(|r| r.ceiling.clone()).collect();
    let mut all_md = String::new();
    let mut all_tables: Vec<(String, Table)> = Vec::new();
    let mut comparison = None;
    if !table_runs.is_empty() {
        let rec: Vec<RunRecord> = table_runs.iter().map(|r| r.record.clone()).collect();
        let noise_free: Vec<RunRecord> =
            table_runs.iter().filter_map(|r| r.noise_free.clone()).collect();
        let paper: Vec<RunRecord> = table_runs.iter().filter_map(|r| r.paper.clone()).collect();
        let observed: Vec<RunRecord> =
            table_runs.iter().filter_map(|r| r.paper_observed.clone()).collect();
        let protocols = Protocols { noise_free: &noise_free, paper: &paper, observed: &observed };
        let mut tables = result_tables(&rec, &protocols, &ceiling, profile);
        let table1_runs: Vec<&CollectedRun> = table_runs
            .iter()
            .copied()
            .filter(|r| {
                r.purposes.contains(&Purpose::Table) && r.record.options == RunOptions::DEFAULT
            })
            .collect();
        if let Some(note) = convergence_note(&table1_runs) {
            for (name, t) in &mut tables {
                if name.starts_with("table1") || name.starts_with("per-object") {
                    t.notes.push(note.clone());
                }
            }
        }
        write_tables(&tables, out, &mut all_md, &mut summary)?;
        all_tables.extend(tables);
        let c = report::paper::compare(&paper, &observed, &rec, profile)
            .map_err(|e| Error::format(Path::new("crates/report/data/paper"), e.to_string()))?;
        let md = c.to_markdown();
        // Each table beside the paper's on its own too (`paper-vs-ours-<table>-<data>`); they
        // are in `paper-vs-ours.md`, so `all.md` gets them once, from there.
        write_tables(&c.tables, out, &mut String::new(), &mut summary)?;
        write(
            SweepLayout::new(out).tables().join("paper-vs-ours.md"),
            md.as_bytes(),
            &mut summary,
        )?;
        all_md.push_str(&md);
        all_md.push('\n');
        comparison = Some(c);
        figures(&runs, out, &mut summary)?;
        super::brdf_figures::brdf_figures(&runs, out, &mut summary)?;
    }
    let sink = (&mut all_md, &mut all_tables, &mut summary);
    runtime_outputs(&runs, &ceiling, (out, profile), sink)?;
    // Where the time went: the last sweep into `out` (if one wrote its timing) and the runs'.
    let timing = super::timing::SweepTiming::read(out);
    let time = [("time".to_string(), super::timing::table(timing.as_ref(), &runs, profile))];
    write_tables(&time, out, &mut all_md, &mut summary)?;
    all_tables.extend(time);
    write(SweepLayout::new(out).tables().join("all.md"), all_md.as_bytes(), &mut summary)?;
    let tables = super::html_report::Tables { all: &all_tables, paper: comparison.as_ref() };
    super::html_report::write_report(out, profile, &tables, &runs, &mut summary)?;
    Ok(summary)
}

/// The run-time table and curves of the runs that record them (`Purpose::Runtime`), into
/// `all_md`, `all_tables` and `summary`.
fn runtime_outputs(
    runs: &[CollectedRun],
    ceiling: &[RunRecord],
    (out, profile): (&Path, &str),
    (all_md, all_tables, summary): (&mut String, &mut Vec<(String, Table)>, &mut CollectSummary),
) -> Result<()> {
    let curves: Vec<RunRecord> = runs
        .iter()
        .filter(|r| r.purposes.contains(&Purpose::Runtime))
        .flat_map(|r| r.curve.iter().cloned())
        .collect();
    if !curves.is_empty() {
        let t = report::time_to_accuracy(&curves, ceiling, profile);
        let runtime = [("runtime".to_string(), t)];
        write_tables(&runtime, out, all_md, summary)?;
        all_tables.extend(runtime);
        let c = ceiling_psnr(ceiling, &curves);
        for (metric, name) in [(MetricKind::Psnr, "psnr"), (MetricKind::CubeRootRmse, "rmse")] {
            let reference = if metric == MetricKind::Psnr { c } else { None };
            let d = Dataset::MerlNbrdf;
            let plot = report::runtime_plot(&curves, &d, metric, reference, profile);
            if !plot.series.is_empty() {
                let png = report::line_plot_png(&plot)?;
                write(
                    SweepLayout::new(out).figures().join(format!("runtime-{name}.png")),
                    &png,
                    summary,
                )?;
            }
        }
    }
    Ok(())
}

/// The records of the runs under the other protocols than ours.
struct Protocols<'a> {
    /// On the mask, against the noise-free renders.
    noise_free: &'a [RunRecord],
    /// The paper's protocol: the whole frame against the noise-free renders.
    paper: &'a [RunRecord],
    /// The paper's whole frame against the observations, background set to 0.
    observed: &'a [RunRecord],
}

/// Every result table of the runs (not the run-time one), with its file stem: `rec` under our
/// protocol, the others from `protocols`.
fn result_tables(
    rec: &[RunRecord],
    protocols: &Protocols<'_>,
    ceiling: &[RunRecord],
    profile: &str,
) -> Vec<(String, Table)> {
    let (noise_free, paper) = (protocols.noise_free, protocols.paper);
    let mut tables: Vec<(String, Table)> =
        vec![("table1".into(), report::table1(rec, ceiling, profile))];
    if !paper.is_empty() {
        let t = report::table1_paper(paper, Protocol::Paper, profile);
        tables.push(("table1-paper".into(), t));
    }
    // The reading against the observations differs from the paper's protocol only where a
    // noise-free render exists.
    if !noise_free.is_empty() {
        let t = report::table1_paper(protocols.observed, Protocol::PaperObserved, profile);
        tables.push(("table1-paper-observed".into(), t));
        tables.push(("table1-noise-free".into(), report::table1_noise_free(noise_free, profile)));
    }
    tables.extend([
        ("nol".into(), report::nol_deltas(rec, profile)),
        ("reciprocity".into(), report::reciprocity_table(rec, profile)),
        ("reciprocity-deltas".into(), report::reciprocity_deltas(rec, profile)),
        ("angles".into(), report::parametrization_deltas(rec, profile)),
        ("nerfactor".into(), report::nerfactor_deltas(rec, profile)),
        ("energy".into(), report::energy_table(rec, profile)),
    ]);
    for (d, tag) in [
        (Dataset::MerlNbrdf, ""),
        (Dataset::DiligentMv, "-diligent-mv"),
        (Dataset::Diligent, "-diligent"),
    ] {
        if rec.iter().any(|r| r.dataset == d) {
            let ours = Protocol::Ours;
            let psnr = report::per_object_table(rec, ceiling, &d, MetricKind::Psnr, ours, profile);
            tables.push((format!("per-object-psnr{tag}"), psnr));
            if paper.iter().any(|r| r.dataset == d) {
                let p = Protocol::Paper;
                let psnr = report::per_object_table(paper, &[], &d, MetricKind::Psnr, p, profile);
                tables.push((format!("per-object-psnr-paper{tag}"), psnr));
            }
            if d.has_brdf_ground_truth() {
                let m = MetricKind::CubeRootRmse;
                let rmse = report::per_object_table(rec, ceiling, &d, m, ours, profile);
                tables.push((format!("per-object-rmse{tag}"), rmse));
            }
        }
    }
    tables
}

/// Writes each table as Markdown and LaTeX and appends the Markdown to `all_md`.
fn write_tables(
    tables: &[(String, Table)],
    out: &Path,
    all_md: &mut String,
    summary: &mut CollectSummary,
) -> Result<()> {
    for (name, t) in tables {
        let md = report::to_markdown(t);
        let tables = SweepLayout::new(out).tables();
        write(tables.join(format!("{name}.md")), md.as_bytes(), summary)?;
        write(tables.join(format!("{name}.tex")), report::to_latex(t).as_bytes(), summary)?;
        all_md.push_str(&md);
        all_md.push('\n');
    }
    Ok(())
}

/// The mean noise-ceiling PSNR over the objects of the run-time curves.
fn ceiling_psnr(ceiling: &[RunRecord], curves: &[RunRecord]) -> Option<f64> {
    let mut mean = metrics::aggregate::PerObjectMean::new();
    for r in ceiling.iter().filter(|r| curves.iter().any(|c| c.object == r.object)) {
        if let Some(s) = r.metric(MetricKind::Psnr) {
            mean.push(&r.object, s.clone());
        }
    }
    if mean.per_object().is_empty() { None } else { mean.overall().value() }
}

fn load_exr(path: &Path) -> Result<metrics::Image> {
    let (w, h, px) = scene::images::read_exr_rgb(path, &stdx::Limits::DEFAULT)?;
    Ok(metrics::Image::new(w, h, px.into_iter().flatten().collect())?)
}

fn load_png(path: &Path) -> Result<RgbImage> {
    let img = image::open(path).map_err(|e| Error::format(path, e.to_string()))?.to_rgb8();
    let (w, h) = img.dimensions();
    let px: Vec<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    Ok(RgbImage::new(w, h, px)?)
}

/// The qualitative grid and the split figure of every object (first test image).
fn figures(runs: &[CollectedRun], out: &Path, summary: &mut CollectSummary) -> Result<()> {
    let mut objects: Vec<&str> = runs.iter().map(|r| r.record.object.as_str()).collect();
    objects.sort();
    objects.dedup();
    for object in objects {
        let mut mine: Vec<&CollectedRun> = runs
            .iter()
            .filter(|r| {
                r.record.object == object
                    && r.record.options == RunOptions::DEFAULT
                    && r.purposes.contains(&Purpose::Table)
            })
            .collect();
        mine.sort_by_key(|r| r.record.model as usize);
        let Some(first) = mine.first() else { continue };
        let Some(scene) = first.config.scene.clone() else { continue };
        let Some(stem) = first_render(&first.dir) else { continue };
        let Some((v, l)) = parse_stem(&stem) else { continue };
        let stem_vl = scene::sample_stem(v, l);
        let Ok(gt) = load_exr(&scene.join(format!("images/{stem_vl}.exr"))) else { continue };
        let flags = scene::images::read_png_gray(
            &scene.join(format!("flags/{stem_vl}.png")),
            &stdx::Limits::DEFAULT,
        );
        let mask: Option<Vec<bool>> =
            flags.ok().map(|(_, _, f)| f.iter().map(|&b| b & flag::FOREGROUND != 0).collect());
        let mut renders = Vec::new();
        let mut split_rows = Vec::new();
        for r in &mine {
            let Some((render, split)) = run_figure_cells(r, &stem, v, &gt, mask.as_deref()) else {
                continue;
            };
            renders.push(render);
            split_rows.extend(split);
        }
        let row = QualitativeRow {
            label: format!("view {v}, light {l}"),
            reference: RgbImage::from_linear(&gt),
            renders,
        };
        let grid = report::qualitative_grid(&format!("{object}: test view {v}, light {l}"), &row);
        write(
            SweepLayout::new(out).figures().join(format!("qualitative-{object}.png")),
            &report::image_grid_png(&grid)?,
            summary,
        )?;
        if !split_rows.is_empty() {
            let headers = ["render", "diffuse", "specular", "albedo"].map(String::from).to_vec();
            let grid = report::ImageGrid::from_images(
                format!("{object}: additive split, view {v}, light {l}"),
                headers,
                split_rows,
            );
            write(
                SweepLayout::new(out).figures().join(format!("split-{object}.png")),
                &report::image_grid_png(&grid)?,
                summary,
            )?;
        }
    }
    Ok(())
}

/// A row of the additive split figure: the model's name and its (caption, image) cells.
type SplitRow = (String, Vec<(String, RgbImage)>);

/// A run's cells of the figures for test image `stem` of view `v`: its render with PSNR and
/// FLIP against the observation `gt` (scored on `mask`), and for an additive model its row of
/// the split figure (render, diffuse, specular, albedo). `None` when the run has no such render.
fn run_figure_cells(
    r: &CollectedRun,
    stem: &str,
    v: usize,
    gt: &metrics::Image,
    mask: Option<&[bool]>,
) -> Option<(ModelRender, Option<SplitRow>)> {
    let run = RunDir::new(&r.dir);
    let img = load_exr(&run.renders().join(format!("{stem}.exr"))).ok()?;
    let psnr = metrics::psnr_linear(&img, gt, mask)
        .map(Score::Value)
        .unwrap_or_else(|e| Score::Unavailable(e.to_string()));
    let flip = load_png(&run.flip().join(format!("{stem}.png"))).ok().map(|map| {
        let mean = metrics::hdr_flip(&img, gt, mask)
            .map(Score::Value)
            .unwrap_or_else(|e| Score::Unavailable(e.to_string()));
        (map, mean)
    });
    let name = r.record.model.paper_name().to_string();
    let split = r.record.model.is_additive().then(|| {
        let mut cells = vec![("render".to_string(), RgbImage::from_linear(&img))];
        for (label, file) in [
            ("diffuse", run.renders().join(format!("{stem}_diffuse.png"))),
            ("specular", run.renders().join(format!("{stem}_specular.png"))),
            ("albedo", run.albedo().join(format!("view{v:03}.png"))),
        ] {
            if let Ok(p) = load_png(&file) {
                cells.push((label.to_string(), p));
            }
        }
        (name.clone(), cells)
    });
    let render =
        ModelRender { model: name, render: RgbImage::from_linear(&img), psnr_db: psnr, flip };
    Some((render, split))
}

/// The stem (`view007_light003`) of the first EXR render of a run.
fn first_render(run: &Path) -> Option<String> {
    let mut names: Vec<String> = std::fs::read_dir(RunDir::new(run).renders())
        .ok()?
        .flatten()
        .filter_map(|e| e.file_name().to_str().map(String::from))
        .filter(|n| n.ends_with(".exr"))
        .collect();
    names.sort();
    names.first().map(|n| n.trim_end_matches(".exr").to_string())
}
