//! The subcommands on one run directory, shared by both command lines so they cannot
//! disagree: `experiments <command>` and `cargo xtask <command>` parse the same [`RunCommand`]
//! and run it with [`run`]. `fit` trains a model on a scene into a run directory, `eval`
//! renders the test images of a finished run and computes its metrics, `energy` re-runs the
//! energy analysis with another estimator, `export` writes a Disney or Torrance-Sparrow fit as
//! glTF 2.0, Mitsuba 3 and pbrt-v4 files (a purely neural fit as a Mitsuba 3 scene for the
//! Python package's `neural_brdf` plugin), `export-merl` any fit as a MERL binary.

use crate::eval::EvalOptions;
use crate::export::SurfacePoint;
use crate::places::Places;
use crate::{FitOptions, FitOutcome};
use anyhow::{Context, Result, bail};
use brdf_neural::device::Backend;
use brdf_neural::precision::{MatmulPrecision, PrecisionSupport};
use clap::Subcommand;
use run_format::config::RunConfig;
use run_format::held_run::RunResults;
use run_format::run_dir::RunDir;
use run_format::{ComputeSettings, EnergyEstimator};
use std::path::{Path, PathBuf};

/// This process's compute settings: the defaults, overridden by those of
/// [`ComputeSettings::variables`] that are set in the environment (the one place where
/// environment variables become settings; both command lines call it). Applies what stays
/// per process before any device is made: the allocator policy of `keep_freed_memory`, and
/// the GPU kernels' index checks (`gpu.checked`, a debugging aid that changes no value).
///
/// # Errors
/// A variable whose value its setting does not take, named.
pub fn process_compute_settings() -> Result<ComputeSettings> {
    let mut settings = ComputeSettings::default();
    for (variable, _) in ComputeSettings::variables() {
        if let Ok(value) = std::env::var(variable) {
            settings = settings.with_override(variable, &value)?;
        }
    }
    if !settings.keep_freed_memory {
        brdf_neural::host_memory::leave_allocator_alone();
    }
    brdf_neural::gpu_linear::launch_checked(settings.gpu.checked);
    Ok(settings)
}

/// This process's places ([`Places`]): the data root, the LPIPS weights and the GPU cache, from
/// the environment (read here only, like the compute settings). Points the GPU backends'
/// cache at its folder before any device is made.
pub fn process_places() -> Places {
    let places = Places::from_vars(|name| std::env::var_os(name));
    brdf_neural::gpu_cache::use_dir(places.gpu_cache.clone());
    places
}

/// This process's limits on users' files: [`stdx::Limits`]'s defaults, overridden by those of
/// [`stdx::Limits::VARIABLES`] that are set in the environment (read here only, like the compute
/// settings), for the importers of captures and DiLiGenT data.
///
/// # Errors
/// A variable whose value its limit does not take, named.
pub fn process_limits() -> Result<stdx::Limits> {
    let mut limits = stdx::Limits::default();
    for (variable, _) in stdx::Limits::VARIABLES {
        if let Ok(value) = std::env::var(variable) {
            limits = limits.with_override(variable, &value).map_err(anyhow::Error::msg)?;
        }
    }
    Ok(limits)
}

/// The precision of the training products on this CPU when neither the command line nor the
/// configuration names one ([`PrecisionSupport::cpu_default`]), with the reason in words for
/// the command line to print.
pub fn cpu_default_precision() -> (MatmulPrecision, &'static str) {
    let p = MatmulPrecision::cpu_default();
    let why = match p {
        MatmulPrecision::Bf16 if MatmulPrecision::bf16_on_amx() => {
            "this CPU runs bf16 products on its AMX tiles"
        }
        MatmulPrecision::Bf16 => "this CPU runs bf16 products natively (AVX512-BF16)",
        MatmulPrecision::F16 => {
            "this CPU's bf16 products are slower than f32 (AVX512-BF16 without AMX tiles), its \
             scaled binary16 products faster (AVX512-FP16)"
        }
        _ if MatmulPrecision::cpu_has_amx_bf16() => {
            "this CPU has AMX, but Linux did not grant its tiles to this process"
        }
        _ if MatmulPrecision::bf16_native() => {
            "this CPU's AVX512-BF16 products are slower than f32 (an Intel CPU without AMX \
             tiles, or with AMX hidden by a hypervisor)"
        }
        _ => "this CPU has no native bf16 products",
    };
    (p, why)
}

