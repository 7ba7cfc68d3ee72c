//! The crate's error type.

use crate::device::Backend;

/// Everything that can go wrong when configuring a model or building a batch. Evaluating a
/// model never fails.
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
    /// A backend whose cargo feature is off in this build.
    #[error(
        "backend {0} is not built in: rebuild with `--features {0}` (e.g. `cargo build --release -p xtask --features {0}`)"
    )]
    BackendNotBuilt(Backend),
    /// A GPU backend that is built in but cannot run here (no driver).
    #[error("backend {0} cannot run here: {1}")]
    BackendUnavailable(Backend, String),
    /// Sample arrays whose lengths disagree.
    #[error("batch shape: {0}")]
    BatchShape(String),
}

/// The configuration errors of `model-spec` become the variants of the same names (and the
/// same messages).
impl From<model_spec::Error> for Error {
    fn from(e: model_spec::Error) -> Self {
        match e {
            model_spec::Error::InvalidConfig(m) => Error::InvalidConfig(m),
            model_spec::Error::UnknownModel(m) => Error::UnknownModel(m),
        }
    }
}

/// `Result` with this crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_spec_errors_keep_their_messages() {
        for e in [
            model_spec::Error::InvalidConfig("width must be positive".into()),
            model_spec::Error::UnknownModel("mlp".into()),
        ] {
            let text = e.to_string();
            assert_eq!(Error::from(e).to_string(), text);
        }
    }
}
