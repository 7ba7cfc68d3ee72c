//! The product of [`crate::gemm`] on tensor cores: the same arguments, zero padding, split-K
//! and epilogues, its operands rounded to bf16 and its sums kept in f32 ([`Precision::Bf16`]).
//! CubeCL's cooperative matrices (`cmma`, CUDA's WMMA, 16 x 16 x 16 in bf16) do the
//! multiply-adds; a device without them (every WGSL device, lavapipe included, and NVIDIA cards
//! before Ampere) cannot run this kernel, and [`bf16_supported`] says so before a launch.
//!
//! One cube of four planes (32 x 4 units) computes a 64 x 64 tile of C; plane `w` keeps the
//! 32 x 32 quarter at rows `32 (w / 2)`, columns `32 (w % 2)` as 2 x 2 accumulator fragments.
//! The k axis is walked in stages of 32: the units stage a 64 x 32 slab of A and a 32 x 64 slab
//! of B in shared memory as bf16 (read along whichever axis is contiguous in memory, as the f32
//! kernels do, zero past the edges), then each plane runs two 16-deep fragment products. At
//! the end the fragments go through shared memory (f32) so that the epilogue and the edge
//! checks are the f32 kernels'. Slab rows are padded by 8 elements (16 bytes) against bank
//! conflicts; fragment starts stay 32-byte aligned, as WMMA's loads and stores require.
//!
//! Within a split the sums run in an order fixed by the shapes (the hardware's within each
//! fragment product), so results are the same bits run to run on one device.
//!
//! [`Precision::Bf16`]: crate::plan::Precision::Bf16

use crate::gemm::{Epilogue, GemmShape};
use cubecl::cmma;
use cubecl::features::MmaConfig;
use cubecl::ir::{ElemType, FloatKind};
use cubecl::prelude::*;
use half::bf16;

/// C's tile per cube (rows and columns).
pub const TILE: u32 = 64;
/// The k stage held in shared memory.
pub const K_STAGE: u32 = 32;
/// Units per plane (CUDA's warp).
const PLANE: u32 = 32;
/// Planes per cube.
const PLANES: u32 = 4;
/// Row stride of A's slab (64 rows x 32 k), in elements.
const A_STRIDE: u32 = 40;
/// Row stride of B's slab (32 k x 64 columns), in elements.
const B_STRIDE: u32 = 72;
/// Row stride of C's staging tile (64 x 64 f32), in elements.
const C_STRIDE: u32 = 68;

/// Whether `client`'s device multiplies 16 x 16 x 16 bf16 fragments into f32 ones (CubeCL's
/// cmma feature; CUDA on Ampere and later).
pub fn bf16_supported(client: &Client) -> bool {
    let bf16 = ElemType::Float(FloatKind::BF16);
    let config = MmaConfig {
        a_type: bf16,
        b_type: bf16,
        cd_type: ElemType::Float(FloatKind::F32),
        m: 16,
        n: 16,
        k: 16,
    };
    client.properties().features.matmul.cmma.contains(&config)
}

