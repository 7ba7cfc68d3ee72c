//! The crate's error type: every message names the file (or material) and the fault.

use std::path::PathBuf;

/// Errors of the MERL format, the material catalogue and the scene generator.
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
    /// A MERL binary is malformed.
    #[error("{origin}: not a valid MERL BRDF file: {fault}")]
    MerlFormat {
        /// Where the bytes came from (a path or a description).
        origin: String,
        /// What is wrong.
        fault: String,
    },
    /// An NBRDF network file is malformed.
    #[error("{origin}: not a valid NBRDF network: {fault}")]
    Nbrdf {
        /// Where the network came from.
        origin: String,
        /// What is wrong.
        fault: String,
    },
    /// The mesh could not be loaded.
    #[error(transparent)]
    Mesh(#[from] mesh_encoding::Error),
    /// The scene format: configuration, orbit, writing or reading a scene directory.
    #[error(transparent)]
    Scene(#[from] scene::Error),
    /// A material name that the catalogue does not know.
    #[error("unknown material `{name}`; known materials: {known}")]
    UnknownMaterial {
        /// The name asked for.
        name: String,
        /// The catalogue's names, comma-separated.
        known: String,
    },
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
