//! The tiled f32 product of [`crate::gemm`] with its shared-memory reads four floats wide
//! ([`Tiling::T64V`] and [`Tiling::T128V`]): the same arguments, zero padding, split-K and
//! epilogues, a different register block.
//!
//! `gemm_vec4_128` is the 128-wide counterpart (the classic layout of fast f32 products on
//! GPUs): unit (tx, ty) keeps 8 x 8 sums, rows `4 ty ..` and `64 + 4 ty ..`, columns `4 tx ..`
//! and `64 + 4 tx ..` (four each), in sixteen vectors, and reads two vectors of A and two of B
//! a k step for 64 multiply-adds. Slab rows are 32 vectors and one of padding.
//!
//! One cube of 16 x 16 units computes a 64 x 64 tile of C; unit (tx, ty) keeps the 4 x 4
//! block of rows `4 ty .. 4 ty + 4` and columns `4 tx .. 4 tx + 4` in four 4-wide vectors. The
//! slabs live in shared memory as 4-wide vectors (A's: four consecutive rows at one k; B's:
//! four consecutive columns at one k), so each step of the inner loop reads one vector of A
//! and one of B and does 16 multiply-adds: a quarter of the scalar kernel's shared-memory
//! reads per multiply-add, the resource a product of these shapes runs out of first. A slab
//! row is 16 vectors and one of padding, so the vector stores of either load order fall in
//! different banks. Each sum runs in the scalar kernel's order (k ascending within a split);
//! whether a multiply-add is fused is the shader compiler's choice in either kernel.
//!
//! [`Tiling::T64V`]: crate::plan::Tiling::T64V
//! [`Tiling::T128V`]: crate::plan::Tiling::T128V

use cubecl::prelude::*;

/// A vector of four floats.
type F4 = Vector<f32, Const<4>>;

/// Vectors per slab row: 16 of the tile and one of padding.
const ROW_VECTORS: u32 = 17;

/// `a[(gi, gk)]`, or 0 outside rows `< m` and k `< k_end`.
#[cube]
#[allow(clippy::too_many_arguments)]
fn read_or_zero(a: &[f32], gi: u32, gk: u32, m: u32, k_end: u32, rs: u32, cs: u32) -> f32 {
    let mut v = 0.0f32;
    if gi < m && gk < k_end {
        v = a[(gi * rs + gk * cs) as usize];
    }
    v
}

