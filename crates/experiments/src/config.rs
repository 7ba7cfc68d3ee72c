//! The run configuration (TOML): model, spatial features, training schedule and seed.
//!
//! Every table rejects unknown keys (`deny_unknown_fields`), so a misspelt key is an error that
//! names it; [`RunConfig::validate`] checks ranges and names the offending key.
//!
//! ```toml
//! seed = 1
//! profile = "quick"          # quick | cpu | full: defaults for [train]
//!
//! [model]                    # brdf_neural::ModelConfig
//! kind = "single_mlp"
//!
//! [features]
//! spatial = "lbo"            # lbo | position
//! [features.lbo]
//! k_max = 512                # selection: 0..first, then `blocks` blocks of `block_len`
//!
//! [train]
//! iterations = 2000
//! learning_rate = 5e-4
//! lr_final = 5e-5
//! schedule = "exponential"   # constant | exponential | cosine
//! ```
//!
//! # Training defaults (project decisions: the paper gives no learning rate, schedule or
//! iteration count)
//!
//! | key | quick | cpu | full |
//! | --- | ---: | ---: | ---: |
//! | `iterations` | 2,000 | 20,000 | 100,000 |
//! | `batch_size` | 32,768 | 32,768 | 32,768 |
//! | `learning_rate` | 5e-4 | 5e-4 | 5e-4 |
//! | `lr_final` | 5e-5 | 5e-5 | 5e-6 |
//! | `schedule` | exponential | exponential | exponential |
//! | `warmup_steps` | 100 | 200 | 500 |
//!
//! Why 5e-4: on a MERL-derived scene (spot, blue-acrylic) Single MLP with 5e-3 or 1e-3
//! collapsed within 40 steps to f = 0 (the loss sat at the zero-prediction baseline that
//! `metrics.json` reports): an untrained model renders far too bright, Adam's coherent steps
//! push every output's softplus deep into its flat region and its gradients vanish. 5e-4 with
//! a short warm-up fitted the same scene to 1/27 of that baseline in 300 steps.
//! | `checkpoint_every` | 500 | 2,000 | 5,000 |
//! | `log_every` | 10 | 50 | 100 |
//! | `diffuse_reg_weight` | 5e-4 | 5e-4 | 5e-4 |
//! | `specular_reg_weight` | 5e-4 | 5e-4 | 5e-4 |
//!
//! The regulariser weights are the paper's (enhanced split, spec 4.5) and only apply to the
//! enhanced additive models.

use crate::{Error, Result};
use brdf_neural::ModelConfig;
use mesh_encoding::LboEncodingConfig;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A run's full configuration, as written to `config.toml` in the run directory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Seed of the model initialisation and of the batches (default 0).
    #[serde(default)]
    pub seed: u64,
    /// Scene directory (set by `fit --scene` when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<PathBuf>,
    /// The model (default: Single MLP). `spatial_dim` is set from the features.
    #[serde(default)]
    pub model: ModelConfig,
    /// Spatial features.
    #[serde(default)]
    pub features: FeatureConfig,
    /// Training schedule.
    pub train: TrainConfig,
    /// What `eval` computes (defaults from the profile; see [`crate::eval::settings`]).
    #[serde(default, skip_serializing_if = "crate::eval::EvalConfig::is_default")]
    pub eval: crate::eval::EvalConfig,
}

/// Which defaults a run starts from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// A few minutes on a laptop.
    #[default]
    Quick,
    /// A long CPU run.
    Cpu,
    /// Full length (GPU).
    Full,
}

/// Spatial input of the networks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SpatialKind {
    /// The LBO eigenfunction encoding of the mesh (the paper's).
    #[default]
    Lbo,
    /// The hit position xyz (3 values; tests and quick checks, no eigensolve).
    Position,
}

/// Spatial features: kind, LBO selection and eigenpair cache.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FeatureConfig {
    /// `lbo` (default) or `position`.
    pub spatial: SpatialKind,
    /// LBO index selection.
    pub lbo: LboSelection,
    /// Eigenpair cache directory (default: `cache/` beside the run directory).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cache_dir: Option<PathBuf>,
}

