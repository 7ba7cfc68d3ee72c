//! Batched evaluation over slices, serial and (feature `rayon`) parallel.

use crate::brdf::{Brdf, Rgb};
use angles::{Real, Vec3};

/// Evaluates `brdf` for every pair `(l[i], v[i])` into `out[i]`.
///
/// # Panics
/// If the slices differ in length.
#[inline]
pub fn eval_batch<T: Real, B: Brdf<T> + ?Sized>(
    brdf: &B,
    l: &[Vec3<T>],
    v: &[Vec3<T>],
    out: &mut [Rgb<T>],
) {
    assert!(l.len() == v.len() && v.len() == out.len(), "eval_batch: slice lengths differ");
    for ((o, &l), &v) in out.iter_mut().zip(l).zip(v) {
        *o = brdf.eval(l, v);
    }
}

/// [`eval_batch`] split into chunks over the rayon thread pool.
///
/// # Panics
/// If the slices differ in length.
#[cfg(feature = "rayon")]
pub fn par_eval_batch<T: Real, B: Brdf<T> + ?Sized>(
    brdf: &B,
    l: &[Vec3<T>],
    v: &[Vec3<T>],
    out: &mut [Rgb<T>],
) {
    use rayon::prelude::*;
    assert!(l.len() == v.len() && v.len() == out.len(), "par_eval_batch: slice lengths differ");
    const CHUNK: usize = 4096;
    out.par_chunks_mut(CHUNK)
        .zip(l.par_chunks(CHUNK))
        .zip(v.par_chunks(CHUNK))
        .for_each(|((o, l), v)| eval_batch(brdf, l, v, o));
}
