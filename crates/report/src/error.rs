//! The crate's error type: a figure that cannot be drawn says which and why.

/// Errors of drawing figures (tables cannot fail).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A figure's input is invalid (sizes, empty data) or its encoding failed.
    #[error("{figure}: {fault}")]
    Figure {
        /// Which figure or image, for example "report.figure".
        figure: String,
        /// What is wrong.
        fault: String,
    },
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// A fault of `figure`.
    pub fn figure(figure: &str, fault: impl Into<String>) -> Self {
        Self::Figure { figure: figure.into(), fault: fault.into() }
    }
}
