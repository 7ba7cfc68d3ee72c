//! The crate's error type: every message names the file (or `capture.toml` key) and the fault.

use std::path::PathBuf;

/// Errors of importing and exporting captures.
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
    /// An input file is malformed or inconsistent with the rest of the capture (a missing
    /// image, a camera count that does not match the lights, NaN pixels, a pose that is not a
    /// rotation, ...).
    #[error("{path}: {fault}")]
    Input {
        /// The offending file.
        path: PathBuf,
        /// What is wrong.
        fault: String,
    },
    /// The mesh does not line up with the cameras: a view's mask and the mesh's silhouette
    /// overlap less than `[check] min_iou`.
    #[error(
        "{path}: mask and mesh silhouette overlap with IoU {iou:.3} (< min_iou {min_iou}) in \
         view {view} ({mask_pixels} mask pixels, {mesh_pixels} silhouette pixels): the mesh is \
         not aligned with the cameras (another frame or scale, OpenGL against OpenCV axes, or \
         wrong intrinsics)"
    )]
    Misaligned {
        /// The view's first image.
        path: PathBuf,
        /// The view (0-based, in the order of the cameras file).
        view: usize,
        /// Intersection over union of mask and silhouette.
        iou: f64,
        /// The threshold.
        min_iou: f64,
        /// Pixels of the mask.
        mask_pixels: u64,
        /// Pixels of the silhouette.
        mesh_pixels: u64,
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

    /// A fault of the input file `path`.
    pub fn input(path: impl Into<PathBuf>, fault: impl Into<String>) -> Self {
        Self::Input { path: path.into(), fault: fault.into() }
    }
}

impl From<stdx::fs::Error> for Error {
    fn from(e: stdx::fs::Error) -> Self {
        Self::Io { path: e.path, source: e.source }
    }
}
