//! Shared helpers of the dataset-merl tests: temporary directories and the shared data folder.
#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh empty directory under the system temp dir, removed on drop.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> Self {
        static N: AtomicUsize = AtomicUsize::new(0);
        let p = std::env::temp_dir().join(format!(
            "dataset-merl-{tag}-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).unwrap();
        Self(p)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The shared data folder (`NEURAL_BRDF_DATA`, default `<workspace>/../shared/data`), or `None`
/// with a skip notice; under `CI=true` a missing folder fails the test.
pub fn shared_data() -> Option<PathBuf> {
    let dir = std::env::var_os("NEURAL_BRDF_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    if dir.is_dir() {
        return Some(dir);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("shared data folder {} is missing (CI=true): set NEURAL_BRDF_DATA", dir.display());
    }
    eprintln!("skipping: shared data folder {} not found (set NEURAL_BRDF_DATA)", dir.display());
    None
}
