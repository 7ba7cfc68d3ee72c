//! Element-wise work on large buffers spread over the rayon threads (patch 5, see the
//! workspace's `vendor/README.md`).
//!
//! Upstream runs every element-wise op on the calling thread. In a training step at batch
//! 32,768 each ReLU, its backward and each bias add touches 16 MB; on the 2-core bench machine
//! one thread moves such a buffer in 0.9 ms (in place) to 3.4 ms (two inputs, fresh output)
//! and two threads in half that. Each element is computed by the same scalar function as
//! before, so values are unchanged to the bit; only who computes which chunk differs.

/// Buffers shorter than this many elements stay on the calling thread.
pub(crate) const PAR_MIN_ELEMS: usize = 1 << 17;
/// Elements per rayon task.
#[cfg(feature = "rayon")]
const CHUNK: usize = 1 << 15;

/// `dst[i] = op(dst[i])` for every i.
pub(crate) fn map_inplace<E, Op>(dst: &mut [E], op: Op)
where
    E: Copy + Send + Sync,
    Op: Fn(E) -> E + Send + Sync,
{
    #[cfg(feature = "rayon")]
    if dst.len() >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        dst.par_chunks_mut(CHUNK).for_each(|c| c.iter_mut().for_each(|x| *x = op(*x)));
        return;
    }
    dst.iter_mut().for_each(|x| *x = op(*x));
}

/// `op(src[i])` for every i, as a new vector.
pub(crate) fn map<E, Op>(src: &[E], op: Op) -> alloc::vec::Vec<E>
where
    E: Copy + Send + Sync,
    Op: Fn(E) -> E + Send + Sync,
{
    #[cfg(feature = "rayon")]
    if src.len() >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        let mut out = alloc::vec::Vec::with_capacity(src.len());
        out.spare_capacity_mut()[..src.len()]
            .par_chunks_mut(CHUNK)
            .zip(src.par_chunks(CHUNK))
            .for_each(|(d, s)| {
                d.iter_mut().zip(s).for_each(|(d, &x)| {
                    d.write(op(x));
                })
            });
        // SAFETY: every one of the first `src.len()` elements was written above.
        unsafe { out.set_len(src.len()) };
        return out;
    }
    src.iter().map(|&x| op(x)).collect()
}

/// `dst[i] = op(dst[i], src[i])` for every i (equal lengths).
pub(crate) fn zip_inplace<D, S, Op>(dst: &mut [D], src: &[S], op: Op)
where
    D: Copy + Send + Sync,
    S: Copy + Send + Sync,
    Op: Fn(D, S) -> D + Send + Sync,
{
    debug_assert_eq!(dst.len(), src.len());
    #[cfg(feature = "rayon")]
    if dst.len() >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        dst.par_chunks_mut(CHUNK).zip(src.par_chunks(CHUNK)).for_each(|(d, s)| {
            d.iter_mut().zip(s).for_each(|(d, &s)| *d = op(*d, s));
        });
        return;
    }
    dst.iter_mut().zip(src).for_each(|(d, &s)| *d = op(*d, s));
}

/// `dst[r * row.len() + j] = op(dst[..], row[j])` for every row r of a dense row-major `dst`:
/// a row vector broadcast down the rows (a bias add).
pub(crate) fn rows_inplace<D, S, Op>(dst: &mut [D], row: &[S], op: Op)
where
    D: Copy + Send + Sync,
    S: Copy + Send + Sync,
    Op: Fn(D, S) -> D + Send + Sync,
{
    let n = row.len();
    debug_assert!(n > 0 && dst.len().is_multiple_of(n));
    let each = |chunk: &mut [D]| {
        for r in chunk.chunks_exact_mut(n) {
            r.iter_mut().zip(row).for_each(|(d, &s)| *d = op(*d, s));
        }
    };
    #[cfg(feature = "rayon")]
    if dst.len() >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        let rows_per_chunk = CHUNK.div_ceil(n);
        dst.par_chunks_mut(rows_per_chunk * n).for_each(each);
        return;
    }
    each(dst);
}
