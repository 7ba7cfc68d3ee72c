//! Training end to end on a tiny Lambertian sphere-over-plane scene (64 x 64, 4 views, 6
//! lights) with `spatial = "position"`: the loss drops for Single MLP and Disney, runs are
//! deterministic, a resumed run equals an uninterrupted one, a non-finite loss stops the run
//! naming the step and the parameters and keeps the last checkpoint, and eval writes renders
//! and finite metrics.

use burn::module::{ModuleMapper, Param};
use burn::tensor::Tensor;
use experiments::{Error, FitOptions, FitOutcome, RunConfig, fit};
use run_format::RunDir;
use scene::{MaterialSpec, SceneConfig, SceneSettings};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use test_support::TempDir;

/// The scene, generated once per test process.
fn scene() -> &'static Path {
    static SCENE: OnceLock<(TempDir, PathBuf)> = OnceLock::new();
    &SCENE
        .get_or_init(|| {
            let dir = TempDir::new("scene");
            let config = SceneConfig {
                mesh: test_support::mesh::write_sphere_over_plane(&dir.0, 16, 32),
                material: MaterialSpec::Lambert { albedo: [0.6, 0.3, 0.15] },
                seed: 3,
                settings: SceneSettings {
                    width: 64,
                    height: 64,
                    views: 4,
                    train_views: 2,
                    lights_per_view: 6,
                    train_lights: 4,
                    ..SceneSettings::default()
                },
                merl_dir: None,
            };
            let out = dir.0.join("scene");
            dataset_merl::generate_scene(&config, &out, false).unwrap();
            (dir, out)
        })
        .1
}

fn config(kind: &str, iterations: u64, extra: &str) -> RunConfig {
    let text = format!(
        "seed = 5\n[model]\nkind = \"{kind}\"\nwidth = 32\n[features]\nspatial = \"position\"\n\
         [train]\niterations = {iterations}\nbatch_size = 2048\nlearning_rate = 5e-4\n\
         lr_final = 1e-4\nwarmup_steps = 20\ncheckpoint_every = 20\nlog_every = 10\n{extra}"
    );
    let mut c = RunConfig::from_toml(&text, Path::new("test.toml")).unwrap();
    c.scene = Some(scene().to_path_buf());
    c
}

fn losses(run: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(RunDir::new(run).curve()).unwrap();
    text.lines().skip(1).map(|l| l.split(',').take(2).collect::<Vec<_>>().join(",")).collect()
}

fn loss_values(run: &Path) -> Vec<f32> {
    losses(run).iter().map(|l| l.split(',').nth(1).unwrap().parse().unwrap()).collect()
}

/// A small LPIPS network (AlexNet's kernel sizes, few channels) with deterministic weights.
fn small_lpips_weights(path: &Path) {
    let mut t = metrics::lpips::weights::Tensors::new();
    let (ks, channels) = ([11, 5, 3, 3, 3], [4, 4, 3, 3, 2]);
    let mut cin = 3;
    for k in 0..5 {
        let (c, n) = (channels[k], channels[k] * cin * ks[k] * ks[k]);
        let w = (0..n).map(|i| ((i * 7 % 13) as f32 - 6.0) / (6.0 * n as f32).sqrt()).collect();
        t.insert(format!("conv{}.weight", k + 1), (vec![c, cin, ks[k], ks[k]], w));
        t.insert(format!("conv{}.bias", k + 1), (vec![c], vec![0.05; c]));
        t.insert(format!("lin{k}.weight"), (vec![1, c, 1, 1], vec![0.5; c]));
        cin = c;
    }
    metrics::lpips::weights::write(path, &t).unwrap();
}

/// The evaluation reads the LPIPS file its process names (`EvalOptions`, the command line's
/// place), not a place of its own.
fn lpips_follows_the_process_place(run: &Path, weights: &Path) {
    small_lpips_weights(weights);
    let options =
        experiments::eval::EvalOptions { progress: false, lpips_weights: weights.to_path_buf() };
    let test = experiments::eval::eval(run, None, None, Default::default(), &options).unwrap();
    assert!(test.lpips.is_some_and(f64::is_finite), "{test:?}");
    assert_eq!(test.lpips_unavailable, None);
    let missing = experiments::eval::EvalOptions {
        lpips_weights: weights.with_extension("absent"),
        ..options
    };
    let test = experiments::eval::eval(run, None, None, Default::default(), &missing).unwrap();
    assert_eq!((test.lpips, test.lpips_unavailable.as_deref()), (None, Some("weights missing")));
}