/// A command on one run: fit, evaluate, analyse or export it.
#[derive(Subcommand)]
pub enum RunCommand {
    /// Train a model on a scene's training split into a run directory (resumes an existing run
    /// from its last checkpoint; a finished run is reported and skipped).
    Fit {
        /// Run configuration (TOML). Optional when RUN already holds a config.toml.
        #[arg(long)]
        config: Option<PathBuf>,
        /// Scene directory (overrides `scene` in the config).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Run directory.
        #[arg(long)]
        out: PathBuf,
        /// Cache directory (default: `features.cache_dir`, else the sweep's `cache/` for a sweep
        /// run, else `<out>/../cache`).
        #[arg(long)]
        cache: Option<PathBuf>,
        /// The burn backend: `cpu` (default), `wgpu` or `cuda` (GPU builds: `--features wgpu`
        /// or `cuda`), also `flex` or `ndarray`.
        #[arg(long, default_value = "cpu", value_parser = parse_backend)]
        backend: Backend,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Render the test images of a finished run into `<run>/renders/` and add the test metrics
    /// (PSNR, DSSIM, HDR-FLIP, cube-root RMSE) to `<run>/metrics.json`.
    Eval {
        /// Run directory.
        run: PathBuf,
        /// Scene directory (default: the one in the run's config).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Cache directory (default: `features.cache_dir`, else the sweep's `cache/` for a sweep
        /// run, else `<run>/../cache`).
        #[arg(long)]
        cache: Option<PathBuf>,
        /// The burn backend: `cpu` (default), `wgpu` or `cuda` (GPU builds: `--features wgpu`
        /// or `cuda`), also `flex` or `ndarray`.
        #[arg(long, default_value = "cpu", value_parser = parse_backend)]
        backend: Backend,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Energy conservation of a finished run's model with a chosen estimator (the paper's
    /// Monte Carlo or the fast importance-sampled QMC), printed as JSON; the run is unchanged.
    Energy {
        /// Run directory.
        run: PathBuf,
        /// `fast`, `paper` (20,000 cosine samples a pair) or `off`.
        #[arg(long, default_value = "fast")]
        estimator: String,
        /// (x, l) pairs (default: the run's `[eval]` setting).
        #[arg(long)]
        pairs: Option<usize>,
        /// Cache directory (default: `features.cache_dir`, else the sweep's `cache/` for a sweep
        /// run, else `<run>/../cache`).
        #[arg(long)]
        cache: Option<PathBuf>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Write a finished Disney or Torrance-Sparrow run as renderer files: glTF 2.0
    /// (`<out>/gltf`), a Mitsuba 3 scene (`<out>/mitsuba`) and a pbrt-v4 scene (`<out>/pbrt`),
    /// the last two with a scene file per test view and light; `<out>/export.json` reports the
    /// round trip (the test views re-rendered from the glTF file against the fit's renders).
    /// A purely neural run (Single MLP, the additive models) exports to Mitsuba 3 only: the
    /// scenes with a `neural_brdf` BSDF on the run's weights, rendered by the Python package's
    /// plugin (`import neural_brdfs.mitsuba`).
    Export {
        /// Run directory.
        run: PathBuf,
        /// Output folder (replaced atomically).
        #[arg(long)]
        out: PathBuf,
        /// Formats, comma-separated: gltf, mitsuba, pbrt or all.
        #[arg(long, default_value = "all")]
        format: String,
        /// Scene directory (default: the one in the run's config).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Cache directory (default: `features.cache_dir`, else the sweep's `cache/` for a sweep
        /// run, else `<run>/../cache`).
        #[arg(long)]
        cache: Option<PathBuf>,
    },
    /// Write a finished run's fitted material as a MERL binary (90 x 90 x 180 bins) at one
    /// surface point, for any renderer that reads MERL files.
    ExportMerl {
        /// Run directory.
        run: PathBuf,
        /// Output file (conventionally `<name>.binary`).
        #[arg(long)]
        out: PathBuf,
        /// Mesh vertex to evaluate at (default: the vertex whose encoding is closest to the
        /// mesh average).
        #[arg(long)]
        vertex: Option<usize>,
        /// Scene directory (default: the one in the run's config).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Cache directory (default: `features.cache_dir`, else the sweep's `cache/` for a sweep
        /// run, else `<run>/../cache`).
        #[arg(long)]
        cache: Option<PathBuf>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
}

/// `--backend`: a backend name (see `brdf_neural::device`).
pub fn parse_backend(name: &str) -> std::result::Result<Backend, String> {
    brdf_neural::device::parse_backend(name).map_err(|e| e.to_string())
}

/// Runs one subcommand, printing its outcome.
pub fn run(command: RunCommand) -> Result<()> {
    let places = process_places();
    match command {
        RunCommand::Fit { config, scene, out, cache, backend, quiet } => {
            fit_command(config, scene, &out, cache, backend, quiet)?;
        }
        RunCommand::Eval { run, scene, cache, backend, quiet } => {
            let options = EvalOptions { progress: !quiet, lpips_weights: places.lpips_weights() };
            let metrics =
                crate::eval::eval(&run, scene.as_deref(), cache.as_deref(), backend, &options)
                    .with_context(|| format!("eval of {}", run.display()))?;
            println!("{}", serde_json::to_string_pretty(&metrics)?);
        }
        RunCommand::Energy { run, estimator, pairs, cache, quiet } => {
            let estimator = match estimator.as_str() {
                "fast" => EnergyEstimator::Fast,
                "paper" => EnergyEstimator::Paper,
                "off" => EnergyEstimator::Off,
                other => bail!("--estimator {other:?}: expected fast, paper or off"),
            };
            let e = crate::eval::energy_of_run(&run, estimator, pairs, cache.as_deref(), !quiet)
                .with_context(|| format!("energy of {}", run.display()))?;
            println!("{}", serde_json::to_string_pretty(&e)?);
        }
        RunCommand::Export { run, out, format, scene, cache } => {
            let formats = crate::export::Format::parse_list(&format)?;
            let e = crate::export::export(&run, &out, &formats, scene.as_deref(), cache.as_deref())
                .with_context(|| format!("export of {}", run.display()))?;
            println!(
                "wrote {} files for a {} {} fit ({} vertices, {} test pairs) into {} in {:.1} s",
                e.files.len(),
                if e.uniform { "spatially uniform" } else { "spatially varying" },
                e.model,
                e.vertices,
                e.test_pairs,
                out.display(),
                e.seconds
            );
            if let Some(t) = &e.round_trip {
                println!(
                    "round trip (glTF read back, {} test images re-rendered): PSNR min {:.1} dB, \
                     mean {:.1} dB; largest relative BRDF difference {:.2e}",
                    t.images, t.min_psnr_db, t.mean_psnr_db, t.max_relative_brdf_difference
                );
            }
        }
        RunCommand::ExportMerl { run, out, vertex, scene, cache, quiet } => {
            let point = vertex.map_or(SurfacePoint::Representative, SurfacePoint::Vertex);
            let e = crate::export::export_merl(
                &run,
                &out,
                point,
                scene.as_deref(),
                cache.as_deref(),
                !quiet,
            )
            .with_context(|| format!("export-merl of {}", run.display()))?;
            println!(
                "wrote {} (vertex {} at {:?}; {} below-horizon bins set to 0) in {:.1} s",
                out.display(),
                e.vertex,
                e.position,
                e.below_horizon,
                e.seconds
            );
        }
    }
    Ok(())
}

/// `fit`: the configuration from `--config` or the run directory, the scene from
/// `--scene` when given; prints how the fit ended.
fn fit_command(
    config: Option<PathBuf>,
    scene: Option<PathBuf>,
    out: &Path,
    cache: Option<PathBuf>,
    backend: Backend,
    quiet: bool,
) -> Result<()> {
    let stored = RunDir::new(out).config();
    let path = match config {
        Some(p) => p,
        None if stored.is_file() => stored,
        None => bail!("--config is required for a new run ({} has none)", out.display()),
    };
    let mut cfg = RunConfig::read(&path)?;
    if let Some(scene) = scene {
        cfg.scene = Some(std::path::absolute(&scene).unwrap_or(scene));
    }
    let compute = process_compute_settings()?;
    let cache_dir = cache.clone();
    let options =
        FitOptions { progress: !quiet, cache_dir, backend, compute, ..Default::default() };
    let context = || format!("fit into {}", out.display());
    cfg.validate().with_context(context)?;
    let held = RunDir::new(out).hold("training").with_context(context)?;
    let (outcome, trained) =
        crate::train::fit_and_keep(Some(&cfg), &held, options).with_context(context)?;
    // The weights for other tools, as a sweep's run exports them after its evaluation.
    if let Some(crate::train::Handoff::Trained(trained)) = trained {
        let portable = crate::portable::fitted_files(&trained.into_fitted());
        let results =
            RunResults { evaluation: None, portable: Some(portable.with_context(context)?) };
        held.write_results(&results).with_context(context)?;
    }
    match outcome {
        FitOutcome::AlreadyFinished(m) => {
            println!("{}: already finished ({} steps), skipped", out.display(), m.steps)
        }
        FitOutcome::Finished { metrics: m, resumed_from } => {
            if resumed_from > 0 {
                println!("resumed from step {resumed_from}");
            }
            let why = match m.stop_reason {
                Some(run_format::plateau::StopReason::Plateau) => "converged",
                _ => "step budget reached",
            };
            let val = match (m.best_val_loss, m.val_loss_floor) {
                (Some(v), Some(f)) => format!(", validation {v:.4e} (noise floor {f:.4e})"),
                (Some(v), None) => format!(", validation {v:.4e}"),
                _ => String::new(),
            };
            println!(
                "{}: {} after {} steps in {:.1} s, {:.0} samples/s, final loss {:.4e}{val}",
                out.display(),
                why,
                m.steps,
                m.wall_seconds,
                m.samples_per_second,
                m.final_train_loss
            );
        }
        FitOutcome::Stopped(step) => println!("stopped after step {step}"),
    }
    Ok(())
}
