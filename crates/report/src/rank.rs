//! Marking table cells: best / second / third of a column (or row), or the improvements of a
//! delta table.
//!
//! Ranking is standard competition ranking ("1, 1, 3"): a value's rank is one plus the number
//! of strictly better values, so tied values share a mark and the next value skips the ranks
//! they used (two tied best values leave no second). Ties are decided on the printed values,
//! so two cells that read the same always carry the same mark. Unavailable ("n/a"), not-run
//! ("–") and non-finite cells are never ranked, and a column with fewer than two rankable
//! values gets no marks.

use super::record::Direction;

/// How a cell is highlighted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// Not highlighted.
    None,
    /// Best of its column (or row).
    First,
    /// Second best.
    Second,
    /// Third best.
    Third,
    /// A delta that is an improvement over the baseline.
    Improved,
}

/// Best / second / third marks of `values` (the printed values; `None` for cells that are not
/// ranked) under `direction`.
pub fn rank(values: &[Option<f64>], direction: Direction) -> Vec<Mark> {
    let sign = match direction {
        Direction::HigherIsBetter => 1.0,
        Direction::LowerIsBetter => -1.0,
        Direction::Neutral => return vec![Mark::None; values.len()],
    };
    let finite: Vec<f64> = values.iter().flatten().copied().filter(|v| v.is_finite()).collect();
    if finite.len() < 2 {
        return vec![Mark::None; values.len()];
    }
    values
        .iter()
        .map(|v| match v {
            Some(v) if v.is_finite() => {
                let better = finite.iter().filter(|&&o| sign * o > sign * v).count();
                match better {
                    0 => Mark::First,
                    1 => Mark::Second,
                    2 => Mark::Third,
                    _ => Mark::None,
                }
            }
            _ => Mark::None,
        })
        .collect()
}

/// [`Mark::Improved`] for each delta (variant minus baseline, as printed) that is an
/// improvement under `direction`: positive when higher is better, negative when lower is.
/// A delta that prints as zero is no improvement.
pub fn improvements(deltas: &[Option<f64>], direction: Direction) -> Vec<Mark> {
    deltas
        .iter()
        .map(|d| match (d, direction) {
            (Some(d), Direction::HigherIsBetter) if d.is_finite() && *d > 0.0 => Mark::Improved,
            (Some(d), Direction::LowerIsBetter) if d.is_finite() && *d < 0.0 => Mark::Improved,
            _ => Mark::None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use Mark::{First, Improved, None as N, Second, Third};

    #[test]
    fn ranks_by_direction() {
        let v = [Some(30.0), Some(32.0), Some(31.0), Some(29.0)];
        assert_eq!(rank(&v, Direction::HigherIsBetter), vec![Third, First, Second, N]);
        assert_eq!(rank(&v, Direction::LowerIsBetter), vec![Second, N, Third, First]);
        assert_eq!(rank(&v, Direction::Neutral), vec![N; 4]);
    }

    #[test]
    fn ties_share_a_mark_and_skip_ranks() {
        let v = [Some(1.0), Some(1.0), Some(2.0), Some(3.0)];
        // Two tied best: no second, the next is third.
        assert_eq!(rank(&v, Direction::LowerIsBetter), vec![First, First, Third, N]);
        let v = [Some(1.0), Some(2.0), Some(2.0), Some(3.0)];
        assert_eq!(rank(&v, Direction::LowerIsBetter), vec![First, Second, Second, N]);
        let v = [Some(0.0); 3];
        assert_eq!(rank(&v, Direction::LowerIsBetter), vec![First; 3]);
    }

    #[test]
    fn unranked_cells() {
        let v = [None, Some(2.0), Some(f64::NAN), Some(1.0), None];
        assert_eq!(rank(&v, Direction::HigherIsBetter), vec![N, First, N, Second, N]);
        // One rankable value: nothing to compare with.
        assert_eq!(rank(&[None, Some(1.0)], Direction::HigherIsBetter), vec![N, N]);
        assert!(rank(&[], Direction::HigherIsBetter).is_empty());
    }

    #[test]
    fn improvements_follow_the_direction() {
        let d = [Some(0.5), Some(-0.5), Some(0.0), None, Some(f64::INFINITY)];
        assert_eq!(improvements(&d, Direction::HigherIsBetter), vec![Improved, N, N, N, N]);
        assert_eq!(improvements(&d, Direction::LowerIsBetter), vec![N, Improved, N, N, N]);
        assert_eq!(improvements(&d, Direction::Neutral), vec![N; 5]);
    }
}
