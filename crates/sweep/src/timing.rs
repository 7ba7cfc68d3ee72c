//! Where a sweep's time went: the sweep's own phases (scenes, LBO features, the runs), which
//! [`crate::sweep`] writes to `<out>/timing.json`, and each run's training and evaluation
//! seconds from its `metrics.json`, summed per model. `collect` turns them into the table
//! `tables/time.md` (and the report's), and `reproduce-tables` prints it at its end.

use crate::collected::CollectedRun;
use brdf_neural::ModelKind;
use experiments::{Error, Result};
use report::{Cell, Column, ColumnGroup, Direction, Marking, Row, Table};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The wall-clock seconds of a sweep's phases.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SweepTiming {
    /// Generating or importing the scenes (and checking those kept).
    pub scenes: f64,
    /// The LBO feature tables.
    pub features: f64,
    /// Running the unfinished runs (training and evaluation, `jobs` at a time).
    pub runs: f64,
    /// The whole sweep, start to end (before the tables).
    pub total: f64,
    /// Runs at a time.
    pub jobs: usize,
    /// Runs done in this sweep (the others were finished earlier and skipped).
    pub completed: usize,
}

/// `<out>/timing.json`.
pub fn path(out: &Path) -> PathBuf {
    out.join("timing.json")
}

impl SweepTiming {
    /// Writes it to `<out>/timing.json`, atomically.
    pub fn write(&self, out: &Path) -> Result<()> {
        let json = serde_json::to_string_pretty(self)
            .map_err(|e| Error::format(path(out), e.to_string()))?;
        stdx::fs::write_atomic(&path(out), json.as_bytes())?;
        Ok(())
    }

    /// The timing of the last sweep into `out`, if it wrote one that reads.
    pub fn read(out: &Path) -> Option<SweepTiming> {
        let text = std::fs::read_to_string(path(out)).ok()?;
        serde_json::from_str(&text).ok()
    }
}

fn seconds_column(label: &str) -> Column {
    Column {
        label: label.into(),
        direction: Direction::Neutral,
        factor: 1.0,
        decimals: 0,
        signed: false,
        reference: false,
    }
}

/// The table of where the time went: the sweep's phases (when `timing` is known), then per
/// model its runs' training and evaluation seconds.
pub fn table(timing: Option<&SweepTiming>, runs: &[CollectedRun], profile: &str) -> Table {
    let mut rows = Vec::new();
    let minutes = |s: f64| Cell::value(s / 60.0);
    let blank = || Cell::NotRun;
    if let Some(t) = timing {
        let count = |n: usize| Cell::value(n as f64);
        rows.push(Row::new(
            "scenes (generate, import, verify)",
            vec![minutes(t.scenes), blank(), blank()],
        ));
        rows.push(Row::new("LBO features", vec![minutes(t.features), blank(), blank()]));
        rows.push(Row::new(
            format!("runs, {} at a time (wall)", t.jobs),
            vec![minutes(t.runs), count(t.completed), blank()],
        ));
    }
    let mut train_all = 0.0;
    let mut eval_all = 0.0;
    for model in ModelKind::ALL {
        let of: Vec<&CollectedRun> = runs.iter().filter(|r| r.config.model.kind == model).collect();
        if of.is_empty() {
            continue;
        }
        let train: f64 = of.iter().map(|r| r.train_seconds).sum();
        let eval: f64 = of.iter().map(|r| r.eval_seconds).sum();
        train_all += train;
        eval_all += eval;
        rows.push(Row::new(
            format!("training, {}", model.paper_name()),
            vec![
                minutes(train),
                Cell::value(of.len() as f64),
                Cell::value(train / of.len() as f64),
            ],
        ));
    }
    let n = runs.len().max(1) as f64;
    rows.push(Row::new(
        "training, every model",
        vec![minutes(train_all), Cell::value(runs.len() as f64), Cell::value(train_all / n)],
    ));
    rows.push(Row::new(
        "evaluation, every model",
        vec![minutes(eval_all), Cell::value(runs.len() as f64), Cell::value(eval_all / n)],
    ));
    let columns = vec![
        Column { decimals: 1, ..seconds_column("minutes") },
        seconds_column("runs"),
        seconds_column("s a run"),
    ];
    Table {
        caption: format!(
            "Where the time went. The sweep's phases are wall time; training and evaluation are \
             the runs' own seconds, summed (runs side by side shared the machine's cores, so \
             their sum exceeds the runs' wall time). Runs finished by an earlier sweep count \
             with the seconds they took then. Profile: {profile}."
        ),
        stub_header: "Phase".into(),
        groups: vec![ColumnGroup { title: String::new(), columns }],
        rows,
        marking: Marking::None,
        notes: vec![],
    }
}
