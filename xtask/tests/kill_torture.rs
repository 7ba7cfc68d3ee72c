//! Kill -9 torture of `reproduce-tables` (issue 19): a miniature sweep (one scene, four models,
//! snapshots for the run-time curve, the NOL ablation) is run once uninterrupted, then again in
//! another directory killed with SIGKILL at random moments (in this process or as the parent of
//! `--jobs 2` children) and resumed each time. Checked after every kill: no run that had
//! finished was written again (its `metrics.json` and `weights.bpk` keep their inode and
//! modification time), and no child outlives its killed parent for long. Checked at the end:
//! every file of the tortured sweep equals the uninterrupted one's (byte for byte, except the
//! wall-clock figures: timing keys of JSON files, `*seconds*` CSV columns and the `time (s)`
//! table columns are masked, and the run-time table, its plots and the HTML report, which are
//! about time, are skipped), and no temporary file is left anywhere.
//!
//! CI runs a cheap version on every run: a tiny sweep (one 24 px scene, two models) killed 5
//! times. The 20-kill version on the larger sweep takes minutes and is opt-in:
//! `cargo test -p xtask --test kill_torture -- --ignored --nocapture`
//! (`NEURAL_BRDF_TORTURE_KILLS` sets the number of kills of either).
//!
//! A third test runs a sweep on a 3 MiB tmpfs (a user namespace; skipped, saying why, where
//! `unshare` cannot mount one): the full disk must end the sweep with an error that says so and
//! names a file, and the results already there must be unchanged.

use serde_json::Value;
use std::collections::BTreeMap;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The tortured sweep: one small scene, four models, snapshots, the NOL ablation.
fn profile() -> String {
    let head = "kill -9 torture: one small scene, four models, snapshots, the NOL ablation";
    test_support::TinyProfile::new("torture", head, 3).scene(64, 4, 12).with(
        r#"[run.train]
profile = "quick"
iterations = 200
batch_size = 1024
warmup_steps = 10
checkpoint_every = 25
log_every = 5
validate_every = 10
patience = 20
[run.eval]
energy_pairs = 4
reciprocity_pairs = 200
[sweep]
models = ["rp", "disney", "single_mlp", "additive_shared_enhanced"]
ablations = ["nol"]
runtime_curve = true
"#,
    )
}

