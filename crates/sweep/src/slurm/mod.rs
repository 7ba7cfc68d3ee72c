//! A sweep on a Slurm cluster: job arrays that requeue, resume and collect
//! (`cargo xtask reproduce-tables --slurm`; docs/guide.md, "On a cluster").
//!
//! The login node prepares what every task shares before anything is submitted: the scenes,
//! the LBO tables in the sweep's cache and the run directories ([`crate::execute`]). The
//! unfinished runs are then grouped by their [`requests`] (one model's runs ask for the same),
//! each group split into arrays of at most the cluster's `MaxArraySize` tasks, and submitted
//! with one collect job that starts when they have all ended (`afterany`) and runs
//! `slurm-collect`: the tables, the report, the failed runs with their jobs and logs, and the one
//! command that resubmits those (`slurm-resubmit`).
//!
//! Everything is recorded in `<out>/slurm/sweep.json` ([`SlurmSweep`]) with the scripts and
//! task lists of each submission in `<out>/slurm/submit-NNN/`. Where a run stands is read from
//! its directory ([`crate::status`]), never from the scheduler.
//!
//! Shared-file-system safety: every task writes only inside its own run directory (atomically,
//! under the run's lock); the scenes and LBO tables are written before the first task starts
//! and only read afterwards; a scene's noise ceiling in the cache is written by the one
//! evaluation that holds its lock; `sweep.json` and the scripts are written by the submitting
//! process alone. The run locks are `flock` locks, which hold across hosts where the file system
//! supports them (NFSv4, NFSv3 with its lock manager, Lustre mounted with `flock`).

pub mod requests;
pub mod script;

use crate::status::{RunState, SweepStatus};
use experiments::{Error, Result};
use requests::{RequestSettings, Requests};
use run_format::run_dir::{RunDir, SweepLayout};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The user's settings of a submission (`reproduce-tables --slurm` flags), kept for
/// resubmissions.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SlurmOptions {
    /// `--partition`.
    pub partition: Option<String>,
    /// `--account`.
    pub account: Option<String>,
    /// `--qos`.
    pub qos: Option<String>,
    /// Extra `#SBATCH` options, one each (`--constraint=avx512`, with or without the
    /// `#SBATCH` prefix).
    pub extra: Vec<String>,
    /// CPUs, memory and the time cap of the tasks.
    pub requests: RequestSettings,
    /// The largest array (default: the cluster's `MaxArraySize`, from `scontrol show config`).
    pub max_array_size: Option<usize>,
    /// Write the scripts and print the `sbatch` commands without submitting.
    #[serde(skip)]
    pub dry_run: bool,
}

impl SlurmOptions {
    /// The options every script carries, as `--key=value` words.
    fn sbatch_options(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (key, value) in
            [("partition", &self.partition), ("account", &self.account), ("qos", &self.qos)]
        {
            if let Some(v) = value {
                out.push(format!("--{key}={v}"));
            }
        }
        for e in &self.extra {
            let e = e.trim();
            out.push(e.strip_prefix("#SBATCH").unwrap_or(e).trim().to_string());
        }
        out
    }
}

/// One submitted (or, dry, written) array.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArrayJob {
    /// Slurm's job id (`None` for a dry run).
    pub job: Option<String>,
    /// The job script.
    pub script: PathBuf,
    /// The task list: line `i + 1` is task `i`'s run directory.
    pub tasks: PathBuf,
    /// Its tasks.
    pub count: usize,
    /// The models of its runs.
    pub models: Vec<String>,
    /// What each task asks for.
    pub requests: Requests,
}

/// One submission: arrays and their collect job.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Submission {
    /// 1, 2, ... (the folder `submit-NNN`).
    pub number: usize,
    /// The arrays.
    pub arrays: Vec<ArrayJob>,
    /// The collect job's id (`None` for a dry run).
    pub collect_job: Option<String>,
    /// The collect job's script.
    pub collect_script: PathBuf,
    /// Whether it was only written (`--dry-run`).
    pub dry_run: bool,
}

/// `<out>/slurm/sweep.json`: a sweep submitted to Slurm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlurmSweep {
    /// The profile's name (the tables' captions).
    pub profile: String,
    /// The xtask executable the tasks run (absolute).
    pub program: String,
    /// `--backend` of the runs.
    pub backend: String,
    /// `--lpips-weights` of the runs (absolute; `None` in a record of an older version: the
    /// tasks' own default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lpips_weights: Option<PathBuf>,
    /// Every run of the sweep (absolute), finished or not: the collect job's tables.
    pub runs: Vec<PathBuf>,
    /// The user's settings.
    pub options: SlurmOptions,
    /// The submissions so far.
    pub submissions: Vec<Submission>,
}

