//! Architecture invariant: crates depend only downward in the layering
//! `angles < brdf-analytic < mesh-encoding < raycast-precompute < dataset-merl < dataset-diligent <
//! metrics < brdf-neural < experiments < xtask` (docs/ARCHITECTURE.md).

use serde_json::Value;
use std::process::Command;

const LAYERS: &[&str] = &[
    "angles",
    "brdf-analytic",
    "mesh-encoding",
    "raycast-precompute",
    "dataset-merl",
    "dataset-diligent",
    "metrics",
    "brdf-neural",
    "experiments",
    "xtask",
];

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
    let meta = metadata();
    let packages = meta["packages"].as_array().expect("packages");
    let names: Vec<&str> = packages.iter().map(|p| p["name"].as_str().unwrap()).collect();
    for layer in LAYERS {
        assert!(names.contains(layer), "workspace member {layer} missing");
    }
    let mut violations = Vec::new();
    for p in packages {
        let name = p["name"].as_str().unwrap();
        let rank = LAYERS.iter().position(|l| *l == name);
        let Some(rank) = rank else {
            violations.push(format!("{name} is not in the layering list"));
            continue;
        };
        for dep in p["dependencies"].as_array().unwrap() {
            let dep_name = dep["name"].as_str().unwrap();
            if let Some(dep_rank) = LAYERS.iter().position(|l| *l == dep_name) {
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
fn xtask_layers_match_this_list() {
    // The CLI's list and this test's list are the same source of truth.
    let src = include_str!("../src/main.rs");
    for l in LAYERS {
        assert!(src.contains(&format!("\"{l}\"")), "xtask LAYERS lacks {l}");
    }
}
