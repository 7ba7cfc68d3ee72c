//! Where every crate's tests find the shared dataset: `$NEURAL_BRDF_DATA`, default
//! `<workspace>/../shared/data`.
//!
//! A missing dataset skips the test with a notice locally and fails it under `CI=true`.

use std::path::PathBuf;

/// The shared data root if `<root>/<probe>` exists (`probe = ""` checks the root itself), else
/// `None` after a skip notice.
///
/// # Panics
/// Under `CI=true` when `<root>/<probe>` is missing: CI must see the data.
pub fn shared_data_root(probe: &str) -> Option<PathBuf> {
    // This crate lives at <workspace>/crates/test-support.
    let root = std::env::var_os("NEURAL_BRDF_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let wanted = root.join(probe);
    if wanted.exists() {
        return Some(root);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("shared data {} is missing (CI=true): set NEURAL_BRDF_DATA", wanted.display());
    }
    eprintln!("SKIP: shared data {} not found (set NEURAL_BRDF_DATA)", wanted.display());
    None
}
