//! The segments of the t axis on which the first layer of FMBRDF's Smith Lambda network keeps
//! one set of active units, for evaluating the network along its one varying input.
//!
//! Within a training step the Lambda network sees (alpha, beta, t, t alpha) with alpha and beta
//! one value per object, so its first layer's pre-activation is affine in t:
//!
//! ```text
//! z1(t) = a + t c,   a = alpha W1[0] + beta W1[1] + b1,   c = W1[2] + alpha W1[3]
//! ```
//!
//! (rows of W1^T). Unit j with c_j > 0 is active (z1_j > 0) exactly for t above its breakpoint
//! t_j = -a_j / c_j, one with c_j < 0 exactly below it, one with c_j = 0 everywhere or nowhere
//! (the sign of a_j). Sorted, the breakpoints cut the t axis into at most width + 1 segments,
//! and on each segment s the active set is one 0/1 mask m_s, so
//!
//! ```text
//! relu(z1(t)) W2 = (m_s * a) W2 + t (m_s * c) W2 = P_s + t Q_s.
//! ```
//!
//! `FmbrdfNets::lambda` computes P and Q once per occupied segment and gathers them per row:
//! the second layer's `[rows, 300] x [300, 100]` product becomes two `[segments, 300] x [300,
//! 100]` products, at most 301 rows each, and O(100) work a row. The identity is exact; only the
//! f32 rounding differs from the dense network. A row within rounding of a breakpoint may get
//! the neighbouring segment's mask: the unit it differs in is then within rounding of zero, the
//! same ambiguity a ReLU has at zero.

/// The occupied segments of a batch of t values.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Segments {
    /// Number of occupied segments (rows of `mask`).
    pub count: usize,
    /// Active-unit masks, 1 or 0, `[count, width]` row-major.
    pub mask: Vec<f32>,
    /// Each t value's row of `mask`.
    pub of_row: Vec<i32>,
}

impl Segments {
    /// The segments of `t` for the first layer's pre-activation `a + t c`.
    ///
    /// `None` when a value is not finite (a diverged alpha or beta; the caller evaluates the
    /// dense network, which propagates it).
    ///
    /// # Panics
    /// If `a` and `c` differ in length.
    pub fn of(a: &[f32], c: &[f32], t: &[f32]) -> Option<Self> {
        assert_eq!(a.len(), c.len(), "Segments::of: a and c lengths");
        if !a.iter().chain(c).chain(t).all(|x| x.is_finite()) {
            return None;
        }
        let width = a.len();
        // Breakpoints of the units that switch, sorted; rank[j] is unit j's place among them.
        let mut switching: Vec<(f32, usize)> =
            (0..width).filter(|&j| c[j] != 0.0).map(|j| (-a[j] / c[j], j)).collect();
        switching.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let breakpoints: Vec<f32> = switching.iter().map(|&(b, _)| b).collect();
        let mut rank = vec![usize::MAX; width];
        for (r, &(_, j)) in switching.iter().enumerate() {
            rank[j] = r;
        }
        // Segment s holds the t with exactly s breakpoints below them.
        let mut slot = vec![u32::MAX; breakpoints.len() + 1];
        let mut occupied = Vec::new();
        let of_row = t
            .iter()
            .map(|&x| {
                let s = breakpoints.partition_point(|&b| b < x);
                if slot[s] == u32::MAX {
                    slot[s] = occupied.len() as u32;
                    occupied.push(s);
                }
                slot[s] as i32
            })
            .collect();
        let mut mask = vec![0.0_f32; occupied.len() * width];
        for (row, &s) in mask.chunks_exact_mut(width.max(1)).zip(&occupied) {
            for (j, m) in row.iter_mut().enumerate() {
                let active = if c[j] > 0.0 {
                    rank[j] < s
                } else if c[j] < 0.0 {
                    rank[j] >= s
                } else {
                    a[j] > 0.0
                };
                *m = if active { 1.0 } else { 0.0 };
            }
        }
        Some(Self { count: occupied.len(), mask, of_row })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Each row's mask is the set of units with a + t c > 0, wherever t is not within
        /// rounding of that unit's breakpoint.
        #[test]
        fn masks_are_the_active_units(
            units in proptest::collection::vec((-5.0_f32..5.0, -5.0_f32..5.0), 1..40),
            zeros in proptest::collection::vec(any::<bool>(), 40),
            t in proptest::collection::vec(-50.0_f32..50.0, 1..200),
        ) {
            let a: Vec<f32> = units.iter().map(|u| u.0).collect();
            // Some units with c = 0 exactly (always or never active).
            let c: Vec<f32> =
                units.iter().zip(&zeros).map(|(u, &z)| if z { 0.0 } else { u.1 }).collect();
            let seg = Segments::of(&a, &c, &t).unwrap();
            let width = a.len();
            prop_assert_eq!(seg.of_row.len(), t.len());
            prop_assert_eq!(seg.mask.len(), seg.count * width);
            prop_assert!(seg.count <= width + 1);
            for (&x, &s) in t.iter().zip(&seg.of_row) {
                let row = &seg.mask[s as usize * width..(s as usize + 1) * width];
                for j in 0..width {
                    let z = a[j] as f64 + x as f64 * c[j] as f64;
                    let scale = a[j].abs() as f64 + (x * c[j]).abs() as f64;
                    if z.abs() > 1e-5 * scale.max(1e-30) {
                        let active = if z > 0.0 { 1.0 } else { 0.0 };
                        prop_assert_eq!(row[j], active, "unit {} t {}", j, x);
                    }
                }
            }
        }
    }

    #[test]
    fn rows_of_one_segment_share_a_mask_row() {
        // Breakpoints at t = 1 (c > 0) and t = 2 (c < 0).
        let (a, c) = ([-1.0, 2.0, 0.5, -0.5], [1.0, -1.0, 0.0, 0.0]);
        let seg = Segments::of(&a, &c, &[1.5, 0.0, 1.7, 3.0, 0.5]).unwrap();
        assert_eq!(seg.count, 3);
        assert_eq!(seg.of_row, vec![0, 1, 0, 2, 1]);
        assert_eq!(&seg.mask[0..4], &[1.0, 1.0, 1.0, 0.0]);
        assert_eq!(&seg.mask[4..8], &[0.0, 1.0, 1.0, 0.0]);
        assert_eq!(&seg.mask[8..12], &[1.0, 0.0, 1.0, 0.0]);
    }

    #[test]
    fn non_finite_values_give_none() {
        assert!(Segments::of(&[f32::NAN], &[1.0], &[0.0]).is_none());
        assert!(Segments::of(&[0.0], &[f32::INFINITY], &[0.0]).is_none());
        assert!(Segments::of(&[0.0], &[1.0], &[f32::NAN]).is_none());
    }
}
