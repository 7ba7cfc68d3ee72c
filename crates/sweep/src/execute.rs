//! Running a sweep: scenes first (generated once, kept when complete), then the LBO tables of
//! their meshes (so that parallel runs do not solve the same eigenproblem twice), then the
//! runs, in this process or as `--jobs N` child processes, or written as one shell command per
//! run for a cluster scheduler (`--emit-jobs`).
//!
//! A run is done when its `metrics.json` holds test metrics and its weights are exported;
//! [`run_one`] otherwise fits (resuming from the last checkpoint), evaluates and exports it. A killed sweep therefore resumes with
//! nothing lost but the steps since the last checkpoint.

use super::heartbeat::{Heartbeat, ProgressLines};
use super::plan::{self, Purpose, RunInfo, RunSpec, SceneSource, SceneSpec};
use super::profile::{CaptureSource, SweepProfile, resolve_mesh};
use super::shell;
use super::timing::SweepTiming;
use brdf_neural::device::Backend;
use dataset_merl::generate_scene;
use experiments::eval::EvalOptions;
use experiments::train::fit_and_keep;
use experiments::{Error, FitOptions, FitOutcome, Result};
use indicatif::ProgressBar;
use run_format::ComputeSettings;
use run_format::config::SpatialKind;
use run_format::held_run::{HeldRun, RunResults};
use run_format::run_dir::{RunDir, SweepLayout};
use scene::SceneDataset;
use scene::{MaterialSpec, SceneConfig, SceneSettings};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// How runs are executed.
#[derive(Clone, Debug, PartialEq)]
pub enum Execution {
    /// One after the other in this process, with progress bars, on this backend and with these
    /// compute settings.
    InProcess(RunOn),
    /// `jobs` child processes at a time, each `<program> <args...> <run dir>` (the arguments
    /// carry the backend, e.g. `run-one --backend wgpu`).
    Children {
        /// Concurrent children.
        jobs: usize,
        /// The program and leading arguments that run one run directory.
        command: Vec<String>,
    },
    /// Submit the unfinished runs to Slurm as job arrays with a collect job ([`crate::slurm`]).
    Slurm {
        /// The xtask executable the tasks run (absolute).
        program: String,
        /// The backend of the runs.
        backend: Backend,
        /// The LPIPS weights of the runs' evaluations when their `[eval]` names none.
        lpips_weights: PathBuf,
        /// The submission's settings.
        options: crate::slurm::SlurmOptions,
    },
    /// Write the commands to this file (one line per unfinished run) and run nothing.
    Emit {
        /// The job file.
        file: PathBuf,
        /// The program and leading arguments that run one run directory.
        command: Vec<String>,
    },
}

/// What the runs a process executes train on: the burn backend, how they compute beyond their
/// configuration ([`ComputeSettings`], the CLI's environment overrides), and the LPIPS weight
/// file their evaluations read (the process's place, `experiments::places`).
#[derive(Clone, Debug, PartialEq)]
pub struct RunOn {
    /// The backend of the runs.
    pub backend: Backend,
    /// The compute settings of the runs.
    pub compute: ComputeSettings,
    /// The LPIPS weights of the runs' evaluations when their `[eval]` names none.
    pub lpips_weights: PathBuf,
}

impl Default for RunOn {
    /// The CPU backend, the default compute settings and places.
    fn default() -> Self {
        RunOn {
            backend: Backend::default(),
            compute: ComputeSettings::default(),
            lpips_weights: experiments::places::Places::default().lpips_weights(),
        }
    }
}

/// What a sweep did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepSummary {
    /// Scenes generated now / found complete.
    pub scenes_generated: usize,
    /// Scenes that were complete already.
    pub scenes_kept: usize,
    /// Run directories of the sweep, in plan order.
    pub runs: Vec<PathBuf>,
    /// Runs finished before this sweep started.
    pub skipped: usize,
    /// Runs completed now.
    pub completed: usize,
    /// Runs that failed: (directory, message).
    pub failed: Vec<(PathBuf, String)>,
    /// Commands written (`Emit`).
    pub emitted: usize,
    /// The Slurm submission (`Slurm`).
    pub submission: Option<crate::slurm::Submission>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// The environment variable through which a `--jobs` child learns its parent's process id.
