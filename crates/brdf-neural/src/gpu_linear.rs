//! Which kernels compute the linear layers on a GPU (a CubeCL device, `--backend wgpu|cuda`):
//!
//! | value of `NEURAL_BRDF_GPU_LINEAR` | kernels |
//! | --- | --- |
//! | `burn` (the default) | burn's: CubeCL's autotuned matrix product; the trainer splits the batch ([`crate::split_k`]) so that autodiff splits the weight gradients |
//! | `ours` | this workspace's `gpu-kernels`: a tiled product with the bias fused, the weight gradient split over the batch inside its kernel and its parts added in a fixed order, through the same backend extension as the CPU kernels ([`crate::linear_op`]) |
//!
//! The choice is per process (the environment is read once). An unknown value is refused when a
//! GPU device is made ([`crate::device::Backend::device`]), naming the variable. `ours` is off
//! by default until it is measured faster on a GPU (`benches/device_gpu.sh`, stage `linear`).

use std::sync::OnceLock;

/// The environment variable that picks the GPU kernels of the linear layers.
pub const VAR: &str = "NEURAL_BRDF_GPU_LINEAR";

/// The kernels of the linear layers on a GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GpuLinear {
    /// burn's own `linear` (CubeCL's matrix product).
    #[default]
    Burn,
    /// The `gpu-kernels` crate.
    Ours,
}

impl GpuLinear {
    /// Parses `burn` or `ours`.
    pub fn parse(value: &str) -> crate::Result<Self> {
        match value.trim().to_ascii_lowercase().as_str() {
            "burn" | "" => Ok(GpuLinear::Burn),
            "ours" => Ok(GpuLinear::Ours),
            other => Err(crate::Error::Setting(format!(
                "{VAR}={other:?}: expected `burn` (burn's kernels, the default) or `ours` \
                 (the gpu-kernels crate)"
            ))),
        }
    }

    /// The value of [`VAR`] (`burn` where it is not set).
    pub fn from_env() -> crate::Result<Self> {
        match std::env::var(VAR) {
            Ok(v) => Self::parse(&v),
            Err(_) => Ok(GpuLinear::Burn),
        }
    }

    /// The process's choice: [`GpuLinear::from_env`] on first use (an unknown value, which
    /// making a GPU device refuses, counts as `burn` here).
    pub fn current() -> Self {
        static CHOICE: OnceLock<GpuLinear> = OnceLock::new();
        *CHOICE.get_or_init(|| Self::from_env().unwrap_or_default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_parse_and_unknown_ones_name_the_variable() {
        assert_eq!(GpuLinear::parse("burn").unwrap(), GpuLinear::Burn);
        assert_eq!(GpuLinear::parse(" Ours ").unwrap(), GpuLinear::Ours);
        assert_eq!(GpuLinear::parse("").unwrap(), GpuLinear::Burn);
        let e = GpuLinear::parse("cublas").unwrap_err().to_string();
        assert!(e.contains(VAR) && e.contains("cublas") && e.contains("ours"), "{e}");
    }
}
