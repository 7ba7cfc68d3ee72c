//! The train/test split of a capture (spec section 6): the paper trains on 10 views x 30 lights
//! and tests on the other 10 views x 12 lights; which ones it does not say.
//!
//! Lights: a seeded shuffle of the capture's lights; the first `train` (sorted) are the training
//! lights, the next `test` (sorted) the test lights, so the two never overlap and the same
//! seed gives the same lights on every view. Views: by default alternating (view 1, 3, 5, ...
//! train; 2, 4, 6, ... test), which spreads both sets around the turntable.

use crate::error::{Error, Result};

/// Disjoint (train, test) light indices (0-based, each sorted) out of `n`.
///
/// # Errors
/// [`Error::Options`] when `train` or `test` is 0 or `train + test > n`.
pub fn split_lights(
    n: usize,
    train: usize,
    test: usize,
    seed: u64,
) -> Result<(Vec<usize>, Vec<usize>)> {
    if train == 0 || test == 0 || train + test > n {
        return Err(Error::option(
            "train_lights/test_lights",
            format!(
                "{train} train + {test} test lights do not fit {n} captured lights (each >= 1)"
            ),
        ));
    }
    let mut order: Vec<usize> = (0..n).collect();
    stdx::rng::SplitMix64::new(seed ^ 0xD1_11_6E_47_5E_ED_00_01).shuffle(&mut order);
    let mut tr = order[..train].to_vec();
    let mut te = order[train..train + test].to_vec();
    tr.sort_unstable();
    te.sort_unstable();
    Ok((tr, te))
}

/// Whether each of `views` views (0-based) is a training view: `train` lists 1-based view
/// numbers, `None` alternates (odd-numbered views train).
///
/// # Errors
/// [`Error::Options`] for a view number out of range or repeated, or a split leaving no train or
/// no test view.
pub fn train_views(views: usize, train: Option<&[usize]>) -> Result<Vec<bool>> {
    let is_train: Vec<bool> = match train {
        None => (0..views).map(|v| v % 2 == 0).collect(),
        Some(list) => {
            let mut t = vec![false; views];
            for &v in list {
                if v == 0 || v > views || t[v - 1] {
                    return Err(Error::option(
                        "train_views",
                        format!("view {v} is out of 1..={views} or repeated"),
                    ));
                }
                t[v - 1] = true;
            }
            t
        }
    };
    let n_train = is_train.iter().filter(|&&t| t).count();
    if n_train == 0 || n_train == views {
        return Err(Error::option(
            "train_views",
            format!("{n_train} of {views} views train: need at least one train and one test view"),
        ));
    }
    Ok(is_train)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_are_disjoint_seeded_and_checked() {
        let (a, b) = split_lights(96, 30, 12, 7).unwrap();
        assert_eq!((a.len(), b.len()), (30, 12));
        assert!(a.iter().all(|x| !b.contains(x) && *x < 96));
        assert_eq!(split_lights(96, 30, 12, 7).unwrap(), (a.clone(), b));
        assert_ne!(split_lights(96, 30, 12, 8).unwrap().0, a);
        assert!(split_lights(10, 8, 3, 0).unwrap_err().to_string().contains("train_lights"));
        assert!(split_lights(10, 0, 3, 0).is_err());
    }

    #[test]
    fn views_alternate_or_follow_the_list() {
        assert_eq!(train_views(4, None).unwrap(), [true, false, true, false]);
        assert_eq!(train_views(3, Some(&[2, 3])).unwrap(), [false, true, true]);
        assert!(train_views(3, Some(&[4])).is_err());
        assert!(train_views(3, Some(&[1, 2, 3])).is_err());
        assert!(train_views(1, None).is_err());
    }
}
