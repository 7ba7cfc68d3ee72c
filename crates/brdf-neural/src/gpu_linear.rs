//! Which kernels compute the linear layers on a GPU (a CubeCL device, `--backend wgpu|cuda`),
//! and the tuning of this workspace's own: model-spec's [`GpuTuning`] (its module documents
//! the values, defaults and the command line's environment variables). A value in each batch's
//! products ([`crate::products::Products::gpu`]), handed to every product, never a process-wide
//! choice:
//!
//! | [`GpuLinear`] | kernels |
//! | --- | --- |
//! | `Ours` (the default) | this workspace's `gpu-kernels`: a tiled product with the bias fused, the weight gradient split over the batch inside its kernel and its parts added in a fixed order, through the same backend extension as the CPU kernels ([`crate::linear_op`]), on [`GpuTuning::tile`] and [`GpuTuning::split_len`] |
//! | `Burn` | burn's: CubeCL's autotuned matrix product; the trainer splits the batch ([`crate::batch_split`]) so that autodiff splits the weight gradients |
//!
//! A training step's batches carry the run's tuning; inference passes (evaluation, export) run
//! the default tuning, so that a fit's scores do not depend on how it was trained fast.
//!
//! One setting stays per process: [`GpuTuning::checked`], CubeCL's index checks, a debugging
//! aid that gives the same values (`gpu_kernels::checks`); the command line applies it with
//! [`launch_checked`].

pub use model_spec::{GpuLinear, GpuTile, GpuTuning};

/// Launches every GPU kernel of this process with CubeCL's index checks (`true`) or without
/// (`false`, the default): a debugging aid whose results are the same bits. Does nothing in a
/// build without a GPU backend.
pub fn launch_checked(checked: bool) {
    #[cfg(any(feature = "wgpu", feature = "cuda"))]
    gpu_kernels::checks::set_checked(checked);
    #[cfg(not(any(feature = "wgpu", feature = "cuda")))]
    let _ = checked;
}

/// The kernels' spelling of `tuning`'s tile and split length.
#[cfg(any(feature = "wgpu", feature = "cuda"))]
pub(crate) fn kernel_tuning(tuning: GpuTuning) -> gpu_kernels::plan::Tuning {
    use gpu_kernels::plan::Tiling;
    let tiling = match tuning.tile {
        GpuTile::T64 => Tiling::T64,
        GpuTile::T128 => Tiling::T128,
        GpuTile::T64V => Tiling::T64V,
        GpuTile::T128V => Tiling::T128V,
    };
    // model-spec checked the length (a power of two from 64 to 65,536); the kernels check again.
    let tuning_of = gpu_kernels::plan::Tuning { tiling, split_len: None };
    tuning_of.with_split_len(tuning.split_len).unwrap_or(tuning_of)
}

#[cfg(all(test, any(feature = "wgpu", feature = "cuda")))]
mod tests {
    use super::*;

    #[test]
    fn every_tile_and_split_length_reaches_the_kernels() {
        use gpu_kernels::plan::Tiling;
        let t =
            |tile, split_len| kernel_tuning(GpuTuning { tile, split_len, ..Default::default() });
        assert_eq!(t(GpuTile::T64, None), gpu_kernels::plan::Tuning::default());
        assert_eq!(t(GpuTile::T128V, Some(512)).tiling, Tiling::T128V);
        assert_eq!(t(GpuTile::T64V, Some(512)).split_len, Some(512));
        assert_eq!(t(GpuTile::T128, None).tiling, Tiling::T128);
    }
}
