//! A whole sweep end to end on a miniature profile (Spot from the shared data at 24 px, three
//! models, the NOL ablation and the run-time curve of their snapshots): scenes, LBO tables,
//! runs, eval and every table and figure, with the noise ceiling and the note on unconverged
//! runs; a second sweep finds every run finished (content addressing); `--emit-jobs` writes
//! one command per unfinished run. The built-in smoke profile end to end, with its HTML report
//! checked (and opened in headless Chromium where installed).

use std::path::PathBuf;
use sweep::{Execution, SweepProfile};

use test_support as support;

fn shared_data() -> Option<PathBuf> {
    support::shared_data_root("")
}

/// The miniature profile: Spot from the shared data (the `data:` mesh path), three models, the
/// NOL ablation and the run-time curve.
fn mini_profile() -> String {
    support::TinyProfile::new("mini", "test", 1).mesh("data:meshes/spot.obj").with(
        r#"[run.train]
iterations = 12
batch_size = 512
warmup_steps = 2
checkpoint_every = 6
log_every = 3
validate_every = 3
patience = 6
[run.eval]
energy_pairs = 4
reciprocity_pairs = 200
[sweep]
models = ["single_mlp", "disney", "additive_shared_enhanced"]
ablations = ["nol"]
runtime_curve = true
"#,
    )
}

#[test]
fn a_miniature_sweep_produces_every_table_and_resumes() {
    let Some(data) = shared_data() else { return };
    let tmp = test_support::TempDir::new("sweep");
    // A hostile output path: spaces, non-ASCII letters, a quote and an emoji (issue 19).
    let out = tmp.0.join("out dir/Ünïcødé it's ✓ 🌈");
    let profile = SweepProfile::parse(&mini_profile(), "mini.toml").unwrap();
    let s = sweep::sweep(&profile, &out, &data, &Execution::InProcess(Default::default())).unwrap();
    assert!(s.failed.is_empty(), "{:?}", s.failed);
    // 3 Table 1 runs (with snapshots: the run-time curve) + 1 NOL (single MLP: of the profile's
    // models the only one among the paper's NOL rows).
    assert_eq!(s.runs.len(), 3 + 1);
    assert_eq!((s.completed, s.skipped, s.scenes_generated), (4, 0, 1));
    let c = sweep::collect(&[out.join("runs")], &out, "mini").unwrap();
    assert_eq!(c.runs, 4);
    let t1 = std::fs::read_to_string(out.join("tables/table1.md")).unwrap();
    for name in [
        "Single MLP",
        "Disney",
        "Enh. Add. Shared",
        "MERL-derived (NBRDF)",
        "mini",
        "Ground truth (noise ceiling)",
        "below ceiling",
        "Not converged: 3 of 3 runs",
        "Our protocol: the object mask",
    ] {
        assert!(t1.contains(name), "{name} missing from\n{t1}");
    }
    // Both protocols: Table 1 and the per-object PSNR under the paper's too, captioned so, and
    // the paper's Table 1 beside ours with the ranking agreement and the findings.
    for (f, needles) in [
        ("table1-paper.md", &["The paper's protocol: the whole frame", "RMSE∛"][..]),
        ("per-object-psnr-paper.md", &["The paper's protocol", "Mean"][..]),
        ("per-object-psnr.md", &["Our protocol"][..]),
        (
            "paper-vs-ours.md",
            &["## Level", "## Ranking agreement", "## The paper's findings", "441 of 441 cells"][..],
        ),
    ] {
        let text = std::fs::read_to_string(out.join("tables").join(f)).unwrap();
        for n in needles {
            assert!(text.contains(n), "{n} missing from {f}:\n{text}");
        }
    }
    let runtime = std::fs::read_to_string(out.join("tables/runtime.md")).unwrap();
    assert!(runtime.contains("s to -0.5 dB") && runtime.contains("Single MLP"), "{runtime}");
    for f in [
        "tables/table1.tex",
        "tables/table1-noise-free.md",
        "tables/runtime.tex",
        "tables/nol.md",
        "tables/energy.md",
        "tables/reciprocity.md",
        "tables/per-object-rmse.md",
        "tables/runtime.md",
        "figures/qualitative-spot__blue-acrylic.png",
        "figures/split-spot__blue-acrylic.png",
        "figures/runtime-psnr.png",
        "figures/spheres-spot__blue-acrylic.png",
        "figures/slices-spot__blue-acrylic.png",
        "figures/slices-log-spot__blue-acrylic.png",
        "figures/albedo-spot__blue-acrylic.png",
        "figures/validity-spot__blue-acrylic.png",
    ] {
        assert!(out.join(f).is_file(), "{f} not written");
    }
    // Everything is finished: a second sweep runs nothing.
    let again =
        sweep::sweep(&profile, &out, &data, &Execution::InProcess(Default::default())).unwrap();
    assert_eq!((again.completed, again.skipped, again.scenes_kept), (0, 4, 1));
    // A changed configuration is a new run; --emit-jobs lists exactly the unfinished one.
    let changed =
        SweepProfile::parse(&mini_profile().replace("seed = 1", "seed = 2"), "mini2.toml").unwrap();
    let jobs = out.join("jobs.txt");
    let how = Execution::Emit { file: jobs.clone(), command: vec!["run-one".into()] };
    let e = sweep::sweep(&changed, &out, &data, &how).unwrap();
    assert_eq!(e.emitted, 4);
    let text = std::fs::read_to_string(&jobs).unwrap();
    assert_eq!(text.lines().count(), 4);
    assert!(text.lines().all(|l| l.starts_with("run-one '/")), "{text}");
    // The shell gives the run directory back whole.
    let line = text.lines().next().unwrap();
    let arg = line.strip_prefix("run-one ").unwrap();
    let echoed = std::process::Command::new("sh")
        .args(["-c", &format!("printf '%s' {arg}")])
        .output()
        .unwrap();
    let dir = PathBuf::from(String::from_utf8(echoed.stdout).unwrap());
    assert!(dir.starts_with(&out) && dir.join("config.toml").is_file(), "{}", dir.display());
}

