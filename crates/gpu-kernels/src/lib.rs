//! The GPU kernels of the neural models' linear layers, written in CubeCL (one kernel source for
//! CUDA, Vulkan/WGSL and Metal), on plain device buffers: no tensor library, so that a burn
//! backend extension can hand them its buffers as `cpu-kernels` gets flex's on the CPU.
//!
//! | module | what |
//! | --- | --- |
//! | [`gemm`] | the tiled f32 product with strided operands, the bias and ReLU fused, split-K |
//! | [`gemm_vec4`] | the same product with 4-wide shared-memory reads ([`gemm::Tiling::T64V`]) |
//! | [`gemm_cmma`] | the same product on tensor cores, bf16 operands, f32 sums ([`linear::Precision::Bf16`]) |
//! | [`reduce`] | fixed-order sums: split-K's partials, column sums (the bias gradient) |
//! | [`elementwise`] | the ReLU backward |
//! | [`linear`] | a layer's five operations on row-major [`linear::Matrix`]es, shapes checked |
//! | [`checks`] | whether the kernels launch with CubeCL's index checks (off by default) |
//!
//! Every sum runs in an order fixed by the shapes and the call's arguments (split counts depend
//! on the shapes and the [`linear::Tuning`] handed to each call, nothing per process), so a
//! result is the same bits run to run. The tests (`--features wgpu`) compare each
//! operation with an f64 reference on any Vulkan device, Mesa's lavapipe included.

pub mod checks;
pub mod elementwise;
pub mod gemm;
pub mod gemm_cmma;
pub mod gemm_vec4;
pub mod linear;
pub mod reduce;