/// The LBO index selection: `0..first`, then `blocks` blocks of `block_len` spread up to
/// `k_max` (spec 5.2; defaults 64, 6, 16, 512: 160 features).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LboSelection {
    /// Last eigenfunction index + 1 (default 512).
    pub k_max: usize,
    /// Leading contiguous indices (default 64).
    pub first: usize,
    /// Number of blocks (default 6).
    pub blocks: usize,
    /// Length of each block (default 16).
    pub block_len: usize,
    /// Eigensolver basis limit as a multiple of the pairs wanted (default: the solver's, 6);
    /// raise it when the solver reports that it did not converge.
    pub max_basis_factor: f64,
}

impl Default for LboSelection {
    fn default() -> Self {
        Self {
            k_max: 512,
            first: 64,
            blocks: 6,
            block_len: 16,
            max_basis_factor: mesh_encoding::EigenSettings::default().max_basis_factor,
        }
    }
}

impl LboSelection {
    /// The encoding configuration (validated first).
    pub fn encoding(&self) -> Result<LboEncodingConfig> {
        self.validate()?;
        Ok(LboEncodingConfig {
            selection: mesh_encoding::lbo::encoding::block_selection(
                self.first,
                self.blocks,
                self.block_len,
                self.k_max,
            ),
            ..LboEncodingConfig::default()
        })
    }

    /// Feature count.
    pub fn dim(&self) -> usize {
        self.first + self.blocks * self.block_len
    }

    fn validate(&self) -> Result<()> {
        if self.dim() == 0 {
            return Err(Error::config("features.lbo", "selects no eigenfunction"));
        }
        if !(self.max_basis_factor.is_finite() && self.max_basis_factor >= 1.0) {
            return Err(Error::config("features.lbo.max_basis_factor", "must be >= 1"));
        }
        if self.first > self.k_max {
            return Err(Error::config("features.lbo.first", "exceeds features.lbo.k_max"));
        }
        if self.blocks > 0 && self.k_max < self.first + self.block_len {
            return Err(Error::config(
                "features.lbo.k_max",
                format!("must be >= first + block_len = {}", self.first + self.block_len),
            ));
        }
        Ok(())
    }
}

/// Learning-rate schedule from `learning_rate` at step 0 to `lr_final` at the last step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Schedule {
    /// `learning_rate` throughout.
    Constant,
    /// Geometric decay.
    Exponential,
    /// Cosine annealing.
    Cosine,
}

/// The training section as written (every key optional; defaults from `profile`).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTrain {
    profile: Option<Profile>,
    iterations: Option<u64>,
    batch_size: Option<usize>,
    learning_rate: Option<f64>,
    lr_final: Option<f64>,
    schedule: Option<Schedule>,
    warmup_steps: Option<u64>,
    checkpoint_every: Option<u64>,
    log_every: Option<u64>,
    diffuse_reg_weight: Option<f64>,
    specular_reg_weight: Option<f64>,
}

/// The training schedule, resolved against the profile's defaults (deserialised through a
/// table of optional keys, unknown keys rejected).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrainConfig {
    /// The profile the defaults came from.
    pub profile: Profile,
    /// Optimizer steps.
    pub iterations: u64,
    /// Samples per batch (2^15 in the paper).
    pub batch_size: usize,
    /// Learning rate at step 0 (Adam).
    pub learning_rate: f64,
    /// Learning rate at the last step (ignored by `constant`).
    pub lr_final: f64,
    /// Schedule between the two.
    pub schedule: Schedule,
    /// Linear warm-up: the rate is scaled by (step + 1) / warmup_steps for the first steps
    /// (0: none). Without it, the large early gradients (an untrained model renders far too
    /// bright) make Adam overshoot into the region where the softplus outputs are ~0 and
    /// their gradients vanish.
    pub warmup_steps: u64,
    /// Steps between checkpoints.
    pub checkpoint_every: u64,
    /// Steps between rows of the training curve and progress updates.
    pub log_every: u64,
    /// Weight of the enhanced split's diffuse regulariser.
    pub diffuse_reg_weight: f64,
    /// Weight of the enhanced split's specular regulariser.
    pub specular_reg_weight: f64,
}

