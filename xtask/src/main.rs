//! `cargo xtask`: the orchestration CLI of the neural-BRDF comparison.
//!
//! Every user-facing job of the workspace is a subcommand here; run `cargo xtask --help`.
//! The main job is `reproduce-tables` (the paper's tables and figures from one command, see
//! `docs/reproduce.md`); `collect` rebuilds them from any run directories, `publish-tables`
//! copies a run's tables into the documents, `fetch-data`
//! downloads the real datasets, `import-diligent` turns a DiLiGenT capture into a scene,
//! `import-capture` a user's own (docs/capture-format.md).

mod analytic_report;
mod capture;
mod fetch;
mod generate_scenes;
mod import_diligent;
mod layers;
mod publish;
mod reproduce;
mod slurm;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use experiments::cli::{RunCommand, parse_backend};
use experiments::{Backend, MatmulPrecision};
use std::path::PathBuf;

/// Orchestration CLI of the neural-BRDF comparison workspace.
#[derive(Parser)]
#[command(name = "cargo xtask", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Characterise every analytic BRDF at its default parameters: directional albedo against
    /// incidence angle (Monte Carlo, with error bars), reciprocity error, evaluation speed.
    AnalyticReport {
        /// Monte Carlo samples per albedo estimate.
        #[arg(long, default_value_t = 200_000)]
        samples: usize,
        /// Random direction pairs for the reciprocity error and the speed measurement.
        #[arg(long, default_value_t = 1_000_000)]
        pairs: usize,
        /// Seed of every random number (the report is deterministic for a seed, speed aside).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Where to write the Markdown report (atomically).
        #[arg(long, default_value = "out/analytic-report.md")]
        out: PathBuf,
    },
    /// Render semi-synthetic scenes: every mesh with every catalogue material (MERL-derived via
    /// the shipped NBRDF networks unless --merl-dir has the real binaries). Complete scenes are
    /// kept; an interrupted run resumes.
    GenerateScenes {
        /// Mesh files (OBJ, PLY, glTF/GLB); repeat the flag for several.
        #[arg(long = "mesh", required = true)]
        meshes: Vec<PathBuf>,
        /// Catalogue material names, repeatable, or "all".
        #[arg(long = "material", required = true)]
        materials: Vec<String>,
        /// Seed of cameras, lights, splits and noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Image width and height in pixels.
        #[arg(long, default_value_t = 512)]
        size: u32,
        /// Views per scene (half train, half test).
        #[arg(long, default_value_t = 20)]
        views: usize,
        /// Lights per view (30 of 42 train by default, the same fraction otherwise).
        #[arg(long, default_value_t = 42)]
        lights: usize,
        /// Point lights at this distance from the origin, in mesh radii (> 1; their irradiance
        /// at the origin is the directional lights'), instead of directional lights.
        #[arg(long)]
        point_lights: Option<f32>,
        /// Directory with real MERL binaries (`<name>.binary`), which take precedence.
        #[arg(long)]
        merl_dir: Option<PathBuf>,
        /// Output directory.
        #[arg(long, default_value = "datasets/semi-synthetic")]
        out: PathBuf,
    },
    /// Download a dataset of `data-manifests/` (resumable, sha256-verified) into the data root.
    FetchData {
        /// Manifest name (`merl`, `nbrdf`, `meshes`, `diligent`, `diligent-mv`, `lpips`).
        #[arg(required_unless_present = "list")]
        name: Option<String>,
        /// Data root [default: $NEURAL_BRDF_DATA, else ./data].
        #[arg(long)]
        dest: Option<PathBuf>,
        /// Fetch only this entry of the manifest; repeatable.
        #[arg(long)]
        only: Vec<String>,
        /// Print the manifests (or the named one) and their entries, fetch nothing.
        #[arg(long)]
        list: bool,
        /// Accept files whose manifest publishes no sha256, recording the computed hash in
        /// `<root>/fetch-lock.toml` so later fetches verify against it.
        #[arg(long)]
        allow_unverified: bool,
        /// Directory of the manifests [default: the workspace's data-manifests/].
        #[arg(long)]
        manifests: Option<PathBuf>,
    },
    /// Reproduce the paper's tables and figures: generate the profile's scenes, fit and evaluate
    /// every run (finished runs are skipped, interrupted ones resume), then write the tables
    /// (Markdown, LaTeX) and figures (PNG) into OUT/tables and OUT/figures.
    ReproduceTables(ReproduceArgs),
    /// Where a sweep's runs stand (done, running, failed, interrupted, pending), read from the
    /// run directories: also after its Slurm jobs have left the queue.
    SweepStatus {
        /// The sweep's output directory.
        #[arg(default_value = "out/reproduce")]
        out: PathBuf,
    },
    /// The collect job of a Slurm sweep: tables and report of the finished runs, then the failed
    /// runs with their jobs and logs and the command that resubmits them (exit status 3 when a
    /// run is not done).
    SlurmCollect {
        /// The sweep's output directory.
        out: PathBuf,
    },
    /// Submit the failed runs of a Slurm sweep again (the first submission's settings), with a
    /// new collect job.
    SlurmResubmit {
        /// The sweep's output directory.
        out: PathBuf,
        /// Also the runs that are interrupted or were never started (every run neither done
        /// nor running).
        #[arg(long)]
        unfinished: bool,
        /// Write the scripts and print the sbatch commands without submitting.
        #[arg(long)]
        dry_run: bool,
    },
    /// Build every table and figure from the evaluated run directories below PATHS.
    Collect {
        /// Run directories or folders holding them.
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Where tables/ and figures/ go.
        #[arg(long, default_value = "out/collected")]
        out: PathBuf,
        /// Profile name the captions print.
        #[arg(long, default_value = "collected")]
        profile: String,
    },
    /// Copy a sweep's tables into the generated blocks of README.md and docs/reproduce.md
    /// (each block names its tables; runs of another results version are refused).
    PublishTables {
        /// The sweep's output directory (holding runs/ and tables/).
        #[arg(default_value = "out/reproduce")]
        out: PathBuf,
    },
    /// Fit (resuming) and evaluate one prepared run directory: what `--jobs` children and
    /// `--emit-jobs` lines run.
    RunOne {
        /// The run directory.
        run: PathBuf,
        /// No progress bars.
        #[arg(long)]
        quiet: bool,
        /// The burn backend (`cpu`, `wgpu`, `cuda`).
        #[arg(long, default_value = "cpu", value_parser = parse_backend)]
        backend: Backend,
        /// The LPIPS weight file of the run's evaluation when its `[eval]` names none
        /// (default: `$NEURAL_BRDF_LPIPS`, else `<data root>/lpips/alex_v0.1.lpipsw`).
        #[arg(long)]
        lpips_weights: Option<PathBuf>,
    },
    /// Import a DiLiGenT capture (`pmsData/<obj>PNG`, the ball) or a DiLiGenT-MV object
    /// (`mvpmsData/<obj>PNG`) as a scene directory that `fit` trains on.
    ImportDiligent {
        /// The object's directory (`.../pmsData/ballPNG` or `.../mvpmsData/bearPNG`).
        src: PathBuf,
        /// Output scene directory.
        #[arg(long)]
        out: PathBuf,
        /// Training lights (per view).
        #[arg(long, default_value_t = 30)]
        train_lights: usize,
        /// Test lights (per view).
        #[arg(long, default_value_t = 12)]
        test_lights: usize,
        /// DiLiGenT-MV: decimate the mesh to this many vertices.
        #[arg(long, default_value_t = 100_000)]
        target_vertices: usize,
    },
    /// Import your own capture (posed images, mesh, calibrated directional or point lights;
    /// docs/capture-format.md) as a scene directory: checks the mesh against every view's mask
    /// (IoU) and refuses a misaligned capture, writing nothing.
    ImportCapture {
        /// The capture folder (holding `capture.toml`).
        capture: PathBuf,
        /// Output scene directory.
        #[arg(long)]
        out: PathBuf,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Write a scene directory in the capture format (transforms.json, lights.json, EXR images,
    /// PNG masks, PLY mesh): an example to start from, and the importer's round trip.
    ExportCapture {
        /// The scene directory.
        scene: PathBuf,
        /// Output capture folder.
        #[arg(long)]
        out: PathBuf,
    },
    /// Print the workspace's crates in layering order (bottom first).
    Layers,
    /// The commands on one run directory (fit, eval, energy, export, export-merl): the same
    /// as the `experiments` binary's.
    #[command(flatten)]
    Run(RunCommand),
}

/// The options of `reproduce-tables`.
#[derive(Args)]
struct ReproduceArgs {
    /// Built-in profile (default: every table of the paper; quick, smoke, runtime, full, real,
    /// figure; all-tables is default's old name) or a profile TOML file.
    #[arg(long, default_value = sweep::DEFAULT_PROFILE)]
    profile: String,
    /// Output directory (scenes, runs, cache, tables, figures).
    #[arg(long, default_value = "out/reproduce")]
    out: PathBuf,
    /// Runs at a time, as child processes (1: in this process) [default: 2 on the CPU, where
    /// two use a 2-core machine fully (one training run keeps about 1.5 cores busy); 1 on a
    /// GPU].
    #[arg(long)]
    jobs: Option<usize>,
    /// Write one shell command per unfinished run to this file (e.g. for a Slurm job array)
    /// instead of running them; then `cargo xtask collect`.
    #[arg(long)]
    emit_jobs: Option<PathBuf>,
    /// Data root for the profile's `data:` meshes and its captures (default:
    /// $NEURAL_BRDF_DATA, else ./data).
    #[arg(long)]
    data: Option<PathBuf>,
    /// The burn backend of every run: `cpu` (default), `wgpu` or `cuda` (an xtask built with
    /// `--features wgpu` or `cuda`). On a GPU, use `--jobs 1`.
    #[arg(long, default_value = "cpu", value_parser = parse_backend)]
    backend: Backend,
    /// Precision of the training steps' matrix products, for every run: `f32`, `bf16` or `f16`
    /// (CPU backend; see docs/guide.md for their speeds). Without it, the profile's
    /// `run.train.matmul_precision` holds where it names one; otherwise, on the CPU, bf16 where
    /// this CPU runs it natively and faster (AMX tiles, or AVX512-BF16 on AMD), else f16 where
    /// it runs binary16 natively (AVX512-FP16), else f32, printed at the start. bf16 and f16
    /// runs get their own run ids.
    #[arg(long, value_parser = parse_precision)]
    matmul_precision: Option<MatmulPrecision>,
    /// Only the runs of these tables of the paper, comma-separated: table1, energy, nol,
    /// reciprocity, view-light, nerfactor (`--tables table1`: the default's Table 1 alone).
    /// Without it, every table the profile plans.
    #[arg(long, value_delimiter = ',')]
    tables: Option<Vec<String>>,
    #[command(flatten)]
    slurm: SlurmArgs,
}

impl ReproduceArgs {
    /// The sweep's options, with the places the command line read.
    fn options(self, places: experiments::places::Places) -> Result<reproduce::Options> {
        let backend = self.backend;
        Ok(reproduce::Options {
            profile: self.profile,
            out: self.out,
            jobs: self.jobs.unwrap_or(if backend.is_gpu() { 1 } else { 2 }),
            emit_jobs: self.emit_jobs,
            lpips_weights: places.clone().with_data(self.data.as_deref()).lpips_weights(),
            data_root: self.data.unwrap_or(places.data),
            backend,
            matmul_precision: self.matmul_precision,
            tables: self.tables,
            slurm: self.slurm.options()?,
        })
    }
}

/// The Slurm flags of `reproduce-tables` (docs/guide.md, "On a cluster").
#[derive(Args)]
struct SlurmArgs {
    /// Submit the unfinished runs to Slurm as job arrays (one task a run, requests from each
    /// model's measured cost, requeued on preemption or time limit) with a collect job that
    /// writes the tables, instead of running them here.
    #[arg(long)]
    slurm: bool,
    /// With --slurm: write the job scripts and print the sbatch commands, submit nothing.
    #[arg(long, requires = "slurm")]
    dry_run: bool,
    /// With --slurm: the partition.
    #[arg(long, requires = "slurm")]
    partition: Option<String>,
    /// With --slurm: the account.
    #[arg(long, requires = "slurm")]
    account: Option<String>,
    /// With --slurm: the QOS.
    #[arg(long, requires = "slurm")]
    qos: Option<String>,
    /// With --slurm: an extra #SBATCH option for every job (repeatable), e.g.
    /// `--sbatch=--constraint=avx512`.
    #[arg(long = "sbatch", requires = "slurm", allow_hyphen_values = true)]
    sbatch: Vec<String>,
    /// With --slurm: CPUs a task [default: 2 on the CPU, 4 beside a GPU].
    #[arg(long, requires = "slurm")]
    slurm_cpus: Option<usize>,
    /// With --slurm: memory a task in MiB [default: from the scene's size].
    #[arg(long, requires = "slurm")]
    slurm_mem: Option<u64>,
    /// With --slurm: the longest time a task may ask for (Slurm's forms: `MM`, `HH:MM:SS`,
    /// `D-HH:MM`) [default: 1-00:00]; a run that needs longer is requeued and resumes.
    #[arg(long, requires = "slurm")]
    slurm_max_time: Option<String>,
    /// With --slurm: the largest array [default: the cluster's MaxArraySize].
    #[arg(long, requires = "slurm")]
    max_array_size: Option<usize>,
}

impl SlurmArgs {
    fn options(self) -> Result<Option<sweep::slurm::SlurmOptions>> {
        if !self.slurm {
            return Ok(None);
        }
        let max_minutes = match &self.slurm_max_time {
            None => None,
            Some(t) => Some(sweep::slurm::requests::parse_slurm_time(t).ok_or_else(|| {
                anyhow::anyhow!("--slurm-max-time {t:?}: not a Slurm time (MM, HH:MM:SS, D-HH:MM)")
            })?),
        };
        Ok(Some(sweep::slurm::SlurmOptions {
            partition: self.partition,
            account: self.account,
            qos: self.qos,
            extra: self.sbatch,
            requests: sweep::slurm::requests::RequestSettings {
                cpus: self.slurm_cpus,
                mem_mib: self.slurm_mem,
                max_minutes,
            },
            max_array_size: self.max_array_size,
            dry_run: self.dry_run,
        }))
    }
}

/// `--matmul-precision`: `f32`, `bf16` or `f16`.
fn parse_precision(name: &str) -> std::result::Result<MatmulPrecision, String> {
    match name {
        "f32" => Ok(MatmulPrecision::F32),
        "bf16" => Ok(MatmulPrecision::Bf16),
        "f16" => Ok(MatmulPrecision::F16),
        other => Err(format!("unknown precision {other:?} (f32, bf16, f16)")),
    }
}

/// `analytic-report`: prints the report and writes it to `out`.
fn write_analytic_report(options: analytic_report::Options, out: &std::path::Path) -> Result<()> {
    anyhow::ensure!(options.samples >= 2, "--samples must be at least 2 (got {})", options.samples);
    anyhow::ensure!(options.pairs >= 1, "--pairs must be at least 1 (got {})", options.pairs);
    let md = analytic_report::report(&options);
    print!("{md}");
    stdx::fs::write_atomic(out, md.as_bytes())?;
    eprintln!("report written to {}", out.display());
    Ok(())
}

fn main() -> Result<()> {
    let command = Cli::parse().command;
    let places = experiments::cli::process_places();
    match command {
        Command::AnalyticReport { samples, pairs, seed, out } => {
            write_analytic_report(analytic_report::Options { samples, pairs, seed }, &out)?
        }
        Command::GenerateScenes {
            meshes,
            materials,
            seed,
            size,
            views,
            lights,
            point_lights,
            merl_dir,
            out,
        } => {
            generate_scenes::run(generate_scenes::Options {
                meshes,
                materials,
                seed,
                size,
                views,
                lights,
                point_light_distance: point_lights,
                merl_dir,
                out,
            })?;
        }
        Command::FetchData { name, dest, only, list, allow_unverified, manifests } => {
            let dest = dest.unwrap_or(places.data);
            fetch::run(fetch::Options { name, dest, only, list, allow_unverified, manifests })?;
        }
        Command::ReproduceTables(args) => reproduce::reproduce(args.options(places)?)?,
        Command::SweepStatus { out } => slurm::status(&out)?,
        Command::SlurmCollect { out } => slurm::collect(&out)?,
        Command::SlurmResubmit { out, unfinished, dry_run } => {
            slurm::resubmit(&out, unfinished, dry_run)?
        }
        Command::Collect { paths, out, profile } => reproduce::collect(&paths, &out, &profile)?,
        Command::PublishTables { out } => {
            publish::run(&out, &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))?
        }
        Command::RunOne { run, quiet, backend, lpips_weights } => {
            let lpips = lpips_weights.unwrap_or_else(|| places.lpips_weights());
            reproduce::run_one(&run, !quiet, backend, lpips)?
        }
        Command::ImportDiligent { src, out, train_lights, test_lights, target_vertices } => {
            import_diligent::run(&src, &out, train_lights, test_lights, target_vertices)?;
        }
        Command::ImportCapture { capture, out, quiet } => capture::import(&capture, &out, !quiet)?,
        Command::ExportCapture { scene, out } => capture::export(&scene, &out)?,
        Command::Layers => {
            for c in layers::layers() {
                println!("{c}");
            }
        }
        Command::Run(command) => experiments::cli::run(command)?,
    }
    Ok(())
}
