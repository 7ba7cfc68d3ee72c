//! Run-time choice of the burn backend: the only place in the crate that names one.
//!
//! Models, batches and the tensor BRDFs take a [`Device`]; which backend runs them is decided
//! here, from cargo features and, at run time, from [`Backend`] (model-spec's names, parsed by
//! [`parse_backend`] from the `--backend` flag of `fit`/`eval` and `reproduce-tables`), through
//! [`BackendDevice`].
//!
//! | backend | `--backend` | cargo feature | default | notes |
//! | --- | --- | --- | --- | --- |
//! | `flex` | `cpu`, `flex` | `flex` | yes | burn's pure-Rust CPU backend; fastest measured CPU backend here |
//! | `ndarray` | `ndarray` | `ndarray` | no | the design's original CPU backend, deprecated upstream |
//! | `wgpu` | `wgpu` | `wgpu` | no | GPU through wgpu (Vulkan, Metal, DX12); tested on Mesa's software Vulkan (lavapipe) |
//! | `cuda` | `cuda` | `cuda` | no | NVIDIA GPUs through CubeCL; builds without a CUDA toolkit (the driver is loaded at run time) |
//!
//! The GPU features go through the layers: `cargo build --release -p xtask --features wgpu`
//! (or `cuda`) builds a `reproduce-tables` that accepts `--backend wgpu` (or `cuda`).
//!
//! The GPU devices made here keep autotune's choices and compiled kernels in one folder per
//! user and machine ([`crate::gpu_cache`]), so only the first process on a machine tunes.
//!
//! The CPU devices made here also tell the C allocator to keep freed tensor buffers for reuse
//! ([`crate::host_memory`]): markedly faster training steps on glibc (`benches/README.md`).
//!
//! No build requires a CPU feature the machine may lack: flex's matrix products come from the
//! `gemm` crate, which picks AVX2/FMA kernels at run time; its AVX-512 kernels are compiled only
//! with the opt-in `x86-v4` feature of this crate (and still selected at run time).

use burn::tensor::Device;

/// The backends' names (model-spec's, so that a run's records need no tensor library).
pub use model_spec::Backend;

/// The build's default CPU backend: flex when built, else ndarray (what `cpu` means).
pub fn default_backend() -> Backend {
    if cfg!(feature = "flex") || !cfg!(feature = "ndarray") {
        Backend::Flex
    } else {
        Backend::NdArray
    }
}

/// Parses a backend name: `cpu` ([`default_backend`]), `flex`, `ndarray`, `wgpu` or `cuda`
/// (case-insensitive). A backend that is not built in parses; [`BackendDevice::device`]
/// refuses it.
pub fn parse_backend(name: &str) -> crate::Result<Backend> {
    Backend::parse_with(name, default_backend())
        .map_err(|_| crate::Error::UnknownBackend(name.into()))
}

/// The backends compiled into this build, default first.
pub fn available() -> Vec<Backend> {
    Backend::ALL.into_iter().filter(|b| b.is_built()).collect()
}

/// Whether `x` lives on a GPU (a CubeCL device: `wgpu` or `cuda`).
pub fn on_gpu<const D: usize>(x: &burn::tensor::Tensor<D>) -> bool {
    #[cfg(any(feature = "wgpu", feature = "cuda"))]
    if matches!(x.device().inner().as_dispatch(), burn::backend::DispatchDevice::Cube(_)) {
        return true;
    }
    let _ = x;
    false
}

/// What this build does with a [`Backend`]: whether it is built in, and its devices.
pub trait BackendDevice {
    /// Whether this backend's cargo feature is on in this build.
    fn is_built(&self) -> bool;
    /// The inference device of this backend, or an error if it was not compiled in.
    fn device(self) -> crate::Result<Device>;
    /// The training device of this backend (the inference device with autodiff).
    fn training_device(self) -> crate::Result<Device>;
}

