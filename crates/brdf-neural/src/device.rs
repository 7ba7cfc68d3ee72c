//! Run-time choice of the burn backend: the only place in the crate that names one.
//!
//! Models, batches and the tensor BRDFs take a [`Device`]; which backend runs them is decided
//! here, from cargo features and, at run time, from [`Backend`] (for example parsed from a
//! configuration or the `--backend` flag of a binary).
//!
//! | backend | cargo feature | default | notes |
//! | --- | --- | --- | --- |
//! | `flex` | `flex` | yes | burn's pure-Rust CPU backend; fastest measured CPU backend here |
//! | `ndarray` | `ndarray` | no | the design's original CPU backend, deprecated upstream |
//! | `wgpu` | `wgpu` | no | GPU (Vulkan/Metal/DX12 through wgpu); not built in CI |
//!
//! The CPU devices made here also tell the C allocator to keep freed tensor buffers for reuse
//! ([`crate::host_memory`]): 1.5 to 1.7x faster training steps on glibc, measured.
//!
//! No build requires a CPU feature the machine may lack: flex's matrix products come from the
//! `gemm` crate, which picks AVX2/FMA kernels at run time; its AVX-512 kernels are compiled only
//! with the opt-in `x86-v4` feature of this crate (and still selected at run time).

use burn::tensor::Device;
use serde::{Deserialize, Serialize};

/// A burn backend this crate can be built with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// burn-flex, pure Rust, CPU (feature `flex`, on by default).
    Flex,
    /// burn-ndarray, CPU (feature `ndarray`).
    NdArray,
    /// burn-wgpu, GPU (feature `wgpu`).
    Wgpu,
}

impl Backend {
    /// The backends compiled into this build, default first.
    pub fn available() -> Vec<Backend> {
        let mut out = Vec::new();
        if cfg!(feature = "flex") {
            out.push(Backend::Flex);
        }
        if cfg!(feature = "ndarray") {
            out.push(Backend::NdArray);
        }
        if cfg!(feature = "wgpu") {
            out.push(Backend::Wgpu);
        }
        out
    }

    /// Parses `flex`, `ndarray` or `wgpu` (case-insensitive).
    pub fn parse(name: &str) -> crate::Result<Backend> {
        match name.to_ascii_lowercase().as_str() {
            "flex" => Ok(Backend::Flex),
            "ndarray" => Ok(Backend::NdArray),
            "wgpu" => Ok(Backend::Wgpu),
            _ => Err(crate::Error::UnknownBackend(name.to_string())),
        }
    }

    /// The inference device of this backend, or an error if it was not compiled in.
    ///
    /// The CPU backends first apply the process's host-memory policy
    /// ([`host_memory::keep_freed_tensor_memory`](crate::host_memory::keep_freed_tensor_memory)).
    #[allow(unreachable_code)]
    pub fn device(self) -> crate::Result<Device> {
        match self {
            Backend::Flex => {
                #[cfg(feature = "flex")]
                {
                    crate::host_memory::keep_freed_tensor_memory();
                    return Ok(Device::flex());
                }
            }
            Backend::NdArray => {
                #[cfg(feature = "ndarray")]
                #[allow(deprecated)]
                {
                    crate::host_memory::keep_freed_tensor_memory();
                    return Ok(Device::ndarray());
                }
            }
            Backend::Wgpu => {
                #[cfg(feature = "wgpu")]
                return Ok(Device::wgpu(Default::default()));
            }
        }
        Err(crate::Error::BackendNotBuilt(self))
    }

    /// The training device of this backend (the inference device with autodiff).
    pub fn training_device(self) -> crate::Result<Device> {
        Ok(self.device()?.autodiff())
    }
}

/// The default CPU device: flex when built, else ndarray.
///
/// # Panics
/// If the crate was built without any CPU backend feature.
pub fn cpu() -> Device {
    Backend::available()
        .into_iter()
        .find(|b| *b != Backend::Wgpu)
        .expect("brdf-neural built without a CPU backend (enable `flex` or `ndarray`)")
        .device()
        .expect("available backend")
}

/// [`cpu`] with autodiff, for training.
pub fn cpu_training() -> Device {
    cpu().autodiff()
}