impl TrainConfig {
    /// The defaults of `profile` (see the module table).
    pub fn profile(profile: Profile) -> Self {
        let (iterations, lr_final, warmup_steps, checkpoint_every, log_every) = match profile {
            Profile::Quick => (2_000, 5e-5, 100, 500, 10),
            Profile::Cpu => (20_000, 5e-5, 200, 2_000, 50),
            Profile::Full => (100_000, 5e-6, 500, 5_000, 100),
        };
        Self {
            profile,
            iterations,
            batch_size: 1 << 15,
            learning_rate: 5e-4,
            lr_final,
            schedule: Schedule::Exponential,
            warmup_steps,
            checkpoint_every,
            log_every,
            diffuse_reg_weight: 5e-4,
            specular_reg_weight: 5e-4,
        }
    }

    /// The learning rate at `step` (0-based) of `iterations`.
    pub fn lr_at(&self, step: u64) -> f64 {
        let t = if self.iterations <= 1 {
            0.0
        } else {
            (step as f64 / (self.iterations - 1) as f64).clamp(0.0, 1.0)
        };
        let (a, b) = (self.learning_rate, self.lr_final);
        let warmup = if step < self.warmup_steps {
            (step + 1) as f64 / self.warmup_steps as f64
        } else {
            1.0
        };
        warmup
            * match self.schedule {
                Schedule::Constant => a,
                Schedule::Exponential => a * (b / a).powf(t),
                Schedule::Cosine => b + 0.5 * (a - b) * (1.0 + (std::f64::consts::PI * t).cos()),
            }
    }

    fn validate(&self) -> Result<()> {
        let pos = |key: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::config(key, format!("must be finite and > 0, got {v}")))
            }
        };
        if self.iterations == 0 {
            return Err(Error::config("train.iterations", "must be >= 1"));
        }
        if self.batch_size == 0 {
            return Err(Error::config("train.batch_size", "must be >= 1"));
        }
        pos("train.learning_rate", self.learning_rate)?;
        pos("train.lr_final", self.lr_final)?;
        if self.checkpoint_every == 0 {
            return Err(Error::config("train.checkpoint_every", "must be >= 1"));
        }
        if self.log_every == 0 {
            return Err(Error::config("train.log_every", "must be >= 1"));
        }
        for (k, v) in [
            ("train.diffuse_reg_weight", self.diffuse_reg_weight),
            ("train.specular_reg_weight", self.specular_reg_weight),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::config(k, format!("must be finite and >= 0, got {v}")));
            }
        }
        Ok(())
    }
}

impl<'de> Deserialize<'de> for TrainConfig {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let r = RawTrain::deserialize(d)?;
        let p = TrainConfig::profile(r.profile.unwrap_or_default());
        Ok(TrainConfig {
            profile: p.profile,
            iterations: r.iterations.unwrap_or(p.iterations),
            batch_size: r.batch_size.unwrap_or(p.batch_size),
            learning_rate: r.learning_rate.unwrap_or(p.learning_rate),
            lr_final: r.lr_final.unwrap_or(p.lr_final),
            schedule: r.schedule.unwrap_or(p.schedule),
            warmup_steps: r.warmup_steps.unwrap_or(p.warmup_steps),
            checkpoint_every: r.checkpoint_every.unwrap_or(p.checkpoint_every),
            log_every: r.log_every.unwrap_or(p.log_every),
            diffuse_reg_weight: r.diffuse_reg_weight.unwrap_or(p.diffuse_reg_weight),
            specular_reg_weight: r.specular_reg_weight.unwrap_or(p.specular_reg_weight),
        })
    }
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self::profile(Profile::Quick)
    }
}

