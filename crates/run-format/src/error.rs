//! The crate's error type: every variant names the file or the key at fault.

use std::path::PathBuf;

/// Errors of reading, checking and writing what a run directory holds.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A configuration file could not be parsed (unknown key, wrong type); serde's message
    /// names the key.
    #[error("{}: {message}", path.display())]
    ConfigParse {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A configuration value is out of range.
    #[error("config key `{key}`: {message}")]
    Config {
        /// The dotted key, e.g. `train.learning_rate`.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// File system error.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A file has unexpected content.
    #[error("{}: {message}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

impl Error {
    /// A range error for `key`.
    pub fn config(key: &str, message: impl Into<String>) -> Self {
        Error::Config { key: key.into(), message: message.into() }
    }

    /// A range error of the configuration file `path`, named with it (`path: config key
    /// \`train.batch_size\`: ...`); other errors are returned as they are.
    pub fn in_file(self, path: impl Into<PathBuf>) -> Self {
        match self {
            Error::Config { key, message } => Error::ConfigParse {
                path: path.into(),
                message: format!("config key `{key}`: {message}"),
            },
            other => other,
        }
    }

    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io { path: path.into(), source }
    }

    /// A format error in `path`.
    pub fn format(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Format { path: path.into(), message: message.into() }
    }
}

/// Result with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl From<stdx::fs::Error> for Error {
    fn from(e: stdx::fs::Error) -> Self {
        Self::Io { path: e.path, source: e.source }
    }
}
