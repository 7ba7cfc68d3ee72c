//! `cargo xtask reproduce-tables`, `collect` and `run-one`: the paper's results from one
//! command (see the `sweep` crate for the profiles, the run layout and the tables).

use anyhow::{Context, Result};
use experiments::{Backend, BackendDevice, MatmulPrecision};
use run_format::run_dir::SweepLayout;
use std::path::{Path, PathBuf};
use sweep::{Execution, SweepProfile};

/// Options of `reproduce-tables`.
pub struct Options {
    /// Built-in profile name or TOML file.
    pub profile: String,
    /// Output directory.
    pub out: PathBuf,
    /// Concurrent runs (child processes); 1 runs in this process.
    pub jobs: usize,
    /// Write one command per unfinished run to this file instead of running.
    pub emit_jobs: Option<PathBuf>,
    /// Data root for `data:` meshes.
    pub data_root: PathBuf,
    /// The LPIPS weights the runs' evaluations read when their `[eval]` names none.
    pub lpips_weights: PathBuf,
    /// The burn backend every run trains and evaluates on.
    pub backend: Backend,
    /// Precision of every run's training matrix products (`train.matmul_precision`), where
    /// given; `None` keeps the profile's.
    pub matmul_precision: Option<MatmulPrecision>,
    /// Only the runs of these tables (`SweepProfile::with_tables`); `None`: every one.
    pub tables: Option<Vec<String>>,
    /// Submit the runs to Slurm as job arrays with these settings instead of running them.
    pub slurm: Option<sweep::slurm::SlurmOptions>,
}

/// The command that runs one run directory in a child process: this executable's `run-one`,
/// with this process's backend and LPIPS weights (an absolute path: a cluster task may start
/// elsewhere).
fn run_one_command(opts: &Options) -> Result<Vec<String>> {
    let exe = std::env::current_exe().context("locating the xtask executable")?;
    let lpips = std::path::absolute(&opts.lpips_weights).unwrap_or(opts.lpips_weights.clone());
    Ok(vec![
        exe.display().to_string(),
        "run-one".into(),
        "--backend".into(),
        opts.backend.to_string(),
        "--lpips-weights".into(),
        lpips.display().to_string(),
    ])
}

/// Runs `reproduce-tables`.
pub fn reproduce(opts: Options) -> Result<()> {
    anyhow::ensure!(
        opts.backend.is_built(),
        "--backend {0}: this xtask was built without it; rebuild with `--features {0}`",
        opts.backend
    );
    anyhow::ensure!(
        opts.matmul_precision.is_none_or(|p| p == MatmulPrecision::F32)
            || opts.backend == Backend::Flex,
        "--matmul-precision {} is implemented for the CPU backend only, not --backend {}",
        opts.matmul_precision.unwrap_or_default().name(),
        opts.backend
    );
    let mut profile = with_precision(SweepProfile::load(&opts.profile)?, &opts);
    if let Some(tables) = &opts.tables {
        profile = profile.with_tables(tables)?;
    }
    eprintln!("profile {}: {}", profile.name, profile.description);
    // The environment's settings are checked before anything is written.
    let how = execution(&opts)?;
    let settings = sweep_settings()?;
    // One sweep at a time per output directory, held through the tables; taking it removes
    // the temporary files of a sweep killed in it (run directories busy in another process
    // keep theirs).
    let lock = stdx::lock::DirLock::acquire(&opts.out, "reproduce-tables")
        .context("cannot start the sweep")?;
    if lock.removed_temporaries > 0 {
        eprintln!(
            "removed {} temporary file(s) left by an interrupted run",
            lock.removed_temporaries
        );
    }
    let s = sweep::sweep_with(&profile, &opts.out, &opts.data_root, &how, &settings)
        .with_context(|| format!("sweep {} into {}", profile.name, opts.out.display()))?;
    print_sweep(&s);
    if let Some(submission) = &s.submission {
        crate::slurm::print_submission(&opts.out, submission);
        return Ok(());
    }
    if let Execution::Emit { file, .. } = &how {
        eprintln!(
            "wrote {} job command(s) to {} (one per line, for your scheduler; on Slurm, \
             `--slurm` submits them as job arrays that requeue and collect); then run \
             `cargo xtask collect {}`",
            s.emitted,
            file.display(),
            SweepLayout::new(&opts.out).runs().display()
        );
        return Ok(());
    }
    // The tables of this profile's runs only: an output directory that also holds runs of
    // another profile or of the other `--matmul-precision` keeps them out of these tables
    // (`cargo xtask collect` gathers any set).
    let c = match sweep::collect(&s.runs, &opts.out, &profile.name) {
        Err(e) if !s.failed.is_empty() => {
            anyhow::bail!(
                "{} run(s) failed (see above), and no table could be made: {e}",
                s.failed.len()
            )
        }
        c => c?,
    };
    eprintln!("{} run(s) collected in {:.1} min", c.runs, s.seconds / 60.0);
    print_results(&opts.out, &c.files);
    anyhow::ensure!(
        s.failed.is_empty(),
        "{} run(s) failed (see above); the tables leave them out",
        s.failed.len()
    );
    Ok(())
}

