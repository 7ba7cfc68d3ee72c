//! Where the time of a fit goes, per model kind: trains each run configuration of one scene of a
//! finished sweep (for example the default's `out/reproduce`) for a fixed number of steps in a
//! temporary directory, evaluates it, and prints milliseconds per step for each phase of the
//! training step (`run_format::phases`) and seconds per phase of the evaluation.
//!
//! ```sh
//! cargo xtask reproduce-tables            # once, for the scenes, caches and run configs
//! cargo run --release -p sweep --example profile_steps -- out/reproduce spot__blue-acrylic 300
//! cargo run --release -p sweep --features wgpu --example profile_steps -- out/reproduce spot__blue-acrylic 300 wgpu
//! ```
//!
//! `profile_steps --prepare <profile> <out>` makes a profile's scenes, caches and run
//! configurations without training (what `cargo xtask reproduce-tables --emit-jobs` does), for
//! a machine that has this example but no xtask (the GPU measurement, benches/device_gpu.sh).
//!
//! The optional fourth argument is the backend that trains (`cpu`, `wgpu`, `cuda`; default `cpu`);
//! evaluation runs where `experiments eval` runs it. The optional fifth is a comma-separated list
//! of model kinds to profile (as printed, for example `SingleMlp,Disney`; default: all).
//!
//! Run it on a quiet machine (no compile: `pgrep -a rustc`). The runs are the sweep's own
//! configurations with `iterations` set to the step count and snapshots off.
//!
//! `PROFILE_EVAL` (a comma-separated list of model kinds, or `none`) evaluates only those
//! models (default: all); each evaluation's phases are also printed to stderr as it ends.
//! `PROFILE_EVAL_REPEAT` (default 1) evaluates each model that many times in a row, so that
//! a GPU backend's start-up in the first evaluation shows against the later ones; the table
//! holds the last.
//!
//! `PROFILE_PRECISION` (`f32` or `bf16`) sets the runs' `matmul_precision` (default: the
//! sweep's).
//!
//! On a GPU backend each model first trains `PROFILE_WARMUP_STEPS` steps (default 50; 0 on the
//! CPU) in a run of its own, timed apart: burn's autotune benchmarks kernels at the first use of
//! each problem shape in a process, and that start-up would otherwise be spread over the
//! measured steps. The warm-up table gives what it cost, and its start-up: from the call of
//! the fit to the end of its first step (`RunMetrics::startup_seconds`), the figure of a fit
//! started in a fresh process once an earlier one has filled the persistent GPU cache.

