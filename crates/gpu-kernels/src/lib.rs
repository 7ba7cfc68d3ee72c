//! The GPU kernels of the neural models' linear layers, written in CubeCL (one kernel source for
//! CUDA, Vulkan/WGSL and Metal), on plain device buffers: no tensor library, so that a burn
//! backend extension can hand them its buffers as `cpu-kernels` gets flex's on the CPU.
//!
//! | module | what |
//! | --- | --- |
//! | [`plan`] | the launch plan in plain Rust: tilings, precisions, tunings, split counts, shape errors |
//! | `gemm` | the tiled f32 product with strided operands, the bias and ReLU fused, split-K |
//! | `gemm_vec4` | the same product with 4-wide shared-memory reads ([`plan::Tiling::T64V`]) |
//! | `gemm_cmma` | the same product on tensor cores, bf16 operands, f32 sums ([`plan::Precision::Bf16`]) |
//! | `reduce` | fixed-order sums: split-K's partials, column sums (the bias gradient) |
//! | `elementwise` | the ReLU backward |
//! | `linear` | a layer's five operations on row-major `linear::Matrix`es, shapes checked |
//! | `checks` | whether the kernels launch with CubeCL's index checks (off by default) |
//!
//! Every sum runs in an order fixed by the shapes and the call's arguments (split counts depend
//! on the shapes and the [`plan::Tuning`] handed to each call, nothing per process), so a
//! result is the same bits run to run. The tests (`--features wgpu`) compare each
//! operation with an f64 reference on any Vulkan device, Mesa's lavapipe included.
//!
//! Everything but [`plan`] needs the feature `kernels` (CubeCL; `wgpu` and `cuda` turn it on,
//! and so do brdf-neural's GPU features). Without it no kernel can launch anyway, and the
//! workspace's default test build does not compile CubeCL's compiler for nothing.

pub mod plan;

#[cfg(feature = "kernels")]
pub mod checks;
#[cfg(feature = "kernels")]
pub mod elementwise;
#[cfg(feature = "kernels")]
pub mod gemm;
#[cfg(feature = "kernels")]
pub mod gemm_cmma;
#[cfg(feature = "kernels")]
pub mod gemm_vec4;
#[cfg(feature = "kernels")]
pub mod linear;
#[cfg(feature = "kernels")]
pub mod reduce;
