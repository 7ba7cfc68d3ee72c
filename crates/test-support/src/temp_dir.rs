//! A fresh, empty directory under the system temp dir for one test, removed on drop
//! (`tempfile`'s, with the path in a public field for the tests' convenience).

use std::path::PathBuf;

/// A fresh empty directory `<temp>/<tag>-XXXXXX`, removed on drop.
pub struct TempDir(
    pub PathBuf,
    #[expect(dead_code, reason = "held for its Drop, which removes the directory")]
    tempfile::TempDir,
);

impl TempDir {
    /// Creates it.
    ///
    /// # Panics
    /// If the directory cannot be created.
    pub fn new(tag: &str) -> Self {
        let dir = tempfile::Builder::new()
            .prefix(&format!("nbrdf-{tag}-"))
            .tempdir()
            .expect("create a temporary directory");
        Self(dir.path().to_path_buf(), dir)
    }
}