/// The product kernel; see the module documentation. Launched on a grid of
/// `(ceil(n / 64), ceil(m / 64), splits)` cubes of 32 x 4 units.
#[cube(launch, launch_unchecked)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn gemm_cmma(
    a: &[f32],
    b: &[f32],
    bias: &[f32],
    c: &mut [f32],
    m: u32,
    n: u32,
    k: u32,
    a_rs: u32,
    a_cs: u32,
    b_rs: u32,
    b_cs: u32,
    k_per_split: u32,
    #[comptime] epilogue: u32,
    #[comptime] a_rows_contiguous: bool,
    #[comptime] b_rows_contiguous: bool,
) {
    let lin = UNIT_POS;
    let plane = UNIT_POS_Y;
    let row0 = CUBE_POS_Y * 64;
    let col0 = CUBE_POS_X * 64;
    let split = CUBE_POS_Z;
    let k_start = split * k_per_split;
    let k_end = select(k < k_start + k_per_split, k, k_start + k_per_split);
    // The plane's quarter of the tile.
    let pr = (plane / 2) * 32;
    let pc = (plane % 2) * 32;

    let mut a_slab =
        Shared::<[bf16]>::new_aligned_slice(comptime![(64 * A_STRIDE) as usize], 32usize);
    let mut b_slab =
        Shared::<[bf16]>::new_aligned_slice(comptime![(32 * B_STRIDE) as usize], 32usize);
    let c00 = cmma::Matrix::<f32>::from_value(
        cmma::MatrixIdent::Accumulator,
        16usize,
        16usize,
        16usize,
        cmma::MatrixLayout::Undefined,
        0.0,
    );
    let c01 = cmma::Matrix::<f32>::from_value(
        cmma::MatrixIdent::Accumulator,
        16usize,
        16usize,
        16usize,
        cmma::MatrixLayout::Undefined,
        0.0,
    );
    let c10 = cmma::Matrix::<f32>::from_value(
        cmma::MatrixIdent::Accumulator,
        16usize,
        16usize,
        16usize,
        cmma::MatrixLayout::Undefined,
        0.0,
    );
    let c11 = cmma::Matrix::<f32>::from_value(
        cmma::MatrixIdent::Accumulator,
        16usize,
        16usize,
        16usize,
        cmma::MatrixLayout::Undefined,
        0.0,
    );

    for k0 in range_stepped(k_start, k_end, 32u32) {
        // Each slab holds 64 x 32 = 2,048 elements: 16 a unit.
        #[unroll]
        for t in 0..16u32 {
            let e = lin + t * 128;
            // A's slab, row-major (r, kk) at r * A_STRIDE + kk.
            let mut r = e / 32;
            let mut kk = e % 32;
            if comptime![!a_rows_contiguous] {
                r = e % 64;
                kk = e / 64;
            }
            let (gi, gk) = (row0 + r, k0 + kk);
            let mut va = 0.0f32;
            if gi < m && gk < k_end {
                va = a[(gi * a_rs + gk * a_cs) as usize];
            }
            a_slab[(r * A_STRIDE + kk) as usize] = bf16::cast_from(va);
            // B's slab, row-major (kb, j) at kb * B_STRIDE + j.
            let mut kb = e / 64;
            let mut j = e % 64;
            if comptime![!b_rows_contiguous] {
                kb = e % 32;
                j = e / 32;
            }
            let (gkb, gj) = (k0 + kb, col0 + j);
            let mut vb = 0.0f32;
            if gkb < k_end && gj < n {
                vb = b[(gkb * b_rs + gj * b_cs) as usize];
            }
            b_slab[(kb * B_STRIDE + j) as usize] = bf16::cast_from(vb);
        }
        sync_cube();
        #[unroll]
        for ks in 0..2u32 {
            let a0_at = pr * A_STRIDE + ks * 16;
            let a1_at = (pr + 16) * A_STRIDE + ks * 16;
            let b0_at = ks * 16 * B_STRIDE + pc;
            let b1_at = ks * 16 * B_STRIDE + pc + 16;
            let a0 = cmma::Matrix::<bf16>::from_slice(
                cmma::MatrixIdent::A,
                16usize,
                16usize,
                16usize,
                cmma::MatrixLayout::RowMajor,
                &a_slab[a0_at as usize..(a0_at + 15 * A_STRIDE + 16) as usize],
                A_STRIDE,
            );
            let a1 = cmma::Matrix::<bf16>::from_slice(
                cmma::MatrixIdent::A,
                16usize,
                16usize,
                16usize,
                cmma::MatrixLayout::RowMajor,
                &a_slab[a1_at as usize..(a1_at + 15 * A_STRIDE + 16) as usize],
                A_STRIDE,
            );
            let b0 = cmma::Matrix::<bf16>::from_slice(
                cmma::MatrixIdent::B,
                16usize,
                16usize,
                16usize,
                cmma::MatrixLayout::RowMajor,
                &b_slab[b0_at as usize..(b0_at + 15 * B_STRIDE + 16) as usize],
                B_STRIDE,
            );
            let b1 = cmma::Matrix::<bf16>::from_slice(
                cmma::MatrixIdent::B,
                16usize,
                16usize,
                16usize,
                cmma::MatrixLayout::RowMajor,
                &b_slab[b1_at as usize..(b1_at + 15 * B_STRIDE + 16) as usize],
                B_STRIDE,
            );
            cmma::execute(&a0, &b0, &c00, &c00);
            cmma::execute(&a0, &b1, &c01, &c01);
            cmma::execute(&a1, &b0, &c10, &c10);
            cmma::execute(&a1, &b1, &c11, &c11);
        }
        sync_cube();
    }

    // Through shared memory, so that the edge checks and the epilogue are per element.
    let mut c_tile =
        Shared::<[f32]>::new_aligned_slice(comptime![(64 * C_STRIDE) as usize], 32usize);
    let c00_at = pr * C_STRIDE + pc;
    let c01_at = c00_at + 16;
    let c10_at = c00_at + 16 * C_STRIDE;
    let c11_at = c10_at + 16;
    let span = 15 * C_STRIDE + 16;
    cmma::store(
        &mut c_tile[c00_at as usize..(c00_at + span) as usize],
        &c00,
        C_STRIDE,
        cmma::MatrixLayout::RowMajor,
    );
    cmma::store(
        &mut c_tile[c01_at as usize..(c01_at + span) as usize],
        &c01,
        C_STRIDE,
        cmma::MatrixLayout::RowMajor,
    );
    cmma::store(
        &mut c_tile[c10_at as usize..(c10_at + span) as usize],
        &c10,
        C_STRIDE,
        cmma::MatrixLayout::RowMajor,
    );
    cmma::store(
        &mut c_tile[c11_at as usize..(c11_at + span) as usize],
        &c11,
        C_STRIDE,
        cmma::MatrixLayout::RowMajor,
    );
    sync_cube();
    let base = split * m * n;
    #[unroll]
    for t in 0..32u32 {
        let e = lin + t * 128;
        let r = e / 64;
        let j = e % 64;
        let (gi, gj) = (row0 + r, col0 + j);
        if gi < m && gj < n {
            let mut v = c_tile[(r * C_STRIDE + j) as usize];
            if comptime![epilogue >= 1] {
                v += bias[gj as usize];
            }
            if comptime![epilogue == 2] {
                v = select(v < 0.0, 0.0, v);
            }
            c[(base + gi * n + gj) as usize] = v;
        }
    }
}

