//! The crate's error type: every variant names the file, the key or the step at fault.

use std::path::PathBuf;

/// Errors of training, evaluation, export and sweeps.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A run's configuration or files: a key out of range, a file that cannot be parsed, read
    /// or written (run-format's error, which names the file or the key).
    #[error(transparent)]
    Run(#[from] run_format::Error),
    /// The MERL catalogue or the scene generator failed.
    #[error(transparent)]
    Dataset(#[from] dataset_merl::Error),
    /// A figure could not be drawn.
    #[error(transparent)]
    Report(#[from] report::Error),
    /// A scene directory could not be read or written.
    #[error(transparent)]
    Scene(#[from] scene::Error),
    /// The LBO encoding failed.
    #[error(transparent)]
    Encoding(#[from] mesh_encoding::Error),
    /// The model could not be built or fed.
    #[error(transparent)]
    Model(#[from] brdf_neural::Error),
    /// A metric failed.
    #[error(transparent)]
    Metrics(#[from] metrics::Error),
    /// The loss became NaN or infinite; the last good checkpoint is kept.
    #[error(
        "non-finite loss ({loss}) at step {step}: {diagnosis}; the last good checkpoint is {}",
        checkpoint.as_ref().map_or("none".into(), |p| p.display().to_string())
    )]
    NonFinite {
        /// The step whose loss was not finite.
        step: u64,
        /// The loss value.
        loss: f32,
        /// Which parameter group is at fault.
        diagnosis: String,
        /// The last good checkpoint.
        checkpoint: Option<PathBuf>,
    },
    /// The backend failed inside a training step or read (a GPU out of memory or lost: burn and
    /// CubeCL panic there), caught by the training loop; the last checkpoint resumes the run.
    #[error(
        "{}: training stopped at step {step}: the {backend} backend failed: {message}; {}",
        run.display(),
        match checkpoint {
            Some(c) => format!(
                "the last checkpoint is {}: run the same command again to resume from it \
                 (a smaller train.batch_size needs a new run directory)",
                c.display()
            ),
            None => "no checkpoint was written yet: the run starts again from step 0".into(),
        }
    )]
    BackendFault {
        /// The run directory.
        run: PathBuf,
        /// Steps done when it failed.
        step: u64,
        /// The backend that trained.
        backend: String,
        /// What the backend said.
        message: String,
        /// The latest checkpoint.
        checkpoint: Option<PathBuf>,
    },
    /// The scene has no training sample.
    #[error("{}: no lit training sample", path.display())]
    NoSamples {
        /// The scene.
        path: PathBuf,
    },
}

impl Error {
    /// A range error for `key`.
    pub fn config(key: &str, message: impl Into<String>) -> Self {
        run_format::Error::config(key, message).into()
    }

    /// A range error of the configuration file `path`, named with it (`path: config key
    /// \`train.batch_size\`: ...`); other errors are returned as they are.
    pub fn in_file(self, path: impl Into<PathBuf>) -> Self {
        match self {
            Error::Run(e) => Error::Run(e.in_file(path)),
            other => other,
        }
    }

    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        run_format::Error::io(path, source).into()
    }

    /// A format error in `path`.
    pub fn format(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        run_format::Error::format(path, message).into()
    }
}

/// Result with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl From<stdx::fs::Error> for Error {
    fn from(e: stdx::fs::Error) -> Self {
        Error::Run(e.into())
    }
}
