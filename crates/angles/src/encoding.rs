//! NeRF positional encoding of angle vectors (spec section 5.1).

use crate::Real;

/// The positional encoding gamma(p) = [p, sin(f_0 p), cos(f_0 p), ..., sin(f_{L-1} p),
/// cos(f_{L-1} p)] with f_k = 2^k (times pi when `pi_factor`), applied element-wise.
///
/// Ordering follows the NeRF code convention: the identity block, then for each frequency a sine
/// block and a cosine block, each block over all input dimensions. Output length:
/// `d (include_input as usize) + 2 L d`; defaults give 3 angles -> 21 values and the 4-value
/// reciprocity mapping -> 28.
///
/// | field | default | meaning |
/// | --- | --- | --- |
/// | `frequencies` | 3 | L, the number of octaves |
/// | `include_input` | true | prepend the raw input |
/// | `pi_factor` | false | use sin(2^k pi p) as in the NeRF paper instead of the code |
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct PositionalEncoding {
    /// Number of frequencies L (default 3).
    pub frequencies: usize,
    /// Whether the raw input is included (default true).
    pub include_input: bool,
    /// Whether frequencies are multiplied by pi (default false).
    pub pi_factor: bool,
}

impl Default for PositionalEncoding {
    fn default() -> Self {
        Self { frequencies: 3, include_input: true, pi_factor: false }
    }
}

impl PositionalEncoding {
    /// Output length for an input of `input_len` values.
    pub fn output_len(&self, input_len: usize) -> usize {
        input_len * (usize::from(self.include_input) + 2 * self.frequencies)
    }

    /// Encodes one input vector into `out`.
    ///
    /// # Panics
    /// If `out.len() != self.output_len(input.len())`.
    pub fn encode_into<T: Real>(&self, input: &[T], out: &mut [T]) {
        let d = input.len();
        assert_eq!(out.len(), self.output_len(d), "positional encoding: output length");
        let mut o = 0;
        if self.include_input {
            out[..d].copy_from_slice(input);
            o = d;
        }
        let base = if self.pi_factor { T::PI() } else { T::one() };
        for k in 0..self.frequencies {
            let f = base * T::lit((1u64 << k) as f64);
            for (i, &p) in input.iter().enumerate() {
                let (s, c) = (f * p).sin_cos();
                out[o + i] = s;
                out[o + d + i] = c;
            }
            o += 2 * d;
        }
    }

    /// Encodes one input vector into a new vector.
    pub fn encode<T: Real>(&self, input: &[T]) -> Vec<T> {
        let mut out = vec![T::zero(); self.output_len(input.len())];
        self.encode_into(input, &mut out);
        out
    }

    /// Encodes `n` row-major input rows of `input_dim` values each into `out` (row-major,
    /// `output_len(input_dim)` per row).
    ///
    /// # Panics
    /// If the slice lengths do not match `input_dim`.
    pub fn encode_batch<T: Real>(&self, input: &[T], input_dim: usize, out: &mut [T]) {
        let od = self.output_len(input_dim);
        assert!(
            input_dim > 0 && input.len().is_multiple_of(input_dim),
            "encode_batch: input shape"
        );
        assert_eq!(out.len(), input.len() / input_dim * od, "encode_batch: output length");
        for (row, o) in input.chunks_exact(input_dim).zip(out.chunks_exact_mut(od)) {
            self.encode_into(row, o);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_sizes_and_layout() {
        let pe = PositionalEncoding::default();
        assert_eq!(pe.output_len(3), 21);
        assert_eq!(pe.output_len(4), 28);
        let x = [0.5_f64, -1.0];
        let e = pe.encode(&x);
        assert_eq!(&e[..2], &x);
        assert_eq!(e[2], 0.5_f64.sin());
        assert_eq!(e[3], (-1.0_f64).sin());
        assert_eq!(e[4], 0.5_f64.cos());
        assert_eq!(e[6], 1.0_f64.sin());
        assert_eq!(e[13], (-4.0_f64).cos());
        let pi = PositionalEncoding { pi_factor: true, include_input: false, frequencies: 1 };
        assert_eq!(
            pi.encode(&[0.5_f64]),
            vec![(0.5 * std::f64::consts::PI).sin(), (0.5 * std::f64::consts::PI).cos()]
        );
    }

    #[test]
    fn batch_matches_single() {
        let pe = PositionalEncoding::default();
        let x: Vec<f32> = (0..12).map(|i| i as f32 * 0.37 - 2.0).collect();
        let mut out = vec![0.0; 4 * 21];
        pe.encode_batch(&x, 3, &mut out);
        for r in 0..4 {
            assert_eq!(&out[r * 21..(r + 1) * 21], pe.encode(&x[r * 3..r * 3 + 3]).as_slice());
        }
    }
}
