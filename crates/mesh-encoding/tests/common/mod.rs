//! Shared helpers of the integration tests: where the shared test data lives and unique temporary
//! directories.

use std::path::PathBuf;

/// The shared data folder: `$NEURAL_BRDF_DATA`, default `<workspace>/../shared/data`.
///
/// Returns `None` (after printing a skip notice) when it is missing, unless `CI=true`, where a
/// missing folder fails the test.
#[allow(dead_code)]
pub fn data_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("NEURAL_BRDF_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    if dir.join("meshes").is_dir() {
        return Some(dir);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("shared test data not found at {} (set NEURAL_BRDF_DATA)", dir.display());
    }
    eprintln!("SKIP: shared test data not found at {} (set NEURAL_BRDF_DATA)", dir.display());
    None
}

/// A fresh, empty temporary directory unique to this process and `name`.
#[allow(dead_code)]
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mesh-encoding-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}