#[test]
fn models_fit_the_scene_and_eval_scores_them() {
    let dir = TempDir::new("fit");
    let eval = "[eval]\nenergy_pairs = 64\nreciprocity_pairs = 500\n";
    let mut ceilings_seen = None;
    for kind in ["single_mlp", "disney", "additive_shared_enhanced"] {
        let run = dir.0.join(kind);
        let out = fit(&config(kind, 300, eval), &run, FitOptions::default()).unwrap();
        let FitOutcome::Finished { metrics, resumed_from: 0 } = out else { panic!("{out:?}") };
        assert_eq!(metrics.steps, 300);
        // The start-up (scene, caches, device, the first step) is part of the wall time.
        let startup = metrics.startup_seconds.expect("the start-up is recorded");
        assert!(startup > 0.0 && startup < metrics.wall_seconds + 60.0, "{kind}: {startup}");
        let l = loss_values(&run);
        let (first, zero) = (l[0], metrics.zero_prediction_loss);
        let last = l[l.len() - 3..].iter().sum::<f32>() / 3.0;
        // A Lambertian scene is easy: every model must end far below the loss of predicting
        // f = 0 (where a collapsed model sits), on the held-out validation lights too, and no
        // worse than it started (the data-driven output initialisation already starts near
        // the scene's albedo). The ground truth's validation loss (the noise floor of sigma
        // = 1e-3 on a bright Lambertian) is tiny.
        assert!(last < 0.01 * zero && last <= first, "{kind}: {first} -> {last}, zero {zero}");
        let (best, floor) = (metrics.best_val_loss.unwrap(), metrics.val_loss_floor.unwrap());
        assert!(best < 0.01 * f64::from(zero), "{kind}: validation {best}, zero {zero}");
        assert!(floor > 0.0 && floor < 1e-4 && floor < best, "{kind}: floor {floor}, {best}");
        assert!(RunDir::new(&run).weights().is_file());
        // A finished run is reported and skipped.
        let again = fit(&config(kind, 300, eval), &run, FitOptions::default()).unwrap();
        assert!(matches!(again, FitOutcome::AlreadyFinished(_)), "{again:?}");
        let test =
            experiments::eval::eval(&run, None, None, Default::default(), &Default::default())
                .unwrap();
        assert!(test.images == 4 && test.psnr.is_finite() && test.psnr > 15.0, "{kind}: {test:?}");
        assert!(test.flip.is_finite() && test.dssim.is_finite(), "{kind}: {test:?}");
        assert!(test.rmse_cbrt.is_some_and(f64::is_finite) && test.rmse_samples > 0);
        // Every score carries its settings, from the metric implementations' defaults.
        let s = test.settings.as_ref().expect("metric settings");
        assert!(s.images == test.images && s.pixels > 0, "{s:?}");
        assert!(s.flip.contains("67.02 pixels per degree"), "{}", s.flip);
        assert!(s.dssim.contains("sigma 1.5") && s.rmse_cbrt.contains("80 degrees"), "{s:?}");
        assert!(s.image_input.contains("clipped at"), "{}", s.image_input);
        // A semi-synthetic scene: the noise ceiling and the scores against the noise-free
        // renders are there; the ceiling is the same for every model (cached per scene after
        // the first evaluation, identical when recomputed).
        let ceiling = test.ceiling.clone().expect("noise ceiling");
        assert!(test.clean.as_ref().is_some_and(|c| c.psnr > test.psnr), "{kind}: {test:?}");
        let ceilings = ceilings_seen.get_or_insert_with(|| ceiling.clone());
        assert_eq!(*ceilings, ceiling, "{kind}");
        // No LPIPS weights at the default place: absent, with the reason.
        if test.lpips.is_none() {
            assert_eq!(test.lpips_unavailable.as_deref(), Some("weights missing"));
        }
        if kind == "single_mlp" {
            lpips_follows_the_process_place(&run, &dir.0.join("lpips.lpipsw"));
        }
        // The fitted BRDF of an albedo-(0.6, 0.3, 0.15) Lambertian scene conserves energy.
        let energy = test.energy.as_ref().expect("energy analysis");
        assert_eq!(energy.pairs, 64);
        assert!(energy.percent_above_one <= 10.0, "{kind}: {energy:?}");
        let recip = test.reciprocity_rmse.expect("reciprocity");
        assert!(recip.is_finite() && recip >= 0.0);
        let count = |d: &str| std::fs::read_dir(run.join(d)).map(|r| r.count()).unwrap_or(0);
        let additive = kind.starts_with("additive");
        let per_image = if additive { 4 } else { 2 };
        assert_eq!(count("renders"), per_image * test.images, "{kind}: renders");
        assert_eq!(count("flip"), test.images, "{kind}: one FLIP map per test image");
        assert_eq!(count("albedo"), if additive { 2 } else { 0 }, "{kind}: albedo maps");
        let first = std::fs::read_dir(run.join("flip")).unwrap().next().unwrap().unwrap();
        assert_eq!(image::open(first.path()).unwrap().width(), 64, "{kind}: FLIP map size");
        // The model fitted to the scene stays finite, forward and backward, on 2^14 adversarial
        // direction pairs and feature rows (issue 19: gradients of trained models).
        let c = config(kind, 300, eval).model;
        let device = brdf_neural::device::cpu_training();
        let weights = RunDir::new(&run).weights();
        let model = burn::module::Module::load_file(
            brdf_neural::BrdfModel::init(&c, &device).unwrap(),
            &weights,
        );
        let n = 1 << 14;
        let (l, v) = test_support::adversarial::direction_pairs(9, 0, n);
        let spatial = test_support::adversarial::spatial_rows(9, 0, n, c.spatial_dim);
        let samples = brdf_neural::Samples { spatial: &spatial, l: &l, v: &v };
        let checked =
            brdf_neural::finite_check::check_forward_backward(&model, &c, &samples, &device);
        let checked = checked.unwrap();
        assert!(checked.problem.is_none() && checked.gradients > 0, "{kind}: {checked:?}");
        if kind == "disney" {
            // The fitted material as a MERL file: the real format, readable back, finite,
            // and (a Lambertian scene, 300 steps) within a factor 2 of albedo / pi at normal
            // incidence: catches a wrong unit or channel scale (a factor of about 1,500).
            let out = run.join("fitted.binary");
            let point = experiments::export::SurfacePoint::Representative;
            let e = experiments::export::export_merl(&run, &out, point, None, None, false).unwrap();
            let merl = dataset_merl::MerlBrdf::read(&out).unwrap();
            assert_eq!(
                std::fs::metadata(&out).unwrap().len() as usize,
                dataset_merl::merl::FILE_BYTES
            );
            assert_eq!(merl.invalid_entries(), 0);
            let f = merl.bin(0, 0, 0).unwrap();
            let expected = [0.6, 0.3, 0.15].map(|a: f64| a / std::f64::consts::PI);
            for c in 0..3 {
                assert!(
                    f[c] > 0.5 * expected[c] && f[c] < 2.0 * expected[c],
                    "{e:?}: {f:?} vs {expected:?}"
                );
            }
        }
    }
}

