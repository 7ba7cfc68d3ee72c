//! The crate's error type: every message names the file (or configuration key) and the fault.

use std::path::PathBuf;

/// Errors of reading, checking and writing scene directories.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A scene configuration value is invalid.
    #[error("scene configuration: `{key}` {fault}")]
    Config {
        /// The offending key.
        key: String,
        /// What is wrong with it.
        fault: String,
    },
    /// A scene directory does not match its manifest, or the manifest is malformed.
    #[error("{path}: {fault}")]
    Dataset {
        /// The manifest or data file.
        path: PathBuf,
        /// What is wrong.
        fault: String,
    },
    /// An image file could not be encoded or decoded.
    #[error("{path}: image error: {fault}")]
    Image {
        /// The image file.
        path: PathBuf,
        /// What is wrong.
        fault: String,
    },
    /// The mesh could not be loaded.
    #[error(transparent)]
    Mesh(#[from] mesh_encoding::Error),
    /// Ray casting or its cache failed.
    #[error(transparent)]
    Raycast(#[from] raycast_precompute::Error),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io { path: path.into(), source }
    }
}

impl From<stdx::fs::Error> for Error {
    fn from(e: stdx::fs::Error) -> Self {
        Self::Io { path: e.path, source: e.source }
    }
}
