//! Products with a long inner dimension and a small output, split over k: the f32 product here,
//! and the split of the bf16 kernels' (`bf16_parts`, used by `bf16dot` and `amx`).
//!
//! A training step's weight gradients are `Xᵀ dY`: [d_in, batch] x [batch, d_out], an output
//! of at most a few hundred squared summed over tens of thousands of samples. The gemm crate
//! parallelises over the output's rows and columns only, so on such a product its threads
//! share a 128 x 128 output and each streams the whole k, slower than the same product summed
//! in two halves, one thread each (`benches/weight_gradient.rs` prints both rates).
//!
//! Here k is cut into a number of blocks that depends on k alone (not on the thread count, so
//! that a product's value is the same on every machine): each block is one single-threaded
//! gemm into its own partial, the blocks run in parallel, and the partials are added in block
//! order (in parallel over the output's elements). The value differs from the unsplit product
//! by f32 summation order only.
//!
//! The blocks are 2,048 long, at most 32 of them: a batch of 2^15 gives 16 blocks, one for
//! every core of a 16-core workstation, where the earlier 4,096-long blocks (8 at 2^15) left
//! half of the cores idle in every weight gradient. One thread's rate on a 2,048-long block is
//! its rate on a 4,096-long one, and shorter blocks cost a few per cent of it
//! (`benches/weight_gradient.rs` prints the rates by block length; figures in
//! `benches/README.md`).

use alloc::vec;
use alloc::vec::Vec;

/// Inner-dimension length per block; a product shorter than two blocks is not split.
const BLOCK_K: usize = 2048;
/// At most this many blocks (bounds the partials' memory: `MAX_BLOCKS` m n floats, 8 MB for
/// the largest output split).
const MAX_BLOCKS: usize = 32;
/// Outputs larger than this (256 x 256) keep gemm's own parallelism over rows and columns.
const MAX_OUTPUT: usize = 256 * 256;

/// How many blocks of k an m x k by k x n product is split into: 1 (not split) unless k is at
/// least two blocks long and the output is small.
pub fn split_k_blocks(m: usize, n: usize, k: usize) -> usize {
    if k < 2 * BLOCK_K || m.saturating_mul(n) > MAX_OUTPUT || m == 0 || n == 0 {
        return 1;
    }
    (k / BLOCK_K).min(MAX_BLOCKS)
}

/// k pairs per part of a bf16 product split over k (the weight gradients, summed over the
/// batch), and the most parts: a batch of 2^13 gives 8 parts, one of 2^15 32.
const PART_PAIRS: usize = 512;
const MAX_PARTS: usize = 32;

/// How a bf16 product of `pairs` k pairs is split over k: (parts, pairs per part, a multiple of
/// `align`). The split depends on k alone, not on the thread count, so that a product's bits
/// are the same however many threads run it (a `--jobs` child, a Slurm task, a workstation), as
/// for the f32 split above; the threads share the parts.
#[cfg_attr(not(feature = "rayon"), allow(dead_code))]
pub(crate) fn bf16_parts(pairs: usize, align: usize) -> (usize, usize) {
    let parts = (pairs / PART_PAIRS).clamp(1, MAX_PARTS);
    let per = pairs.div_ceil(parts).next_multiple_of(align.max(1));
    (pairs.div_ceil(per).max(1), per)
}

/// A read-only strided matrix operand: element (i, j) at `ptr + i rs + j cs`.
#[derive(Clone, Copy)]
pub(crate) struct Operand {
    pub ptr: *const f32,
    pub rs: isize,
    pub cs: isize,
}

// SAFETY: the operand is only read, while the tensors it points into are borrowed by the
// caller for the whole product.
unsafe impl Send for Operand {}
unsafe impl Sync for Operand {}

