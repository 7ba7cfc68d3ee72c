//! The crate's error type: every message names the file (or option) and the fault.

use std::path::PathBuf;

/// Errors of the DiLiGenT loaders and importers.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file or directory could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// An input file is malformed or inconsistent with the others (missing view, mismatched
    /// light counts, bad intensities, wrong image size, ...).
    #[error("{path}: {fault}")]
    Input {
        /// The offending file or directory.
        path: PathBuf,
        /// What is wrong.
        fault: String,
    },
    /// A MATLAB v5 file is malformed, or a variable is missing or has the wrong shape.
    #[error("{path}: MATLAB v5 file: {fault}")]
    Mat {
        /// The MAT file.
        path: PathBuf,
        /// What is wrong.
        fault: String,
    },
    /// An import option is invalid.
    #[error("import option `{key}`: {fault}")]
    Options {
        /// The option.
        key: String,
        /// What is wrong with it.
        fault: String,
    },
    /// Writing the scene directory (the scene format) failed.
    #[error(transparent)]
    Scene(#[from] scene::Error),
    /// The mesh could not be loaded or is invalid.
    #[error(transparent)]
    Mesh(#[from] mesh_encoding::Error),
    /// Ray casting failed (for example an invalid camera).
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

    /// A malformed or inconsistent input file.
    pub fn input(path: impl Into<PathBuf>, fault: impl Into<String>) -> Self {
        Self::Input { path: path.into(), fault: fault.into() }
    }

    /// An invalid option.
    pub fn option(key: &str, fault: impl Into<String>) -> Self {
        Self::Options { key: key.into(), fault: fault.into() }
    }
}

impl From<stdx::fs::Error> for Error {
    fn from(e: stdx::fs::Error) -> Self {
        Self::Io { path: e.path, source: e.source }
    }
}
