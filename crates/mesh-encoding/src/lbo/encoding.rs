//! From eigenpairs to the network input: index selection, range rescaling and barycentric
//! interpolation (spec section 5.2 and its decisions table).
//!
//! Column `i` of the encoding is eigenfunction `selection[i]`, counted **after** dropping the
//! constant one (so index 0 is the first non-constant eigenfunction), divided by its range
//! `max - min` over the vertices (the intrinsic-neural-fields "standard" rescaling; the range
//! width becomes 1, the sign stays arbitrary). A surface point `(triangle, barycentrics)` gets
//! the barycentric blend of its three vertices' rows, in f32.

use super::eigen::Eigenpairs;
use crate::error::{Error, Result};

/// Which eigenfunctions feed the encoding, and how.
#[derive(Debug, Clone, PartialEq)]
pub struct LboEncodingConfig {
    /// Eigenfunction indices, 0-based after dropping the constant one when `drop_constant` is
    /// set. Default: `0..64` plus 6 blocks of 16 starting at `round(linspace(64, 496, 6))` =
    /// 64, 150, 237, 323, 410, 496: 160 inputs, the last being eigenfunction 511.
    pub selection: Vec<usize>,
    /// Drop the first (constant) eigenfunction before indexing (default true).
    pub drop_constant: bool,
    /// Divide each eigenfunction by its range `max - min` over the vertices (default true).
    pub rescale: bool,
}

impl Default for LboEncodingConfig {
    fn default() -> Self {
        LboEncodingConfig {
            selection: block_selection(64, 6, 16, 512).expect("the default selection is valid"),
            drop_constant: true,
            rescale: true,
        }
    }
}

impl LboEncodingConfig {
    /// Number of eigenpairs (including the constant one) the solver must provide.
    pub fn required_pairs(&self) -> usize {
        self.selection.iter().max().map_or(0, |&m| m + 1) + usize::from(self.drop_constant)
    }
}

/// Indices `0..first` followed by `blocks` blocks of `block_len` whose starts are
/// `round(linspace(first, k_max - block_len, blocks))` (numpy's rounding, half to even), so the
/// last block ends at `k_max - 1`. The default, `(64, 6, 16, 512)`, gives 0..64 and blocks at
/// 64, 150, 237, 323, 410, 496: 160 indices, the last 511.
///
/// # Errors
/// [`Error::Lbo`] if `k_max < first + block_len` while `blocks > 0`.
pub fn block_selection(
    first: usize,
    blocks: usize,
    block_len: usize,
    k_max: usize,
) -> Result<Vec<usize>> {
    let mut out: Vec<usize> = (0..first).collect();
    if blocks == 0 {
        return Ok(out);
    }
    if k_max < first + block_len {
        return Err(Error::lbo(format!(
            "k_max {k_max} is smaller than first + block_len = {}",
            first + block_len
        )));
    }
    let last = (k_max - block_len) as f64;
    for b in 0..blocks {
        let start = if blocks == 1 {
            first as f64
        } else {
            first as f64 + (last - first as f64) * b as f64 / (blocks - 1) as f64
        };
        let start = start.round_ties_even() as usize;
        out.extend(start..start + block_len);
    }
    Ok(out)
}

/// The per-vertex encoding: `dim` f32 values a vertex, rows in vertex order.
#[derive(Debug, Clone, PartialEq)]
pub struct LboEncoding {
    dim: usize,
    values: Vec<f32>,
}

