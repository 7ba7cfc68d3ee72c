//! A sweep whose output goes to a file (CI, Slurm, nohup) prints plain progress lines: a line
//! at each run's end and at least every `NEURAL_BRDF_PROGRESS_SECS` in between, with the runs
//! done of the total, the running runs and the time left (`sweep::heartbeat`).

use std::process::{Command, Stdio};

fn tiny() -> String {
    test_support::tiny_profile(
        "lines",
        "progress lines: one tiny scene, two models",
        1,
        r#"[run.train]
iterations = 40
batch_size = 512
warmup_steps = 2
checkpoint_every = 10
log_every = 5
validate_every = 5
patience = 40
[run.eval]
energy_pairs = 4
reciprocity_pairs = 200
images = false
[sweep]
models = ["single_mlp", "disney"]
"#,
    )
}

#[test]
fn a_sweep_logging_to_a_file_prints_progress_lines() {
    let tmp = test_support::TempDir::new("progress-lines");
    let profile = tmp.0.join("lines.toml");
    std::fs::write(&profile, tiny()).unwrap();
    let log = tmp.0.join("sweep.log");
    let status = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(["reproduce-tables", "--jobs", "2", "--profile"])
        .arg(&profile)
        .arg("--out")
        .arg(tmp.0.join("out"))
        .env("NEURAL_BRDF_PROGRESS_SECS", "1")
        .env_remove("NEURAL_BRDF_PROGRESS_LINES")
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .status()
        .unwrap();
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(status.success(), "{text}");
    let lines: Vec<&str> = text.lines().filter(|l| l.starts_with("sweep: ")).collect();
    assert!(lines.iter().any(|l| l.starts_with("sweep: 1/2 runs done")), "{text}");
    assert!(lines.iter().any(|l| l.starts_with("sweep: 2/2 runs done")), "{text}");
    assert_eq!(lines.iter().filter(|l| l.ends_with(" finished")).count(), 2, "{text}");
    // After the first run's end the lines estimate the time left; before it they name the
    // running runs.
    assert!(lines.iter().any(|l| l.contains("left")), "{text}");
    assert!(lines.iter().any(|l| l.contains("; running spot__blue-acrylic__")), "{text}");
}