impl SlurmSweep {
    /// The record's path in the sweep `out`.
    pub fn path(out: &Path) -> PathBuf {
        SweepLayout::new(out).slurm().join("sweep.json")
    }

    /// Reads the record of the sweep `out`.
    pub fn read(out: &Path) -> Result<Self> {
        let path = Self::path(out);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            Error::format(
                &path,
                format!("{e}: not a sweep submitted to Slurm (`reproduce-tables --slurm`)"),
            )
        })?;
        serde_json::from_str(&text).map_err(|e| Error::format(&path, e.to_string()))
    }

    fn write(&self, out: &Path) -> Result<()> {
        let text =
            serde_json::to_string_pretty(self).map_err(|e| Error::format(out, e.to_string()))?;
        stdx::fs::write_atomic(&Self::path(out), text.as_bytes())?;
        Ok(())
    }

    /// Where the sweep's runs stand.
    pub fn status(&self) -> SweepStatus {
        SweepStatus::read(&self.runs)
    }
}

/// What a sweep's first submission records: the profile's name and what its tasks run.
#[derive(Clone, Copy, Debug)]
pub struct FirstSubmission<'a> {
    /// The profile's name.
    pub profile: &'a str,
    /// The xtask executable the tasks run (absolute).
    pub program: &'a str,
    /// `--backend` of the runs.
    pub backend: &'a str,
    /// `--lpips-weights` of the runs (made absolute).
    pub lpips_weights: &'a Path,
}

/// Submits `todo` (unfinished runs among `all`, the sweep's runs) as a new submission of the
/// sweep `out`, and records it; what the tasks run is recorded on the first.
pub fn submit(
    out: &Path,
    all: &[PathBuf],
    todo: &[PathBuf],
    first: Option<FirstSubmission>,
    options: &SlurmOptions,
) -> Result<Submission> {
    let mut sweep = sweep_record(out, all, first, options)?;
    let number = sweep.submissions.iter().map(|s| s.number).max().unwrap_or(0) + 1;
    let layout = SweepLayout::new(out);
    let dir = layout.slurm().join(format!("submit-{number:03}"));
    let logs = std::path::absolute(layout.slurm().join("logs")).map_err(|e| Error::io(out, e))?;
    std::fs::create_dir_all(&logs).map_err(|e| Error::io(&logs, e))?;
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let dir = std::path::absolute(&dir).map_err(|e| Error::io(&dir, e))?;
    let backend = brdf_neural::device::parse_backend(&sweep.backend)
        .map_err(|e| Error::config("backend", e.to_string()))?;
    let sbatch_options = options.sbatch_options();
    let name = format!("nbrdf-{}", sweep.profile);
    let settings = script::ScriptSettings {
        name: &name,
        program: &sweep.program,
        backend: backend.name(),
        lpips_weights: sweep.lpips_weights.as_deref(),
        options: &sbatch_options,
        logs: &logs,
    };
    let max = match options.max_array_size {
        Some(m) => m.max(1),
        None => max_array_size(options.dry_run)?,
    };
    let mut arrays = Vec::new();
    for (k, (requests, runs)) in groups(todo, backend, &options.requests)?.into_iter().enumerate() {
        for (c, chunk) in runs.chunks(max).enumerate() {
            let id = format!(
                "{}{}",
                k + 1,
                if runs.len() > max { format!("-{}", c + 1) } else { String::new() }
            );
            let (models, tasks) = (models_of(chunk), dir.join(format!("tasks-{id}.txt")));
            write_task_list(&tasks, chunk)?;
            let label = match models.as_slice() {
                [one] => one.clone(),
                [first, rest @ ..] => format!("{first}-and-{}-more", rest.len()),
                [] => "runs".into(),
            };
            let text = script::array_script(&settings, &label, chunk.len(), &tasks, &requests);
            let path = dir.join(format!("array-{id}.sh"));
            stdx::fs::write_atomic(&path, text.as_bytes())?;
            let job = sbatch(&path, &[], options.dry_run)?;
            arrays.push(ArrayJob {
                job,
                script: path,
                tasks,
                count: chunk.len(),
                models,
                requests: requests.clone(),
            });
        }
    }
    let out_abs = std::path::absolute(out).map_err(|e| Error::io(out, e))?;
    let collect_script = dir.join("collect.sh");
    stdx::fs::write_atomic(
        &collect_script,
        script::collect_script(&settings, &out_abs).as_bytes(),
    )?;
    let ids: Vec<&str> = arrays.iter().filter_map(|a| a.job.as_deref()).collect();
    let dependency = if ids.is_empty() {
        Vec::new()
    } else {
        vec![format!("--dependency=afterany:{}", ids.join(":"))]
    };
    let collect_job = sbatch(&collect_script, &dependency, options.dry_run)?;
    let submission =
        Submission { number, arrays, collect_job, collect_script, dry_run: options.dry_run };
    sweep.submissions.push(submission.clone());
    sweep.write(out)?;
    Ok(submission)
}

