//! The tiled f32 product `C = A B (+ bias) (ReLU)`, with A and B read through strides (a
//! transposed operand costs nothing) and the k axis optionally cut into splits, each written to
//! its own slice of the output (split-K: a weight gradient's long sum over the batch spread over
//! many cubes, the partials then added in a fixed order by [`crate::reduce`]).
//!
//! One cube of 16 x 16 units computes a 64 x 64 tile of C; each unit keeps a 4 x 4 block of
//! sums in registers, at rows `ty + 16 i` and columns `tx + 16 j` (so that neighbouring units
//! read neighbouring shared-memory words and write neighbouring output words). The k axis is
//! walked in steps of 16: each step stages a 64 x 16 slab of A and a 16 x 64 slab of B in shared
//! memory, zero-padded past the matrix edges, so any shape is exact.
//!
//! | name | shape | meaning |
//! | --- | --- | --- |
//! | `a` | m x k, element (i, p) at `i a_rs + p a_cs` | left operand |
//! | `b` | k x n, element (p, j) at `p b_rs + j b_cs` | right operand |
//! | `bias` | n | added to every row (epilogue [`Epilogue::Bias`] or [`Epilogue::BiasRelu`]) |
//! | `c` | splits x m x n, row-major | the product, or one partial sum per split |

use cubecl::prelude::*;

/// Rows and columns of C per cube.
pub const TILE: u32 = 64;
/// Units per cube along each axis.
pub const UNITS: u32 = 16;
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
    fn code(self) -> u32 {
        match self {
            Epilogue::None => 0,
            Epilogue::Bias => 1,
            Epilogue::BiasRelu => 2,
        }
    }
}

/// The product kernel; see the module documentation. Launched on a grid of
/// `(ceil(n / 64), ceil(m / 64), splits)` cubes of 16 x 16 units.
#[cube(launch)]
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
) {
    let tx = UNIT_POS_X;
    let ty = UNIT_POS_Y;
    let lin = UNIT_POS;
    let row0 = CUBE_POS_Y * 64;
    let col0 = CUBE_POS_X * 64;
    let split = CUBE_POS_Z;
    let k_start = split * k_per_split;
    let k_end = select(k < k_start + k_per_split, k, k_start + k_per_split);

    let mut a_tile = Shared::<[f32]>::new_slice(1024usize);
    let mut b_tile = Shared::<[f32]>::new_slice(1024usize);
    let mut acc = Array::<f32>::new(16usize);
    #[unroll]
    for e in 0..16usize {
        acc[e] = 0.0;
    }

    for k0 in range_stepped(k_start, k_end, 16u32) {
        #[unroll]
        for t in 0..4u32 {
            let e = lin + t * 256;
            // A's slab, stored k-major: (r, kk) at kk * 64 + r.
            let r = e / 16;
            let kk = e % 16;
            let (gi, gk) = (row0 + r, k0 + kk);
            let mut va = 0.0f32;
            if gi < m && gk < k_end {
                va = a[(gi * a_rs + gk * a_cs) as usize];
            }
            a_tile[(kk * 64 + r) as usize] = va;
            // B's slab: (kk, j) at kk * 64 + j.
            let kb = e / 64;
            let j = e % 64;
            let (gkb, gj) = (k0 + kb, col0 + j);
            let mut vb = 0.0f32;
            if gkb < k_end && gj < n {
                vb = b[(gkb * b_rs + gj * b_cs) as usize];
            }
            b_tile[(kb * 64 + j) as usize] = vb;
        }
        sync_cube();
        for kk in 0..16u32 {
            let mut av = Array::<f32>::new(4usize);
            let mut bv = Array::<f32>::new(4usize);
            #[unroll]
            for i in 0..4u32 {
                av[i as usize] = a_tile[(kk * 64 + ty + i * 16) as usize];
                bv[i as usize] = b_tile[(kk * 64 + tx + i * 16) as usize];
            }
            #[unroll]
            for i in 0..4u32 {
                #[unroll]
                for j in 0..4u32 {
                    let at = (i * 4 + j) as usize;
                    acc[at] += av[i as usize] * bv[j as usize];
                }
            }
        }
        sync_cube();
    }

    let base = split * m * n;
    #[unroll]
    for i in 0..4u32 {
        #[unroll]
        for j in 0..4u32 {
            let gi = row0 + ty + i * 16;
            let gj = col0 + tx + j * 16;
            if gi < m && gj < n {
                let mut v = acc[(i * 4 + j) as usize];
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
    let grid = CubeCount::Static(shape.n.div_ceil(TILE), shape.m.div_ceil(TILE), splits);
    let [la, lb, lbias, lc] = lens;
    unsafe {
        gemm_tiled::launch(
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
        );
    }
}