#[test]
fn runs_are_deterministic_and_resume_is_exact() {
    let dir = TempDir::new("resume");
    // Validation every 10 steps: the plateau rule's state crosses the interruption too.
    let c = config("single_mlp", 60, "validate_every = 10\npatience = 20\n");
    let (a, b, r) = (dir.0.join("a"), dir.0.join("b"), dir.0.join("r"));
    fit(&c, &a, FitOptions::default()).unwrap();
    fit(&c, &b, FitOptions::default()).unwrap();
    assert_eq!(losses(&a), losses(&b));
    let stop = FitOptions { stop_after: Some(30), ..Default::default() };
    assert_eq!(fit(&c, &r, stop).unwrap(), FitOutcome::Stopped(30));
    // What a kill between a checkpoint's write and the removal of the older ones leaves: an
    // older complete checkpoint and a half-removed one. The resumed run removes both.
    let ckpt = |run: &Path, step: u32| run.join(format!("checkpoints/step-{step:09}"));
    std::fs::create_dir_all(ckpt(&r, 20)).unwrap();
    for f in ["model.bpk", "optim.bpk", "state.json"] {
        std::fs::copy(ckpt(&r, 30).join(f), ckpt(&r, 20).join(f)).unwrap();
    }
    std::fs::create_dir_all(ckpt(&r, 10)).unwrap();
    std::fs::copy(ckpt(&r, 30).join("model.bpk"), ckpt(&r, 10).join("model.bpk")).unwrap();
    let out = fit(&c, &r, FitOptions::default()).unwrap();
    let checkpoints = |run: &Path| -> Vec<String> {
        let d = std::fs::read_dir(run.join("checkpoints")).unwrap();
        let mut names: Vec<String> =
            d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    };
    assert_eq!(checkpoints(&r), checkpoints(&a), "the resumed run keeps other checkpoints");
    assert_eq!(checkpoints(&a), ["step-000000060"]);
    assert!(matches!(out, FitOutcome::Finished { resumed_from: 30, .. }), "{out:?}");
    assert_eq!(losses(&a), losses(&r));
    let curve = |run: &Path| std::fs::read_to_string(RunDir::new(run).curve()).unwrap();
    let strip_time = |text: String| -> Vec<String> {
        text.lines().map(|l| l.rsplit_once(',').unwrap().0.to_string()).collect()
    };
    assert_eq!(strip_time(curve(&a)), strip_time(curve(&r)), "validation losses too");
    assert!(curve(&a).starts_with("step,loss,val_loss,lr,wall_seconds\n"));
    // The files themselves are equal byte for byte: weights, and the last checkpoint's weights
    // and Adam state (burn's random parameter ids and hash-ordered optimizer tensors are made
    // deterministic).
    let bytes = |run: &Path, rel: &str| std::fs::read(run.join(rel)).unwrap();
    for rel in [
        "weights.bpk",
        "checkpoints/step-000000060/model.bpk",
        "checkpoints/step-000000060/optim.bpk",
    ] {
        assert!(bytes(&a, rel) == bytes(&b, rel), "{rel}: two fits differ");
        assert!(bytes(&a, rel) == bytes(&r, rel), "{rel}: the resumed fit differs");
    }
    // A kill between the last checkpoint and its curve: that checkpoint, the curve of the one
    // before, no weights or metrics. The resume trains no step and still writes the whole curve.
    let (full, run) = (curve(&r), RunDir::new(&r));
    let cut: String = full.lines().take(4).map(|l| format!("{l}\n")).collect();
    std::fs::write(run.curve(), cut).unwrap();
    std::fs::remove_file(run.metrics()).unwrap();
    std::fs::remove_file(run.weights()).unwrap();
    fit(&c, &r, FitOptions::default()).unwrap();
    assert_eq!(curve(&r), full, "the resumed run leaves the last checkpoint's curve");
    // A run directory another process works in is refused, naming that process.
    let busy = stdx::lock::DirLock::acquire(&r, "a test").unwrap();
    let msg = fit(&c, &r, FitOptions::default()).unwrap_err().to_string();
    assert!(msg.contains("in use by process") && msg.contains("(a test)"), "{msg}");
    drop(busy);
    // A different configuration in the same run directory is refused.
    let other = config("single_mlp", 61, "validate_every = 10\npatience = 20\n");
    let msg = fit(&other, &r, FitOptions::default()).unwrap_err().to_string();
    assert!(msg.contains("train.iterations"), "{msg}");
}

