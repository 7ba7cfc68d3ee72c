//! Shared helpers of the integration tests: where the shared test data lives and unique temporary
//! directories.

use std::path::PathBuf;

#[path = "../../../../test-support/shared_data.rs"]
mod support;

/// The shared data folder (`$NEURAL_BRDF_DATA`, default `<workspace>/../shared/data`) when
/// it holds `meshes/`; see `test-support/shared_data.rs`.
#[allow(dead_code)]
pub fn data_dir() -> Option<PathBuf> {
    support::shared_data_root("meshes")
}

/// A fresh, empty temporary directory unique to this process and `name`.
#[allow(dead_code)]
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mesh-encoding-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}
