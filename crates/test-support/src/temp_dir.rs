//! A fresh, empty directory under the system temp dir for one test, removed on drop; included
//! by the test helpers of several crates with `#[path]` (see `shared_data.rs` beside it).

use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh empty directory `<temp>/<crate>-<tag>-<pid>-<n>`, removed on drop.
pub struct TempDir(pub PathBuf);

impl TempDir {
    /// Creates it (removing any leftover of the same name first).
    ///
    /// # Panics
    /// If the directory cannot be created.
    #[allow(dead_code)]
    pub fn new(tag: &str) -> Self {
        static N: AtomicUsize = AtomicUsize::new(0);
        let p = std::env::temp_dir().join(format!(
            "{}-{tag}-{}-{}",
            env!("CARGO_PKG_NAME"),
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