/// Batches selected on the device from tables of every point and record (a GPU's default:
/// spatial rows, encoded angles or geometry terms, weights, targets) train exactly as batches
/// gathered and encoded on the CPU: the same losses, validation losses and weights to the bit,
/// on the CPU backend, for angle features with and without random swaps, the parametric
/// geometry, and FMBRDF's.
#[test]
fn inputs_selected_on_the_device_train_like_gathered_ones() {
    let dir = TempDir::new("table");
    for (kind, swap) in
        [("single_mlp", false), ("single_mlp", true), ("disney", false), ("fmbrdf", false)]
    {
        let mut c = config(kind, 30, "validate_every = 10\n");
        if swap {
            c.model.angles.reciprocity = brdf_neural::Reciprocity::RandomSwap;
            c.model.angles.swap_probability = 0.5;
        }
        let name = format!("{kind}-{swap}");
        let (a, b) = (dir.0.join(format!("{name}-host")), dir.0.join(format!("{name}-table")));
        fit(&c, &a, FitOptions { inputs_on_device: Some(false), ..Default::default() }).unwrap();
        fit(&c, &b, FitOptions { inputs_on_device: Some(true), ..Default::default() }).unwrap();
        assert_eq!(losses(&a).len(), 3, "{name}");
        // step, loss, val_loss, lr: validation selects its rows from a table of its own.
        let curve = |run: &Path| -> Vec<String> {
            let text = std::fs::read_to_string(RunDir::new(run).curve()).unwrap();
            text.lines().map(|l| l.rsplit_once(',').unwrap().0.to_string()).collect()
        };
        assert!(curve(&a).iter().skip(1).all(|l| !l.contains(",,")), "{name}: validated");
        assert_eq!(curve(&a), curve(&b), "{name}: losses differ");
        let weights = |run: &Path| std::fs::read(run.join("weights.bpk")).unwrap();
        assert!(weights(&a) == weights(&b), "{name}: the fitted weights differ");
    }
}

