//! Architecture invariant: crates depend only downward in the layering, which is written once:
//! the order of the path entries of `[workspace.dependencies]` in the root Cargo.toml, printed by
//! `cargo xtask layers` (docs/ARCHITECTURE.md).

use serde_json::Value;
use std::process::Command;

/// The layering as `cargo xtask layers` prints it (read from the root Cargo.toml).
fn layers() -> Vec<String> {
    let out = Command::new(env!("CARGO_BIN_EXE_xtask")).arg("layers").output().expect("run xtask");
    assert!(out.status.success(), "xtask layers failed");
    String::from_utf8(out.stdout).expect("UTF-8").lines().map(str::to_owned).collect()
}

fn metadata() -> Value {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--no-deps", "--offline"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run cargo metadata");
    assert!(
        out.status.success(),
        "cargo metadata failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("cargo metadata JSON")
}

#[test]
fn dependencies_point_only_downward() {
    let layers = layers();
    let meta = metadata();
    let packages = meta["packages"].as_array().expect("packages");
    let names: Vec<&str> = packages.iter().map(|p| p["name"].as_str().unwrap()).collect();
    for layer in &layers {
        assert!(names.contains(&layer.as_str()), "workspace member {layer} missing");
    }
    let mut violations = Vec::new();
    for p in packages {
        let name = p["name"].as_str().unwrap();
        let rank = layers.iter().position(|l| l == name);
        let Some(rank) = rank else {
            violations.push(format!("{name} is not in the layering list"));
            continue;
        };
        for dep in p["dependencies"].as_array().unwrap() {
            let dep_name = dep["name"].as_str().unwrap();
            if let Some(dep_rank) = layers.iter().position(|l| l == dep_name) {
                // Dev-dependencies may not point up either: a test must not reach back.
                if dep_rank >= rank {
                    violations.push(format!("{name} depends on {dep_name}, which is not below it"));
                }
            }
        }
    }
    assert!(violations.is_empty(), "layering violations:\n{}", violations.join("\n"));
}

#[test]
fn every_member_is_in_the_layering_once() {
    let layers = layers();
    let meta = metadata();
    let members = meta["packages"].as_array().expect("packages").len();
    let mut unique = layers.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), layers.len(), "a crate listed twice: {layers:?}");
    assert_eq!(layers.len(), members, "layering {layers:?} against {members} members");
}

/// The normal (non-dev) dependency tree of `package`, one crate name a line.
fn normal_tree(package: &str) -> Vec<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["tree", "-p", package, "-e", "normal", "--prefix", "none", "--offline"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run cargo tree");
    assert!(out.status.success(), "cargo tree failed: {}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).expect("UTF-8");
    text.lines().filter_map(|l| l.split_whitespace().next()).map(str::to_owned).collect()
}

/// The on-disk format of a run is read by tools that train nothing (the report, the sweep's
/// collectors, users' scripts): it must build without the tensor stack.
#[test]
fn run_format_and_report_build_without_burn() {
    for package in ["run-format", "report", "model-spec"] {
        let tree = normal_tree(package);
        assert!(tree.iter().any(|c| c == package), "{package} missing from its own tree");
        let tensor: Vec<&String> =
            tree.iter().filter(|c| c.starts_with("burn") || c.starts_with("cubecl")).collect();
        assert!(tensor.is_empty(), "{package} builds {tensor:?}");
    }
}