pub const PARENT_PID_VAR: &str = "NEURAL_BRDF_SWEEP_PID";

/// In a `--jobs` child (one started with [`PARENT_PID_VAR`] set): ends this process within half
/// a second of its parent sweep's end, even a SIGKILL, so that killing a sweep stops its runs
/// (their files are written atomically and resume from the last checkpoint). Does nothing in
/// any other process.
pub fn exit_with_parent() {
    #[cfg(unix)]
    {
        let Some(parent) = std::env::var(PARENT_PID_VAR).ok().and_then(|v| v.parse::<u32>().ok())
        else {
            return;
        };
        std::thread::spawn(move || {
            loop {
                if std::os::unix::process::parent_id() != parent {
                    eprintln!("the sweep (process {parent}) has ended: stopping this run");
                    std::process::exit(143);
                }
                std::thread::sleep(std::time::Duration::from_millis(250));
            }
        });
    }
}

/// Whether a run directory holds a complete run: evaluated, its weights exported.
pub fn is_done(run: &Path) -> bool {
    RunDir::new(run).is_complete()
}

/// How [`run_one`] ended without an error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunEnd {
    /// Trained and evaluated (or found so).
    Done,
    /// Stopped by a signal for a requeue ([`experiments::interrupt`]): a checkpoint of this
    /// step is written (`None`: training had ended; the evaluation is left to the next start).
    Interrupted(Option<u64>),
}

/// Fits (resuming), evaluates and exports one prepared run directory, in that order, holding
/// its lock throughout. The configuration is read once; a run trained here is evaluated with
/// the model and scene training hands over, on the backend it trained on; a stage whose
/// results the directory already holds is not run again.
///
/// A failure is also recorded in the run directory ([`crate::status::Failure`], what
/// `sweep-status` and a cluster's collect job list); the next start clears it. A run another
/// process works in is refused without a record (that process's start is the one that counts).
pub fn run_one(run: &Path, progress: bool, on: &RunOn) -> Result<RunEnd> {
    if is_done(run) {
        return Ok(RunEnd::Done);
    }
    let dir = RunDir::new(run);
    let held = dir.hold("training, evaluating")?;
    crate::status::Failure::clear(run);
    let end = fit_evaluate_export(&held, progress, on);
    if let Err(e) = &end {
        crate::status::Failure::record(run, &e.to_string());
    }
    end
}

/// The stages of a held run: fit, evaluate, export.
fn fit_evaluate_export(held: &HeldRun, progress: bool, on: &RunOn) -> Result<RunEnd> {
    let backend = on.backend;
    let options =
        FitOptions { progress, backend, compute: on.compute.clone(), ..Default::default() };
    let (fitted, metrics) = match fit_and_keep(None, held, options)? {
        (FitOutcome::Stopped(step), _) if experiments::interrupt::requested() => {
            return Ok(RunEnd::Interrupted(Some(step)));
        }
        (FitOutcome::Stopped(step), _) => {
            return Err(Error::format(held.path(), format!("training stopped at step {step}")));
        }
        // The grace period after the signal is too short for an evaluation: the next start
        // evaluates the weights just written.
        _ if experiments::interrupt::requested() => return Ok(RunEnd::Interrupted(None)),
        (FitOutcome::AlreadyFinished(metrics) | FitOutcome::Finished { metrics, .. }, handoff) => {
            let handoff = handoff.ok_or_else(|| Error::format(held.path(), "no trained model"))?;
            (handoff.into_fitted(held.dir(), backend)?, metrics)
        }
    };
    // A run evaluated by an earlier start keeps its evaluation; export follows either way, and
    // both are written together, the evaluation's `metrics.json` last.
    let evaluation = match held.is_evaluated() {
        true => None,
        false => {
            let options = EvalOptions { progress, lpips_weights: on.lpips_weights.clone() };
            Some(experiments::eval::evaluate(&fitted, held, metrics, &options, Instant::now())?)
        }
    };
    let portable = Some(experiments::portable::fitted_files(&fitted)?);
    held.write_results(&RunResults { evaluation, portable })?;
    Ok(RunEnd::Done)
}