/// Losses left on the device and read in windows (a GPU's default) train exactly as losses
/// read every step: the same curve, validation losses and weights to the bit, for windows that
/// divide nothing (7 steps), span several curve rows and validations (45), and with the run
/// interrupted and resumed in the middle of a window.
#[test]
fn losses_read_in_windows_train_like_losses_read_every_step() {
    let dir = TempDir::new("windows");
    let curve = |run: &Path| -> Vec<String> {
        let text = std::fs::read_to_string(RunDir::new(run).curve()).unwrap();
        text.lines().map(|l| l.rsplit_once(',').unwrap().0.to_string()).collect()
    };
    let weights = |run: &Path| std::fs::read(run.join("weights.bpk")).unwrap();
    for kind in ["single_mlp", "disney"] {
        let c = config(kind, 50, "validate_every = 15\npatience = 20\n");
        let every = dir.0.join(format!("{kind}-1"));
        let options = |reads: u64| FitOptions { compute: reads_every(reads), ..Default::default() };
        fit(&c, &every, options(1)).unwrap();
        assert_eq!(curve(&every).len(), 1 + 5 + 2, "{kind}: 5 log rows and 2 validation rows");
        for reads in [7, 45] {
            let run = dir.0.join(format!("{kind}-{reads}"));
            fit(&c, &run, options(reads)).unwrap();
            assert_eq!(curve(&every), curve(&run), "{kind}, reads every {reads}: curves differ");
            assert!(weights(&every) == weights(&run), "{kind}, reads every {reads}: weights");
        }
        let resumed = dir.0.join(format!("{kind}-resumed"));
        let stop =
            FitOptions { stop_after: Some(26), compute: reads_every(7), ..Default::default() };
        assert_eq!(fit(&c, &resumed, stop).unwrap(), FitOutcome::Stopped(26));
        fit(&c, &resumed, options(7)).unwrap();
        assert_eq!(curve(&every), curve(&resumed), "{kind}: the resumed run's curve differs");
        assert!(weights(&every) == weights(&resumed), "{kind}: the resumed run's weights");
    }
}

/// The compute settings reach the products and the record: a bf16 fit with the AMX tiles and
/// one on the AVX512-BF16 kernel differ in their weights (their sums run in other orders) on a
/// CPU that has both, and each run's `metrics.json` says which it trained with.
#[test]
fn compute_settings_reach_the_products_and_the_record() {
    let dir = TempDir::new("compute");
    let weights = |run: &Path| std::fs::read(run.join("weights.bpk")).unwrap();
    let c = config("single_mlp", 30, "matmul_precision = \"bf16\"\n");
    let mut runs = Vec::new();
    for amx in [true, false] {
        let run = dir.0.join(format!("amx-{amx}"));
        let compute = run_format::ComputeSettings { bf16_amx: amx, ..Default::default() };
        fit(&c, &run, FitOptions { compute: compute.clone(), ..Default::default() }).unwrap();
        let m = run_format::RunMetrics::read(&RunDir::new(&run).metrics()).unwrap();
        assert_eq!(m.compute, Some(compute), "metrics.json records the settings");
        runs.push(run);
    }
    use brdf_neural::precision::{MatmulPrecision, PrecisionSupport};
    let both = MatmulPrecision::bf16_on_amx();
    assert_eq!(weights(&runs[0]) != weights(&runs[1]), both, "AMX on this CPU: {both}");
}

