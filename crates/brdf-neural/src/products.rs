//! How a batch's linear layers compute their matrix products: in which precision, on which
//! bf16 kernel, and with the batch split into how many parts for the weight gradients. A value
//! carried by the batch ([`crate::BrdfBatch::products`]) and handed to every product as an
//! argument ([`crate::linear_op`]), never a per-thread or per-process switch, so a product's
//! inputs say everything that decides its value.
//!
//! A batch starts as [`Products::F32`], the plain f32 product (every evaluation, the
//! validation loss). A training loop builds its step batches with [`Products::training`]: the
//! run's `matmul_precision` (checked against the backend, [`PrecisionSupport::check`]) and, on
//! a GPU, the batch split of [`crate::batch_split`]. An evaluation on a GPU splits its passes
//! the same way ([`Products::inference`]), so that it meets the shapes training tuned.

use crate::device::Backend;
use crate::gpu_linear::{GpuLinear, GpuTuning};
use crate::precision::{MatmulPrecision, PrecisionSupport};

/// The split a GPU training loop uses for a batch of `rows` ([`crate::batch_split`]): parts of
/// 512 rows (64 parts at 2^15), at most 64 parts, and 1 where that does not divide the batch.
pub fn gpu_parts(rows: usize) -> usize {
    let parts = (rows / 512).clamp(1, 64);
    if rows.is_multiple_of(parts) { parts } else { 1 }
}

/// The precision and the batch split of a batch's linear layers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Products {
    /// The precision of the network's large matrix products ([`crate::precision`]).
    pub precision: MatmulPrecision,
    /// Parts of the batch whose weight-gradient sums are split (1: the plain product;
    /// [`crate::batch_split`]).
    pub parts: usize,
    /// Whether bf16 products on the CPU take Intel's AMX tiles where the CPU and the OS allow
    /// them ([`PrecisionSupport::bf16_on_amx`]; default true), or the AVX512-BF16 kernel. The
    /// two sum in different orders: their values differ in the last bits.
    pub bf16_amx: bool,
    /// How the linear layers run on a GPU: which kernels, their tile and split length
    /// ([`crate::gpu_linear`]; default: this workspace's kernels with their own rules).
    pub gpu: GpuTuning,
}

impl Default for Products {
    fn default() -> Self {
        Self::F32
    }
}

impl Products {
    /// Plain f32 products, unsplit.
    pub const F32: Products = Products {
        precision: MatmulPrecision::F32,
        parts: 1,
        bf16_amx: true,
        gpu: GpuTuning {
            linear: GpuLinear::Ours,
            split_len: None,
            tile: crate::gpu_linear::GpuTile::T64,
            checked: false,
        },
    };

    /// These products with bf16 on AMX tiles where available (`true`) or on the AVX512-BF16
    /// kernel (`false`).
    pub fn with_bf16_amx(self, bf16_amx: bool) -> Products {
        Products { bf16_amx, ..self }
    }

    /// These products with the GPU's linear layers on `gpu`.
    pub fn with_gpu(self, gpu: GpuTuning) -> Products {
        Products { gpu, ..self }
    }

    /// The products of a training step of `batch_rows` samples on `backend`: `precision`,
    /// and on a GPU the split of [`gpu_parts`] (the CPU keeps the plain product), on the
    /// default GPU kernels ([`Products::with_gpu`] picks others).
    ///
    /// # Errors
    /// [`crate::Error::Spec`] where `backend` cannot run `precision`
    /// ([`PrecisionSupport::check`]).
    pub fn training(
        precision: MatmulPrecision,
        backend: Backend,
        batch_rows: usize,
    ) -> crate::Result<Products> {
        precision.check(backend)?;
        let parts = if backend.is_gpu() { gpu_parts(batch_rows) } else { 1 };
        Ok(Products { precision, parts, ..Products::F32 })
    }

    /// Refuses products that `backend` cannot run: bf16 where no kernel implements it
    /// ([`PrecisionSupport::check`]), and bf16 on cuda with burn's kernels for the linear
    /// layers, which have no bf16 path.
    ///
    /// # Errors
    /// [`crate::Error::Spec`], saying what to change.
    pub fn check(&self, backend: Backend) -> crate::Result<()> {
        self.precision.check(backend)?;
        if self.precision == MatmulPrecision::Bf16
            && backend == Backend::Cuda
            && self.gpu.linear == GpuLinear::Burn
        {
            return Err(model_spec::Error::InvalidConfig(
                "matmul precision bf16 on cuda runs on this workspace's GPU kernels, not burn's \
                 (NEURAL_BRDF_GPU_LINEAR=burn): unset it"
                    .into(),
            )
            .into());
        }
        Ok(())
    }

