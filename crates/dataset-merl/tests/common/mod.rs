//! Shared helpers of the dataset-merl tests: temporary directories and the shared data folder.
#![allow(dead_code)]

use std::path::PathBuf;

#[path = "../../../../test-support/temp_dir.rs"]
mod temp_dir;
#[allow(unused_imports)]
pub use temp_dir::TempDir;

#[path = "../../../../test-support/shared_data.rs"]
mod support;

/// The shared data folder (`NEURAL_BRDF_DATA`, default `<workspace>/../shared/data`); see
/// `test-support/shared_data.rs`.
pub fn shared_data() -> Option<PathBuf> {
    support::shared_data_root("")
}
