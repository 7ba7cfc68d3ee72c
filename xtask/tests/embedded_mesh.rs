//! `embedded:spot` is in the binary: a copy of the built xtask, run from another directory with
//! the source tree out of reach, sweeps a profile on the embedded Spot. Out of reach means
//! hidden under an empty tmpfs in a user namespace (`unshare -rm`); where that is not possible
//! the test says so and checks the weaker property, that the scene's mesh was not read from
//! the source tree.

use std::path::{Path, PathBuf};
use std::process::Command;

/// One Disney run on the embedded mesh at 16 px, without images or probes.
fn profile() -> String {
    let head = "the embedded mesh, away from the source tree";
    test_support::TinyProfile::new("embedded", head, 1).scene(16, 2, 4).with(
        r#"[run.train]
iterations = 4
batch_size = 256
warmup_steps = 1
checkpoint_every = 2
log_every = 1
validate_every = 2
patience = 4
[run.eval]
energy_estimator = "off"
reciprocity_pairs = 0
images = false
[sweep]
models = ["disney"]
"#,
    )
}

/// A fresh directory under the system's temporary directory (outside the source tree, which
/// holds the tests' usual temporary folders).
fn outside_dir() -> PathBuf {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let dir = std::env::temp_dir().join(format!("nbrdf-embedded-{}-{nanos}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn quote(p: &Path) -> String {
    format!("'{}'", p.display().to_string().replace('\'', "'\\''"))
}

#[test]
fn the_embedded_mesh_needs_no_source_tree() {
    let dir = outside_dir();
    let exe = dir.join("xtask");
    std::fs::copy(env!("CARGO_BIN_EXE_xtask"), &exe).unwrap();
    std::fs::write(dir.join("p.toml"), profile()).unwrap();
    let source = std::path::absolute(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .unwrap()
        .canonicalize()
        .unwrap();
    assert!(!dir.starts_with(&source), "the temporary directory is inside the source tree");
    let sweep = format!(
        "cd {d} && {x} reproduce-tables --jobs 1 --profile p.toml --out out >log.txt 2>&1; echo rc=$?",
        d = quote(&dir),
        x = quote(&exe)
    );
    // The source tree hidden under an empty tmpfs, where user namespaces allow it.
    let hidden = Command::new("unshare")
        .args(["-rm", "sh", "-c"])
        .arg(format!("mount -t tmpfs tmpfs {} || exit 77; {sweep}", quote(&source)))
        .output();
    let log = || std::fs::read_to_string(dir.join("log.txt")).unwrap_or_default();
    match hidden {
        Ok(o)
            if o.status.code() != Some(77)
                && String::from_utf8_lossy(&o.stdout).contains("rc=") =>
        {
            let out = String::from_utf8_lossy(&o.stdout);
            assert!(
                out.contains("rc=0"),
                "the sweep failed with the source tree hidden:\n{}",
                log()
            );
        }
        other => {
            eprintln!(
                "skipped hiding the source tree (unshare -rm with a tmpfs mount is not \
                 available here: {:?}); running the copy from another directory instead",
                other.map(|o| String::from_utf8_lossy(&o.stderr).into_owned())
            );
            let o = Command::new("sh").args(["-c", &sweep]).output().unwrap();
            assert!(String::from_utf8_lossy(&o.stdout).contains("rc=0"), "{}", log());
        }
    }
    // The scene was made from the embedded copy, not from the source tree.
    let manifest =
        std::fs::read_to_string(dir.join("out/scenes/spot__blue-acrylic/manifest.json")).unwrap();
    let m: serde_json::Value = serde_json::from_str(&manifest).unwrap();
    let mesh = PathBuf::from(m["config"]["mesh"].as_str().unwrap());
    assert!(!mesh.starts_with(&source), "{}", mesh.display());
    assert!(mesh.with_file_name("NOTICE.md").is_file(), "the notice travels with the mesh");
    assert!(dir.join("out/tables/table1.md").is_file(), "{}", log());
    let _ = std::fs::remove_dir_all(&dir);
}