/// The product kernel; see the module documentation. Launched on a grid of
/// `(ceil(n / 64), ceil(m / 64), splits)` cubes of 16 x 16 units.
#[cube(launch, launch_unchecked)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn gemm_vec4(
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
    let tx = UNIT_POS_X;
    let ty = UNIT_POS_Y;
    let lin = UNIT_POS;
    let row0 = CUBE_POS_Y * 64;
    let col0 = CUBE_POS_X * 64;
    let split = CUBE_POS_Z;
    let k_start = split * k_per_split;
    let k_end = select(k < k_start + k_per_split, k, k_start + k_per_split);

    let mut a_tile = Shared::<[F4]>::new_slice(comptime![(16 * ROW_VECTORS) as usize]);
    let mut b_tile = Shared::<[F4]>::new_slice(comptime![(16 * ROW_VECTORS) as usize]);
    let mut acc0 = F4::broadcast(0.0);
    let mut acc1 = F4::broadcast(0.0);
    let mut acc2 = F4::broadcast(0.0);
    let mut acc3 = F4::broadcast(0.0);

    // Each unit stores one vector of each slab: A's rows 4 qa .. 4 qa + 4 at k step ka, B's
    // columns 4 qb .. 4 qb + 4 at kb. Neighbouring units take neighbouring k where a row of
    // the operand is contiguous in memory, else neighbouring vectors.
    let mut qa = lin / 16;
    let mut ka = lin % 16;
    if comptime![!a_rows_contiguous] {
        qa = lin % 16;
        ka = lin / 16;
    }
    let mut qb = lin % 16;
    let mut kb = lin / 16;
    if comptime![!b_rows_contiguous] {
        qb = lin / 16;
        kb = lin % 16;
    }

    for k0 in range_stepped(k_start, k_end, 16u32) {
        let gi = row0 + 4 * qa;
        let gk = k0 + ka;
        let mut va = F4::empty();
        va.insert(0usize, read_or_zero(a, gi, gk, m, k_end, a_rs, a_cs));
        va.insert(1usize, read_or_zero(a, gi + 1, gk, m, k_end, a_rs, a_cs));
        va.insert(2usize, read_or_zero(a, gi + 2, gk, m, k_end, a_rs, a_cs));
        va.insert(3usize, read_or_zero(a, gi + 3, gk, m, k_end, a_rs, a_cs));
        a_tile[(ka * ROW_VECTORS + qa) as usize] = va;
        // B's element (p, j) is "row" j, "column" p of the transposed view read_or_zero takes.
        let gj = col0 + 4 * qb;
        let gkb = k0 + kb;
        let mut vb = F4::empty();
        vb.insert(0usize, read_or_zero(b, gj, gkb, n, k_end, b_cs, b_rs));
        vb.insert(1usize, read_or_zero(b, gj + 1, gkb, n, k_end, b_cs, b_rs));
        vb.insert(2usize, read_or_zero(b, gj + 2, gkb, n, k_end, b_cs, b_rs));
        vb.insert(3usize, read_or_zero(b, gj + 3, gkb, n, k_end, b_cs, b_rs));
        b_tile[(kb * ROW_VECTORS + qb) as usize] = vb;
        sync_cube();
        for kk in 0..16u32 {
            let av = a_tile[(kk * ROW_VECTORS + ty) as usize];
            let bv = b_tile[(kk * ROW_VECTORS + tx) as usize];
            acc0 += F4::broadcast(av.extract(0usize)) * bv;
            acc1 += F4::broadcast(av.extract(1usize)) * bv;
            acc2 += F4::broadcast(av.extract(2usize)) * bv;
            acc3 += F4::broadcast(av.extract(3usize)) * bv;
        }
        sync_cube();
    }

    let base = split * m * n;
    let gi = row0 + 4 * ty;
    store_row(c, bias, acc0, base, gi, col0 + 4 * tx, m, n, epilogue);
    store_row(c, bias, acc1, base, gi + 1, col0 + 4 * tx, m, n, epilogue);
    store_row(c, bias, acc2, base, gi + 2, col0 + 4 * tx, m, n, epilogue);
    store_row(c, bias, acc3, base, gi + 3, col0 + 4 * tx, m, n, epilogue);
}

/// Vectors per slab row of the 128-wide kernel: 32 of the tile and one of padding.
const ROW_VECTORS_128: u32 = 33;

/// Four values of `x` (rows or columns `g .. g + 4` of the transposed view `read_or_zero`
/// takes) as a vector.
#[cube]
#[allow(clippy::too_many_arguments)]
fn read4(x: &[f32], g: u32, gk: u32, len: u32, k_end: u32, rs: u32, cs: u32) -> F4 {
    let mut v = F4::empty();
    v.insert(0usize, read_or_zero(x, g, gk, len, k_end, rs, cs));
    v.insert(1usize, read_or_zero(x, g + 1, gk, len, k_end, rs, cs));
    v.insert(2usize, read_or_zero(x, g + 2, gk, len, k_end, rs, cs));
    v.insert(3usize, read_or_zero(x, g + 3, gk, len, k_end, rs, cs));
    v
}

/// `acc[2 r + c] += a[lane] b_c` for the four rows `r = first + lane` that the vector `av`
/// holds, against the column vectors `b0` and `b1`.
#[cube]
fn outer4(acc: &mut Array<F4>, av: F4, b0: F4, b1: F4, #[comptime] first: usize) {
    let a0 = F4::broadcast(av.extract(0usize));
    let a1 = F4::broadcast(av.extract(1usize));
    let a2 = F4::broadcast(av.extract(2usize));
    let a3 = F4::broadcast(av.extract(3usize));
    acc[2 * first] += a0 * b0;
    acc[2 * first + 1] += a0 * b1;
    acc[2 * first + 2] += a1 * b0;
    acc[2 * first + 3] += a1 * b1;
    acc[2 * first + 4] += a2 * b0;
    acc[2 * first + 5] += a2 * b1;
    acc[2 * first + 6] += a3 * b0;
    acc[2 * first + 7] += a3 * b1;
}

