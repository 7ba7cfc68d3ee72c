//! The `[eval]` table of a run configuration: what `eval` computes besides the image metrics,
//! with defaults that follow the run's profile.
//!
//! ```toml
//! [eval]
//! energy_estimator = "fast"   # fast | paper | off
//! energy_pairs = 1000         # (x, l) pairs drawn from the test records
//! energy_samples = 20000      # paper estimator: cosine samples per pair
//! reciprocity_pairs = 100000  # test records used for the reciprocity RMSE (0: off)
//! lpips_weights = "..."       # default: the process's (<data root>/lpips/alex_v0.1.lpipsw)
//! images = true               # write renders, FLIP maps and split figures
//! probe = true                # with images: the BRDF plots' probe (`probe.bin`)
//! ```
//!
//! A sweep turns off, in its ablation runs, what no table reads of them: the energy analysis
//! and the probe (the energy table and the BRDF figures show the default options only), and the
//! reciprocity RMSE outside the reciprocity ablation (`sweep::plan`).
//!
//! | key | quick | cpu | full |
//! | --- | ---: | ---: | ---: |
//! | `energy_estimator` | fast | fast | paper |
//! | `energy_pairs` | 1,000 | 5,000 | 50,000 (the paper's) |
//! | `energy_samples` | 20,000 | 20,000 | 20,000 (the paper's) |
//! | `reciprocity_pairs` | 100,000 | 100,000 | all |
//!
//! The fast estimator (importance-sampled randomized QMC, [`metrics::energy::Estimator::fast`])
//! gives the paper's answer with error bars 10 to 1000 times smaller at a fraction of the
//! evaluations; the full profile keeps the paper's protocol for fidelity.

use crate::train_config::Profile;
use crate::{Error, Result};
use metrics::energy::Estimator;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Which energy estimator `eval` runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EnergyEstimator {
    /// Importance-sampled randomized QMC with adaptive stopping.
    Fast,
    /// The paper's protocol: i.i.d. cosine-weighted samples.
    Paper,
    /// No energy analysis.
    Off,
}

/// The `[eval]` table as written: every key optional, defaults from the profile.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EvalConfig {
    /// Energy estimator.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_estimator: Option<EnergyEstimator>,
    /// (x, l) pairs of the energy analysis.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_pairs: Option<usize>,
    /// Samples per pair of the paper's estimator.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_samples: Option<usize>,
    /// Test records of the reciprocity RMSE (0: off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reciprocity_pairs: Option<usize>,
    /// LPIPS weights file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lpips_weights: Option<PathBuf>,
    /// Write images (renders, FLIP maps, split figures).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub images: Option<bool>,
    /// With images, evaluate the model on the BRDF plots' fixed directions (`probe.bin`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub probe: Option<bool>,
}

/// The resolved evaluation settings.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalSettings {
    /// Energy estimator, `None` when off.
    pub energy: Option<Estimator>,
    /// Name of the estimator for the results.
    pub energy_name: &'static str,
    /// (x, l) pairs of the energy analysis.
    pub energy_pairs: usize,
    /// Test records of the reciprocity RMSE (0: off).
    pub reciprocity_pairs: usize,
    /// LPIPS weights file.
    pub lpips_weights: PathBuf,
    /// Write images.
    pub images: bool,
    /// Write the BRDF plots' probe (only with images).
    pub probe: bool,
}

impl EvalConfig {
    /// The settings for a run of `profile`, with the LPIPS weights at `default_lpips` unless
    /// the table names them (the evaluating process's place, `experiments::places`).
    pub fn resolve(&self, profile: Profile, default_lpips: &Path) -> EvalSettings {
        let (estimator, pairs, recip) = match profile {
            Profile::Quick => (EnergyEstimator::Fast, 1_000, 100_000),
            Profile::Cpu => (EnergyEstimator::Fast, 5_000, 100_000),
            Profile::Full => (EnergyEstimator::Paper, 50_000, usize::MAX),
        };
        let kind = self.energy_estimator.unwrap_or(estimator);
        let samples = self.energy_samples.unwrap_or(20_000);
        let (energy, energy_name) = match kind {
            EnergyEstimator::Fast => (Some(Estimator::fast()), "fast"),
            EnergyEstimator::Paper => (Some(Estimator::MonteCarlo { samples }), "paper"),
            EnergyEstimator::Off => (None, "off"),
        };
        EvalSettings {
            energy,
            energy_name,
            energy_pairs: self.energy_pairs.unwrap_or(pairs),
            reciprocity_pairs: self.reciprocity_pairs.unwrap_or(recip),
            lpips_weights: self.lpips_weights.clone().unwrap_or_else(|| default_lpips.into()),
            images: self.images.unwrap_or(true),
            probe: self.images.unwrap_or(true) && self.probe.unwrap_or(true),
        }
    }

    /// Whether every key is left to the profile (the table is then not written).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks the ranges; errors name the key.
    pub fn validate(&self) -> Result<()> {
        if self.energy_pairs == Some(0) && self.energy_estimator != Some(EnergyEstimator::Off) {
            return Err(Error::config(
                "eval.energy_pairs",
                "must be >= 1 (or energy_estimator = \"off\")",
            ));
        }
        if self.energy_samples == Some(0) {
            return Err(Error::config("eval.energy_samples", "must be >= 1"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_pick_the_estimator_and_keys_override() {
        let here = Path::new("data/lpips/alex_v0.1.lpipsw");
        let q = EvalConfig::default().resolve(Profile::Quick, here);
        assert_eq!((q.energy_name, q.energy_pairs), ("fast", 1_000));
        assert_eq!(q.lpips_weights, here);
        let f = EvalConfig::default().resolve(Profile::Full, here);
        assert_eq!(f.energy, Some(Estimator::MonteCarlo { samples: 20_000 }));
        assert_eq!(f.energy_pairs, 50_000);
        let c = EvalConfig {
            energy_estimator: Some(EnergyEstimator::Off),
            images: Some(false),
            lpips_weights: Some("mine.lpipsw".into()),
            ..Default::default()
        };
        let r = c.resolve(Profile::Quick, here);
        assert!(r.energy.is_none() && !r.images && !r.probe);
        assert!(q.probe, "the probe follows the images by default");
        let no_probe = EvalConfig { probe: Some(false), ..Default::default() };
        let n = no_probe.resolve(Profile::Quick, here);
        assert!(n.images && !n.probe);
        assert_eq!(r.lpips_weights, Path::new("mine.lpipsw"));
        let bad = EvalConfig { energy_pairs: Some(0), ..Default::default() };
        assert!(bad.validate().unwrap_err().to_string().contains("eval.energy_pairs"));
    }
}
