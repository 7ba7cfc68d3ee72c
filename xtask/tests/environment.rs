//! Architecture invariant: environment variables are read in the command-line layer only
//! (`xtask`, `experiments::cli` and the `experiments` binary), which turns them into typed
//! settings (run-format's `ComputeSettings`, sweep's `SweepSettings`) that the library crates
//! take as values. Read from the sources of every crate's `src` (test modules left out), so
//! that a new `std::env::var` below the command line fails here unless it is one of the few
//! listed reads that are not settings, each with its reason.

use std::path::{Path, PathBuf};

/// The files of the command-line layer, where environment variables may be read freely.
const COMMAND_LINE: &[&str] =
    &["xtask/src/", "crates/experiments/src/cli.rs", "crates/experiments/src/main.rs"];

/// Reads below the command line that are not settings: (file, variable, why).
const NOT_SETTINGS: &[(&str, &str, &str)] = &[
    ("crates/stdx/src/lock.rs", "HOSTNAME", "names the lock's holder"),
    ("crates/sweep/src/status.rs", "SLURM_", "the scheduler's job id, recorded with a failure"),
    ("crates/sweep/src/execute.rs", "PARENT_PID_VAR", "the parent-child protocol of --jobs"),
    ("crates/test-support/src/", "", "test set-up (CI, the shared data)"),
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

/// The `src` files of every crate of the workspace and of xtask.
fn sources() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(root().join("crates")).unwrap() {
        let src = entry.unwrap().path().join("src");
        if src.is_dir() {
            rust_files(&src, &mut files);
        }
    }
    rust_files(&root().join("xtask/src"), &mut files);
    files.sort();
    files
}

/// The lines of `text` before its test module that read an environment variable, with the
/// line (comments left out).
fn reads(text: &str) -> Vec<(usize, String)> {
    let code = text.split("#[cfg(test)]").next().unwrap_or("");
    code.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split("//").next().unwrap_or("").to_string()))
        .filter(|(_, l)| l.contains("env::var") || l.contains("env::vars"))
        .collect()
}

#[test]
fn environment_variables_are_read_by_the_command_line_only() {
    let root = root();
    let mut found = Vec::new();
    let mut listed_seen = vec![false; NOT_SETTINGS.len()];
    for file in sources() {
        let rel = file.strip_prefix(&root).unwrap().to_string_lossy().replace('\\', "/");
        if COMMAND_LINE.iter().any(|c| rel.starts_with(c)) {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        for (line_no, line) in reads(&text) {
            let listed: Vec<usize> = (0..NOT_SETTINGS.len())
                .filter(|&i| {
                    let (f, var, _) = NOT_SETTINGS[i];
                    rel.starts_with(f)
                        && (var.is_empty() || line.contains(var) || text.contains(var))
                })
                .collect();
            if listed.is_empty() {
                found.push(format!("{rel}:{line_no}: {}", line.trim()));
            }
            for i in listed {
                listed_seen[i] = true;
            }
        }
    }
    assert!(
        found.is_empty(),
        "environment variables read below the command line (make them a setting the CLI \
         fills, or list why not):\n{}",
        found.join("\n")
    );
    // The list stays true: every entry still names a read.
    for ((file, var, _), seen) in NOT_SETTINGS.iter().zip(listed_seen) {
        assert!(seen, "{file} ({var}) no longer reads the environment: drop it from the list");
    }
}

#[test]
fn the_check_sees_a_read() {
    let text = "fn f() {\n    let v = std::env::var(\"NEURAL_BRDF_X\");\n}\n// env::var in a comment\n#[cfg(test)]\nmod tests { fn g() { std::env::var(\"Y\"); } }\n";
    let r = reads(text);
    assert_eq!(r.len(), 1, "{r:?}");
    assert_eq!(r[0].0, 2);
}

/// The product finds its data through the command line's places (`experiments::places`), never
/// in the development checkout's `../shared` (only the tests' set-up looks there).
#[test]
fn the_product_never_looks_in_the_shared_folder() {
    let root = root();
    let mut found = Vec::new();
    for file in sources() {
        let rel = file.strip_prefix(&root).unwrap().to_string_lossy().replace('\\', "/");
        if rel.starts_with("crates/test-support/") {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        for (i, line) in code.lines().enumerate() {
            let line = line.split("//").next().unwrap_or("");
            if line.contains("shared/data") || line.contains("../shared") {
                found.push(format!("{rel}:{}: {}", i + 1, line.trim()));
            }
        }
    }
    assert!(found.is_empty(), "the product reads the shared folder:\n{}", found.join("\n"));
}
