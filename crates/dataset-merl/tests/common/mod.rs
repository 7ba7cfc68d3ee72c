//! Shared helpers of the dataset-merl tests: temporary directories and the shared data folder.
#![allow(dead_code)]

use std::path::PathBuf;

#[allow(unused_imports)]
pub use test_support::TempDir;

use test_support as support;

/// The shared data folder (`NEURAL_BRDF_DATA`, default `<workspace>/../shared/data`); see
/// `test_support::shared_data_root`.
pub fn shared_data() -> Option<PathBuf> {
    support::shared_data_root("")
}