/// The real-world half in miniature: the DiLiGenT ball of the shared data imported as the
/// profile's capture, two models briefly trained, Table 1 with its real-world column in both
/// protocols and the finding on real captures checked against a MERL-derived scene's gap.
#[test]
fn a_real_capture_sweep_gives_the_real_world_column() {
    let Some(data) = shared_data() else { return };
    let tmp = test_support::TempDir::new("real-sweep");
    let out = tmp.0.join("out");
    let text = mini_profile()
        .replace("ablations = [\"nol\"]\nruntime_curve = true\n", "")
        .replace("\"additive_shared_enhanced\"", "")
        .replace("lights = 4\n", "lights = 4\ncaptures = [\"diligent:ball\"]\n");
    let profile = SweepProfile::parse(&text, "mini-real.toml").unwrap();
    let s = sweep::sweep(&profile, &out, &data, &Execution::InProcess(Default::default())).unwrap();
    assert!(s.failed.is_empty(), "{:?}", s.failed);
    assert_eq!(s.runs.len(), 4, "2 models x (1 generated scene + the ball)");
    sweep::collect(&[out.join("runs")], &out, "mini-real").unwrap();
    let read = |f: &str| std::fs::read_to_string(out.join("tables").join(f)).unwrap();
    for f in ["table1.md", "table1-paper.md"] {
        let t = read(f);
        assert!(t.contains("| DiLiGenT"), "{f} has no DiLiGenT column:\n{t}");
        assert!(t.contains("Real captures (the real-world columns): DiLiGenT"), "{t}");
    }
    assert!(read("per-object-psnr-paper-diligent.md").contains("| ball |"));
    let cmp = read("paper-vs-ours.md");
    let real = cmp.lines().find(|l| l.contains("On real data the purely neural")).unwrap();
    assert!(real.contains("on DiLiGenT") && !real.contains("not checked"), "{real}");
    // The ball's run scored both protocols; a capture has no noise-free image.
    let run = s.runs.iter().find(|d| d.to_string_lossy().contains("ball__disney")).unwrap();
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("metrics.json")).unwrap()).unwrap();
    let settings = m.pointer("/test/paper/settings/image_input").unwrap().as_str().unwrap();
    assert!(settings.contains("outside the object mask set to 0"), "{settings}");
    assert!(m.pointer("/test/clean").is_none() && m.pointer("/test/paper/scores/psnr").is_some());
}