#[test]
fn a_converged_run_stops_on_its_plateau_and_says_so() {
    let dir = TempDir::new("plateau");
    let run = dir.0.join("run");
    // Validation every 10 steps, two decays allowed (1e-3 -> 2.5e-4 -> 6.25e-5 >= 5e-5), a
    // budget far beyond what a Lambertian scene needs.
    let extra = "validate_every = 10\npatience = 40\nlr_decay = 0.25\nmin_improvement = 0.01\n";
    let mut c = config("disney", 5000, extra);
    c.train.learning_rate = 1e-3;
    c.train.lr_final = 5e-5;
    let out = fit(&c, &run, FitOptions::default()).unwrap();
    let FitOutcome::Finished { metrics, .. } = out else { panic!("{out:?}") };
    assert_eq!(metrics.stop_reason, Some(run_format::plateau::StopReason::Plateau));
    assert!(metrics.steps < 5000, "{metrics:?}");
    assert_eq!(metrics.lr_decays, 2, "{metrics:?}");
    assert!(metrics.val_records > 0 && metrics.best_val_loss.is_some_and(|v| v > 0.0));
    // Validation lights are held out of training: 1 of 4 training lights per training view.
    assert!(metrics.train_records > 2 * metrics.val_records, "{metrics:?}");
    // The same budget on a decaying schedule runs to the end, reported as such.
    let mut e = c.clone();
    e.train.schedule = run_format::config::Schedule::Exponential;
    e.train.iterations = 50;
    let out = fit(&e, &dir.0.join("exp"), FitOptions::default()).unwrap();
    let FitOutcome::Finished { metrics, .. } = out else { panic!("{out:?}") };
    assert_eq!(metrics.stop_reason, Some(run_format::plateau::StopReason::Budget));
    assert_eq!(metrics.steps, 50);
}

/// Turns the first float parameter (the first layer's weight) into NaN.
struct Poison(bool);

impl ModuleMapper for Poison {
    fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        if std::mem::replace(&mut self.0, true) {
            param
        } else {
            param.map(|t| t.add_scalar(f32::NAN))
        }
    }
}

/// The same error whether the loss is read every step or in windows of 16 steps left on the
/// device (the NaN at step 25 is found at the read after step 32, and steps 20 to 25 replayed).
#[test]
fn a_non_finite_loss_stops_the_run_and_keeps_the_last_checkpoint() {
    let dir = TempDir::new("nan");
    for reads in [1, 16] {
        let run = dir.0.join(format!("run-{reads}"));
        let hook = Box::new(|step: u64, model: brdf_neural::BrdfModel| {
            if step == 25 { burn::module::Module::map(model, &mut Poison(false)) } else { model }
        });
        let options =
            FitOptions { hook: Some(hook), compute: reads_every(reads), ..Default::default() };
        let err = fit(&config("disney", 100, ""), &run, options).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, Error::NonFinite { step: 25, .. }), "reads {reads}: {msg}");
        assert!(msg.contains("step 25"), "{msg}");
        assert!(
            msg.contains(
                "non-finite parameters in Parametric.mlp.layers.0.weight (96 non-finite);"
            ),
            "reads {reads}: {msg}"
        );
        assert!(msg.contains("step-000000020"), "{msg}");
        let worst = "the batch's worst input: output f = NaN at batch row 0: l = [";
        assert!(msg.contains(worst), "reads {reads}: {msg}");
        assert!(run.join("checkpoints/step-000000020/model.bpk").is_file());
        assert!(!RunDir::new(&run).weights().exists());
    }
}

/// A backend that fails inside a step (burn and CubeCL panic when a GPU runs out of memory or
/// is lost; a hook panics here) ends the fit with an error naming the step, the backend's
/// message and the checkpoint; the same command then resumes from that checkpoint and ends
/// with the uninterrupted run's weights, byte for byte.
#[test]
fn a_failing_backend_ends_with_an_error_and_the_run_resumes() {
    let dir = TempDir::new("fault");
    let c = config("single_mlp", 40, "");
    let (clean, faulty) = (dir.0.join("clean"), dir.0.join("faulty"));
    fit(&c, &clean, FitOptions::default()).unwrap();
    let hook = Box::new(|step: u64, model: brdf_neural::BrdfModel| {
        if step == 25 {
            panic!("out of memory (simulated): cannot allocate 2 GiB");
        }
        model
    });
    let options = FitOptions { hook: Some(hook), ..Default::default() };
    let err = fit(&c, &faulty, options).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, Error::BackendFault { step: 25, .. }), "{msg}");
    assert!(msg.contains("the flex backend failed: out of memory (simulated)"), "{msg}");
    assert!(msg.contains("step-000000020"), "{msg}");
    assert!(msg.contains("run the same command again to resume"), "{msg}");
    let out = fit(&c, &faulty, FitOptions::default()).unwrap();
    assert!(matches!(out, FitOutcome::Finished { resumed_from: 20, .. }), "{out:?}");
    let weights = |run: &Path| std::fs::read(run.join("weights.bpk")).unwrap();
    assert!(weights(&clean) == weights(&faulty), "the resumed run's weights differ");
}