/// The 128-wide product kernel; see the module documentation. Launched on a grid of
/// `(ceil(n / 128), ceil(m / 128), splits)` cubes of 16 x 16 units.
#[cube(launch, launch_unchecked)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn gemm_vec4_128(
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
    let tx = UNIT_POS_X;
    let ty = UNIT_POS_Y;
    let lin = UNIT_POS;
    let row0 = CUBE_POS_Y * 128;
    let col0 = CUBE_POS_X * 128;
    let split = CUBE_POS_Z;
    let k_start = split * k_per_split;
    let k_end = select(k < k_start + k_per_split, k, k_start + k_per_split);

    let mut a_tile = Shared::<[F4]>::new_slice(comptime![(16 * ROW_VECTORS_128) as usize]);
    let mut b_tile = Shared::<[F4]>::new_slice(comptime![(16 * ROW_VECTORS_128) as usize]);
    // Row r (of 8), column half h: acc[2 r + h].
    let mut acc = Array::<F4>::new(16usize);
    #[unroll]
    for e in 0..16usize {
        acc[e] = F4::broadcast(0.0);
    }

    for k0 in range_stepped(k_start, k_end, 16u32) {
        // Each slab holds 16 k x 32 vectors: two a unit.
        #[unroll]
        for t in 0..2u32 {
            let e = lin + t * 256;
            let mut qa = e / 16;
            let mut ka = e % 16;
            if comptime![!a_rows_contiguous] {
                qa = e % 32;
                ka = e / 32;
            }
            let va = read4(a, row0 + 4 * qa, k0 + ka, m, k_end, a_rs, a_cs);
            a_tile[(ka * ROW_VECTORS_128 + qa) as usize] = va;
            let mut qb = e % 32;
            let mut kb = e / 32;
            if comptime![!b_rows_contiguous] {
                qb = e / 16;
                kb = e % 16;
            }
            let vb = read4(b, col0 + 4 * qb, k0 + kb, n, k_end, b_cs, b_rs);
            b_tile[(kb * ROW_VECTORS_128 + qb) as usize] = vb;
        }
        sync_cube();
        for kk in 0..16u32 {
            let at = kk * ROW_VECTORS_128;
            let av0 = a_tile[(at + ty) as usize];
            let av1 = a_tile[(at + ty + 16) as usize];
            let b0 = b_tile[(at + tx) as usize];
            let b1 = b_tile[(at + tx + 16) as usize];
            outer4(&mut acc, av0, b0, b1, 0usize);
            outer4(&mut acc, av1, b0, b1, 4usize);
        }
        sync_cube();
    }

    let base = split * m * n;
    #[unroll]
    for r in 0..8u32 {
        let gi = row0 + 4 * ty + (r % 4) + 64 * (r / 4);
        let at = (2 * r) as usize;
        store_row(c, bias, acc[at], base, gi, col0 + 4 * tx, m, n, epilogue);
        store_row(c, bias, acc[at + 1], base, gi, col0 + 64 + 4 * tx, m, n, epilogue);
    }
}

/// Writes the four sums of `acc` to row `gi`, columns `gj .. gj + 4` of C (those inside it),
/// through the epilogue.
#[cube]
#[allow(clippy::too_many_arguments)]
fn store_row(
    c: &mut [f32],
    bias: &[f32],
    acc: F4,
    base: u32,
    gi: u32,
    gj: u32,
    m: u32,
    n: u32,
    #[comptime] epilogue: u32,
) {
    if gi < m {
        store_one(c, bias, acc.extract(0usize), base, gi, gj, n, epilogue);
        store_one(c, bias, acc.extract(1usize), base, gi, gj + 1, n, epilogue);
        store_one(c, bias, acc.extract(2usize), base, gi, gj + 2, n, epilogue);
        store_one(c, bias, acc.extract(3usize), base, gi, gj + 3, n, epilogue);
    }
}

#[cube]
#[allow(clippy::too_many_arguments)]
fn store_one(
    c: &mut [f32],
    bias: &[f32],
    sum: f32,
    base: u32,
    gi: u32,
    gj: u32,
    n: u32,
    #[comptime] epilogue: u32,
) {
    if gj < n {
        let mut v = sum;
        if comptime![epilogue >= 1] {
            v += bias[gj as usize];
        }
        if comptime![epilogue == 2] {
            v = select(v < 0.0, 0.0, v);
        }
        c[(base + gi * n + gj) as usize] = v;
    }
}
