//! Precision of the f32 matrix products in training: plain f32, bf16 dot products, or scaled
//! binary16 multiply-adds.
//!
//! [`MatmulPrecision::Bf16`] is the CPU counterpart of PyTorch's
//! `torch.set_float32_matmul_precision("medium")`: the operands of the network's large matrix
//! products are rounded to bfloat16 (8 significant bits), the products summed in f32; weights,
//! activations, gradients and Adam stay f32. On Intel CPUs with AMX the products run on its tiles
//! (`tdpbf16ps`), on other CPUs with AVX512-BF16 at twice the multiply-adds per instruction of
//! f32 (`vdpbf16ps`), both in the `cpu-kernels` crate; elsewhere the same rounding is emulated,
//! slower than f32. On an NVIDIA GPU (`--backend cuda`, Ampere or later) the products run on
//! tensor cores (`gpu-kernels`' `gemm_cmma`), PyTorch's bf16 autocast for the linear layers.
//! The flex and cuda backends implement it; the others refuse it.
//!
//! [`MatmulPrecision::F16`] is for Intel CPUs whose bf16 is slow (AVX512-BF16 without AMX
//! tiles) but which run AVX512-FP16's `vfmadd231ph`: twice f32's multiply-adds per
//! instruction. The operands are scaled by powers of two per row and column and rounded to
//! binary16 (11 significant bits), the products summed in binary16 over runs of 64 and the
//! runs in f32 (`cpu_kernels::f16dot` defines the value to the bit and emulates it on other
//! CPUs). The forward and input-gradient products take it; the weight gradients stay f32. The
//! flex backend alone implements it.
//!
//! The precision is part of a batch's [`crate::products::Products`], with the choice of the
//! bf16 kernel (AMX tiles where available, or AVX512-BF16): a training loop's step
//! batches carry the run's precision, every other batch (the validation loss, which decides
//! the plateau schedule, and every evaluation) plain f32. The layers hand it to the kernels as
//! an argument of each product ([`crate::linear_op`]), which keep it for the product's
//! backward pass; no other matrix product in the process is affected. Products that gain
//! nothing (narrow heads such as the 3-channel output, small products) stay f32.

/// The precisions' names (model-spec's, so that a run's configuration needs no tensor library).
pub use model_spec::MatmulPrecision;

/// What this crate knows of a [`MatmulPrecision`]: where it runs
/// ([`PrecisionSupport::check`]) and what the CPU runs natively.
pub trait PrecisionSupport {
    /// Whether `backend` runs this precision's products.
    ///
    /// # Errors
    /// [`crate::Error::Spec`] (an invalid configuration) for bf16 on a backend other than flex
    /// and cuda (on cuda with this workspace's kernels for the linear layers, the default;
    /// [`crate::products::Products::check`] also refuses burn's there).
    fn check(self, backend: crate::device::Backend) -> crate::Result<()>;

    /// Whether this CPU has Intel's AMX-BF16 tile unit (Xeons from Sapphire Rapids on; CPUID
    /// leaf 7, EDX bit 22). The flex backend's bf16 products run on it when Linux grants the
    /// tile registers ([`PrecisionSupport::bf16_on_amx`]); without it they take the AVX512-BF16
    /// kernel, measured slower than f32 on such a Xeon (`benches/README.md`, "bf16 on an Intel
    /// Xeon with AMX"), and the trainer warns.
    fn cpu_has_amx_bf16() -> bool;

    /// Whether bf16 products that ask for AMX tiles ([`crate::products::Products::bf16_amx`])
    /// run on them here (the flex backend's AMX kernel: the CPU has AMX-BF16 and Linux granted
    /// the tile registers).
    fn bf16_on_amx() -> bool;

    /// Whether this CPU runs bf16 products natively (otherwise they are emulated, slowly).
    fn bf16_native() -> bool;

    /// Whether this CPU's AVX512-BF16 kernel is faster than f32 (AMD's CPUs with it; not
    /// Intel's, where AMX is the fast bf16 path: `cpu_kernels::bf16_dot_outpaces_f32`).
    fn bf16_dot_outpaces_f32() -> bool;

    /// Whether this CPU runs [`MatmulPrecision::F16`]'s binary16 multiply-adds natively
    /// (AVX512-FP16: Intel's Xeons from Sapphire Rapids on); otherwise they are emulated.
    fn f16_native() -> bool;

    /// The precision a CPU run takes when neither its configuration nor the command line names
    /// one: bf16 where it is faster than f32 here (AMX tiles granted, or AVX512-BF16 on an AMD
    /// CPU); else f16 where AVX512-FP16 runs it (an Intel CPU whose AMX tiles were refused or
    /// are hidden by a hypervisor: its AVX512-BF16 kernel is slower than f32, its binary16
    /// products faster); else f32. `docs/reproduce.md` ("bf16 as the CPU default", "f16 where
    /// bf16 is slow") gives the measurements that keep their converged scores within f32's seed
    /// noise.
    fn cpu_default() -> MatmulPrecision {
        if Self::bf16_on_amx() || Self::bf16_dot_outpaces_f32() {
            MatmulPrecision::Bf16
        } else if Self::f16_native() {
            MatmulPrecision::F16
        } else {
            MatmulPrecision::F32
        }
    }
}

