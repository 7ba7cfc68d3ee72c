//! The run configuration (TOML): model, spatial features, training schedule and seed.
//!
//! Every table rejects unknown keys (`deny_unknown_fields`), so a misspelt key is an error that
//! names it; [`RunConfig::validate`] checks ranges and names the offending key.
//!
//! ```toml
//! seed = 1
//! profile = "quick"          # quick | cpu | full: defaults for [train]
//!
//! [model]                    # model_spec::ModelConfig
//! kind = "single_mlp"
//!
//! [features]
//! spatial = "lbo"            # lbo | position | uniform
//! [features.lbo]
//! k_max = 512                # selection: 0..first, then `blocks` blocks of `block_len`
//!
//! [train]                    # see run_format::train_config
//! learning_rate = 1e-3
//! schedule = "plateau"       # plateau | exponential | cosine | constant
//! ```
//!
//! The `[train]` table and its profile defaults are documented in [`crate::train_config`].

pub use crate::train_config::{OutputInit, Profile, Schedule, TrainConfig};
use crate::{Error, Result};
use model_spec::ModelConfig;
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
    /// What `eval` computes (defaults from the profile; see [`crate::eval_config`]).
    #[serde(default, skip_serializing_if = "crate::eval_config::EvalConfig::is_default")]
    pub eval: crate::eval_config::EvalConfig,
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
    /// One constant feature (1.0) at every point: a spatially uniform material, one parameter
    /// set for the whole object (a homogeneous capture; exports without textures).
    Uniform,
}

/// Spatial features: kind, LBO selection and eigenpair cache.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FeatureConfig {
    /// `lbo` (default), `position` or `uniform`.
    pub spatial: SpatialKind,
    /// LBO index selection.
    pub lbo: LboSelection,
    /// Cache directory (default: the sweep's `cache/` for a run of a sweep, else `cache/` beside
    /// the run directory; [`crate::run_dir`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cache_dir: Option<PathBuf>,
}

/// The LBO index selection, as data: `0..first`, then `blocks` blocks of `block_len` spread up
/// to `k_max` (spec 5.2; defaults 64, 6, 16, 512: 160 features). The indices it stands for
/// are mesh-encoding's `block_selection`, which the data step calls.
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

/// The eigensolver's default basis limit (mesh-encoding's `EigenSettings::max_basis_factor`;
/// experiments' tests hold the two equal).
pub const DEFAULT_MAX_BASIS_FACTOR: f64 = 6.0;

impl Default for LboSelection {
    fn default() -> Self {
        Self {
            k_max: 512,
            first: 64,
            blocks: 6,
            block_len: 16,
            max_basis_factor: DEFAULT_MAX_BASIS_FACTOR,
        }
    }
}

impl LboSelection {
    /// Feature count.
    pub fn dim(&self) -> usize {
        self.first + self.blocks * self.block_len
    }

    /// Checks the selection; errors name the key.
    pub fn validate(&self) -> Result<()> {
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
        config.validate().map_err(|e| e.in_file(origin))?;
        Ok(config)
    }

    /// Reads and parses a TOML file.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Self::from_toml(&text, path)
    }

    /// Dotted keys whose values differ between this configuration and `other`.
    pub fn differing_keys(&self, other: &RunConfig) -> Vec<String> {
        fn walk(prefix: &str, a: &toml::Value, b: &toml::Value, out: &mut Vec<String>) {
            match (a, b) {
                (toml::Value::Table(x), toml::Value::Table(y)) => {
                    let keys: std::collections::BTreeSet<&String> =
                        x.keys().chain(y.keys()).collect();
                    for k in keys {
                        let key =
                            if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                        match (x.get(k), y.get(k)) {
                            (Some(p), Some(q)) => walk(&key, p, q, out),
                            _ => out.push(key),
                        }
                    }
                }
                _ if a != b => out.push(prefix.to_string()),
                _ => {}
            }
        }
        let table = |c: &RunConfig| toml::Value::try_from(c).unwrap_or(toml::Value::Boolean(false));
        let mut out = Vec::new();
        walk("", &table(self), &table(other), &mut out);
        out
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
            SpatialKind::Uniform => 1,
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
}
