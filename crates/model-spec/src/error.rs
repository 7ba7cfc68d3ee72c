//! The crate's error type: what can be wrong with a model's name or configuration.
//!
//! brdf-neural's `Error` converts from it (`From<model_spec::Error>`) into its variants of the
//! same names and messages, so an error reads the same whichever crate reports it.

/// A model name or configuration that names no model of the comparison.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A model configuration combines options the paper does not combine, or has a value out
    /// of range; the message names the field.
    #[error("invalid model configuration: {0}")]
    InvalidConfig(String),
    /// A model name that is neither a configuration name nor a paper table row.
    #[error("unknown model name {0:?} (see ModelKind::ALL for the names)")]
    UnknownModel(String),
    /// A backend name other than cpu, flex, ndarray, wgpu or cuda.
    #[error("unknown backend {0:?} (expected cpu, flex, ndarray, wgpu or cuda)")]
    UnknownBackend(String),
}

/// `Result` with this crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