/// out (m x n, row-major, every element written) = lhs (m x k) x rhs (k x n), summed in
/// `blocks` consecutive blocks of k (see [`split_k_blocks`]).
///
/// # Safety
/// `lhs` and `rhs` must address m x k and k x n valid f32 elements with their strides; `out`
/// must hold m n elements.
pub(crate) unsafe fn matmul_split_k(
    m: usize,
    n: usize,
    k: usize,
    blocks: usize,
    lhs: Operand,
    rhs: Operand,
    out: *mut f32,
) {
    let block = |b: usize, dst: *mut f32| {
        let (k0, k1) = (b * k / blocks, (b + 1) * k / blocks);
        // SAFETY: the block's operands lie inside the caller's; `dst` holds m n elements.
        unsafe { gemm_block(m, n, k0, k1, lhs, rhs, dst) }
    };
    let mut partials: Vec<Vec<f32>> = (1..blocks).map(|_| vec![0f32; m * n]).collect();
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        let out_addr = out as usize;
        rayon::join(
            || block(0, out_addr as *mut f32),
            || partials.par_iter_mut().enumerate().for_each(|(i, p)| block(i + 1, p.as_mut_ptr())),
        );
    }
    #[cfg(not(feature = "rayon"))]
    {
        block(0, out);
        for (i, p) in partials.iter_mut().enumerate() {
            block(i + 1, p.as_mut_ptr());
        }
    }
    // SAFETY: `out` holds m n elements, written above.
    let dst = unsafe { core::slice::from_raw_parts_mut(out, m * n) };
    add_partials(dst, &partials);
}

/// `dst[i] += partials[0][i] + ...`, one element's additions in block order; spread over the
/// threads by chunks of elements, so the value does not depend on the thread count.
fn add_partials(dst: &mut [f32], partials: &[Vec<f32>]) {
    const CHUNK: usize = 2048;
    let add = |c: usize, d: &mut [f32]| {
        let (start, len) = (c * CHUNK, d.len());
        for p in partials {
            for (d, s) in d.iter_mut().zip(&p[start..start + len]) {
                *d += s;
            }
        }
    };
    #[cfg(feature = "rayon")]
    if dst.len() > CHUNK && partials.len() > 1 {
        use rayon::prelude::*;
        dst.par_chunks_mut(CHUNK).enumerate().for_each(|(c, d)| add(c, d));
        return;
    }
    dst.chunks_mut(CHUNK).enumerate().for_each(|(c, d)| add(c, d));
}

/// [`matmul_split_k`] with a block count chosen by the caller, on row-major-or-strided
/// operands: for `benches/weight_gradient.rs`, which compares block lengths on one machine.
/// The product's value depends on `blocks`; the kernels' own choice is [`split_k_blocks`].
///
/// # Safety
/// As [`crate::matmul`], with `1 <= blocks <= k`.
#[doc(hidden)]
pub unsafe fn matmul_in_blocks(
    m: usize,
    n: usize,
    k: usize,
    blocks: usize,
    lhs: crate::MatRef,
    rhs: crate::MatRef,
    out: *mut f32,
) {
    assert!(blocks >= 1 && blocks <= k.max(1), "matmul_in_blocks: {blocks} blocks of k = {k}");
    let op = |r: crate::MatRef| Operand { ptr: r.ptr, rs: r.rs, cs: r.cs };
    // SAFETY: the caller's.
    unsafe { matmul_split_k(m, n, k, blocks, op(lhs), op(rhs), out) }
}

