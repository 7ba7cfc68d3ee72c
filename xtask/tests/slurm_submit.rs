//! `reproduce-tables --slurm` against stand-in `sbatch` and `scontrol` commands (shell scripts
//! that record their arguments and hand out job ids): the arrays respect the cluster's
//! `MaxArraySize`, every unfinished run is one task of exactly one array, the collect job
//! depends on every array (`afterany`), the user's options reach every script, and `--dry-run`
//! submits nothing. The real cluster runs in `.ci/slurm/test.sh`.

#![cfg(unix)]

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;

fn tiny() -> String {
    test_support::tiny_profile(
        "submit",
        "Slurm submission test: one tiny scene, three models",
        1,
        r#"[run.train]
profile = "quick"
iterations = 100000
batch_size = 512
[sweep]
models = ["single_mlp", "disney", "fmbrdf"]
ablations = ["nol"]
"#,
    )
}

fn executable(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// A `bin/` with stand-ins that log to `calls.txt`; `MaxArraySize` is `max`.
fn fake_slurm(root: &Path, max: usize) -> PathBuf {
    let bin = root.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let log = root.join("calls.txt");
    executable(
        &bin.join("sbatch"),
        &format!(
            "#!/bin/sh\necho \"sbatch $*\" >> '{log}'\nn=$(grep -c '^sbatch' '{log}')\necho \"$((100 + n));cluster\"\n",
            log = log.display()
        ),
    );
    executable(
        &bin.join("scontrol"),
        &format!(
            "#!/bin/sh\necho \"MaxJobCount = 10000\"\necho \"MaxArraySize            = {max}\"\n"
        ),
    );
    bin
}

fn submit(root: &Path, out: &Path, bin: &Path, extra: &[&str]) -> std::process::Output {
    let profile = root.join("submit.toml");
    std::fs::write(&profile, tiny()).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .env("PATH", path)
        .args(["reproduce-tables", "--profile"])
        .arg(&profile)
        .arg("--out")
        .arg(out)
        .args(["--slurm", "--partition", "cpu", "--sbatch=--constraint=avx512"])
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn arrays_respect_max_array_size_and_the_collect_job_waits_for_them_all() {
    let tmp = test_support::TempDir::new("slurm-submit");
    let bin = fake_slurm(&tmp.0, 2);
    let out = tmp.0.join("sweep");

    let dry = submit(&tmp.0, &out, &bin, &["--dry-run"]);
    let text = String::from_utf8_lossy(&dry.stderr);
    assert!(dry.status.success(), "{text}");
    assert!(text.contains("(dry run) sbatch"), "{text}");
    assert!(!tmp.0.join("calls.txt").exists(), "a dry run submits nothing");

    let real = submit(&tmp.0, &out, &bin, &[]);
    let text = String::from_utf8_lossy(&real.stderr);
    assert!(real.status.success(), "{text}");
    let calls = std::fs::read_to_string(tmp.0.join("calls.txt")).unwrap();
    let calls: Vec<&str> = calls.lines().collect();
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("slurm/sweep.json")).unwrap())
            .unwrap();
    let submissions = record["submissions"].as_array().unwrap();
    assert_eq!(submissions.len(), 2, "the dry run and the real one");
    let arrays = submissions[1]["arrays"].as_array().unwrap();
    // 3 models + the NOL ablation of the Single MLP: 4 runs in three groups of requests (the
    // two Single MLP runs, Disney, FMBRDF: their measured steps differ), at most 2 tasks an
    // array.
    let runs = record["runs"].as_array().unwrap().len();
    assert_eq!(runs, 4);
    assert_eq!(arrays.len(), 3, "{arrays:?}");
    let minutes: Vec<u64> =
        arrays.iter().map(|a| a["requests"]["minutes"].as_u64().unwrap()).collect();
    assert!(minutes[0] < minutes[1] && minutes[1] < minutes[2], "{minutes:?}");
    let mut tasks = Vec::new();
    for a in arrays {
        let count = a["count"].as_u64().unwrap() as usize;
        assert!((1..=2).contains(&count), "{a}");
        let list = std::fs::read_to_string(a["tasks"].as_str().unwrap()).unwrap();
        assert_eq!(list.lines().count(), count);
        tasks.extend(list.lines().map(str::to_string));
        let script = std::fs::read_to_string(a["script"].as_str().unwrap()).unwrap();
        assert!(script.contains(&format!("#SBATCH --array=0-{}", count - 1)), "{script}");
        for line in ["#SBATCH --partition=cpu", "#SBATCH --constraint=avx512", "--requeue"] {
            assert!(script.contains(line), "{line}: {script}");
        }
    }
    tasks.sort();
    tasks.dedup();
    assert_eq!(tasks.len(), runs, "every run is one task of one array");
    // sbatch: the arrays, then the collect job after all of them.
    assert_eq!(calls.len(), arrays.len() + 1, "{calls:?}");
    let ids: Vec<String> = (1..=arrays.len()).map(|n| (100 + n).to_string()).collect();
    let collect = calls.last().unwrap();
    assert!(collect.contains(&format!("--dependency=afterany:{}", ids.join(":"))), "{collect}");
    assert!(collect.ends_with("collect.sh"), "{collect}");
    assert_eq!(submissions[1]["collect_job"], (101 + arrays.len()).to_string());
    let status = Command::new(env!("CARGO_BIN_EXE_xtask")).arg("sweep-status").arg(&out).output();
    let status = String::from_utf8(status.unwrap().stdout).unwrap();
    assert!(status.starts_with("4 runs: 0 done, 0 running, 0 failed, 0 interrupted, 4 pending"));
}