/// Generates the profile's semi-synthetic scenes and imports its captures (within `limits`)
/// under `scenes_dir` (complete ones are kept).
pub fn prepare_scenes(
    profile: &SweepProfile,
    scenes: &[SceneSpec],
    (scenes_dir, data_root): (&Path, &Path),
    limits: &stdx::Limits,
    summary: &mut SweepSummary,
) -> Result<Vec<PathBuf>> {
    let d = &profile.data;
    let settings = SceneSettings::with_counts(d.size, d.views, d.lights);
    let mut dirs = Vec::new();
    for (i, s) in scenes.iter().enumerate() {
        let out = scenes_dir.join(&s.name);
        eprintln!("scene {}/{}: {}", i + 1, scenes.len(), s.name);
        let skipped = match &s.source {
            SceneSource::Generated { mesh, material } => {
                let config = SceneConfig {
                    mesh: resolve_mesh(mesh, data_root)?,
                    material: MaterialSpec::Merl { name: material.clone() },
                    seed: d.seed,
                    settings: settings.clone(),
                    merl_dir: None,
                };
                generate_scene(&config, &out, true)?.skipped
            }
            SceneSource::Captured(capture) => import_capture(capture, data_root, &out, limits)?,
        };
        if skipped {
            summary.scenes_kept += 1;
        } else {
            summary.scenes_generated += 1;
        }
        dirs.push(out);
    }
    Ok(dirs)
}

/// Imports a real capture into the scene directory `out` with the importer's defaults (the
/// paper's 30 training and 12 test lights a view) within `limits`; a complete scene already
/// there is kept (returns `true`).
fn import_capture(
    capture: &CaptureSource,
    data_root: &Path,
    out: &Path,
    limits: &stdx::Limits,
) -> Result<bool> {
    if SceneDataset::open(out).is_ok() {
        return Ok(true);
    }
    let src = capture.find(data_root)?;
    let report = if src.join("view_01").is_dir() {
        let o = dataset_diligent::MultiViewOptions {
            progress: true,
            limits: *limits,
            ..Default::default()
        };
        dataset_diligent::import_multi_view(&src, out, &o)
    } else {
        let o = dataset_diligent::SingleViewOptions {
            progress: true,
            limits: *limits,
            ..Default::default()
        };
        dataset_diligent::import_single_view(&src, out, &o)
    }
    .map_err(|e| Error::format(&src, format!("importing the capture: {e}")))?;
    for w in &report.warnings {
        eprintln!("  warning: {w}");
    }
    Ok(false)
}

/// Creates (or finds) the directory of every planned run: `config.toml` with the scene path,
/// and `run.json`.
pub fn prepare_runs(
    specs: &[RunSpec],
    scenes: &[SceneSpec],
    scene_dirs: &[PathBuf],
    runs_dir: &Path,
) -> Result<Vec<PathBuf>> {
    let mut checksums = Vec::new();
    for dir in scene_dirs {
        let path = dir.join(scene::MANIFEST_FILE);
        checksums.push(scene::Manifest::read(&path)?.checksum);
    }
    let mut dirs = Vec::new();
    for spec in specs {
        let id = plan::run_id(&spec.config, &checksums[spec.scene])?;
        let object = &scenes[spec.scene].name;
        let dir = RunDir::new(runs_dir.join(plan::run_dir_name(object, &spec.config, &id)));
        let mut purposes: Vec<Purpose> =
            plan::read_info(&dir).map(|i| i.purposes).unwrap_or_default();
        for p in &spec.purposes {
            if !purposes.contains(p) {
                purposes.push(*p);
            }
        }
        let info = RunInfo {
            id,
            object: object.clone(),
            dataset: scenes[spec.scene].dataset(Some(&scene_dirs[spec.scene])),
            purposes,
            code_version: plan::CODE_VERSION.into(),
        };
        let mut config = spec.config.clone();
        config.scene = Some(
            std::path::absolute(&scene_dirs[spec.scene])
                .map_err(|e| Error::io(&scene_dirs[spec.scene], e))?,
        );
        let config_path = dir.config();
        if !config_path.is_file() {
            stdx::fs::write_atomic(&config_path, config.to_toml()?.as_bytes())?;
        }
        plan::write_info(&dir, &info)?;
        dirs.push(dir.path().to_path_buf());
    }
    Ok(dirs)
}

