//! Which burn backend runs a model, and how a training step's matrix products are computed:
//! the names a run's configuration and `metrics.json` record. brdf-neural makes the devices
//! and checks the precision (`brdf_neural::device::BackendDevice`,
//! `brdf_neural::precision::PrecisionSupport`); here they are only values, so that the crates
//! that read a run's records compile no tensor library.

use serde::{Deserialize, Serialize};

/// A burn backend brdf-neural can be built with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// burn-flex, pure Rust, CPU (brdf-neural's feature `flex`, on by default).
    #[default]
    Flex,
    /// burn-ndarray, CPU (feature `ndarray`).
    NdArray,
    /// burn-wgpu, GPU (feature `wgpu`).
    Wgpu,
    /// CubeCL's CUDA runtime, NVIDIA GPUs (feature `cuda`).
    Cuda,
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Backend {
    /// Every backend, built or not.
    pub const ALL: [Backend; 4] = [Backend::Flex, Backend::NdArray, Backend::Wgpu, Backend::Cuda];

    /// Whether the backend runs on a GPU.
    pub fn is_gpu(self) -> bool {
        matches!(self, Backend::Wgpu | Backend::Cuda)
    }

    /// The name [`Backend::parse_with`] reads (and `metrics.json` records).
    pub fn name(self) -> &'static str {
        match self {
            Backend::Flex => "flex",
            Backend::NdArray => "ndarray",
            Backend::Wgpu => "wgpu",
            Backend::Cuda => "cuda",
        }
    }

    /// Parses `cpu` (`cpu_default`, the build's CPU backend), `flex`, `ndarray`, `wgpu` or
    /// `cuda` (case-insensitive). A backend that is not built in parses; making its device
    /// fails.
    pub fn parse_with(name: &str, cpu_default: Backend) -> crate::Result<Backend> {
        match name.to_ascii_lowercase().as_str() {
            "cpu" => Ok(cpu_default),
            "flex" => Ok(Backend::Flex),
            "ndarray" => Ok(Backend::NdArray),
            "wgpu" => Ok(Backend::Wgpu),
            "cuda" => Ok(Backend::Cuda),
            _ => Err(crate::Error::UnknownBackend(name.to_string())),
        }
    }
}

/// How the f32 matrix products of a training step are computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MatmulPrecision {
    /// f32 operands, f32 sums (the default).
    #[default]
    F32,
    /// Operands rounded to bf16, products summed in f32.
    Bf16,
    /// Operands scaled by powers of two and rounded to binary16, products summed in binary16
    /// over runs of 32, the runs in f32 (the CPU's AVX512-FP16; `cpu_kernels::f16dot`).
    F16,
}

impl MatmulPrecision {
    /// The config and command-line spelling.
    pub fn name(self) -> &'static str {
        match self {
            MatmulPrecision::F32 => "f32",
            MatmulPrecision::Bf16 => "bf16",
            MatmulPrecision::F16 => "f16",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_cpu_is_the_builds_default() {
        for b in Backend::ALL {
            assert_eq!(Backend::parse_with(b.name(), Backend::Flex).unwrap(), b);
            assert_eq!(Backend::parse_with(&b.name().to_uppercase(), Backend::Flex).unwrap(), b);
        }
        assert_eq!(Backend::parse_with("cpu", Backend::NdArray).unwrap(), Backend::NdArray);
        let e = Backend::parse_with("tpu", Backend::Flex).unwrap_err().to_string();
        assert!(e.contains("\"tpu\"") && e.contains("wgpu"), "{e}");
        assert!(Backend::Cuda.is_gpu() && !Backend::Flex.is_gpu());
        assert_eq!(MatmulPrecision::default().name(), "f32");
    }
}
