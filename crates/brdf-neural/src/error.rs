//! The crate's error type.

use crate::device::Backend;

/// Everything that can go wrong when configuring a model or building a batch. Evaluating a
/// model never fails.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A model configuration that combines options the paper does not combine or has a value
    /// out of range, or an unknown model name (model-spec's error; the message names the
    /// field or the name).
    #[error(transparent)]
    Spec(#[from] model_spec::Error),
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
    /// A setting (an environment variable) with a value this crate does not know; the message
    /// names the variable and the values it takes.
    #[error("{0}")]
    Setting(String),
    /// Sample arrays whose lengths disagree.
    #[error("batch shape: {0}")]
    BatchShape(String),
    /// A model output that could not be read back from the device as f32.
    #[error("cannot read the model's output back: {0}")]
    Readback(String),
}

/// `Result` with this crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