impl BackendDevice for Backend {
    fn is_built(&self) -> bool {
        match *self {
            Backend::Flex => cfg!(feature = "flex"),
            Backend::NdArray => cfg!(feature = "ndarray"),
            Backend::Wgpu => cfg!(feature = "wgpu"),
            Backend::Cuda => cfg!(feature = "cuda"),
        }
    }

    /// The CPU backends first apply the process's host-memory policy
    /// ([`host_memory::keep_freed_tensor_memory`](crate::host_memory::keep_freed_tensor_memory)).
    /// A GPU device is made lazily: a machine without one fails at its first tensor operation.
    #[allow(unreachable_code)]
    fn device(self) -> crate::Result<Device> {
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
                {
                    crate::gpu_cache::configure();
                    return Ok(Device::wgpu(Default::default()));
                }
            }
            Backend::Cuda => {
                #[cfg(feature = "cuda")]
                {
                    // CubeCL loads the driver on a thread of its own and panics there without
                    // one; look for it first, for an error instead.
                    if !cuda_driver_present() {
                        return Err(crate::Error::BackendUnavailable(
                            self,
                            "no NVIDIA driver library (libcuda.so.1) could be loaded; \
                             install the NVIDIA driver or use `--backend wgpu` or `cpu`"
                                .into(),
                        ));
                    }
                    crate::gpu_cache::configure();
                    return Ok(Device::cuda(0usize));
                }
            }
        }
        Err(crate::Error::BackendNotBuilt(self))
    }

    fn training_device(self) -> crate::Result<Device> {
        Ok(self.device()?.autodiff())
    }
}

/// Whether the CUDA driver library can be loaded (what CubeCL's CUDA runtime needs first).
#[cfg(feature = "cuda")]
fn cuda_driver_present() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        ["libcuda.so.1", "libcuda.so"].iter().any(|name| {
            let name = std::ffi::CString::new(*name).expect("no NUL in the name");
            // SAFETY: a NUL-terminated name; the handle is only tested, then released.
            let handle = unsafe { libc::dlopen(name.as_ptr(), libc::RTLD_LAZY | libc::RTLD_LOCAL) };
            if handle.is_null() {
                return false;
            }
            // SAFETY: the handle dlopen just returned.
            unsafe { libc::dlclose(handle) };
            true
        })
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    true
}

/// Whether `device` (with or without autodiff) is a CPU backend's device (flex or ndarray);
/// every other device this crate makes is a GPU's.
pub fn is_cpu_device(device: &Device) -> bool {
    let inner = device.clone().inner();
    #[cfg(feature = "flex")]
    if inner == Device::flex() {
        return true;
    }
    #[cfg(feature = "ndarray")]
    #[allow(deprecated)]
    if inner == Device::ndarray() {
        return true;
    }
    let _ = inner;
    false
}

/// The default CPU device: flex when built, else ndarray.
///
/// # Panics
/// If the crate was built without any CPU backend feature.
pub fn cpu() -> Device {
    default_backend()
        .device()
        .expect("brdf-neural built without a CPU backend (enable `flex` or `ndarray`)")
}

/// [`cpu`] with autodiff, for training.
pub fn cpu_training() -> Device {
    cpu().autodiff()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_cpu_means_the_default() {
        for b in Backend::ALL {
            assert_eq!(parse_backend(b.name()).unwrap(), b);
            assert_eq!(parse_backend(&b.name().to_uppercase()).unwrap(), b);
        }
        assert_eq!(parse_backend("cpu").unwrap(), default_backend());
        assert!(parse_backend("metal").is_err());
        assert!(available().contains(&default_backend()));
        assert!(is_cpu_device(&cpu()));
        assert!(is_cpu_device(&cpu_training()));
    }

    #[test]
    fn a_backend_not_built_in_is_refused_with_its_name() {
        for b in Backend::ALL.into_iter().filter(|b| !b.is_built()) {
            let msg = b.device().unwrap_err().to_string();
            assert!(msg.contains(b.name()), "{msg}");
        }
    }
}
