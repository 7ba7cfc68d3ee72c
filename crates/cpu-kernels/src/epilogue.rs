//! What a product does to its output before it returns: a bias added to every row, then a
//! ReLU, so a hidden layer `relu(x W + b)` is one kernel call instead of a product and two
//! passes over its output.
//!
//! Each element gets exactly the operations of the unfused layer, in the same order: one f32
//! addition of the column's bias, then the ReLU of burn-flex (`x` where `x > 0` or `x` is NaN,
//! else `+0.0`, so `-0.0` becomes `+0.0` and NaN passes). So a fused layer equals the product
//! followed by burn's broadcast add and burn's `relu`, to the bit, on every path.
//!
//! The paths that add the epilogue while a block of the output is still in cache (the f32
//! gemm in blocks of rows, the AMX kernel's block store) call [`Epilogue::apply_row`] per row;
//! the others call [`Epilogue::apply_rows`] once after the product.

/// A bias per column and an optional ReLU, applied to a product's output.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Epilogue<'a> {
    /// One value per output column, added to every row.
    pub bias: Option<&'a [f32]>,
    /// Then `relu` on every element.
    pub relu: bool,
}

/// burn-flex's ReLU of one value: `x` where `x > 0` or `x` is NaN, else `+0.0`.
#[inline(always)]
pub fn relu(x: f32) -> f32 {
    if x.is_nan() || x > 0.0 { x } else { 0.0 }
}

impl<'a> Epilogue<'a> {
    /// Nothing: the bare product.
    pub const NONE: Epilogue<'static> = Epilogue { bias: None, relu: false };

    /// The bias only (a linear layer).
    pub fn bias(bias: Option<&'a [f32]>) -> Self {
        Epilogue { bias, relu: false }
    }

    /// Whether the epilogue changes the product at all.
    pub fn is_some(&self) -> bool {
        self.bias.is_some() || self.relu
    }

    /// Applies the epilogue to one row (or the first `row.len()` columns of a row starting at
    /// column `col0`: the bias values `col0..col0 + row.len()`).
    #[inline]
    pub fn apply_row(&self, row: &mut [f32], col0: usize) {
        match (self.bias, self.relu) {
            (Some(b), true) => {
                for (x, b) in row.iter_mut().zip(&b[col0..]) {
                    *x = relu(*x + b);
                }
            }
            (Some(b), false) => {
                for (x, b) in row.iter_mut().zip(&b[col0..]) {
                    *x += b;
                }
            }
            (None, true) => row.iter_mut().for_each(|x| *x = relu(*x)),
            (None, false) => {}
        }
    }

    /// Applies the epilogue to every row of the m x n row-major matrix at `out`, rows in
    /// parallel for large matrices.
    ///
    /// # Safety
    /// `out` addresses m * n floats that no one else touches meanwhile; a bias holds n values.
    pub unsafe fn apply_rows(&self, m: usize, n: usize, out: *mut f32) {
        if !self.is_some() || m == 0 || n == 0 {
            return;
        }
        if let Some(b) = self.bias {
            assert_eq!(
                b.len(),
                n,
                "Epilogue::apply_rows: bias of {} values for {n} columns",
                b.len()
            );
        }
        // SAFETY: the caller's.
        let out = unsafe { core::slice::from_raw_parts_mut(out, m * n) };
        let apply = |rows: &mut [f32]| {
            for row in rows.chunks_exact_mut(n) {
                self.apply_row(row, 0);
            }
        };
        #[cfg(feature = "rayon")]
        if m * n >= 1 << 17 {
            use rayon::prelude::*;
            let rows = (1usize << 14).div_ceil(n).max(1);
            out.par_chunks_mut(rows * n).for_each(apply);
            return;
        }
        apply(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relu_is_burn_flex_s() {
        assert_eq!(relu(2.5), 2.5);
        assert_eq!(relu(-1.0).to_bits(), 0f32.to_bits());
        assert_eq!(relu(-0.0).to_bits(), 0f32.to_bits());
        assert_eq!(relu(0.0).to_bits(), 0f32.to_bits());
        assert!(relu(f32::NAN).is_nan());
        assert_eq!(relu(f32::INFINITY), f32::INFINITY);
        assert_eq!(relu(f32::NEG_INFINITY), 0.0);
    }

    #[test]
    fn rows_get_the_bias_then_the_relu() {
        let (m, n) = (1100, 130);
        let bias: Vec<f32> = (0..n).map(|j| (j as f32 - 60.0) / 7.0).collect();
        let src: Vec<f32> = (0..m * n).map(|i| ((i * 37 % 101) as f32 - 50.0) / 3.0).collect();
        for relu_on in [false, true] {
            for b in [None, Some(bias.as_slice())] {
                let e = Epilogue { bias: b, relu: relu_on };
                let mut got = src.clone();
                // SAFETY: `got` holds m n floats.
                unsafe { e.apply_rows(m, n, got.as_mut_ptr()) };
                for (i, (g, s)) in got.iter().zip(&src).enumerate() {
                    let z = b.map_or(*s, |b| s + b[i % n]);
                    let want = if relu_on { relu(z) } else { z };
                    assert_eq!(
                        g.to_bits(),
                        want.to_bits(),
                        "[{i}] bias {} relu {relu_on}",
                        b.is_some()
                    );
                }
            }
        }
    }
}
