//! `sweep-status`, `slurm-collect` and `slurm-resubmit`: a sweep on a Slurm cluster after
//! `reproduce-tables --slurm` submitted it (the `sweep::slurm` module documents the design).

use anyhow::{Context, Result};
use std::path::Path;
use sweep::slurm::{SlurmOptions, SlurmSweep, Submission};
use sweep::status::SweepStatus;

/// Prints what a submission sent and how to follow it.
pub fn print_submission(out: &Path, s: &Submission) {
    let verb = if s.dry_run { "wrote (dry run, nothing submitted)" } else { "submitted" };
    let tasks: usize = s.arrays.iter().map(|a| a.count).sum();
    eprintln!("slurm: {verb} {} array(s), {tasks} task(s), and the collect job:", s.arrays.len());
    for a in &s.arrays {
        eprintln!(
            "  {} {:>4} task(s)  {}  cpus {}, mem {} MiB, time {}{}  {}",
            a.job.as_deref().unwrap_or("-"),
            a.count,
            a.models.join(", "),
            a.requests.cpus,
            a.requests.mem_mib,
            sweep::slurm::requests::slurm_time(a.requests.minutes),
            if a.requests.gpu { ", 1 GPU" } else { "" },
            a.script.display()
        );
    }
    eprintln!(
        "  {} collect (after every array ends)  {}",
        s.collect_job.as_deref().unwrap_or("-"),
        s.collect_script.display()
    );
    let out = sweep::shell::quote(&out.display().to_string());
    eprintln!(
        "follow it with `cargo xtask sweep-status {out}` (or squeue); the tables land in {out}/tables"
    );
}

/// The sweep folder's lock, as `reproduce-tables` takes it: one process at a time writes its
/// tables or its Slurm record.
fn lock(out: &Path, what: &str) -> Result<stdx::lock::DirLock> {
    stdx::lock::DirLock::acquire(out, what)
        .with_context(|| format!("cannot {what} {}", out.display()))
}

/// `sweep-status DIR`: where each run stands, from the run directories.
pub fn status(out: &Path) -> Result<()> {
    let runs = match SlurmSweep::read(out) {
        Ok(s) => s.runs,
        Err(_) => sweep::status::runs_under(out)
            .with_context(|| format!("{} holds no sweep (no runs/ folder)", out.display()))?,
    };
    print!("{}", SweepStatus::read(&runs).report());
    Ok(())
}

/// `slurm-collect DIR` (the collect job): the tables and report of the finished runs, then the
/// failed ones and the command that resubmits them. Exits with status 3 when a run is not done.
pub fn collect(out: &Path) -> Result<()> {
    let _lock = lock(out, "slurm-collect")?;
    let sweep = SlurmSweep::read(out)?;
    let status = sweep.status();
    if status.count("done") > 0 {
        crate::reproduce::collect(&sweep.runs, out, &sweep.profile)?;
    } else {
        eprintln!("no run is done yet: no tables written");
    }
    match sweep::slurm::failure_report(out, &status) {
        None => {
            eprintln!("{}", status.summary());
            Ok(())
        }
        Some(report) => {
            print!("{report}");
            // Written beside the scripts too, for whoever looks after the job has gone.
            let path = run_format::run_dir::SweepLayout::new(out).slurm().join("failed.txt");
            stdx::fs::write_atomic(&path, report.as_bytes())?;
            std::process::exit(3)
        }
    }
}

/// `slurm-resubmit DIR`: submits the failed runs again (with `unfinished`, every run neither
/// done nor running), with the settings of the first submission and a new collect job.
pub fn resubmit(out: &Path, unfinished: bool, dry_run: bool) -> Result<()> {
    let _lock = lock(out, "slurm-resubmit")?;
    let sweep = SlurmSweep::read(out)?;
    let todo = sweep::slurm::to_resubmit(&sweep.status(), unfinished);
    anyhow::ensure!(
        !todo.is_empty(),
        "nothing to resubmit in {}: {}{}",
        out.display(),
        sweep.status().summary(),
        if unfinished { "" } else { " (--unfinished also sends interrupted and pending runs)" }
    );
    let options = SlurmOptions { dry_run, ..sweep.options.clone() };
    let s = sweep::slurm::submit(out, &[], &todo, None, &options)?;
    print_submission(out, &s);
    Ok(())
}