impl RunConfig {
    /// Parses TOML text; `origin` names the source in errors. A missing `[train]` table takes
    /// the quick profile. The model's `spatial_dim` is set from the features.
    pub fn from_toml(text: &str, origin: &Path) -> Result<Self> {
        let mut table: toml::Table = toml::from_str(text)
            .map_err(|e| Error::ConfigParse { path: origin.into(), message: e.to_string() })?;
        table.entry("train").or_insert_with(|| toml::Value::Table(Default::default()));
        let mut config: RunConfig = table.try_into().map_err(|e: toml::de::Error| {
            Error::ConfigParse { path: origin.into(), message: e.to_string() }
        })?;
        config.model.spatial_dim = config.spatial_dim();
        config.validate()?;
        Ok(config)
    }

    /// Reads and parses a TOML file.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Self::from_toml(&text, path)
    }

    /// The resolved configuration as TOML.
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::ConfigParse {
            path: "<resolved config>".into(),
            message: e.to_string(),
        })
    }

    /// Width of the spatial features.
    pub fn spatial_dim(&self) -> usize {
        match self.features.spatial {
            SpatialKind::Lbo => self.features.lbo.dim(),
            SpatialKind::Position => 3,
        }
    }

    /// Checks every range; errors name the key.
    pub fn validate(&self) -> Result<()> {
        self.train.validate()?;
        self.eval.validate()?;
        if self.features.spatial == SpatialKind::Lbo {
            self.features.lbo.validate()?;
        }
        if self.model.spatial_dim != self.spatial_dim() {
            return Err(Error::config(
                "model.spatial_dim",
                format!("is {}, the features give {}", self.model.spatial_dim, self.spatial_dim()),
            ));
        }
        self.model.validate().map_err(|e| Error::config("model", e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<RunConfig> {
        RunConfig::from_toml(text, Path::new("test.toml"))
    }

    #[test]
    fn defaults_follow_the_profile_and_round_trip() {
        let c = parse("[train]\nprofile = \"cpu\"\niterations = 7\n").unwrap();
        assert_eq!(c.train.iterations, 7);
        assert_eq!(c.train.checkpoint_every, 2_000);
        assert_eq!(c.model.spatial_dim, 160);
        let again = parse(&c.to_toml().unwrap()).unwrap();
        assert_eq!(again, c);
        assert_eq!(parse("").unwrap().train, TrainConfig::default());
    }

    #[test]
    fn unknown_keys_and_bad_ranges_are_named() {
        let e = parse("[train]\nlearnig_rate = 1.0\n").unwrap_err().to_string();
        assert!(e.contains("learnig_rate"), "{e}");
        let e = parse("[model]\nwidht = 3\n").unwrap_err().to_string();
        assert!(e.contains("widht"), "{e}");
        let e = parse("[features]\nspatial = \"xyz\"\n").unwrap_err().to_string();
        assert!(e.contains("xyz"), "{e}");
        let e = parse("[train]\nlearning_rate = -1.0\n").unwrap_err().to_string();
        assert!(e.contains("train.learning_rate"), "{e}");
        let e = parse("[features.lbo]\nk_max = 10\n").unwrap_err().to_string();
        assert!(e.contains("features.lbo"), "{e}");
    }

    #[test]
    fn schedules_hit_both_ends() {
        for schedule in [Schedule::Exponential, Schedule::Cosine] {
            let t =
                TrainConfig { iterations: 11, schedule, warmup_steps: 0, ..TrainConfig::default() };
            assert!((t.lr_at(0) - 5e-4).abs() < 1e-12);
            assert!((t.lr_at(10) - 5e-5).abs() < 1e-12);
            assert!(t.lr_at(5) < 5e-4 && t.lr_at(5) > 5e-5);
        }
        let t = TrainConfig { warmup_steps: 4, schedule: Schedule::Constant, ..Default::default() };
        assert!((t.lr_at(0) - 5e-4 / 4.0).abs() < 1e-12 && t.lr_at(4) == 5e-4);
    }
}