/// The sweep's record with this submission's runs and options: the one on disk (an unreadable
/// one is an error, not replaced: its job ids would be lost), or a new one for a first
/// submission (`first`).
fn sweep_record(
    out: &Path,
    all: &[PathBuf],
    first: Option<FirstSubmission>,
    options: &SlurmOptions,
) -> Result<SlurmSweep> {
    let recorded = SlurmSweep::path(out).exists();
    let mut sweep = match SlurmSweep::read(out) {
        // A record that cannot be read is not replaced: its job ids would be lost.
        Err(e) if recorded => return Err(e),
        Ok(mut s) => {
            if !all.is_empty() {
                s.runs = absolute_all(all)?;
            }
            if first.is_some() {
                s.options = options.clone();
            }
            s
        }
        Err(_) => {
            let f = first.ok_or_else(|| {
                Error::format(SlurmSweep::path(out), "no submission recorded to resubmit")
            })?;
            SlurmSweep {
                profile: f.profile.into(),
                program: f.program.into(),
                backend: f.backend.into(),
                lpips_weights: None,
                runs: absolute_all(all)?,
                options: options.clone(),
                submissions: Vec::new(),
            }
        }
    };
    if let Some(f) = first {
        (sweep.program, sweep.backend) = (f.program.into(), f.backend.into());
        let lpips =
            std::path::absolute(f.lpips_weights).map_err(|e| Error::io(f.lpips_weights, e))?;
        sweep.lpips_weights = Some(lpips);
    }
    Ok(sweep)
}

/// Writes the absolute paths of `runs`, one a line: task i runs line i + 1.
fn write_task_list(tasks: &Path, runs: &[PathBuf]) -> Result<()> {
    let mut list = String::new();
    for r in runs {
        list.push_str(&std::path::absolute(r).map_err(|e| Error::io(r, e))?.display().to_string());
        list.push('\n');
    }
    Ok(stdx::fs::write_atomic(tasks, list.as_bytes())?)
}

fn absolute_all(runs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    runs.iter().map(|r| std::path::absolute(r).map_err(|e| Error::io(r, e))).collect()
}

/// The runs grouped by their requests, in first-seen order.
fn groups(
    runs: &[PathBuf],
    backend: brdf_neural::device::Backend,
    settings: &RequestSettings,
) -> Result<Vec<(Requests, Vec<PathBuf>)>> {
    let mut out: Vec<(Requests, Vec<PathBuf>)> = Vec::new();
    for run in runs {
        let config = RunDir::new(run).read_config()?;
        let bytes = config.scene.as_deref().map(scene_bytes).unwrap_or(0);
        let r = requests::requests(&config, bytes, backend, settings);
        match out.iter_mut().find(|(q, _)| *q == r) {
            Some((_, list)) => list.push(run.clone()),
            None => out.push((r, vec![run.clone()])),
        }
    }
    Ok(out)
}

/// The bytes of a scene's data files, from its manifest (0 when unreadable: the task's own
/// error will name it).
fn scene_bytes(scene: &Path) -> u64 {
    scene::Manifest::read(&scene.join(scene::MANIFEST_FILE))
        .map(|m| m.files.iter().map(|f| f.bytes).sum())
        .unwrap_or(0)
}

/// The model names of these runs (`run.json` directory names: `<object>__<model>__...`).
fn models_of(runs: &[PathBuf]) -> Vec<String> {
    let mut models: Vec<String> = Vec::new();
    for r in runs {
        let name = r.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let model = name.split("__").nth(2).unwrap_or("run").to_string();
        if !models.contains(&model) {
            models.push(model);
        }
    }
    models
}

/// The cluster's `MaxArraySize` (the largest array has that many tasks, ids 0 to size - 1);
/// Slurm's default, 1001, for a dry run without `scontrol`.
fn max_array_size(dry_run: bool) -> Result<usize> {
    let output = Command::new("scontrol").args(["show", "config"]).output();
    let text = match output {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout).into_owned(),
        _ if dry_run => return Ok(1001),
        Ok(o) => {
            return Err(Error::config(
                "slurm",
                format!(
                    "`scontrol show config` failed: {}",
                    String::from_utf8_lossy(&o.stderr).trim()
                ),
            ));
        }
        Err(e) => {
            return Err(Error::config(
                "slurm",
                format!(
                    "scontrol: {e} (is this a Slurm login node? --dry-run writes the scripts without submitting)"
                ),
            ));
        }
    };
    Ok(parse_max_array_size(&text).unwrap_or(1001))
}

