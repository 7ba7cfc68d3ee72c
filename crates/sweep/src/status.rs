//! Where a sweep's runs stand, read from their directories alone (`cargo xtask sweep-status`).
//!
//! No scheduler is asked: a run is **done** when it is evaluated, **running** while a process
//! holds its lock (the lock names the process and its host, [`stdx::lock::holder`]), **failed**
//! when its last start recorded an error ([`Failure`], `failure.json`), **interrupted** when it
//! holds a checkpoint but nothing runs it (preempted and waiting for its requeue, or killed), and
//! **pending** otherwise. The answer is therefore the same after the jobs have left `squeue`, on
//! any host that sees the sweep's folder.

use run_format::run_dir::RunDir;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Why the last start of a run failed, as `run_one` recorded it in `failure.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    /// The error.
    pub message: String,
    /// The host it ran on.
    pub host: String,
    /// The Slurm job (`<array job>_<task>`, or the job id) when it ran under Slurm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub job: Option<String>,
    /// When it failed, seconds since the Unix epoch.
    pub unix_seconds: u64,
}

impl Failure {
    /// Records `message` as the failure of `run`'s current start. Best effort: a failure to
    /// write it (a full disk) is printed, not returned, since the error itself is reported.
    pub fn record(run: &Path, message: &str) {
        let failure = Failure {
            message: message.to_string(),
            host: stdx::lock::host_name(),
            job: slurm_job(),
            unix_seconds: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
        };
        let path = RunDir::new(run).failure();
        let written = serde_json::to_vec_pretty(&failure)
            .map_err(std::io::Error::other)
            .and_then(|bytes| stdx::fs::write_atomic(&path, &bytes).map_err(|e| e.source));
        if let Err(e) = written {
            eprintln!("warning: could not record the failure in {}: {e}", path.display());
        }
    }

    /// Removes `run`'s failure record (a new start).
    pub fn clear(run: &Path) {
        let _ = std::fs::remove_file(RunDir::new(run).failure());
    }

    /// The failure recorded in `run`, if any (an unreadable record reads as a failure that
    /// says so).
    pub fn read(run: &Path) -> Option<Failure> {
        let path = RunDir::new(run).failure();
        let text = std::fs::read_to_string(&path).ok()?;
        Some(serde_json::from_str(&text).unwrap_or_else(|e| Failure {
            message: format!("unreadable failure record {}: {e}", path.display()),
            host: String::new(),
            job: None,
            unix_seconds: 0,
        }))
    }
}

/// The Slurm job of this process, from its environment.
fn slurm_job() -> Option<String> {
    let var = |name: &str| std::env::var(name).ok().filter(|v| !v.is_empty());
    match (var("SLURM_ARRAY_JOB_ID"), var("SLURM_ARRAY_TASK_ID")) {
        (Some(job), Some(task)) => Some(format!("{job}_{task}")),
        _ => var("SLURM_JOB_ID"),
    }
}

/// Where one run stands.
#[derive(Clone, Debug, PartialEq)]
pub enum RunState {
    /// Evaluated.
    Done,
    /// A process holds its lock: the holder's note (process, host, what it does).
    Running(String),
    /// Its last start failed.
    Failed(Failure),
    /// A checkpoint of this step, nothing running it.
    Interrupted(u64),
    /// Not started.
    Pending,
}

impl RunState {
    /// The state's one-word name.
    pub fn name(&self) -> &'static str {
        match self {
            RunState::Done => "done",
            RunState::Running(_) => "running",
            RunState::Failed(_) => "failed",
            RunState::Interrupted(_) => "interrupted",
            RunState::Pending => "pending",
        }
    }
}

/// Reads where `run` stands.
pub fn state(run: &Path) -> RunState {
    let dir = RunDir::new(run);
    if dir.is_complete() {
        return RunState::Done;
    }
    if let Some(holder) = stdx::lock::holder(run) {
        return RunState::Running(holder);
    }
    if let Some(failure) = Failure::read(run) {
        return RunState::Failed(failure);
    }
    match dir.checkpoint_steps().ok().and_then(|mut l| l.pop()) {
        Some((step, _)) => RunState::Interrupted(step),
        None => RunState::Pending,
    }
}

/// Every run of a sweep and where it stands.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepStatus {
    /// The runs, in the order given.
    pub runs: Vec<(PathBuf, RunState)>,
}

impl SweepStatus {
    /// Reads the state of each of `runs`.
    pub fn read(runs: &[PathBuf]) -> Self {
        SweepStatus { runs: runs.iter().map(|r| (r.clone(), state(r))).collect() }
    }

    /// How many runs are in the state named `name` ([`RunState::name`]).
    pub fn count(&self, name: &str) -> usize {
        self.runs.iter().filter(|(_, s)| s.name() == name).count()
    }

    /// The failed runs with their failures.
    pub fn failed(&self) -> impl Iterator<Item = (&PathBuf, &Failure)> {
        self.runs.iter().filter_map(|(r, s)| match s {
            RunState::Failed(f) => Some((r, f)),
            _ => None,
        })
    }

    /// The one-line summary: `27 runs: 20 done, 2 running, 1 failed, 1 interrupted, 3 pending`.
    pub fn summary(&self) -> String {
        let parts: Vec<String> = ["done", "running", "failed", "interrupted", "pending"]
            .iter()
            .map(|n| format!("{} {n}", self.count(n)))
            .collect();
        format!("{} runs: {}", self.runs.len(), parts.join(", "))
    }

    /// The summary, then one line per run that is not done (its state, and the holder, the
    /// checkpoint's step or the failure with its job and log).
    pub fn report(&self) -> String {
        let mut out = self.summary();
        out.push('\n');
        for (run, s) in &self.runs {
            let name = run.file_name().map(|n| n.to_string_lossy()).unwrap_or_default();
            let detail = match s {
                RunState::Done => continue,
                RunState::Running(holder) => holder.clone(),
                RunState::Interrupted(step) => format!("checkpoint at step {step}"),
                RunState::Pending => String::new(),
                RunState::Failed(f) => {
                    let job = f.job.as_deref().map(|j| format!("job {j}, ")).unwrap_or_default();
                    let log = RunDir::new(run).log();
                    format!("{job}{}; log {}: {}", f.host, log.display(), first_line(&f.message))
                }
            };
            out.push_str(&format!("  {:<11} {name}  {detail}\n", s.name()));
        }
        out
    }
}

fn first_line(s: &str) -> &str {
    s.lines().next().unwrap_or("")
}

/// The run directories under a sweep's `runs/` folder, sorted.
pub fn runs_under(out: &Path) -> std::io::Result<Vec<PathBuf>> {
    let root = run_format::run_dir::SweepLayout::new(out).runs();
    let mut runs = Vec::new();
    for entry in std::fs::read_dir(&root)? {
        let path = entry?.path();
        if run_format::run_dir::RunDir::new(&path).config().is_file() {
            runs.push(path);
        }
    }
    runs.sort();
    Ok(runs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_come_from_the_run_directory() {
        let t = test_support::TempDir::new("sweep-status");
        let run = t.0.join("runs/spot__brass__disney__x");
        std::fs::create_dir_all(&run).unwrap();
        std::fs::write(run.join("config.toml"), "").unwrap();
        assert_eq!(state(&run), RunState::Pending);
        let checkpoint = RunDir::new(&run).checkpoint(15);
        std::fs::create_dir_all(&checkpoint).unwrap();
        std::fs::write(checkpoint.join("state.json"), "{}").unwrap();
        assert_eq!(state(&run), RunState::Interrupted(15));
        Failure::record(&run, "scene: checksum mismatch\nmore");
        let RunState::Failed(f) = state(&run) else { panic!("{:?}", state(&run)) };
        assert_eq!(f.message, "scene: checksum mismatch\nmore");
        let lock = stdx::lock::DirLock::acquire(&run, "training").unwrap();
        assert!(matches!(state(&run), RunState::Running(h) if h.contains("(training)")));
        drop(lock);
        let status = SweepStatus::read(&runs_under(&t.0).unwrap());
        assert_eq!(
            status.summary(),
            "1 runs: 0 done, 0 running, 1 failed, 0 interrupted, 0 pending"
        );
        let report = status.report();
        assert!(report.contains("failed") && report.contains("checksum mismatch"), "{report}");
        assert!(!report.contains("more"), "one line per run: {report}");
        Failure::clear(&run);
        assert_eq!(state(&run), RunState::Interrupted(15));
    }
}