/// Computes the LBO tables of every scene's mesh once (cached under `cache`), each solve's
/// factor within `lbo_memory` bytes (`None`: the solver's default budget).
pub fn prepare_features(
    specs: &[RunSpec],
    scene_dirs: &[PathBuf],
    cache: &Path,
    lbo_memory: Option<u64>,
) -> Result<()> {
    let mut seen = Vec::new();
    for spec in specs {
        if spec.config.features.spatial != SpatialKind::Lbo {
            continue;
        }
        let key = (spec.scene, format!("{:?}", spec.config.features.lbo));
        if seen.contains(&key) {
            continue;
        }
        seen.push(key);
        let scene = SceneDataset::open(&scene_dirs[spec.scene])?;
        experiments::data::lbo_table(&scene, &spec.config.features, cache, lbo_memory)?;
    }
    Ok(())
}

/// Executes the unfinished runs among `dirs`.
pub fn execute(
    dirs: &[PathBuf],
    how: &Execution,
    progress: &ProgressLines,
    summary: &mut SweepSummary,
) -> Result<()> {
    let mut todo: Vec<&PathBuf> = dirs.iter().filter(|d| !is_done(d)).collect();
    summary.skipped = dirs.len() - todo.len();
    if let Execution::Children { jobs, .. } = how
        && *jobs > 1
    {
        longest_first(&mut todo);
    }
    let bar = stdx::progress::bar(todo.len() as u64, "runs", "sweep", true);
    let costs = || -> Vec<(PathBuf, f64)> {
        todo.iter().map(|d| ((*d).clone(), expected_cost(d))).collect()
    };
    let lines = match how {
        Execution::InProcess(_) => Heartbeat::start(costs(), 1, progress),
        Execution::Children { jobs, .. } => Heartbeat::start(costs(), *jobs, progress),
        Execution::Emit { .. } | Execution::Slurm { .. } => {
            Heartbeat::start(Vec::new(), 1, progress)
        }
    };
    match how {
        Execution::InProcess(on) => run_in_process(&todo, on, (&bar, &lines), summary),
        Execution::Children { jobs, command } => {
            run_children(&todo, (*jobs, command.as_slice()), (&bar, &lines), summary)?
        }
        Execution::Emit { file, command } => {
            emit_jobs(&todo, (file.as_path(), command.as_slice()), summary)?
        }
        // Submitted by `sweep`, which knows the output directory.
        Execution::Slurm { .. } => {}
    }
    bar.finish_and_clear();
    Ok(())
}

/// Orders runs by their expected training time, longest first (a stable sort: runs of one cost
/// keep the plan's order), so that several at a time end together instead of one core
/// finishing a long run alone. A run whose configuration does not read keeps its place at the
/// end, where its own start reports the fault.
fn longest_first(todo: &mut [&PathBuf]) {
    let mut keyed: Vec<(f64, &PathBuf)> = todo.iter().map(|d| (expected_cost(d), *d)).collect();
    keyed.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (slot, (_, d)) in todo.iter_mut().zip(keyed) {
        *slot = d;
    }
}

/// A run's evaluation in the cost model's seconds: 9 to 25 s a run measured on 2-core CPUs
/// (2026-12-07), which the training estimate leaves out; it weighs in the short runs' time left.
const EVALUATION_SECONDS: f64 = 20.0;