/// dst (m x n, every element written) = lhs[.., k0..k1] x rhs[k0..k1, ..], one thread.
///
/// # Safety
/// As [`matmul_split_k`], with `k0 <= k1 <= k`.
unsafe fn gemm_block(
    m: usize,
    n: usize,
    k0: usize,
    k1: usize,
    lhs: Operand,
    rhs: Operand,
    dst: *mut f32,
) {
    // SAFETY: the caller's; gemm with `read_dst = false` writes every element of `dst`.
    unsafe {
        gemm::gemm(
            m,
            n,
            k1 - k0,
            dst,
            1,
            n as isize,
            false,
            lhs.ptr.offset(k0 as isize * lhs.cs),
            lhs.cs,
            lhs.rs,
            rhs.ptr.offset(k0 as isize * rhs.rs),
            rhs.cs,
            rhs.rs,
            0.0f32,
            1.0f32,
            false,
            false,
            false,
            gemm::Parallelism::None,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(m: usize, n: usize, k: usize, a: &[f32], b: &[f32]) -> Vec<f64> {
        let mut c = vec![0f64; m * n];
        for i in 0..m {
            for j in 0..n {
                c[i * n + j] = (0..k).map(|p| a[i * k + p] as f64 * b[p * n + j] as f64).sum();
            }
        }
        c
    }

    #[test]
    fn blocks_depend_on_k_and_the_output_size_only() {
        assert_eq!(split_k_blocks(128, 128, 32_768), 16);
        assert_eq!(split_k_blocks(128, 128, 8_192), 4);
        assert_eq!(split_k_blocks(128, 128, 4_096), 2);
        assert_eq!(split_k_blocks(128, 128, 4_095), 1);
        assert_eq!(split_k_blocks(128, 128, 1 << 20), MAX_BLOCKS);
        assert_eq!(split_k_blocks(512, 512, 32_768), 1);
        assert_eq!(split_k_blocks(32_768, 128, 128), 1);
        assert_eq!(split_k_blocks(0, 128, 32_768), 1);
    }

    #[test]
    fn bf16_parts_depend_on_k_alone_and_cover_it() {
        assert_eq!(bf16_parts(1_024, 1), (2, 512), "k = 2,048: two parts");
        assert_eq!(bf16_parts(4_096, 1), (8, 512), "a batch of 2^13");
        assert_eq!(bf16_parts(16_384, 16), (32, 512), "a batch of 2^15");
        assert_eq!(bf16_parts(1 << 20, 16), (32, 32_768), "at most 32 parts");
        for pairs in [1, 7, 511, 1_000, 1_025, 4_097, 20_001, 70_000] {
            for align in [1, 16] {
                let (parts, per) = bf16_parts(pairs, align);
                assert_eq!(per % align, 0, "{pairs} {align}");
                assert!(parts >= 1 && parts * per >= pairs && (parts - 1) * per < pairs, "{pairs}");
            }
        }
    }

    #[test]
    fn split_product_matches_f64_for_both_layouts_of_the_left_operand() {
        let (m, n, k) = (7, 19, 4_201);
        let a: Vec<f32> = (0..m * k).map(|i| ((i * 37 % 101) as f32 - 50.0) / 50.0).collect();
        let b: Vec<f32> = (0..k * n).map(|i| ((i * 53 % 89) as f32 - 44.0) / 44.0).collect();
        let want = reference(m, n, k, &a, &b);
        // The left operand row-major, then stored transposed (as a weight gradient's Xᵀ).
        let at: Vec<f32> = (0..k * m).map(|idx| a[(idx % m) * k + idx / m]).collect();
        for (ptr, rs, cs) in [(a.as_ptr(), k as isize, 1), (at.as_ptr(), 1, m as isize)] {
            let blocks = split_k_blocks(m, n, k);
            assert_eq!(blocks, 2);
            let mut out = vec![f32::NAN; m * n];
            let lhs = Operand { ptr, rs, cs };
            let rhs = Operand { ptr: b.as_ptr(), rs: n as isize, cs: 1 };
            unsafe { matmul_split_k(m, n, k, blocks, lhs, rhs, out.as_mut_ptr()) };
            for (got, want) in out.iter().zip(&want) {
                assert!((*got as f64 - want).abs() <= 1e-5 * k as f64, "{got} vs {want}");
            }
        }
    }

    /// The partials of a product with more than one chunk of output are added on every thread;
    /// the bits must not depend on how many there are.
    #[cfg(feature = "rayon")]
    #[test]
    fn bits_do_not_depend_on_the_thread_count() {
        let (m, n, k) = (70, 128, 40_000);
        let a: Vec<f32> = (0..k * m).map(|i| ((i * 37 % 101) as f32 - 50.0) / 50.0).collect();
        let b: Vec<f32> = (0..k * n).map(|i| ((i * 53 % 89) as f32 - 44.0) / 44.0).collect();
        let blocks = split_k_blocks(m, n, k);
        assert_eq!(blocks, 19);
        let product = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut out = vec![f32::NAN; m * n];
            let lhs = Operand { ptr: a.as_ptr(), rs: 1, cs: m as isize };
            let rhs = Operand { ptr: b.as_ptr(), rs: n as isize, cs: 1 };
            pool.install(|| unsafe { matmul_split_k(m, n, k, blocks, lhs, rhs, out.as_mut_ptr()) });
            out
        };
        let one = product(1);
        for threads in [2, 3, 7] {
            let other = product(threads);
            assert!(
                one.iter().zip(&other).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{threads} threads"
            );
        }
        let at: Vec<f32> = (0..m * k).map(|idx| a[(idx % k) * m + idx / k]).collect();
        let want = reference(m, n, k, &at, &b);
        for (got, want) in one.iter().zip(&want) {
            assert!((*got as f64 - want).abs() <= 1e-5 * k as f64, "{got} vs {want}");
        }
    }
}
