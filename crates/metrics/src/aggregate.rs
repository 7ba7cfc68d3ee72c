//! Averaging "first per object, then over objects" (spec section 7), the "n/a" value of a metric
//! that could not be computed, and the tables' scaling convention.

use std::collections::BTreeMap;
use std::fmt;

/// A metric value, or the reason it is not available (printed as `n/a (reason)`).
#[derive(Clone, Debug, PartialEq)]
pub enum Score {
    /// A computed value.
    Value(f64),
    /// Not computed; the tables print `n/a (<reason>)`, e.g. "weights missing" for LPIPS.
    Unavailable(String),
}

impl Score {
    /// The value, if any.
    pub fn value(&self) -> Option<f64> {
        match self {
            Score::Value(v) => Some(*v),
            Score::Unavailable(_) => None,
        }
    }
}

impl fmt::Display for Score {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Score::Value(v) => write!(f, "{v}"),
            Score::Unavailable(why) => write!(f, "n/a ({why})"),
        }
    }
}

/// How the paper's tables print each metric: the raw value times [`TableScale::factor`].
///
/// RMSE^(1/3), DSSIM, LPIPS and HDR-FLIP are scaled by 100; PSNR (dB), the reciprocity RMSE and
/// the energy statistics (a percentage and a median energy) are not.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum TableScale {
    /// PSNR in dB.
    Psnr,
    /// DSSIM = (1 - SSIM) / 2.
    Dssim,
    /// LPIPS (AlexNet, v0.1).
    Lpips,
    /// Mean HDR-FLIP.
    Flip,
    /// RMSE of cube roots of BRDF values.
    CubeRootRmse,
    /// Reciprocity RMSE.
    Reciprocity,
    /// Percentage of (x, l) pairs with energy above 1.
    EnergyPercent,
    /// Median energy of the violating pairs.
    EnergyMedian,
}

impl TableScale {
    /// The factor the tables multiply the raw value by.
    pub fn factor(self) -> f64 {
        match self {
            TableScale::Dssim | TableScale::Lpips | TableScale::Flip | TableScale::CubeRootRmse => {
                100.0
            }
            _ => 1.0,
        }
    }

    /// `score` as the table prints it (value times [`TableScale::factor`]).
    pub fn scale(self, score: &Score) -> Score {
        match score {
            Score::Value(v) => Score::Value(v * self.factor()),
            other => other.clone(),
        }
    }
}

/// Collects per-image (or per-experiment) values tagged with their object and averages them
/// per object first, then over objects.
#[derive(Clone, Debug, Default)]
pub struct PerObjectMean {
    objects: BTreeMap<String, Vec<Score>>,
}

impl PerObjectMean {
    /// An empty collector.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records one value of `object`.
    pub fn push(&mut self, object: &str, score: Score) {
        self.objects.entry(object.to_string()).or_default().push(score);
    }

    /// Mean of each object's values (unavailable if any of them is).
    pub fn per_object(&self) -> BTreeMap<String, Score> {
        self.objects.iter().map(|(k, v)| (k.clone(), mean(v))).collect()
    }

    /// Mean over objects of the per-object means; unavailable if any object is, and
    /// unavailable ("no data") when nothing was recorded.
    pub fn overall(&self) -> Score {
        mean(&self.per_object().into_values().collect::<Vec<_>>())
    }
}

fn mean(values: &[Score]) -> Score {
    if values.is_empty() {
        return Score::Unavailable("no data".into());
    }
    let mut sum = 0.0;
    for s in values {
        match s {
            Score::Value(v) => sum += v,
            other => return other.clone(),
        }
    }
    Score::Value(sum / values.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn per_object_then_over_objects() {
        let mut m = PerObjectMean::new();
        // bear: mean 2; cow: mean 10 -> 6 (a flat mean of the four values would be 4.5).
        m.push("bear", Score::Value(1.0));
        m.push("bear", Score::Value(2.0));
        m.push("bear", Score::Value(3.0));
        m.push("cow", Score::Value(10.0));
        assert_eq!(m.overall(), Score::Value(6.0));
        m.push("pot2", Score::Unavailable("weights missing".into()));
        assert_eq!(m.overall().to_string(), "n/a (weights missing)");
        assert_eq!(m.per_object()["cow"], Score::Value(10.0));
    }

    #[test]
    fn scaling_convention() {
        assert_eq!(TableScale::Flip.scale(&Score::Value(0.1234)), Score::Value(12.34));
        assert_eq!(TableScale::Reciprocity.factor(), 1.0);
        assert_eq!(TableScale::Psnr.factor(), 1.0);
        assert_eq!(TableScale::CubeRootRmse.factor(), 100.0);
    }
}