/// The built-in smoke profile (the shipped Spot mesh, no shared data needed): all 9 models and
/// every ablation on 2 scenes, every table and figure written, nothing failed.
#[test]
fn the_smoke_profile_runs_end_to_end() {
    let tmp = test_support::TempDir::new("smoke");
    let out = tmp.0.clone();
    let profile = SweepProfile::load("smoke").unwrap();
    let s = sweep::sweep(
        &profile,
        &out,
        std::path::Path::new("data"),
        &Execution::InProcess(Default::default()),
    )
    .unwrap();
    assert!(s.failed.is_empty(), "{:?}", s.failed);
    assert_eq!((s.runs.len(), s.completed), (46, 46));
    let c = sweep::collect(&[out.join("runs")], &out, "smoke").unwrap();
    assert_eq!(c.runs, 46);
    for t in [
        "table1",
        "nol",
        "reciprocity",
        "reciprocity-deltas",
        "angles",
        "nerfactor",
        "energy",
        "time",
    ] {
        let md = std::fs::read_to_string(out.join(format!("tables/{t}.md"))).unwrap();
        assert!(md.contains("Profile: smoke"), "{t}:\n{md}");
        if t == "table1" {
            // Every model's cell was run (the ceiling row has no RMSE, gap or time).
            let models = md.lines().filter(|l| l.starts_with("| ") && !l.contains("Ground truth"));
            assert!(models.clone().all(|l| !l.contains("| – |")), "not run:\n{md}");
            assert!(md.contains("| Ground truth (noise ceiling) |"), "{md}");
        }
        assert!(out.join(format!("tables/{t}.tex")).is_file());
    }
    // Where the time went: the sweep's phases and each model's runs.
    let time = std::fs::read_to_string(out.join("tables/time.md")).unwrap();
    for row in ["| scenes", "| LBO features", "| runs, 1 at a time", "| training, FMBRDF |"] {
        assert!(time.contains(row), "{row} missing from\n{time}");
    }
    assert!(time.contains("| evaluation, every model | ") && time.contains("| 46 |"), "{time}");
    // Every table of the paper beside ours, with the paper's rows, our value and our spread
    // over the two objects in each row's first column group.
    for (t, rows) in [
        ("table1", 9),
        ("nol", 3),
        ("reciprocity-rmse", 6),
        ("energy", 7),
        ("reciprocity-quality", 6),
        ("view-light", 3),
        ("nerfactor", 2),
    ] {
        let f = format!("tables/paper-vs-ours-{t}-merl.md");
        let md = std::fs::read_to_string(out.join(&f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert!(md.contains("± (objects)") && md.contains("paper"), "{f}:\n{md}");
        let body: Vec<Vec<&str>> = md
            .lines()
            .filter(|l| l.starts_with("| ") && !l.starts_with("| Model") && !l.starts_with("| :"))
            .map(|l| l.split('|').map(str::trim).collect())
            .collect();
        assert_eq!(body.len(), rows, "{f}:\n{md}");
        for cells in &body {
            // cells[0] is empty (before the first bar), cells[1] the label.
            for (what, c) in [("ours", cells[2]), ("spread", cells[3]), ("paper", cells[4])] {
                let n = c.trim_matches('*').trim_start_matches('+');
                assert!(n.parse::<f64>().is_ok(), "{f}, {}: {what} {c:?}", cells[1]);
            }
        }
    }
    let cmp = std::fs::read_to_string(out.join("tables/paper-vs-ours.md")).unwrap();
    assert_eq!(cmp.matches("\n* **").count(), 11, "the 11 findings:\n{cmp}");
    // The mapping makes every purely neural model it ran on (the paper's three) exactly
    // reciprocal.
    let recip = std::fs::read_to_string(out.join("tables/reciprocity.md")).unwrap();
    let neural = ["| Single MLP |", "| Add. Sep. |", "| Add. Shared |"];
    for line in recip.lines().filter(|l| neural.iter().any(|n| l.starts_with(n))) {
        let mapping = line.trim_end_matches('|').rsplit('|').next().unwrap().trim();
        assert_eq!(mapping.trim_matches('*'), "0.0000", "{line}");
    }
    // The HTML report: well formed, every link resolves, a page per run, Table 1 ranked with
    // its noise ceiling.
    let report = out.join("report");
    let index = report.join("index.html");
    let mut pages: Vec<PathBuf> = std::fs::read_dir(report.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "html"))
        .collect();
    assert_eq!(pages.len(), 46);
    pages.push(index.clone());
    for page in &pages {
        let html = std::fs::read_to_string(page).unwrap();
        report::html::check_well_formed(&html).unwrap_or_else(|e| panic!("{page:?}: {e}"));
        for link in report::html::links(&html) {
            assert!(page.parent().unwrap().join(&link).exists(), "{page:?} links to {link}");
        }
    }
    let html = std::fs::read_to_string(&index).unwrap();
    assert!(html.contains("Ground truth (noise ceiling)") && html.contains("class=\"best\""));
    assert!(html.contains("qualitative-") && html.contains("runs/"), "figures and runs linked");
    for f in ["spheres-", "slices-log-", "albedo-", "validity-"] {
        assert!(html.contains(f), "BRDF plot {f} not in the report");
    }
    let run_html = std::fs::read_to_string(&pages[0]).unwrap();
    assert!(run_html.contains("How the scores were computed"), "metric settings on the run page");
    assert!(run_html.contains("computed (the paper"), "the paper's protocol on the run page");
    assert!(html.contains("The paper beside ours") && html.contains("Kendall"), "{html}");
    assert!(run_html.contains("pixels per degree") && run_html.contains("-curve-steps.png"));
    // A collect missing one run: the model's means cover one object fewer than the others',
    // so they print with a dagger, take no mark, and the legend names the missing object.
    let dropped = |d: &PathBuf| {
        let n = d.file_name().unwrap().to_string_lossy().into_owned();
        n.starts_with("spot__gold-metallic-paint__additive_separate__default__")
    };
    assert_eq!(s.runs.iter().filter(|d| dropped(d)).count(), 1);
    let kept: Vec<PathBuf> = s.runs.iter().filter(|d| !dropped(d)).cloned().collect();
    let partial = tmp.0.join("partial");
    sweep::collect(&kept, &partial, "smoke").unwrap();
    let t1 = std::fs::read_to_string(partial.join("tables/table1.md")).unwrap();
    let row = t1.lines().find(|l| l.starts_with("| Add. Sep. |")).unwrap();
    assert!(row.contains('†') && !row.contains("**") && !row.contains("<u>"), "{row}");
    assert!(t1.contains("Add. Sep. without spot__gold-metallic-paint"), "{t1}");
    let tex = std::fs::read_to_string(partial.join("tables/table1.tex")).unwrap();
    assert!(tex.contains("\\dagger"), "{tex}");
    browser_check(&index, "smoke-report-index");
    browser_check(&pages[0], "smoke-report-run");
}

/// Opens `page` in headless Chromium, when installed (`apt-get install chromium`; or
/// `NEURAL_BRDF_CHROMIUM` names the binary): every image must load, and a screenshot goes to
/// `target/tmp/<name>.png`. Without Chromium, says so and returns.
fn browser_check(page: &std::path::Path, name: &str) {
    let chromium = std::env::var_os("NEURAL_BRDF_CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    if !chromium.is_file() {
        eprintln!("browser check skipped: no Chromium at {}", chromium.display());
        return;
    }
    let profile = test_support::TempDir::new("chromium");
    let run = |extra: &[String], url: String| {
        let out = std::process::Command::new(&chromium)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
            ])
            .arg(format!("--user-data-dir={}", profile.0.display()))
            .args(extra)
            .arg(url)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    // Every image of the page loads (a frame inspected by a checker page beside it).
    let template = include_str!("support/check_images.html");
    let file = page.file_name().unwrap().to_string_lossy();
    let checker = page.with_file_name(format!(".check-{file}"));
    std::fs::write(&checker, template.replace("PAGE", &file)).unwrap();
    let flags = ["--allow-file-access-from-files", "--virtual-time-budget=20000", "--dump-dom"];
    let dom = run(&flags.map(String::from), format!("file://{}", checker.display()));
    std::fs::remove_file(&checker).unwrap();
    let result = dom
        .split("<pre id=\"result\">IMAGES ")
        .nth(1)
        .unwrap_or_else(|| panic!("no result:\n{dom}"));
    let (count, broken) = result.split_once(" BROKEN ").unwrap();
    assert!(count.parse::<usize>().unwrap() > 0, "{result}");
    assert!(broken.starts_with("[]"), "images that did not load: {broken}");
    let shot = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}.png"));
    let flags = ["--window-size=1280,2400".to_string(), format!("--screenshot={}", shot.display())];
    run(&flags, format!("file://{}", page.display()));
    assert!(std::fs::metadata(&shot).unwrap().len() > 10_000, "{shot:?}");
}