    /// Why these products would be slower than f32 on this CPU (bf16 emulated, the AMX kernel
    /// off, or AVX512-BF16 on an Intel CPU without AMX tiles), for a warning; `None` when they
    /// are not, or on a GPU backend.
    pub fn slow_bf16_warning(&self, backend: Backend) -> Option<&'static str> {
        if backend.is_gpu() {
            return None;
        }
        if self.precision == MatmulPrecision::F16 {
            return (!MatmulPrecision::f16_native()).then_some(
                "matmul_precision = \"f16\" on a CPU without AVX512-FP16: the products are \
                 emulated one multiply-add at a time, many times slower than f32; f32 (or bf16 \
                 where native) is the faster choice here",
            );
        }
        if self.precision != MatmulPrecision::Bf16 {
            return None;
        }
        if !MatmulPrecision::bf16_native() {
            Some(
                "matmul_precision = \"bf16\" on a CPU without AVX512-BF16: the products are \
                 emulated, about 2x slower a step than f32 (measured on an Intel Xeon without \
                 it); f32 is the faster choice here",
            )
        } else if self.bf16_amx && MatmulPrecision::bf16_on_amx() {
            None
        } else if MatmulPrecision::cpu_has_amx_bf16() {
            Some(
                "matmul_precision = \"bf16\" on an Intel CPU with AMX, but the AMX kernel is off \
                 (CPU_KERNELS_AMX=0, or Linux refused the tile registers): the products run on \
                 AVX512-BF16, measured 1.3x slower a step than f32 on such a Xeon \
                 (benches/README.md); f32 is likely the faster choice here",
            )
        } else if !MatmulPrecision::bf16_dot_outpaces_f32() {
            Some(
                "matmul_precision = \"bf16\" on an Intel CPU without AMX tiles (or whose \
                 hypervisor hides them): the products run on AVX512-BF16, measured 1.3 to 1.8x \
                 slower a step than f32 on such a Xeon (benches/README.md); f32 is likely the \
                 faster choice here",
            )
        } else {
            None
        }
    }

    /// The products of an inference pass of `rows` samples: f32, split as a training step on
    /// a GPU would split them (`gpu`), unsplit on the CPU.
    pub fn inference(gpu: bool, rows: usize) -> Products {
        Products { parts: if gpu { gpu_parts(rows) } else { 1 }, ..Products::F32 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gpu_parts_divide_the_batch_into_parts_of_512_rows() {
        assert_eq!(gpu_parts(32_768), 64);
        assert_eq!(gpu_parts(8_192), 16);
        assert_eq!(gpu_parts(65_536), 64);
        assert_eq!(gpu_parts(300), 1);
        assert_eq!(gpu_parts(1_536), 3);
        assert_eq!(gpu_parts(1_600), 1); // 3 parts do not divide 1,600 rows
    }

    #[test]
    fn training_splits_only_on_a_gpu_and_checks_the_precision() {
        let cpu = Products::training(MatmulPrecision::Bf16, Backend::Flex, 32_768).unwrap();
        assert_eq!(cpu, Products { precision: MatmulPrecision::Bf16, ..Products::F32 });
        assert!(!cpu.with_bf16_amx(false).bf16_amx);
        let gpu = Products::training(MatmulPrecision::F32, Backend::Wgpu, 32_768).unwrap();
        assert_eq!(gpu, Products { parts: 64, ..Products::F32 });
        assert_eq!(Products::F32.gpu, GpuTuning::default());
        assert!(Products::training(MatmulPrecision::Bf16, Backend::Wgpu, 32_768).is_err());
        assert_eq!(Products::inference(false, 32_768), Products::F32);
        assert_eq!(Products::inference(true, 8_192).parts, 16);
        assert_eq!(Products::default(), Products::F32);
        let cuda = Products::training(MatmulPrecision::Bf16, Backend::Cuda, 32_768).unwrap();
        assert!(cuda.check(Backend::Cuda).is_ok());
        let burn = cuda.with_gpu(GpuTuning { linear: GpuLinear::Burn, ..Default::default() });
        let e = burn.check(Backend::Cuda).unwrap_err().to_string();
        assert!(e.contains("burn"), "{e}");
    }
}
