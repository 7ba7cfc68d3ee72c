//! RMSE of cube roots of BRDF values (Lavoue et al. 2021; spec section 7), semi-synthetic data
//! only:
//!
//! RMSE^(1/3) = sqrt( mean over kept samples and channels of (f_pred^(1/3) - f_gt^(1/3))^2 ).
//!
//! A sample (a test pixel's (x, l, v)) is dropped when theta_l or theta_v exceeds the grazing
//! cut-off (default 80 degrees), when its GT pixel was saturated, or when the GT BRDF is invalid
//! (any channel negative or not finite: MERL's missing entries). The value is raw; the tables
//! scale it by 100 ([`crate::aggregate::TableScale`]).

use crate::error::{Error, Result};

/// Settings of [`CubeRootRmse`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RmseConfig {
    /// Samples with theta_l or theta_v above this angle (degrees) are dropped (default 80).
    pub max_angle_deg: f64,
}

impl Default for RmseConfig {
    fn default() -> Self {
        Self { max_angle_deg: 80.0 }
    }
}

/// Why a sample was dropped, or that it was kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleFate {
    /// Entered the mean.
    Kept,
    /// theta_l or theta_v above the cut-off.
    Grazing,
    /// GT pixel saturated.
    Saturated,
    /// GT BRDF negative or not finite.
    InvalidGt,
}

/// Accumulates the cube-root RMSE over samples (f64 sums), with counts of dropped samples.
#[derive(Clone, Debug, Default)]
pub struct CubeRootRmse {
    cos_max: f64,
    sum: f64,
    /// Samples kept.
    pub kept: usize,
    /// Samples dropped at grazing angles.
    pub grazing: usize,
    /// Samples dropped as saturated.
    pub saturated: usize,
    /// Samples dropped for an invalid GT value.
    pub invalid: usize,
}

impl CubeRootRmse {
    /// An empty accumulator.
    pub fn new(cfg: RmseConfig) -> Self {
        Self { cos_max: cfg.max_angle_deg.to_radians().cos(), ..Default::default() }
    }

    /// Adds one sample given the cosines of theta_l and theta_v (n.l, n.v).
    pub fn push(
        &mut self,
        pred: [f32; 3],
        gt: [f32; 3],
        cos_theta_l: f32,
        cos_theta_v: f32,
        saturated: bool,
    ) -> SampleFate {
        if gt.iter().any(|g| !g.is_finite() || *g < 0.0) {
            self.invalid += 1;
            return SampleFate::InvalidGt;
        }
        if saturated {
            self.saturated += 1;
            return SampleFate::Saturated;
        }
        if (cos_theta_l as f64) < self.cos_max || (cos_theta_v as f64) < self.cos_max {
            self.grazing += 1;
            return SampleFate::Grazing;
        }
        for c in 0..3 {
            let d = (pred[c] as f64).cbrt() - (gt[c] as f64).cbrt();
            self.sum += d * d;
        }
        self.kept += 1;
        SampleFate::Kept
    }

    /// The RMSE of cube roots; an error if no sample was kept or a prediction was NaN.
    pub fn value(&self) -> Result<f64> {
        if self.kept == 0 {
            return Err(Error::Empty("cube-root RMSE: every sample was dropped"));
        }
        if self.sum.is_nan() {
            return Err(Error::Config("cube-root RMSE: NaN in the predictions".into()));
        }
        Ok((self.sum / (3 * self.kept) as f64).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_computed_with_exclusions() {
        let mut acc = CubeRootRmse::new(RmseConfig::default());
        let up = 1.0;
        // Kept: cube roots differ by (2 - 1) in every channel -> squared error 1 each.
        assert_eq!(acc.push([8.0; 3], [1.0; 3], up, up, false), SampleFate::Kept);
        // Kept: identical -> 0.
        assert_eq!(acc.push([0.027; 3], [0.027; 3], up, 0.5, false), SampleFate::Kept);
        // Dropped: theta_v = 85 degrees.
        let c85 = 85f32.to_radians().cos();
        assert_eq!(acc.push([100.0; 3], [0.0; 3], up, c85, false), SampleFate::Grazing);
        assert_eq!(acc.push([100.0; 3], [0.0; 3], c85, up, false), SampleFate::Grazing);
        assert_eq!(acc.push([100.0; 3], [0.0; 3], up, up, true), SampleFate::Saturated);
        assert_eq!(acc.push([100.0; 3], [-1.0, 0.0, 0.0], up, up, false), SampleFate::InvalidGt);
        // 79 degrees is kept; pred^(1/3) - gt^(1/3) = 3 - 0 in one channel: + 9.
        let c79 = 79f32.to_radians().cos();
        assert_eq!(acc.push([27.0, 0.0, 0.0], [0.0; 3], c79, c79, false), SampleFate::Kept);
        // (3 + 0 + 9) / 9 values.
        assert!((acc.value().unwrap() - (12.0f64 / 9.0).sqrt()).abs() < 1e-6);
        assert_eq!((acc.kept, acc.grazing, acc.saturated, acc.invalid), (3, 2, 1, 1));
    }

    #[test]
    fn empty_is_an_error() {
        assert!(CubeRootRmse::new(RmseConfig::default()).value().is_err());
    }
}
