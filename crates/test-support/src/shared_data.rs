//! Where every crate's tests find the shared dataset: `$NEURAL_BRDF_DATA`, default
//! `<workspace>/../shared/data`, and the shared documents beside it (`<data>/../docs`: the
//! paper's LaTeX source).
//!
//! A missing dataset or document skips the test with a notice locally and fails it under
//! `CI=true`.

use std::path::PathBuf;

/// The shared data root if `<root>/<probe>` exists (`probe = ""` checks the root itself), else
/// `None` after a skip notice.
///
/// # Panics
/// Under `CI=true` when `<root>/<probe>` is missing: CI must see the data.
pub fn shared_data_root(probe: &str) -> Option<PathBuf> {
    found(data_root(), probe, "shared data")
}

/// The shared documents folder (`<data root>/../docs`) if `<docs>/<probe>` exists, else `None`
/// after a skip notice.
///
/// # Panics
/// Under `CI=true` when `<docs>/<probe>` is missing.
pub fn shared_docs_root(probe: &str) -> Option<PathBuf> {
    found(data_root().join("../docs"), probe, "shared document")
}

fn data_root() -> PathBuf {
    // This crate lives at <workspace>/crates/test-support.
    std::env::var_os("NEURAL_BRDF_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

fn found(root: PathBuf, probe: &str, what: &str) -> Option<PathBuf> {
    let wanted = root.join(probe);
    if wanted.exists() {
        return Some(root);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("{what} {} is missing (CI=true): set NEURAL_BRDF_DATA", wanted.display());
    }
    eprintln!("SKIP: {what} {} not found (set NEURAL_BRDF_DATA)", wanted.display());
    None
}