#[test]
fn an_absurd_learning_rate_is_caught() {
    let dir = TempDir::new("lr");
    let run = dir.0.join("run");
    let c = config("single_mlp", 200, "schedule = \"constant\"\n");
    let mut c = c;
    c.train.learning_rate = 1e30;
    match fit(&c, &run, FitOptions::default()) {
        Err(Error::NonFinite { step, diagnosis, .. }) => {
            assert!(step < 200 && !diagnosis.is_empty());
        }
        other => panic!("expected a non-finite loss, got {other:?}"),
    }
}

#[test]
fn lbo_features_are_interpolated_and_cached() {
    let dir = TempDir::new("lbo");
    let text = "[features]\nspatial = \"lbo\"\n[features.lbo]\nk_max = 24\nfirst = 8\nblocks = 2\n\
                block_len = 4\n";
    let mut c = RunConfig::from_toml(text, Path::new("lbo.toml")).unwrap();
    c.scene = Some(scene().to_path_buf());
    assert_eq!(c.model.spatial_dim, 16);
    let cache = dir.0.join("cache");
    let first = experiments::train::training_data(&c, (&cache, None)).unwrap().train;
    let files: Vec<_> =
        std::fs::read_dir(&cache).unwrap().map(|e| e.unwrap().file_name()).collect();
    let table = files.iter().find(|f| f.to_string_lossy().starts_with("lbo-table-"));
    assert!(table.is_some(), "{files:?}");
    let again = experiments::train::training_data(&c, (&cache, None)).unwrap().train;
    assert_eq!(first.spatial, again.spatial);
    assert_eq!(first.point, again.point);
    // One row per distinct surface point: fewer rows than records (a pixel under many lights).
    let points = first.spatial.len() / 16;
    assert_eq!(first.spatial.len(), points * 16);
    assert!(points < first.len(), "{points} rows for {} records", first.len());
    assert!(first.point.iter().all(|&p| (p as usize) < points));
    // Eigenfunctions are divided by their range: interpolated values lie within [-1, 1].
    assert!(first.spatial.iter().all(|v| v.is_finite() && v.abs() <= 1.0 + 1e-5));
    // The features vary over the surface (not a constant column).
    let col0: Vec<f32> = first.spatial.iter().step_by(16).copied().collect();
    let (lo, hi) = col0.iter().fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(hi - lo > 0.1, "{lo} {hi}");
}