impl LboEncoding {
    /// Selects, rescales and converts eigenfunctions to the per-vertex encoding.
    ///
    /// # Errors
    /// [`Error::Lbo`] when the selection is empty or names an eigenfunction that `pairs` does
    /// not have.
    pub fn new(pairs: &Eigenpairs, config: &LboEncodingConfig) -> Result<Self> {
        let needed = config.required_pairs();
        if config.selection.is_empty() {
            return Err(Error::lbo("the LBO index selection is empty"));
        }
        if needed > pairs.len() {
            return Err(Error::lbo(format!(
                "the LBO selection needs {needed} eigenpairs, only {} were computed",
                pairs.len()
            )));
        }
        let n = pairs.vertex_count();
        let dim = config.selection.len();
        let offset = usize::from(config.drop_constant);
        let mut values = vec![0f32; n * dim];
        for (c, &sel) in config.selection.iter().enumerate() {
            let col = pairs.vectors.col_as_slice(sel + offset);
            let scale = if config.rescale {
                let (lo, hi) =
                    col.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                        (lo.min(x), hi.max(x))
                    });
                // A constant column has no range to divide by; it stays as is.
                if hi - lo > 0.0 { 1.0 / (hi - lo) } else { 1.0 }
            } else {
                1.0
            };
            for (v, &x) in col.iter().enumerate() {
                values[v * dim + c] = (x * scale) as f32;
            }
        }
        Ok(LboEncoding { dim, values })
    }

    /// Values per vertex (160 by default).
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.values.len() / self.dim
    }

    /// The encoding of vertex `v`.
    ///
    /// # Panics
    /// If `v` is out of range.
    pub fn vertex(&self, v: usize) -> &[f32] {
        &self.values[v * self.dim..(v + 1) * self.dim]
    }

    /// All values, row-major (`vertex_count x dim`).
    pub fn as_slice(&self) -> &[f32] {
        &self.values
    }

    /// Writes the encoding of the surface point with barycentrics `bary` (weights of the
    /// triangle's corners in order) on triangle `tri` into `out`.
    ///
    /// # Panics
    /// If `out.len() != dim` or an index of `tri` is out of range.
    pub fn interpolate_into(&self, tri: [u32; 3], bary: [f32; 3], out: &mut [f32]) {
        assert_eq!(out.len(), self.dim, "output length must equal the encoding dimension");
        let [a, b, c] = tri.map(|i| self.vertex(i as usize));
        for (i, o) in out.iter_mut().enumerate() {
            *o = bary[0] * a[i] + bary[1] * b[i] + bary[2] * c[i];
        }
    }

    /// The encoding of many surface points `(triangle index, barycentrics)` on a mesh with
    /// `triangles`, row-major (`points x dim`).
    ///
    /// # Panics
    /// If a triangle index or a vertex index is out of range.
    pub fn interpolate(&self, triangles: &[[u32; 3]], points: &[(u32, [f32; 3])]) -> Vec<f32> {
        let mut out = vec![0f32; points.len() * self.dim];
        for (row, &(t, bary)) in out.chunks_exact_mut(self.dim).zip(points) {
            self.interpolate_into(triangles[t as usize], bary, row);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    #[test]
    fn default_selection_matches_the_spec() {
        let s = LboEncodingConfig::default();
        assert_eq!(s.selection.len(), 160);
        let starts: Vec<usize> = s.selection[64..].chunks(16).map(|c| c[0]).collect();
        assert_eq!(starts, vec![64, 150, 237, 323, 410, 496]);
        assert_eq!(*s.selection.last().unwrap(), 511);
        assert_eq!(s.required_pairs(), 513);
    }

    #[test]
    fn block_selection_spreads_its_blocks_to_k_max_and_refuses_too_small_a_k_max() {
        assert_eq!(block_selection(0, 1, 4, 4).unwrap(), [0, 1, 2, 3]);
        assert_eq!(block_selection(3, 0, 16, 3).unwrap(), [0, 1, 2], "no blocks: 0..first");
        let s = block_selection(10, 3, 5, 100).unwrap();
        let starts: Vec<usize> = s[10..].chunks(5).map(|c| c[0]).collect();
        assert_eq!(starts, [10, 52, 95], "linspace(10, 95, 3), the last block ending at 99");
        // (0, 3, 1, 4): the starts are linspace(0, 3, 3) = 0, 1.5, 3.
        assert_eq!(block_selection(0, 3, 1, 4).unwrap(), [0, 2, 3], "1.5 rounds half to even");
        let err = block_selection(10, 2, 8, 17).unwrap_err().to_string();
        assert!(err.contains("k_max 17") && err.contains("18"), "{err}");
    }

    #[test]
    fn rescaling_selection_and_interpolation() {
        // Three vertices, four pairs: a constant column and three others.
        let vectors = Mat::<f64>::from_fn(3, 4, |i, j| match j {
            0 => 1.0,
            1 => [0.0, 2.0, -2.0][i],
            2 => [1.0, 1.5, 3.0][i],
            _ => [5.0, 5.0, 5.0][i],
        });
        let pairs = Eigenpairs { values: vec![0.0, 1.0, 2.0, 3.0], vectors };
        let config =
            LboEncodingConfig { selection: vec![1, 0, 2], drop_constant: true, rescale: true };
        let enc = LboEncoding::new(&pairs, &config).unwrap();
        assert_eq!(enc.dim(), 3);
        // Column 0 = eigenfunction 2 (range 2), column 1 = eigenfunction 1 (range 4), column 2
        // = constant 5 kept as is.
        assert_eq!(enc.vertex(0), &[0.5, 0.0, 5.0]);
        assert_eq!(enc.vertex(2), &[1.5, -0.5, 5.0]);
        let mut out = [0f32; 3];
        enc.interpolate_into([0, 1, 2], [0.25, 0.25, 0.5], &mut out);
        let expected = [0.25 * 0.5 + 0.25 * 0.75 + 0.5 * 1.5, 0.25 * 0.0 + 0.25 * 0.5 - 0.25, 5.0];
        for (o, e) in out.iter().zip(expected) {
            assert!((o - e).abs() < 1e-6, "{out:?}");
        }
        let many = enc.interpolate(&[[2, 1, 0]], &[(0, [1.0, 0.0, 0.0]), (0, [0.0, 0.0, 1.0])]);
        assert_eq!(&many[..3], enc.vertex(2));
        assert_eq!(&many[3..], enc.vertex(0));
        let too_many = LboEncodingConfig { selection: vec![3], ..config };
        assert!(LboEncoding::new(&pairs, &too_many).is_err());
    }
}