/// The profile with its training products' precision: `--matmul-precision` where given, the
/// profile's own where it names one, and otherwise, on the CPU, the machine's choice (bf16 where
/// it is native and faster, whose converged scores stay within f32's seed noise:
/// docs/reproduce.md, "bf16 as the CPU default"), printed with its reason.
fn with_precision(profile: SweepProfile, opts: &Options) -> SweepProfile {
    if let Some(precision) = opts.matmul_precision {
        return profile.with_matmul_precision(precision);
    }
    if opts.backend != Backend::Flex || profile.names_precision {
        return profile;
    }
    let (precision, why) = experiments::cli::cpu_default_precision();
    eprintln!(
        "matmul precision {}: {why} (`--matmul-precision f32`, `bf16` or `f16` chooses; bf16 and \
         f16 runs have their own run ids)",
        precision.name()
    );
    profile.with_matmul_precision(precision)
}

/// The sweep's own settings: the progress lines (`NEURAL_BRDF_PROGRESS_LINES`, `_SECS`), the
/// LBO stage's memory budget (the compute settings' `lbo_memory_gib`) and the importers' limits
/// (`stdx::Limits`), from the environment.
fn sweep_settings() -> Result<sweep::SweepSettings> {
    let mut progress = sweep::ProgressLines::default();
    for (variable, _) in sweep::ProgressLines::VARIABLES {
        if let Ok(value) = std::env::var(variable) {
            progress = progress.with_override(variable, &value)?;
        }
    }
    let lbo_memory = experiments::cli::process_compute_settings()?.lbo_memory_bytes();
    let limits = experiments::cli::process_limits()?;
    Ok(sweep::SweepSettings { progress, lbo_memory, limits })
}

/// How the runs are executed: `--slurm`, `--emit-jobs`, `--jobs N` children or in process.
/// The compute settings come from this process's environment
/// ([`experiments::cli::process_compute_settings`], checked here for every kind): children,
/// emitted jobs and Slurm tasks inherit it and read it again.
fn execution(opts: &Options) -> Result<Execution> {
    let compute = experiments::cli::process_compute_settings()?;
    anyhow::ensure!(
        opts.slurm.is_none() || opts.emit_jobs.is_none(),
        "--slurm and --emit-jobs are two ways to hand the runs to a cluster: choose one"
    );
    Ok(match (&opts.emit_jobs, opts.jobs) {
        _ if opts.slurm.is_some() => Execution::Slurm {
            program: run_one_command(opts)?.swap_remove(0),
            backend: opts.backend,
            lpips_weights: opts.lpips_weights.clone(),
            options: opts.slurm.clone().unwrap_or_default(),
        },
        (Some(file), _) => Execution::Emit { file: file.clone(), command: run_one_command(opts)? },
        (None, 0 | 1) => Execution::InProcess(sweep::RunOn {
            backend: opts.backend,
            compute,
            lpips_weights: opts.lpips_weights.clone(),
        }),
        (None, jobs) => Execution::Children { jobs, command: run_one_command(opts)? },
    })
}

/// The sweep's counts and its failed runs.
fn print_sweep(s: &sweep::SweepSummary) {
    eprintln!(
        "\nscenes: {} generated, {} kept; runs: {} planned, {} finished earlier (skipped), {} completed now, {} failed",
        s.scenes_generated,
        s.scenes_kept,
        s.runs.len(),
        s.skipped,
        s.completed,
        s.failed.len()
    );
    for (dir, why) in &s.failed {
        eprintln!("  failed: {}: {why}", dir.display());
    }
}

fn print_results(out: &Path, files: &[PathBuf]) {
    for table in ["table1", "runtime", "time"] {
        let path = SweepLayout::new(out).tables().join(format!("{table}.md"));
        if let Ok(text) = std::fs::read_to_string(path) {
            println!("{text}");
        }
    }
    eprintln!("tables and figures ({} files) in {}:", files.len(), out.display());
    for f in files {
        eprintln!("  {}", f.display());
    }
}

/// Runs `collect`.
pub fn collect(paths: &[PathBuf], out: &Path, profile: &str) -> Result<()> {
    let c = sweep::collect(paths, out, profile)?;
    eprintln!("{} evaluated run(s) collected, {} unfinished left out", c.runs, c.unfinished);
    print_results(out, &c.files);
    Ok(())
}

/// Runs `run-one` (what `--jobs` children, emitted job lines and Slurm tasks execute). A
/// SIGTERM or SIGUSR1 stops it for a requeue: a checkpoint is written and the process exits with
/// `experiments::interrupt::EXIT_REQUEUE`.
pub fn run_one(dir: &Path, progress: bool, backend: Backend, lpips_weights: PathBuf) -> Result<()> {
    sweep::exit_with_parent();
    experiments::interrupt::install();
    let compute = experiments::cli::process_compute_settings()?;
    let on = sweep::RunOn { backend, compute, lpips_weights };
    match sweep::run_one(dir, progress, &on).with_context(|| format!("run {}", dir.display()))? {
        sweep::RunEnd::Done => Ok(()),
        sweep::RunEnd::Interrupted(step) => {
            match step {
                Some(step) => eprintln!(
                    "{}: stopped by a signal after step {step}, checkpoint written; the next start resumes it",
                    dir.display()
                ),
                None => eprintln!(
                    "{}: stopped by a signal after training; the next start evaluates it",
                    dir.display()
                ),
            }
            std::process::exit(experiments::interrupt::EXIT_REQUEUE)
        }
    }
}