/// A run's expected seconds on the CPU by the sweep's cost model
/// (`slurm::requests::expected_seconds`, plus its evaluation), 0 where its configuration does
/// not read.
fn expected_cost(d: &Path) -> f64 {
    RunDir::new(d)
        .read_config()
        .map(|c| crate::slurm::requests::expected_seconds(&c, Backend::Flex) + EVALUATION_SECONDS)
        .unwrap_or(0.0)
}

/// Runs `todo` one after the other in this process.
fn run_in_process(
    todo: &[&PathBuf],
    on: &RunOn,
    (bar, lines): (&ProgressBar, &Heartbeat),
    summary: &mut SweepSummary,
) {
    for d in todo {
        bar.set_message(short(d));
        lines.started(d);
        match bar.suspend(|| run_one(d, true, on)) {
            Ok(RunEnd::Interrupted(_)) => {
                summary.failed.push(((*d).clone(), "interrupted by a signal".into()));
                lines.finished(d, false);
            }
            Ok(RunEnd::Done) => {
                summary.completed += 1;
                lines.finished(d, true);
            }
            Err(e) => {
                summary.failed.push(((*d).clone(), e.to_string()));
                lines.finished(d, false);
            }
        }
        bar.inc(1);
    }
}

/// Runs `todo` as child processes of `command`, `jobs` at a time, each writing its run's log.
fn run_children(
    todo: &[&PathBuf],
    (jobs, command): (usize, &[String]),
    (bar, lines): (&ProgressBar, &Heartbeat),
    summary: &mut SweepSummary,
) -> Result<()> {
    let (program, args) =
        command.split_first().ok_or_else(|| Error::config("jobs", "no command"))?;
    let mut queue = todo.iter();
    let mut running: Vec<(PathBuf, std::process::Child)> = Vec::new();
    loop {
        while running.len() < jobs.max(1) {
            let Some(d) = queue.next() else { break };
            let log = RunDir::new(d.as_path()).log();
            std::fs::create_dir_all(d).map_err(|e| Error::io(d, e))?;
            let file = std::fs::File::create(&log).map_err(|e| Error::io(&log, e))?;
            let err = file.try_clone().map_err(|e| Error::io(&log, e))?;
            let child = Command::new(program)
                .args(args)
                .env(PARENT_PID_VAR, std::process::id().to_string())
                .arg(d.as_path())
                .stdout(file)
                .stderr(err)
                .spawn()
                .map_err(|e| Error::io(Path::new(program), e))?;
            lines.started(d);
            running.push(((*d).clone(), child));
        }
        if running.is_empty() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(200));
        let mut i = 0;
        while i < running.len() {
            if let Some(status) =
                running[i].1.try_wait().map_err(|e| Error::io(&running[i].0, e))?
            {
                let (d, _) = running.swap_remove(i);
                let ok = status.success() && is_done(&d);
                lines.finished(&d, ok);
                if ok {
                    summary.completed += 1;
                } else {
                    let log = RunDir::new(&d).log();
                    summary.failed.push((
                        d.clone(),
                        format!("{status}: {}; see {}", last_error(&log), log.display()),
                    ));
                }
                bar.inc(1);
            } else {
                i += 1;
            }
        }
        bar.set_message(format!("{} running", running.len()));
    }
    Ok(())
}

/// Writes one shell line a run of `todo` (`command` and the run's absolute path) to `file`.
fn emit_jobs(
    todo: &[&PathBuf],
    (file, command): (&Path, &[String]),
    summary: &mut SweepSummary,
) -> Result<()> {
    let mut text = String::new();
    for d in todo {
        let abs = std::path::absolute(d).map_err(|e| Error::io(d, e))?;
        let mut parts: Vec<String> = command.iter().map(|c| shell::quote(c)).collect();
        parts.push(shell::quote(&abs.display().to_string()));
        text.push_str(&parts.join(" "));
        text.push('\n');
    }
    stdx::fs::write_atomic(file, text.as_bytes())?;
    summary.emitted = todo.len();
    Ok(())
}

