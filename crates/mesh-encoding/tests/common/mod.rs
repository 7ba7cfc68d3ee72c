//! Shared helpers of the integration tests: where the shared test data lives and unique temporary
//! directories.

use std::path::PathBuf;

use test_support as support;
#[allow(unused_imports)]
pub use test_support::TempDir;

/// The shared data folder (`$NEURAL_BRDF_DATA`, default `<workspace>/../shared/data`) when
/// it holds `meshes/`; see `test_support::shared_data_root`.
#[allow(dead_code)]
pub fn data_dir() -> Option<PathBuf> {
    support::shared_data_root("meshes")
}