/// Launches `gemm_cmma` with the arguments of [`crate::gemm::launch_gemm`] (whose tiling field
/// it ignores: its tile is [`TILE`]); `splits` partials of `ceil(k / splits)` terms, rounded up
/// to [`K_STAGE`].
///
/// # Safety
/// As [`crate::gemm::launch_gemm`]; and the device must pass [`bf16_supported`].
#[allow(clippy::too_many_arguments)]
pub unsafe fn launch_gemm_cmma(
    client: &Client,
    a: cubecl::server::Handle,
    b: cubecl::server::Handle,
    bias: cubecl::server::Handle,
    c: cubecl::server::Handle,
    lens: [usize; 4],
    shape: GemmShape,
    splits: u32,
    epilogue: Epilogue,
) {
    let splits = splits.max(1);
    let per_split = shape.k.div_ceil(splits).div_ceil(K_STAGE) * K_STAGE;
    let grid = CubeCount::Static(shape.n.div_ceil(TILE), shape.m.div_ceil(TILE), splits);
    let [la, lb, lbias, lc] = lens;
    unsafe {
        crate::checks::launch!(
            gemm_cmma,
            client,
            grid,
            CubeDim::new_2d(PLANE, PLANES),
            BufferArg::from_raw_parts(a, la),
            BufferArg::from_raw_parts(b, lb),
            BufferArg::from_raw_parts(bias, lbias),
            BufferArg::from_raw_parts(c, lc),
            shape.m,
            shape.n,
            shape.k,
            shape.a_strides.0,
            shape.a_strides.1,
            shape.b_strides.0,
            shape.b_strides.1,
            per_split,
            epilogue.code(),
            shape.a_strides.1 == 1,
            shape.b_strides.1 == 1,
        );
    }
}
