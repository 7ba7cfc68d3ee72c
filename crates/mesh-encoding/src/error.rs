//! The crate's error type: every failure names the file (or `<memory>` for meshes built in code)
//! and the fault. Loading and cleanup return these; evaluating normals or topology never fails.

use std::fmt;
use std::path::PathBuf;

use crate::mesh::MeshFormat;

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What is wrong with a mesh's data (independent of where it came from).
#[derive(Debug, Clone, PartialEq)]
pub enum MeshFault {
    /// The mesh has no vertices or no faces.
    Empty,
    /// A vertex coordinate is NaN or infinite.
    NonFiniteVertex {
        /// Index of the vertex (0-based, after loading).
        vertex: usize,
        /// Its coordinates as read.
        position: [f32; 3],
    },
    /// A face refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Index of the face (0-based, counting faces as they appear in the file).
        face: usize,
        /// The offending vertex index as written (may be negative in a PLY file).
        index: i64,
        /// Number of vertices the mesh has.
        vertex_count: usize,
    },
    /// A face with fewer than three corners.
    TooFewCorners {
        /// Index of the face.
        face: usize,
        /// Its number of corners.
        corners: usize,
    },
    /// More vertices than a `u32` index can address.
    TooManyVertices(usize),
}

impl fmt::Display for MeshFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshFault::Empty => write!(f, "the mesh is empty (no vertices or no faces)"),
            MeshFault::NonFiniteVertex { vertex, position } => {
                write!(f, "vertex {vertex} has a non-finite coordinate {position:?}")
            }
            MeshFault::IndexOutOfRange { face, index, vertex_count } => write!(
                f,
                "face {face} refers to vertex {index}, out of range for {vertex_count} vertices"
            ),
            MeshFault::TooFewCorners { face, corners } => {
                write!(f, "face {face} has {corners} corners, at least 3 are needed")
            }
            MeshFault::TooManyVertices(n) => {
                write!(f, "{n} vertices exceed the u32 index range")
            }
        }
    }
}

/// Errors of mesh loading and cleanup. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file could not be opened or read.
    #[error("{}: cannot read mesh file: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file extension names no supported format.
    #[error(
        "{}: unsupported mesh format {extension:?}; expected .obj, .ply, .gltf or .glb",
        path.display()
    )]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
        /// Its extension (empty when it has none).
        extension: String,
    },
    /// The file is not a well-formed file of its format.
    #[error("{}: malformed {format} file: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// The format it was read as.
        format: MeshFormat,
        /// What the parser reported.
        message: String,
    },
    /// The file parsed, but its mesh data is unusable.
    #[error("{}: invalid mesh: {fault}", path.display())]
    Invalid {
        /// The file (`<memory>` for meshes built in code).
        path: PathBuf,
        /// The fault.
        fault: MeshFault,
    },
    /// The Laplace-Beltrami encoding failed: unusable matrices, a failed factorisation or an
    /// eigen-solve that did not converge.
    #[error("LBO encoding: {message}")]
    Lbo {
        /// What went wrong.
        message: String,
    },
    /// An LBO eigenpair cache file could not be written (a corrupted one is recomputed, not an
    /// error).
    #[error("{}: LBO eigenpair cache: {message}", path.display())]
    LboCache {
        /// The cache file or directory.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl Error {
    /// An [`Error::Invalid`] for a mesh built in memory.
    pub fn in_memory(fault: MeshFault) -> Self {
        Error::Invalid { path: PathBuf::from("<memory>"), fault }
    }
}

impl Error {
    /// An [`Error::Lbo`] with a message.
    pub fn lbo(message: impl Into<String>) -> Self {
        Error::Lbo { message: message.into() }
    }
}
