//! How a batch's linear layers compute their matrix products: in which precision, and with
//! the batch split into how many parts for the weight gradients. A value carried by the batch
//! ([`crate::BrdfBatch::products`]), never a per-thread or per-process switch, so a product's
//! inputs say everything that decides its value.
//!
//! A batch starts as [`Products::F32`], the plain f32 product (every evaluation, the
//! validation loss). A training loop builds its step batches with [`Products::training`]: the
//! run's `matmul_precision` (checked against the backend, [`PrecisionSupport::check`]) and, on
//! a GPU, the batch split of [`crate::batch_split`]. An evaluation on a GPU splits its passes
//! the same way ([`Products::inference`]), so that it meets the shapes training tuned.

use crate::batch_split::gpu_parts;
use crate::device::Backend;
use crate::precision::{MatmulPrecision, PrecisionSupport};

/// The precision and the batch split of a batch's linear layers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Products {
    /// The precision of the network's large matrix products ([`crate::precision`]).
    pub precision: MatmulPrecision,
    /// Parts of the batch whose weight-gradient sums are split (1: the plain product;
    /// [`crate::batch_split`]).
    pub parts: usize,
}

impl Default for Products {
    fn default() -> Self {
        Self::F32
    }
}

impl Products {
    /// Plain f32 products, unsplit.
    pub const F32: Products = Products { precision: MatmulPrecision::F32, parts: 1 };

    /// The products of a training step of `batch_rows` samples on `backend`: `precision`,
    /// and on a GPU the split of [`gpu_parts`] (the CPU keeps the plain product).
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
        Ok(Products { precision, parts })
    }

    /// The products of an inference pass of `rows` samples: f32, split as a training step on
    /// a GPU would split them (`gpu`), unsplit on the CPU.
    pub fn inference(gpu: bool, rows: usize) -> Products {
        Products { precision: MatmulPrecision::F32, parts: if gpu { gpu_parts(rows) } else { 1 } }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn training_splits_only_on_a_gpu_and_checks_the_precision() {
        let cpu = Products::training(MatmulPrecision::Bf16, Backend::Flex, 32_768).unwrap();
        assert_eq!(cpu, Products { precision: MatmulPrecision::Bf16, parts: 1 });
        let gpu = Products::training(MatmulPrecision::F32, Backend::Wgpu, 32_768).unwrap();
        assert_eq!(gpu, Products { precision: MatmulPrecision::F32, parts: 64 });
        assert!(Products::training(MatmulPrecision::Bf16, Backend::Wgpu, 32_768).is_err());
        assert_eq!(Products::inference(false, 32_768), Products::F32);
        assert_eq!(Products::inference(true, 8_192).parts, 16);
        assert_eq!(Products::default(), Products::F32);
    }
}