impl PrecisionSupport for MatmulPrecision {
    fn check(self, backend: crate::device::Backend) -> crate::Result<()> {
        use crate::device::Backend;
        if self == MatmulPrecision::F32 {
            return Ok(());
        }
        if self == MatmulPrecision::F16 && backend != Backend::Flex {
            let why = format!(
                "matmul precision f16 is implemented for the flex CPU backend only (AVX512-FP16),                  not {}: use bf16 on a GPU",
                backend.name()
            );
            return Err(model_spec::Error::InvalidConfig(why).into());
        }
        let refused = match backend {
            Backend::Flex => None,
            Backend::Cuda => None,
            Backend::Wgpu => Some(
                "matmul precision bf16 needs tensor cores, which wgpu's shading language (WGSL) \
                 cannot reach: on an NVIDIA GPU use --backend cuda (Ampere or later), or train \
                 in f32"
                    .to_string(),
            ),
            other => Some(format!(
                "matmul precision bf16 is implemented for the flex CPU backend and for cuda, not \
                 {}",
                other.name()
            )),
        };
        match refused {
            Some(why) => Err(model_spec::Error::InvalidConfig(why).into()),
            None => Ok(()),
        }
    }

    fn cpu_has_amx_bf16() -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{__cpuid, __cpuid_count};
            __cpuid(0).eax >= 7 && (__cpuid_count(7, 0).edx >> 22) & 1 == 1
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            false
        }
    }

    fn bf16_on_amx() -> bool {
        #[cfg(feature = "flex")]
        {
            cpu_kernels::bf16_amx_available()
        }
        #[cfg(not(feature = "flex"))]
        {
            false
        }
    }

    fn bf16_native() -> bool {
        #[cfg(feature = "flex")]
        {
            cpu_kernels::bf16_dot_native()
        }
        #[cfg(not(feature = "flex"))]
        {
            false
        }
    }

    fn bf16_dot_outpaces_f32() -> bool {
        #[cfg(feature = "flex")]
        {
            cpu_kernels::bf16_dot_outpaces_f32()
        }
        #[cfg(not(feature = "flex"))]
        {
            false
        }
    }

    fn f16_native() -> bool {
        #[cfg(feature = "flex")]
        {
            cpu_kernels::f16dot::f16_native()
        }
        #[cfg(not(feature = "flex"))]
        {
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{MatmulPrecision, PrecisionSupport};

    /// The CPUID bit agrees with the kernel's own reading of it (Linux's `amx_bf16` flag).
    #[test]
    fn amx_detection_agrees_with_the_kernel() {
        let Ok(info) = std::fs::read_to_string("/proc/cpuinfo") else {
            return; // not Linux: nothing to compare with
        };
        let Some(flags) = info.lines().find(|l| l.starts_with("flags")) else {
            return; // an architecture whose cpuinfo has no flags line
        };
        let kernel = flags.split_whitespace().any(|f| f == "amx_bf16");
        assert_eq!(MatmulPrecision::cpu_has_amx_bf16(), kernel, "{flags}");
    }

    /// The CPU default is bf16 exactly where bf16 runs natively and faster than f32, else f16
    /// where AVX512-FP16 runs it, else f32.
    #[test]
    fn the_cpu_default_is_bf16_only_where_it_is_native_and_faster() {
        let d = MatmulPrecision::cpu_default();
        if !MatmulPrecision::bf16_native() {
            assert_eq!(d, MatmulPrecision::F32, "emulated bf16 is slower than f32");
        }
        if MatmulPrecision::bf16_on_amx() {
            assert_eq!(d, MatmulPrecision::Bf16);
        }
        if d == MatmulPrecision::F16 {
            assert!(MatmulPrecision::f16_native(), "emulated f16 is slower than f32");
        }
        if MatmulPrecision::cpu_has_amx_bf16() && !MatmulPrecision::bf16_on_amx() {
            assert_eq!(d, MatmulPrecision::F32, "AVX512-BF16 on an AMX Xeon is slower than f32");
        }
        // The vendor as Linux reads it, against the kernels' own CPUID reading.
        let vendor = std::fs::read_to_string("/proc/cpuinfo").ok().and_then(|info| {
            let line = info.lines().find(|l| l.starts_with("vendor_id"))?;
            Some(line.split(':').nth(1)?.trim().to_string())
        });
        if MatmulPrecision::bf16_native() && !MatmulPrecision::bf16_on_amx() {
            match vendor.as_deref() {
                Some("GenuineIntel") => assert_ne!(
                    d,
                    MatmulPrecision::Bf16,
                    "AVX512-BF16 without AMX tiles on an Intel CPU is slower than f32"
                ),
                Some("AuthenticAMD") => {
                    assert_eq!(d, MatmulPrecision::Bf16, "AVX512-BF16 on AMD outpaces f32")
                }
                _ => {}
            }
        }
    }
}