/// The error a child printed last (the lines from its last `Error:` on, joined), or a note that
/// its log has none (a child killed by a signal).
fn last_error(log: &Path) -> String {
    let text = std::fs::read_to_string(log).unwrap_or_default();
    let lines: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    match lines.iter().rposition(|l| l.starts_with("Error:")) {
        Some(i) => lines[i..]
            .iter()
            .filter(|l| *l != &"Caused by:" && !l.starts_with("Stack backtrace"))
            .take(6)
            .copied()
            .collect::<Vec<_>>()
            .join(" / "),
        None if lines.is_empty() => "its log is empty (a full disk, or killed)".into(),
        None => "no error message in its log (killed?)".into(),
    }
}

fn short(d: &Path) -> String {
    d.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

/// Plans, prepares and executes a whole sweep into `out`, with the default [`SweepSettings`].
pub fn sweep(
    profile: &SweepProfile,
    out: &Path,
    data_root: &Path,
    how: &Execution,
) -> Result<SweepSummary> {
    sweep_with(profile, out, data_root, how, &SweepSettings::default())
}

/// How a sweep reports its progress and prepares its features, beyond its profile: the
/// command line's settings (environment variables override them there, and only there).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepSettings {
    /// When and how often the plain progress lines are printed.
    pub progress: ProgressLines,
    /// The memory the LBO eigensolver's Cholesky factor may take, in bytes (`None`: three
    /// quarters of the memory available when a solve starts).
    pub lbo_memory: Option<u64>,
    /// What the importers of the profile's captures accept from their files.
    pub limits: stdx::Limits,
}

/// [`sweep`] with `settings`.
pub fn sweep_with(
    profile: &SweepProfile,
    out: &Path,
    data_root: &Path,
    how: &Execution,
    settings: &SweepSettings,
) -> Result<SweepSummary> {
    let start = Instant::now();
    let mut summary = SweepSummary::default();
    let (profile, notes) = profile.clone().with_captures_found(data_root)?;
    for n in &notes {
        eprintln!("{n}");
    }
    let profile = &profile;
    let layout = SweepLayout::new(out);
    let (scenes_dir, runs_dir, cache) = (layout.scenes(), layout.runs(), layout.cache());
    let scenes = plan::scenes(profile);
    let specs = plan::runs(profile)?;
    let scene_dirs =
        prepare_scenes(profile, &scenes, (&scenes_dir, data_root), &settings.limits, &mut summary)?;
    let mut timing = SweepTiming { scenes: start.elapsed().as_secs_f64(), ..Default::default() };
    eprintln!("features: LBO tables of {} scene(s)", scene_dirs.len());
    let features = Instant::now();
    prepare_features(&specs, &scene_dirs, &cache, settings.lbo_memory)?;
    timing.features = features.elapsed().as_secs_f64();
    summary.runs = prepare_runs(&specs, &scenes, &scene_dirs, &runs_dir)?;
    let runs = Instant::now();
    execute(&summary.runs.clone(), how, &settings.progress, &mut summary)?;
    if let Execution::Slurm { program, backend, lpips_weights, options } = how {
        let todo: Vec<PathBuf> = summary.runs.iter().filter(|d| !is_done(d)).cloned().collect();
        // Nothing left to run: no job is submitted, and the tables are made here.
        if !todo.is_empty() {
            let first = crate::slurm::FirstSubmission {
                profile: &profile.name,
                program,
                backend: backend.name(),
                lpips_weights,
            };
            summary.submission =
                Some(crate::slurm::submit(out, &summary.runs, &todo, Some(first), options)?);
        }
    }
    summary.seconds = start.elapsed().as_secs_f64();
    if !matches!(how, Execution::Emit { .. } | Execution::Slurm { .. }) {
        timing.runs = runs.elapsed().as_secs_f64();
        timing.total = summary.seconds;
        timing.jobs = match how {
            Execution::Children { jobs, .. } => *jobs,
            _ => 1,
        };
        timing.completed = summary.completed;
        // Where the time went is a report, not a result: a failed write (a full disk) warns
        // and leaves the previous timing whole.
        if let Err(e) = timing.write(out) {
            eprintln!("warning: the sweep's timing was not written: {e}");
        }
    }
    Ok(summary)
}