use experiments::eval::evaluate;
use experiments::train::{FitOptions, fit_and_keep};
use run_format::held_run::RunResults;
use run_format::run_dir::{RunDir, SweepLayout};
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, profile, out] = args.as_slice()
        && flag == "--prepare"
    {
        let profile = sweep::SweepProfile::load(profile)?;
        let how = sweep::Execution::Emit {
            file: PathBuf::from(out).join("jobs.txt"),
            command: vec!["profile_steps".into()],
        };
        let data = std::env::var_os("NEURAL_BRDF_DATA")
            .map_or_else(|| PathBuf::from("data"), PathBuf::from);
        let s = sweep::sweep(&profile, out.as_ref(), &data, &how)?;
        println!(
            "{}: {} scenes generated, {} runs planned",
            profile.name,
            s.scenes_generated,
            s.runs.len()
        );
        return Ok(());
    }
    let [out, scene, rest @ ..] = args.as_slice() else {
        return Err(
            "usage: profile_steps <sweep out dir> <scene name> [steps] [backend] [models]".into()
        );
    };
    let steps: u64 = rest.first().map_or(Ok(300), |s| s.parse())?;
    let backend = brdf_neural::device::parse_backend(rest.get(1).map_or("cpu", String::as_str))?;
    let only: Option<Vec<&str>> = rest.get(2).map(|m| m.split(',').map(str::trim).collect());
    let eval_list = std::env::var("PROFILE_EVAL").ok();
    let eval_repeat: u32 = std::env::var("PROFILE_EVAL_REPEAT").map_or(Ok(1), |v| v.parse())?;
    let eval_only: Option<Vec<&str>> =
        eval_list.as_deref().map(|m| m.split(',').map(str::trim).collect());
    let layout = SweepLayout::new(out);
    let mut runs: Vec<PathBuf> = std::fs::read_dir(layout.runs())?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().unwrap_or_default().to_string_lossy().into_owned();
            name.starts_with(&format!("{scene}__")) && name.contains("__default__")
        })
        .collect();
    runs.sort();
    if runs.is_empty() {
        return Err(format!("no default runs of {scene} under {}", layout.runs().display()).into());
    }
    let tmp = std::env::temp_dir().join(format!("profile-steps-{}", std::process::id()));
    let warmup: u64 = match std::env::var("PROFILE_WARMUP_STEPS") {
        Ok(v) => v.parse()?,
        Err(_) if backend.is_gpu() => 50,
        Err(_) => 0,
    };
    println!(
        "{steps} steps per model on {scene}, backend {backend}; ms per step, then evaluation \
         seconds\n"
    );
    println!(
        "| model | gather | encode | forward | loss | backward | optimizer | validation | \
         bookkeeping | total | samples/s |"
    );
    println!("| --- |{}", " ---: |".repeat(10));
    let precision = match std::env::var("PROFILE_PRECISION").as_deref() {
        Ok("f32") => Some(brdf_neural::precision::MatmulPrecision::F32),
        Ok("bf16") => Some(brdf_neural::precision::MatmulPrecision::Bf16),
        Ok("f16") => Some(brdf_neural::precision::MatmulPrecision::F16),
        Ok(other) => {
            return Err(format!("PROFILE_PRECISION={other:?}: expected f32, bf16 or f16").into());
        }
        Err(_) => None,
    };
    let mut evals = Vec::new();
    let mut warmups = Vec::new();
    for template in &runs {
        let mut config = RunDir::new(template).read_config()?;
        config.train.iterations = steps;
        if let Some(p) = precision {
            config.train.matmul_precision = p;
        }
        config.train.snapshots = false;
        let kind = format!("{:?}", config.model.kind);
        if only.as_ref().is_some_and(|o| !o.contains(&kind.as_str())) {
            continue;
        }
        let run = tmp.join(&kind);
        let options = || FitOptions {
            progress: false,
            cache_dir: Some(layout.cache()),
            backend,
            ..Default::default()
        };
        if warmup > 0 {
            let mut short = config.clone();
            short.train.iterations = warmup;
            let start = Instant::now();
            let held = RunDir::new(tmp.join(format!("{kind}-warmup"))).hold("training")?;
            let (warm, _) = fit_and_keep(Some(&short), &held, options())?;
            let startup = match warm {
                experiments::train::FitOutcome::Finished { metrics, .. } => metrics.startup_seconds,
                _ => None,
            };
            warmups.push((kind.clone(), start.elapsed().as_secs_f64(), startup));
        }
        let held = RunDir::new(&run).hold("training, evaluating")?;
        let (outcome, trained) = fit_and_keep(Some(&config), &held, options())?;
        let Some(experiments::train::Handoff::Trained(trained)) = trained else {
            return Err(format!("{kind}: did not train ({outcome:?})").into());
        };
        let metrics = run_format::RunMetrics::read(&RunDir::new(&run).metrics())?;
        let phases = metrics.phases.clone().unwrap_or_default();
        let cells: Vec<String> =
            phases.per_step_ms().iter().map(|(_, ms)| format!("{ms:.1}")).collect();
        let total = 1e3 * phases.total() / phases.steps.max(1) as f64;
        println!(
            "| {kind} | {} | {total:.1} | {:.0} |",
            cells.join(" | "),
            metrics.samples_per_second
        );
        if eval_only.as_ref().is_some_and(|e| !e.contains(&kind.as_str())) {
            continue;
        }
        let fitted = trained.into_fitted();
        for round in 1..=eval_repeat {
            let start = Instant::now();
            let evaluation = evaluate(&fitted, &held, metrics.clone(), &Default::default(), start)?;
            let test = evaluation.metrics.test.clone().ok_or("no test record")?;
            held.write_results(&RunResults { evaluation: Some(evaluation), portable: None })?;
            let cells: Vec<String> =
                test.phases.named().iter().map(|(name, s)| format!("{name} {s:.2}")).collect();
            eprintln!(
                "{kind}: evaluation {round} of {eval_repeat} in {:.2} s ({})",
                test.seconds,
                cells.join(", ")
            );
            if round == eval_repeat {
                evals.push((kind.clone(), test));
            }
        }
    }
    println!(
        "\n| model | records | predict | images | reciprocity | energy | curve | probe | total (s) |"
    );
    println!("| --- |{}", " ---: |".repeat(8));
    for (kind, test) in &evals {
        let cells: Vec<String> =
            test.phases.named().iter().map(|(_, s)| format!("{s:.2}")).collect();
        println!("| {kind} | {} | {:.2} |", cells.join(" | "), test.seconds);
    }
    if !warmups.is_empty() {
        println!(
            "\n| model | warm-up: {warmup} steps, wall s (kernel tuning and compilation) | \
             its start-up: fit called to first step done, s |"
        );
        println!("| --- | ---: | ---: |");
        for (kind, secs, startup) in &warmups {
            let startup = startup.map_or("-".into(), |s| format!("{s:.2}"));
            println!("| {kind} | {secs:.2} | {startup} |");
        }
    }
    std::fs::remove_dir_all(&tmp).ok();
    Ok(())
}