#[test]
fn fits_export_to_renderers() {
    use experiments::export::{ExportedMaterial, Format, export, gltf};
    use experiments::fitted::FittedRun;
    use run_format::config::SpatialKind;
    let dir = TempDir::new("export");
    for kind in ["ts", "disney"] {
        // A spatially uniform fit: the exported material is the fitted BRDF.
        let mut c = config(kind, 60, "");
        c.features.spatial = SpatialKind::Uniform;
        c.model.spatial_dim = 1;
        let run = dir.0.join(kind);
        fit(&c, &run, FitOptions::default()).unwrap();
        let out = dir.0.join(format!("{kind}-export"));
        let e = export(&run, &out, &Format::ALL, None, None).unwrap();
        assert!(e.uniform && e.test_pairs == 4, "{kind}: {e:?}");
        let t = e.round_trip.clone().expect("round trip");
        assert!(t.images == 4 && t.min_psnr_db >= 60.0, "{kind}: {t:?}");
        assert!(t.max_relative_brdf_difference < 1e-4, "{kind}: {t:?}");
        for f in &e.files {
            assert!(out.join(f).is_file(), "{kind}: {f} listed but missing");
        }
        let count = |d: &str, ext: &str| {
            std::fs::read_dir(out.join(d))
                .unwrap()
                .filter(|f| f.as_ref().unwrap().path().extension().unwrap() == ext)
                .count()
        };
        // One scene per test pair plus the object file, beside the mesh.
        assert_eq!(count("mitsuba", "xml"), 5, "{kind}");
        assert_eq!(count("pbrt", "pbrt"), 5, "{kind}");
        assert!(out.join("export.json").is_file());
        // The glTF asset parses and validates with the gltf crate, and holds exactly the
        // parameters of the fit.
        let name = if kind == "ts" { "torrance_sparrow" } else { "disney" };
        let path = out.join("gltf").join(format!("{name}.gltf"));
        let doc = ::gltf::Gltf::open(&path).unwrap();
        assert_eq!(doc.meshes().count(), 1);
        let fitted = FittedRun::open(&run, None, None).unwrap();
        let material = ExportedMaterial::from_run(&fitted).unwrap();
        assert_eq!(gltf::read(&path).unwrap(), material, "{kind}");
        khronos_validator(&path);
        // The standard fields carry the documented mapping.
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
        let m = &json["materials"][0];
        let row = material.row(0);
        let roughness = if kind == "ts" { row[0] } else { row[6] };
        let factor = m["pbrMetallicRoughness"]["roughnessFactor"].as_f64().unwrap();
        assert!((factor - roughness as f64).abs() < 1e-7, "{kind}: {factor} vs {roughness}");
        if kind == "ts" {
            let spec = &m["extensions"]["KHR_materials_specular"]["specularColorFactor"];
            for c in 0..3 {
                let base = m["pbrMetallicRoughness"]["baseColorFactor"][c].as_f64().unwrap();
                assert!((base - row[1 + c] as f64).abs() < 1e-7);
                let f0 = 0.04 * spec[c].as_f64().unwrap();
                assert!((f0 - row[4 + c] as f64).abs() < 1e-7, "F0 {f0} vs {}", row[4 + c]);
            }
        }
    }
    // A spatially varying fit: every column per vertex, read back exactly; the renderer's
    // interpolation of parameters (not features) shows in the round trip.
    let run = dir.0.join("ts-varying");
    fit(&config("ts", 60, ""), &run, FitOptions::default()).unwrap();
    let out = dir.0.join("ts-varying-export");
    let e = export(&run, &out, &[Format::Gltf], None, None).unwrap();
    assert!(!e.uniform);
    let t = e.round_trip.unwrap();
    assert!(t.min_psnr_db.is_finite() && t.min_psnr_db > 25.0, "{t:?}");
    let fitted = FittedRun::open(&run, None, None).unwrap();
    let back = gltf::read(&out.join("gltf/torrance_sparrow.gltf")).unwrap();
    assert_eq!(back, ExportedMaterial::from_run(&fitted).unwrap());
    assert!(!out.join("mitsuba").exists());
    // A neural fit has no glTF or pbrt-v4 material: asking for one is an error that says what
    // to use, and nothing is written; all formats give the Mitsuba 3 scene for the Python
    // package's `neural_brdf` plugin, with the portable weights beside it.
    let run = dir.0.join("neural");
    fit(&config("single_mlp", 20, ""), &run, FitOptions::default()).unwrap();
    let out = dir.0.join("neural-export");
    let err = export(&run, &out, &[Format::Gltf], None, None).unwrap_err().to_string();
    assert!(err.contains("export-merl") && err.contains("Mitsuba 3 only"), "{err}");
    assert!(!out.exists());
    let e = export(&run, &out, &Format::ALL, None, None).unwrap();
    assert_eq!(e.model, "single_mlp");
    for f in ["object.xml", "mesh.ply", "model.json", "model.safetensors"] {
        assert!(e.files.contains(&format!("mitsuba/{f}")), "{f}: {:?}", e.files);
    }
    let object = std::fs::read_to_string(out.join("mitsuba/object.xml")).unwrap();
    assert!(object.contains("<bsdf type=\"neural_brdf\">"), "{object}");
    assert!(!out.join("gltf").exists() && !out.join("pbrt").exists());
}

/// Runs the Khronos glTF validator on `path` when `NEURAL_BRDF_GLTF_VALIDATOR` names a folder
/// where `npm install --prefix <folder> gltf-validator` put it (`.ci/run` does so where npm
/// reaches its registry): no error and no warning allowed. Without it, says so and returns.
fn khronos_validator(path: &Path) {
    let Some(prefix) = std::env::var_os("NEURAL_BRDF_GLTF_VALIDATOR") else {
        eprintln!("Khronos glTF validator skipped: NEURAL_BRDF_GLTF_VALIDATOR is not set");
        return;
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/support/validate_gltf.js");
    let out = std::process::Command::new("node")
        .arg(script)
        .arg(path)
        .env("NODE_PATH", Path::new(&prefix).join("node_modules"))
        .output()
        .expect("node runs");
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{report}{}", String::from_utf8_lossy(&out.stderr));
    assert!(report.contains("\"warnings\": 0"), "{report}");
}

/// The default compute settings with the training loss read every `reads` steps.
fn reads_every(reads: u64) -> run_format::ComputeSettings {
    run_format::ComputeSettings { loss_reads: Some(reads), ..Default::default() }
}
