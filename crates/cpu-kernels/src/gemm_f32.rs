//! f32 products through the `gemm` crate, called exactly as burn-flex calls it (the same
//! strides, parallelism threshold and flags, so the same bits), plus the fused-bias variant.
//!
//! [`gemm_by_rows`] adds a linear layer's bias (and a hidden layer's ReLU, [`Epilogue`]) inside
//! the product: the output is computed in blocks of about 512 KB of rows, each a
//! single-threaded gemm followed by the epilogue while the block is still in L2, the blocks in
//! parallel. burn's default `linear` is the product and
//! then a broadcast add, one more pass over the output read and written (16 MB each way for a
//! [32768, 128] activation, a visible share of a bf16 step in a `perf` profile). A row's value
//! does not depend on the block it falls in (gemm sums every output over the same k blocks), so
//! the result equals the whole-matrix gemm followed by the add (and the ReLU), to the bit.
//!
//! Tall products without a bias (the input gradients `dY Wᵀ`, the skip projections) take the
//! same blocks of rows: each block one single-threaded gemm, so a batch of 2^15 rows at 128
//! columns gives 32 blocks, work for every core of a many-core machine, where gemm's own
//! threading over such a narrow output is left to the crate. On the 2-core bench machine the
//! blocks ran these products at 0.75 to 1.03 of gemm's own time on two threads and 0.83 to
//! 1.03 on one (`benches/weight_gradient.rs`, which also checks the bits are equal).

use crate::{Epilogue, MatRef};

/// m n k from which gemm runs on every thread (burn-flex's threshold).
const PARALLEL_THRESHOLD: usize = 192 * 192 * 192;

fn parallelism(m: usize, n: usize, k: usize) -> gemm::Parallelism {
    if m.saturating_mul(n).saturating_mul(k) >= PARALLEL_THRESHOLD {
        #[cfg(feature = "rayon")]
        return gemm::Parallelism::Rayon(0);
    }
    gemm::Parallelism::None
}

/// One gemm call: `out` (rows x n, row stride n) = lhs rhs, without reading `out`.
///
/// # Safety
/// As [`crate::matmul`] for a rows x k by k x n product.
unsafe fn gemm_call(
    rows: usize,
    n: usize,
    k: usize,
    out: *mut f32,
    lhs: MatRef,
    rhs: MatRef,
    parallelism: gemm::Parallelism,
) {
    // SAFETY: the caller's; gemm with `read_dst = false` writes every element of `out`.
    unsafe {
        gemm::gemm(
            rows,
            n,
            k,
            out,
            1,
            n as isize,
            false,
            lhs.ptr,
            lhs.cs,
            lhs.rs,
            rhs.ptr,
            rhs.cs,
            rhs.rs,
            0.0f32,
            1.0f32,
            false,
            false,
            false,
            parallelism,
        )
    }
}

/// `out = lhs rhs`, with gemm's own parallelism over the output.
///
/// # Safety
/// As [`crate::matmul`].
pub unsafe fn gemm(m: usize, n: usize, k: usize, lhs: MatRef, rhs: MatRef, out: *mut f32) {
    if k == 0 {
        // SAFETY: `out` holds m n floats.
        unsafe { core::ptr::write_bytes(out, 0, m * n) };
        return;
    }
    // SAFETY: the caller's.
    unsafe { gemm_call(m, n, k, out, lhs, rhs, parallelism(m, n, k)) }
}

/// Rows of output per block of [`gemm_by_rows`]: about 512 KB of output, so a block and
/// its share of the left operand stay in L2 until the bias is added.
fn bias_block_rows(n: usize) -> usize {
    ((1usize << 17) / n).clamp(64, 4096)
}

/// How many blocks of rows [`gemm_by_rows`] cuts an m x n output into.
pub fn row_blocks(m: usize, n: usize) -> usize {
    m.div_ceil(bias_block_rows(n.max(1)))
}

/// `out = epilogue(lhs rhs)`, in blocks of rows (see the module documentation), each block
/// one single-threaded gemm, the blocks on every thread.
///
/// # Safety
/// As [`crate::matmul`], with a bias of n values if given, and k > 0.
pub unsafe fn gemm_by_rows(
    m: usize,
    n: usize,
    k: usize,
    lhs: MatRef,
    rhs: MatRef,
    epilogue: Epilogue,
    out: *mut f32,
) {
    struct Out(*mut f32);
    // SAFETY: the blocks write disjoint rows of `out`.
    unsafe impl Sync for Out {}
    let dst = Out(out);
    let rows_per = bias_block_rows(n);
    let blocks = m.div_ceil(rows_per);
    let run = |blk: usize| {
        let r0 = blk * rows_per;
        let rows = rows_per.min(m - r0);
        let dst = &dst;
        // SAFETY: rows r0..r0 + rows of `out` and of the left operand exist (r0 + rows <= m).
        let (c, a) = unsafe { (dst.0.add(r0 * n), lhs.row(r0)) };
        let a = MatRef { ptr: a, ..lhs };
        // SAFETY: the caller's, for this block of rows; the block is written, then read.
        unsafe { gemm_call(rows, n, k, c, a, rhs, gemm::Parallelism::None) };
        if !epilogue.is_some() {
            return;
        }
        // SAFETY: the block's rows x n floats, written just above.
        let block = unsafe { core::slice::from_raw_parts_mut(c, rows * n) };
        for row in block.chunks_exact_mut(n) {
            epilogue.apply_row(row, 0);
        }
    };
    #[cfg(feature = "rayon")]
    if m.saturating_mul(n).saturating_mul(k) >= PARALLEL_THRESHOLD && blocks > 1 {
        use rayon::prelude::*;
        (0..blocks).into_par_iter().for_each(run);
        return;
    }
    (0..blocks).for_each(run);
}