/// `MaxArraySize = N` from `scontrol show config`.
fn parse_max_array_size(config: &str) -> Option<usize> {
    config.lines().find_map(|l| {
        let (key, value) = l.split_once('=')?;
        (key.trim() == "MaxArraySize").then(|| value.trim().parse().ok()).flatten()
    })
}

/// Submits `script` (`sbatch --parsable`) and returns its job id; a dry run prints the command.
fn sbatch(script: &Path, extra: &[String], dry_run: bool) -> Result<Option<String>> {
    if dry_run {
        let mut words = vec!["sbatch".to_string()];
        words.extend(extra.iter().cloned());
        words.push(script.display().to_string());
        eprintln!(
            "  (dry run) {}",
            words.iter().map(|w| crate::shell::quote(w)).collect::<Vec<_>>().join(" ")
        );
        return Ok(None);
    }
    let output =
        Command::new("sbatch").arg("--parsable").args(extra).arg(script).output().map_err(|e| {
            Error::config("slurm", format!("sbatch: {e} (is this a Slurm login node?)"))
        })?;
    if !output.status.success() {
        return Err(Error::format(
            script,
            format!("sbatch refused it: {}", String::from_utf8_lossy(&output.stderr).trim()),
        ));
    }
    // `--parsable` prints `<id>` or `<id>;<cluster>`.
    let text = String::from_utf8_lossy(&output.stdout);
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() {
        return Err(Error::format(script, "sbatch printed no job id"));
    }
    Ok(Some(id))
}

/// The runs `slurm-resubmit` sends again: the failed ones, or with `unfinished` every run that
/// is neither done nor running (failed, interrupted without a requeue, never started).
pub fn to_resubmit(status: &SweepStatus, unfinished: bool) -> Vec<PathBuf> {
    status
        .runs
        .iter()
        .filter(|(_, s)| match s {
            RunState::Failed(_) => true,
            RunState::Interrupted(_) | RunState::Pending => unfinished,
            RunState::Done | RunState::Running(_) => false,
        })
        .map(|(r, _)| r.clone())
        .collect()
}

/// What `slurm-collect` prints after the tables: the failed runs (id, job, host, log, error)
/// and the command that resubmits exactly those; `None` when every run is done.
pub fn failure_report(out: &Path, status: &SweepStatus) -> Option<String> {
    let failed: Vec<_> = status.failed().collect();
    let not_done = status.runs.len() - status.count("done");
    if not_done == 0 {
        return None;
    }
    let mut text = format!("{}\n", status.summary());
    for (run, f) in &failed {
        let id =
            crate::plan::read_info(&RunDir::new(run.as_path())).map(|i| i.id).unwrap_or_default();
        text.push_str(&format!(
            "failed: {}\n  run id {id}, job {}, host {}\n  log {}\n  error: {}\n",
            run.display(),
            f.job.as_deref().unwrap_or("-"),
            f.host,
            RunDir::new(run.as_path()).log().display(),
            f.message.lines().next().unwrap_or(""),
        ));
    }
    let out = crate::shell::quote(&out.display().to_string());
    if failed.is_empty() {
        text.push_str(&format!(
            "no run failed, {not_done} not done; to send those again: cargo xtask slurm-resubmit {out} --unfinished\n"
        ));
    } else {
        text.push_str(&format!(
            "to resubmit exactly these {} run(s), after fixing their cause: cargo xtask slurm-resubmit {out}\n",
            failed.len()
        ));
    }
    Some(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_array_size_is_read_from_scontrol() {
        let text = "MailProg                = /bin/mail\nMaxArraySize            = 1001\nMaxJobCount = 10000\n";
        assert_eq!(parse_max_array_size(text), Some(1001));
        assert_eq!(parse_max_array_size("MaxArraySizeX = 3\n"), None);
    }

    #[test]
    fn options_become_sbatch_words() {
        let o = SlurmOptions {
            partition: Some("gpu".into()),
            qos: Some("long".into()),
            extra: vec!["#SBATCH --constraint=a100".into(), "--exclusive".into()],
            ..Default::default()
        };
        assert_eq!(
            o.sbatch_options(),
            ["--partition=gpu", "--qos=long", "--constraint=a100", "--exclusive"]
        );
    }
}
