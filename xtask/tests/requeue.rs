//! A run stopped by SIGTERM (a cluster's preemption or time limit) stops at a step boundary
//! with a checkpoint, exits with the requeue status 75, resumes from that checkpoint when
//! started again and ends with the same weights, byte for byte, as an uninterrupted run; a run
//! that fails records why, and `sweep-status` reads both from the run directories. (The same
//! under a real Slurm: `.ci/slurm/test.sh`.)

#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn tiny() -> String {
    test_support::tiny_profile(
        "requeue",
        "SIGTERM test: one tiny scene, one model, 300 steps",
        5,
        r#"[run.train]
profile = "quick"
iterations = 300
batch_size = 512
warmup_steps = 5
checkpoint_every = 10
log_every = 10
validate_every = 10
patience = 1000
[run.eval]
energy_pairs = 4
reciprocity_pairs = 200
[sweep]
models = ["single_mlp"]
ablations = []
"#,
    )
}

fn xtask() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_xtask"));
    // One thread, as a one-CPU cluster task; the results do not depend on what runs beside.
    c.env("RAYON_NUM_THREADS", "1");
    c
}

/// Prepares the profile's one run under `out` (`--emit-jobs`: nothing trained) and returns it.
fn prepare(root: &Path, out: &Path) -> PathBuf {
    let profile = root.join("requeue.toml");
    std::fs::write(&profile, tiny()).unwrap();
    let jobs = root.join("jobs.txt");
    let status = xtask()
        .args(["reproduce-tables", "--profile"])
        .arg(&profile)
        .arg("--out")
        .arg(out)
        .arg("--emit-jobs")
        .arg(&jobs)
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    let runs: Vec<PathBuf> = std::fs::read_dir(out.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    assert_eq!(runs.len(), 1, "{runs:?}");
    runs.into_iter().next().unwrap()
}

fn run_one(run: &Path) -> Command {
    let mut c = xtask();
    c.args(["run-one", "--quiet"]).arg(run);
    c
}

fn status_of(out: &Path) -> String {
    let o = xtask().arg("sweep-status").arg(out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn sigterm_stops_at_a_checkpoint_and_the_resumed_run_ends_with_the_same_weights() {
    let tmp = test_support::TempDir::new("requeue");
    let (a, b) = (tmp.0.join("a"), tmp.0.join("b"));
    let run_a = prepare(&tmp.0, &a);
    let run_b = prepare(&tmp.0, &b);
    assert!(
        status_of(&a).starts_with("1 runs: 0 done, 0 running, 0 failed, 0 interrupted, 1 pending")
    );

    // Uninterrupted.
    assert!(run_one(&run_a).stderr(Stdio::null()).status().unwrap().success());
    assert!(status_of(&a).starts_with("1 runs: 1 done"));

    // Stopped by SIGTERM once its first checkpoint is there, mid-training.
    let log = tmp.0.join("b.log");
    let mut child = run_one(&run_b).stderr(std::fs::File::create(&log).unwrap()).spawn().unwrap();
    let checkpoints = run_b.join("checkpoints");
    let start = Instant::now();
    while std::fs::read_dir(&checkpoints).map_or(true, |mut d| d.next().is_none()) {
        assert!(start.elapsed() < Duration::from_secs(300), "no checkpoint");
        assert!(child.try_wait().unwrap().is_none(), "finished before a checkpoint");
        std::thread::sleep(Duration::from_millis(20));
    }
    let term = Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap();
    assert!(term.success());
    let code = child.wait().unwrap().code();
    let text = std::fs::read_to_string(&log).unwrap();
    assert_eq!(code, Some(75), "{text}");
    assert!(text.contains("stopped by a signal after step"), "{text}");
    let status = status_of(&b);
    assert!(status.contains("1 interrupted"), "{status}");
    assert!(!run_b.join("weights.bpk").exists(), "stopped before the end: {text}");

    // Started again: resumes, and ends where the uninterrupted run did.
    let o = run_one(&run_b).output().unwrap();
    let text = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{text}");
    assert!(text.contains("resuming from the checkpoint at step"), "{text}");
    let same = std::fs::read(run_a.join("weights.bpk")).unwrap()
        == std::fs::read(run_b.join("weights.bpk")).unwrap();
    assert!(same, "the resumed run's weights differ from the uninterrupted run's");

    // A failure is recorded in the run directory and listed with its log.
    let run_c = prepare(&tmp.0, &tmp.0.join("c"));
    let scene = std::fs::read_to_string(run_c.join("config.toml")).unwrap();
    let scene_dir = scene
        .lines()
        .find_map(|l| l.strip_prefix("scene = \"").and_then(|s| s.strip_suffix('"')))
        .map(PathBuf::from)
        .expect("the run's scene");
    std::fs::write(scene_dir.join("manifest.json"), "{").unwrap();
    let o = run_one(&run_c).output().unwrap();
    assert!(!o.status.success());
    let status = status_of(&tmp.0.join("c"));
    assert!(status.contains("1 failed"), "{status}");
    assert!(status.contains("manifest.json"), "the failure names the file: {status}");
    assert!(status.contains("sweep.log"), "and the log: {status}");
}