/// The cheap torture of every CI run: one tiny scene, two models, the NOL ablation.
fn tiny() -> String {
    test_support::tiny_profile(
        "tiny-torture",
        "kill -9 torture in CI: one tiny scene, two models",
        3,
        r#"[run.train]
profile = "quick"
iterations = 60
batch_size = 512
warmup_steps = 5
checkpoint_every = 10
log_every = 5
validate_every = 10
patience = 20
[run.eval]
energy_pairs = 4
reciprocity_pairs = 200
[sweep]
models = ["disney", "single_mlp"]
ablations = ["nol"]
"#,
    )
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn start(profile: &Path, out: &Path, jobs: usize, log: &Path) -> Child {
    let log = std::fs::File::create(log).unwrap();
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("reproduce-tables")
        .arg("--profile")
        .arg(profile)
        .arg("--out")
        .arg(out)
        .arg("--jobs")
        .arg(jobs.to_string())
        .stdout(Stdio::null())
        .stderr(log.try_clone().unwrap())
        .spawn()
        .expect("start xtask")
}

/// Every file under `root`, by path relative to it.
fn files(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries.flatten() {
            let p = e.path();
            if e.file_type().unwrap().is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// Whether a relative path is left out of the comparison (about time, or per process).
fn skipped(rel: &Path) -> bool {
    let s = rel.to_string_lossy();
    let name = rel.file_name().unwrap().to_string_lossy();
    // `all.md` concatenates the other tables, the run-time one included (compared one by one).
    // `timing.json` and the time table are where the time went, and which sweep did the runs
    // (a resumed sweep completes fewer): timing through and through.
    s.starts_with("report/")
        || name == ".lock"
        || name == "sweep.log"
        || name == "all.md"
        || name.starts_with("runtime")
        || name == "timing.json"
        || name.starts_with("time.")
}

fn is_timing_key(k: &str) -> bool {
    ["second", "phase", "time", "wall"].iter().any(|w| k.contains(w))
}

fn strip_timing(v: &mut Value) {
    match v {
        Value::Object(m) => {
            m.retain(|k, _| !is_timing_key(k));
            m.values_mut().for_each(strip_timing);
        }
        Value::Array(a) => a.iter_mut().for_each(strip_timing),
        _ => {}
    }
}

/// Drops the CSV columns whose header names seconds.
fn strip_csv(text: &str) -> String {
    let mut lines = text.lines();
    let Some(header) = lines.next() else { return String::new() };
    let keep: Vec<bool> = header.split(',').map(|h| !h.contains("second")).collect();
    let pick = |l: &str| {
        l.split(',').zip(&keep).filter(|(_, k)| **k).map(|(c, _)| c).collect::<Vec<_>>().join(",")
    };
    std::iter::once(pick(header)).chain(lines.map(pick)).collect::<Vec<_>>().join("\n")
}

/// Masks the cells of `time (s)` columns in Markdown (`|`) and LaTeX (`&`) tables.
fn mask_time_columns(text: &str) -> String {
    let mut column: Option<(char, usize, usize)> = None;
    let mut out = Vec::new();
    for line in text.lines() {
        let sep = if line.trim_start().starts_with('|') { '|' } else { '&' };
        let cells: Vec<&str> = line.split(sep).collect();
        if let Some(i) = cells.iter().position(|c| c.contains("time (s)")) {
            column = Some((sep, i, cells.len()));
        }
        match column {
            Some((s, i, n)) if s == sep && cells.len() == n => {
                let mut c: Vec<String> = cells.iter().map(|c| c.to_string()).collect();
                if !c[i].contains("time (s)") {
                    c[i] = " T ".into();
                }
                out.push(c.join(&sep.to_string()));
            }
            _ => {
                if line.trim().is_empty() {
                    column = None;
                }
                out.push(line.to_string());
            }
        }
    }
    out.join("\n")
}

/// The comparable content of a file: bytes, or text with the sweep's own path and the timing
/// figures taken out.
fn content(root: &Path, rel: &Path) -> Vec<u8> {
    let bytes = std::fs::read(root.join(rel)).unwrap();
    let ext = rel.extension().map(|e| e.to_string_lossy().into_owned()).unwrap_or_default();
    if !["json", "csv", "md", "tex", "toml"].contains(&ext.as_str()) {
        return bytes;
    }
    let text = String::from_utf8(bytes).unwrap().replace(&root.display().to_string(), "<out>");
    let text = match ext.as_str() {
        "json" => {
            let mut v: Value = serde_json::from_str(&text).unwrap();
            strip_timing(&mut v);
            v.to_string()
        }
        "csv" => strip_csv(&text),
        "md" | "tex" => mask_time_columns(&text),
        _ => text,
    };
    text.into_bytes()
}

/// Asserts that `b` holds the same results as `a`.
fn assert_same_results(a: &Path, b: &Path) -> usize {
    let fa: Vec<PathBuf> = files(a).into_iter().filter(|p| !skipped(p)).collect();
    let fb: Vec<PathBuf> = files(b).into_iter().filter(|p| !skipped(p)).collect();
    let only_a: Vec<&PathBuf> = fa.iter().filter(|p| !fb.contains(p)).collect();
    let only_b: Vec<&PathBuf> = fb.iter().filter(|p| !fa.contains(p)).collect();
    assert!(
        only_a.is_empty() && only_b.is_empty(),
        "the tortured sweep holds other files than the uninterrupted one: missing {only_a:?}, \
         extra {only_b:?}"
    );
    let differing: Vec<String> = fa
        .iter()
        .filter_map(|rel| {
            let (ca, cb) = (content(a, rel), content(b, rel));
            (ca != cb).then(|| format!("{}: {}", rel.display(), first_difference(&ca, &cb)))
        })
        .collect();
    assert!(
        differing.is_empty(),
        "{} of {} files differ from the uninterrupted sweep's (timing masked):\n{}",
        differing.len(),
        fa.len(),
        differing.join("\n")
    );
    fa.len()
}

/// Where two comparable contents first differ: the line of each (text), or the byte offset
/// and the sizes (binary); the failure message quotes it, so that a rare failure in CI says
/// what differed, not only where.
fn first_difference(a: &[u8], b: &[u8]) -> String {
    match (std::str::from_utf8(a), std::str::from_utf8(b)) {
        (Ok(ta), Ok(tb)) => {
            let (la, lb): (Vec<&str>, Vec<&str>) = (ta.lines().collect(), tb.lines().collect());
            let i = la.iter().zip(&lb).position(|(x, y)| x != y).unwrap_or(la.len().min(lb.len()));
            let at = |l: &[&str]| l.get(i).map_or("<end>".to_string(), |s| format!("{s:?}"));
            format!(
                "{} and {} lines; line {} is {} uninterrupted, {} tortured",
                la.len(),
                lb.len(),
                i + 1,
                at(&la),
                at(&lb)
            )
        }
        _ => {
            let i = a.iter().zip(b).position(|(x, y)| x != y).unwrap_or(a.len().min(b.len()));
            format!("{} and {} bytes, first difference at byte {i}", a.len(), b.len())
        }
    }
}

/// Temporary files ([`stdx::fs::is_temporary`]) anywhere under `root`.
fn temporaries(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries.flatten() {
            if stdx::fs::is_temporary(&e.file_name().to_string_lossy()) {
                out.push(e.path());
            } else if e.file_type().unwrap().is_dir() {
                stack.push(e.path());
            }
        }
    }
    out
}

/// The evaluated runs and the identity (inode, mtime) of their result files.
fn finished_runs(out: &Path) -> BTreeMap<PathBuf, Vec<(u64, i64, i64)>> {
    let mut m = BTreeMap::new();
    let Ok(entries) = std::fs::read_dir(out.join("runs")) else { return m };
    for e in entries.flatten() {
        let run = e.path();
        let Ok(text) = std::fs::read_to_string(run.join("metrics.json")) else { continue };
        let Ok(v) = serde_json::from_str::<Value>(&text) else { continue };
        if v.get("test").is_none_or(Value::is_null) {
            continue;
        }
        let ids = ["metrics.json", "weights.bpk"]
            .iter()
            .map(|f| {
                let md = std::fs::metadata(run.join(f)).unwrap();
                (md.ino(), md.mtime(), md.mtime_nsec())
            })
            .collect();
        m.insert(run, ids);
    }
    m
}

/// Which stage a sweep stopped in, read from what it left.
fn stage(out: &Path) -> &'static str {
    let scenes = std::fs::read_dir(out.join("scenes"))
        .map(|d| d.flatten().filter(|e| e.path().join("manifest.json").is_file()).count())
        .unwrap_or(0);
    if scenes == 0 {
        return "scene generation";
    }
    let lbo = std::fs::read_dir(out.join("cache")).is_ok_and(|d| {
        d.flatten().any(|e| e.file_name().to_string_lossy().starts_with("lbo-table"))
    });
    if !lbo {
        return "LBO caching";
    }
    let runs: Vec<PathBuf> = std::fs::read_dir(out.join("runs"))
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    let trained = |r: &PathBuf| r.join("weights.bpk").is_file() && r.join("metrics.json").is_file();
    let evaluated = finished_runs(out);
    // A run trained but not evaluated was being evaluated (runs are evaluated right after
    // their training); else one with checkpoints but no weights was training.
    if runs.iter().any(|r| trained(r) && !evaluated.contains_key(r)) {
        return "evaluation";
    }
    if runs.is_empty() || !runs.iter().all(trained) {
        let started = runs.iter().any(|r| r.join("checkpoints").is_dir());
        return if started { "training" } else { "run preparation" };
    }
    if !out.join("report/index.html").is_file() {
        return "tables and figures";
    }
    "finished"
}

/// Waits until no process holds a run directory's lock (the children of a killed parent
/// notice within half a second).
fn wait_for_children(out: &Path) -> Duration {
    let t = Instant::now();
    let runs: Vec<PathBuf> = std::fs::read_dir(out.join("runs"))
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    for r in runs {
        loop {
            match stdx::lock::DirLock::acquire(&r, "torture check") {
                Ok(_) => break,
                Err(_) if t.elapsed() < Duration::from_secs(10) => {
                    std::thread::sleep(Duration::from_millis(50))
                }
                Err(e) => panic!("a child outlived its killed parent: {e}"),
            }
        }
    }
    t.elapsed()
}

/// The number of kills: `NEURAL_BRDF_TORTURE_KILLS`, else `default`.
fn kills(default: usize) -> usize {
    std::env::var("NEURAL_BRDF_TORTURE_KILLS").ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

#[test]
fn a_tiny_sweep_killed_five_times_resumes_to_the_same_results() {
    torture(&tiny(), "tiny-torture", kills(5));
}

#[test]
#[ignore = "minutes: cargo test -p xtask --test kill_torture -- --ignored --nocapture"]
fn a_sweep_killed_at_random_moments_resumes_to_the_same_results() {
    torture(&profile(), "torture", kills(20));
}

/// Runs the sweep of `profile_text` once uninterrupted, then `kills` times killed at random
/// moments and resumed, and compares (see the module doc).
fn torture(profile_text: &str, label: &str, kills: usize) {
    let tmp = test_support::TempDir::new(label);
    let profile = tmp.0.join("torture.toml");
    std::fs::write(&profile, profile_text).unwrap();
    let (clean, log) = (tmp.0.join("clean"), tmp.0.join("log.txt"));
    let t = Instant::now();
    let status = start(&profile, &clean, 1, &log).wait().unwrap();
    let full = t.elapsed().as_secs_f64();
    assert!(status.success(), "{}", std::fs::read_to_string(&log).unwrap());
    eprintln!("uninterrupted sweep: {full:.1} s");

    let mut rng = Rng(0x5eed_1234_abcd_ef01);
    let (mut round, mut landed) = (0, BTreeMap::<&str, usize>::new());
    let mut out = tmp.0.join(format!("tortured-{round}"));
    let mut seen: BTreeMap<PathBuf, Vec<(u64, i64, i64)>> = BTreeMap::new();
    let mut slowest_child = Duration::ZERO;
    // Temporary files found right after a kill: writes the kill interrupted.
    let mut interrupted_writes = 0;
    let mut k = 0;
    while k < kills {
        let jobs = if k % 2 == 0 { 1 } else { 2 };
        // Every third kill is drawn towards the start (scenes, LBO tables, the first runs).
        let r = if k % 3 == 0 { rng.next().powi(3) } else { rng.next() };
        let delay = Duration::from_secs_f64(0.05 + r * 0.6 * full);
        let mut child = start(&profile, &out, jobs, &log);
        let t = Instant::now();
        let finished = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break Some(s);
            }
            if t.elapsed() >= delay {
                break None;
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        if let Some(s) = finished {
            assert!(s.success(), "{}", std::fs::read_to_string(&log).unwrap());
            let n = assert_same_results(&clean, &out);
            eprintln!(
                "round {round} finished before kill {}: {n} files equal the clean sweep's",
                k + 1
            );
            round += 1;
            out = tmp.0.join(format!("tortured-{round}"));
            seen.clear();
            continue;
        }
        k += 1;
        child.kill().unwrap();
        child.wait().unwrap();
        interrupted_writes += temporaries(&out).len();
        slowest_child = slowest_child.max(wait_for_children(&out));
        let at = stage(&out);
        *landed.entry(at).or_default() += 1;
        eprintln!("kill {k} (jobs {jobs}) after {:.2} s: {at}", delay.as_secs_f64());
        let now = finished_runs(&out);
        for (run, ids) in &seen {
            assert_eq!(now.get(run), Some(ids), "{} was written again", run.display());
        }
        seen = now;
    }
    let status = start(&profile, &out, 1, &log).wait().unwrap();
    assert!(status.success(), "{}", std::fs::read_to_string(&log).unwrap());
    for (run, ids) in &seen {
        assert_eq!(finished_runs(&out).get(run), Some(ids), "{} was written again", run.display());
    }
    let n = assert_same_results(&clean, &out);
    for r in 0..=round {
        let left = temporaries(&tmp.0.join(format!("tortured-{r}")));
        assert!(left.is_empty(), "temporary files left: {left:?}");
    }
    eprintln!(
        "{kills} kills over {} round(s); stages hit: {landed:?}; {interrupted_writes} \
         temporary file(s) of interrupted writes found after the kills and cleaned on resume; \
         slowest child exit after its parent's kill: {:.2} s; {n} files equal the clean sweep's",
        round + 1,
        slowest_child.as_secs_f64()
    );
}

#[test]
fn a_full_disk_is_a_clear_error_and_keeps_the_previous_results() {
    let tmp = test_support::TempDir::new("fulldisk");
    let profile = tmp.0.join("torture.toml");
    std::fs::write(&profile, self::profile()).unwrap();
    let mount = tmp.0.join("disk");
    std::fs::create_dir_all(&mount).unwrap();
    let out = mount.join("out");
    let exe = env!("CARGO_BIN_EXE_xtask");
    // A first sweep fills most of the 3 MiB (`scenes/`, `cache/`), then a filler takes the rest:
    // the runs cannot write their checkpoints.
    let script = format!(
        "mount -t tmpfs -o size=3m tmpfs '{m}' || exit 77; \
         '{exe}' reproduce-tables --profile '{p}' --out '{o}' >/dev/null 2>'{m}/../first.txt'; \
         echo first=$?; \
         cp -a '{o}' '{m}/../before'; \
         dd if=/dev/zero of='{m}/filler' bs=64k 2>/dev/null; \
         '{exe}' reproduce-tables --profile '{p}' --out '{o}' >/dev/null 2>'{m}/../second.txt'; \
         echo second=$?; \
         rm -f '{m}/filler'; cp -a '{o}' '{m}/../after'",
        m = mount.display(),
        p = profile.display(),
        o = out.display(),
    );
    let o = Command::new("unshare").args(["-rm", "sh", "-c", &script]).output();
    let Ok(o) = o else {
        eprintln!("skipped: no unshare");
        return;
    };
    let stdout = String::from_utf8_lossy(&o.stdout);
    if o.status.code() == Some(77) || !stdout.contains("first=") {
        eprintln!("skipped: cannot mount a tmpfs here ({})", String::from_utf8_lossy(&o.stderr));
        return;
    }
    let first = std::fs::read_to_string(tmp.0.join("first.txt")).unwrap();
    let second = std::fs::read_to_string(tmp.0.join("second.txt")).unwrap();
    eprintln!("{stdout}first sweep:\n{first}\nsecond sweep:\n{second}");
    assert!(!stdout.contains("first=0"), "3 MiB should not hold the sweep");
    assert!(first.contains("No space left on device"), "{first}");
    assert!(first.contains("run(s) failed (see above)"), "{first}");
    assert!(second.contains("No space left on device"), "{second}");
    assert!(second.contains(&mount.display().to_string()), "the error names a file: {second}");
    // What the full disk found is still there, unchanged (temporaries aside).
    let (before, after) = (tmp.0.join("before"), tmp.0.join("after"));
    for rel in files(&before) {
        let name = rel.file_name().unwrap().to_string_lossy().into_owned();
        if stdx::fs::is_temporary(&name) || name == ".lock" || name == "sweep.log" {
            continue;
        }
        assert!(
            std::fs::read(before.join(&rel)).ok() == std::fs::read(after.join(&rel)).ok(),
            "{} changed or vanished",
            rel.display()
        );
    }
    let left = temporaries(&after);
    assert!(left.is_empty(), "temporary files left after the failed write: {left:?}");
}
