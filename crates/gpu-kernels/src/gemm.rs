//! The tiled f32 product `C = A B (+ bias) (ReLU)`, with A and B read through strides (a
//! transposed operand costs nothing) and the k axis optionally cut into splits, each written to
//! its own slice of the output (split-K: a weight gradient's long sum over the batch spread over
//! many cubes, the partials then added in a fixed order by [`crate::reduce`]).
//!
//! One cube of 16 x 16 units computes a square tile of C, 64 or 128 wide ([`Tiling`]); each
//! unit keeps a 4 x 4 (or 8 x 8) block of sums in registers, at rows `ty + 16 i` and columns
//! `tx + 16 j` (so that neighbouring units read neighbouring shared-memory words and write
//! neighbouring output words). The k axis is walked in steps of 16: each step stages a tile x
//! 16 slab of A and a 16 x tile slab of B in shared memory, zero-padded past the matrix edges,
//! so any shape is exact. The units load a slab along whichever of its axes is contiguous in
//! memory (so that a warp reads consecutive words, also for the transposed operands of the
//! gradients), and the slabs' rows in shared memory are one word longer than the tile, so that
//! the stores of either order fall in different banks.
//!
//! | name | shape | meaning |
//! | --- | --- | --- |
//! | `a` | m x k, element (i, p) at `i a_rs + p a_cs` | left operand |
//! | `b` | k x n, element (p, j) at `p b_rs + j b_cs` | right operand |
//! | `bias` | n | added to every row (epilogue [`Epilogue::Bias`] or [`Epilogue::BiasRelu`]) |
//! | `c` | splits x m x n, row-major | the product, or one partial sum per split |

use crate::gemm_vec4::{gemm_vec4, gemm_vec4_128};
use crate::plan::{Tiling, UNITS};
use cubecl::prelude::*;

/// The k step staged in shared memory.
pub const K_STEP: u32 = 16;

/// What is applied to each sum before it is written (comptime: one kernel per variant).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Epilogue {
    /// The sum as it is.
    None,
    /// The sum plus `bias[j]`.
    Bias,
    /// `max(sum + bias[j], 0)`, NaN kept.
    BiasRelu,
}

impl Epilogue {
    pub(crate) fn code(self) -> u32 {
        match self {
            Epilogue::None => 0,
            Epilogue::Bias => 1,
            Epilogue::BiasRelu => 2,
        }
    }
}

