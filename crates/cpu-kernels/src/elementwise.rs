//! The element-wise halves of a layer's backward pass, on every thread: the ReLU mask of an
//! upstream gradient (in place) and the bias gradient, a sum over the rows.
//!
//! Both give the same bits on any number of threads: the mask is element-wise, and the row sum
//! adds a block count of partials that depends on the shape alone (`rows / 4096`, at most 16),
//! each a sum of its rows in order, then the partials in block order. Short sums add all rows
//! in order, as burn-flex does.

/// Buffers at least this long are split over the threads.
pub const PAR_MIN_ELEMS: usize = 1 << 17;
/// Elements per parallel task.
const CHUNK: usize = 1 << 15;
/// Rows per block of the row sum.
const BLOCK_ROWS: usize = 4096;

/// `grad[i] = 0` where `output[i] <= 0` (a NaN output keeps its gradient): the backward pass
/// of `output = relu(x)`, in place.
///
/// # Panics
/// If the lengths differ.
pub fn relu_backward_in_place(grad: &mut [f32], output: &[f32]) {
    assert_eq!(grad.len(), output.len(), "relu_backward_in_place: lengths");
    // A select and an unconditional store, which vectorise; a conditional store does not, and
    // its branch, taken for about half of a layer's units in no order, mispredicts.
    let mask = |g: &mut [f32], o: &[f32]| {
        for (g, &o) in g.iter_mut().zip(o) {
            *g = if o > 0.0 || o.is_nan() { *g } else { 0.0 };
        }
    };
    #[cfg(feature = "rayon")]
    if grad.len() >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        grad.par_chunks_mut(CHUNK).zip(output.par_chunks(CHUNK)).for_each(|(g, o)| mask(g, o));
        return;
    }
    mask(grad, output);
}

/// Adds rows `r0..r1` of the row-major `data` (`cols` wide) to `out`, in row order.
fn add_rows(data: &[f32], cols: usize, r0: usize, r1: usize, out: &mut [f32]) {
    for row in data[r0 * cols..r1 * cols].chunks_exact(cols) {
        for (o, &x) in out.iter_mut().zip(row) {
            *o += x;
        }
    }
}

/// The sum over the rows of the row-major `rows x cols` matrix `data`: `cols` values.
///
/// # Panics
/// If `data` does not hold `rows * cols` values.
pub fn sum_rows(data: &[f32], rows: usize, cols: usize) -> Vec<f32> {
    assert_eq!(data.len(), rows * cols, "sum_rows: shape");
    let blocks = (rows / BLOCK_ROWS).min(16);
    #[cfg(feature = "rayon")]
    if blocks >= 2 && rows * cols >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        let partials: Vec<Vec<f32>> = (0..blocks)
            .into_par_iter()
            .map(|b| {
                let mut part = vec![0f32; cols];
                add_rows(data, cols, b * rows / blocks, (b + 1) * rows / blocks, &mut part);
                part
            })
            .collect();
        let mut out = partials[0].clone();
        for part in &partials[1..] {
            out.iter_mut().zip(part).for_each(|(o, p)| *o += p);
        }
        return out;
    }
    let _ = blocks;
    let mut out = vec![0f32; cols];
    add_rows(data, cols, 0, rows, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_sums_match_f64_and_not_the_thread_count() {
        for (rows, cols) in [(3, 5), (8191, 16), (9000, 33), (70_000, 4)] {
            let data: Vec<f32> =
                (0..rows * cols).map(|i| ((i * 37 % 101) as f32 - 50.0) / 7.0).collect();
            let want: Vec<f64> =
                (0..cols).map(|c| (0..rows).map(|r| data[r * cols + c] as f64).sum()).collect();
            let got = sum_rows(&data, rows, cols);
            for (g, w) in got.iter().zip(&want) {
                assert!(
                    (*g as f64 - w).abs() <= 1e-4 * (1.0 + w.abs()) * rows as f64 / 1000.0 + 1e-3,
                    "{g} {w}"
                );
            }
            let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
            assert_eq!(one.install(|| sum_rows(&data, rows, cols)), got, "{rows} x {cols}");
        }
    }

    #[test]
    fn relu_mask_keeps_positive_and_nan_outputs() {
        let n = PAR_MIN_ELEMS + 3;
        let output: Vec<f32> = (0..n)
            .map(|i| match i % 4 {
                0 => -1.0,
                1 => 0.0,
                2 => f32::NAN,
                _ => 2.0,
            })
            .collect();
        let mut grad = vec![5.0f32; n];
        relu_backward_in_place(&mut grad, &output);
        for (i, g) in grad.iter().enumerate() {
            assert_eq!(*g, if i % 4 >= 2 { 5.0 } else { 0.0 }, "{i}");
        }
    }
}
