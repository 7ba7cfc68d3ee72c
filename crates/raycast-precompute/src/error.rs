//! The crate's error type. Invalid inputs (a camera that is not a rotation, a light that is not a
//! direction, a mask of the wrong size) and cache I/O fail with a message naming the input or the
//! file; ray casting on valid inputs never fails. A corrupted cache file is not an error: it is
//! recomputed (see [`crate::cache`]).

use std::path::PathBuf;

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Errors of camera construction, precompute inputs and cache I/O.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A camera's parameters are unusable.
    #[error("invalid camera: {0}")]
    Camera(String),
    /// A view's inputs are unusable.
    #[error("view {view}: {message}")]
    View {
        /// Index of the view in the input list.
        view: usize,
        /// What is wrong.
        message: String,
    },
    /// Reading or writing a cache file failed.
    #[error("{}: cache I/O failed: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

impl From<stdx::fs::Error> for Error {
    fn from(e: stdx::fs::Error) -> Self {
        Self::Io { path: e.path, source: e.source }
    }
}