/// The product kernel; see the module documentation. Launched on a grid of
/// `(ceil(n / tile), ceil(m / tile), splits)` cubes of 16 x 16 units.
#[cube(launch, launch_unchecked)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn gemm_tiled(
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
    #[comptime] per_unit: u32,
) {
    let tx = UNIT_POS_X;
    let ty = UNIT_POS_Y;
    let lin = UNIT_POS;
    let tile = comptime![16 * per_unit];
    // Slab rows one word longer than the tile: no bank conflicts in the stores of either order.
    let stride = comptime![16 * per_unit + 1];
    let row0 = CUBE_POS_Y * tile;
    let col0 = CUBE_POS_X * tile;
    let split = CUBE_POS_Z;
    let k_start = split * k_per_split;
    let k_end = select(k < k_start + k_per_split, k, k_start + k_per_split);

    let mut a_tile = Shared::<[f32]>::new_slice(comptime![(16 * (16 * per_unit + 1)) as usize]);
    let mut b_tile = Shared::<[f32]>::new_slice(comptime![(16 * (16 * per_unit + 1)) as usize]);
    let mut acc = Array::<f32>::new(comptime![(per_unit * per_unit) as usize]);
    #[unroll]
    for e in 0..per_unit * per_unit {
        acc[e as usize] = 0.0;
    }

    for k0 in range_stepped(k_start, k_end, 16u32) {
        // Each slab holds 16 x tile = 256 x per_unit elements: per_unit loads a unit.
        #[unroll]
        for t in 0..per_unit {
            let e = lin + t * 256;
            // A's slab, stored k-major: (r, kk) at kk * stride + r; neighbouring units take
            // neighbouring k where A's rows are contiguous in memory, else neighbouring rows.
            let mut r = e / 16;
            let mut kk = e % 16;
            if comptime![!a_rows_contiguous] {
                r = e % tile;
                kk = e / tile;
            }
            let (gi, gk) = (row0 + r, k0 + kk);
            let mut va = 0.0f32;
            if gi < m && gk < k_end {
                va = a[(gi * a_rs + gk * a_cs) as usize];
            }
            a_tile[(kk * stride + r) as usize] = va;
            // B's slab: (kb, j) at kb * stride + j; neighbouring units take neighbouring
            // columns where B's rows are contiguous, else neighbouring k.
            let mut kb = e / tile;
            let mut j = e % tile;
            if comptime![!b_rows_contiguous] {
                kb = e % 16;
                j = e / 16;
            }
            let (gkb, gj) = (k0 + kb, col0 + j);
            let mut vb = 0.0f32;
            if gkb < k_end && gj < n {
                vb = b[(gkb * b_rs + gj * b_cs) as usize];
            }
            b_tile[(kb * stride + j) as usize] = vb;
        }
        sync_cube();
        // Not unrolled in the source (on lavapipe that made the tests' shader compiles 30
        // times slower); launched unchecked, the loop has no counter that keeps the driver
        // from unrolling it.
        for kk in 0..16u32 {
            let mut av = Array::<f32>::new(comptime![per_unit as usize]);
            let mut bv = Array::<f32>::new(comptime![per_unit as usize]);
            #[unroll]
            for i in 0..per_unit {
                av[i as usize] = a_tile[(kk * stride + ty + i * 16) as usize];
                bv[i as usize] = b_tile[(kk * stride + tx + i * 16) as usize];
            }
            #[unroll]
            for i in 0..per_unit {
                #[unroll]
                for j in 0..per_unit {
                    let at = (i * per_unit + j) as usize;
                    acc[at] += av[i as usize] * bv[j as usize];
                }
            }
        }
        sync_cube();
    }

    let base = split * m * n;
    #[unroll]
    for i in 0..per_unit {
        #[unroll]
        for j in 0..per_unit {
            let gi = row0 + ty + i * 16;
            let gj = col0 + tx + j * 16;
            if gi < m && gj < n {
                let mut v = acc[(i * per_unit + j) as usize];
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
}

/// The launch geometry and arguments of one product.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GemmShape {
    /// Rows of A and C.
    pub m: u32,
    /// Columns of B and C.
    pub n: u32,
    /// The summed axis.
    pub k: u32,
    /// A's strides (row, column).
    pub a_strides: (u32, u32),
    /// B's strides (row, column).
    pub b_strides: (u32, u32),
    /// The tile of C a cube computes.
    pub tiling: Tiling,
}

/// Launches `gemm_tiled`: `splits` partial products of `ceil(k / splits)` (rounded up to the k
/// step) terms each into `c` (`splits * m * n` floats); with one split and an epilogue, the
/// finished layer output. `bias` must hold `n` floats where the epilogue reads it (any
/// non-empty handle otherwise).
///
/// # Safety
/// The handles must hold at least the elements the strides and shape address.
#[allow(clippy::too_many_arguments)]
pub unsafe fn launch_gemm(
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
    let per_split = shape.k.div_ceil(splits).div_ceil(K_STEP) * K_STEP;
    let tile = shape.tiling.tile();
    let grid = CubeCount::Static(shape.n.div_ceil(tile), shape.m.div_ceil(tile), splits);
    let [la, lb, lbias, lc] = lens;
    if shape.tiling == Tiling::T128V {
        unsafe {
            crate::checks::launch!(
                gemm_vec4_128,
                client,
                grid,
                CubeDim::new_2d(UNITS, UNITS),
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
        return;
    }
    if shape.tiling == Tiling::T64V {
        unsafe {
            crate::checks::launch!(
                gemm_vec4,
                client,
                grid,
                CubeDim::new_2d(UNITS, UNITS),
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
        return;
    }
    unsafe {
        crate::checks::launch!(
            gemm_tiled,
            client,
            grid,
            CubeDim::new_2d(UNITS, UNITS),
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
            // "Rows contiguous": a row's elements are neighbours (column stride 1).
            shape.a_strides.1 == 1,
            shape.b_strides.1 == 1,
            shape.tiling.per_unit(),
        );
    }
}
