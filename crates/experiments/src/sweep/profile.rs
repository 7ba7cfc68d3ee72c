//! Sweep profiles: which scenes, models, ablations and training budgets a reproduction runs.
//!
//! A profile is a TOML file. The built-in ones live in `crates/experiments/profiles/` and are
//! compiled in (`default`, `smoke`, `quick`, `runtime`, `full`); `--profile` takes one of those names or
//! a path to a file of the same shape:
//!
//! ```toml
//! name = "quick"
//! description = "All 9 models of Table 1 on 3 MERL-derived scenes, under 20 min on 2 cores"
//!
//! [data]
//! meshes = ["embedded:spot"]      # embedded:NAME (shipped), data:PATH (under the data root) or a path
//! materials = ["blue-acrylic", "gold-metallic-paint", "green-plastic"]   # catalogue names
//! pairing = "product"             # product: every mesh x every material; zip: pairwise
//! size = 128                      # image width = height
//! views = 20                      # half train, half test
//! lights = 42                     # per view; 30/42 of them train
//!
//! [run]                           # a run configuration (see `experiments::config`), shared
//! seed = 1
//! [run.train]
//! iterations = 1000
//!
//! [sweep]
//! models = ["all"]                # Table 1 rows (paper names or config names)
//! ablations = ["nol", "reciprocity", "angles", "nerfactor"]
//! runtime_curve = true            # snapshots of the Table 1 runs on one scene, each scored
//! runtime_scene = 0               # which scene the curve runs on
//! ```
//!
//! Every key is checked: unknown keys are errors that name the key and the file.

use crate::{Error, Result};
use brdf_neural::ModelKind;
use brdf_neural::precision::MatmulPrecision;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The built-in profiles: (name, TOML text).
pub const BUILT_IN: [(&str, &str); 5] = [
    ("default", include_str!("../../profiles/default.toml")),
    ("smoke", include_str!("../../profiles/smoke.toml")),
    ("quick", include_str!("../../profiles/quick.toml")),
    ("runtime", include_str!("../../profiles/runtime.toml")),
    ("full", include_str!("../../profiles/full.toml")),
];

/// The profile `reproduce-tables` runs without `--profile`: Table 1 with every run trained to
/// its plateau on three scenes of the shipped Spot mesh (no download), and the run-time curve
/// of the first scene.
pub const DEFAULT_PROFILE: &str = "default";

/// The scenes of a profile.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataSection {
    /// Mesh sources: `embedded:NAME`, `data:PATH` (under the data root) or a file path.
    pub meshes: Vec<String>,
    /// Catalogue material names.
    pub materials: Vec<String>,
    /// `product` (default) or `zip`.
    #[serde(default)]
    pub pairing: Pairing,
    /// Image width and height.
    pub size: u32,
    /// Views per scene (half train, half test).
    pub views: usize,
    /// Lights per view.
    pub lights: usize,
    /// Seed of cameras, lights, splits and noise (default 1).
    #[serde(default = "one")]
    pub seed: u64,
}

fn one() -> u64 {
    1
}

/// How meshes and materials combine into scenes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Pairing {
    /// Every mesh with every material.
    #[default]
    Product,
    /// Mesh i with material i (cycling the shorter list).
    Zip,
}

/// What runs on the scenes.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SweepSection {
    /// Table 1 models (`all` for the nine).
    pub models: Vec<String>,
    /// Ablation groups: `nol`, `reciprocity`, `angles`, `nerfactor`.
    pub ablations: Vec<String>,
    /// Record the run-time curve: the Table 1 runs on `runtime_scene` keep weight snapshots
    /// (`train.snapshots`) and `eval` scores each of them (all nine models when `models` is
    /// empty).
    pub runtime_curve: bool,
    /// Index of the scene the curve runs on.
    pub runtime_scene: usize,
}

/// A parsed profile.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepProfile {
    /// Its name (tables print it).
    pub name: String,
    /// One line for the summary.
    pub description: String,
    /// The scenes.
    pub data: DataSection,
    /// The shared run configuration, as TOML text (a valid `RunConfig` fragment).
    pub run: String,
    /// What runs.
    pub sweep: SweepSection,
    /// Where it came from (a built-in name or a path), for errors.
    pub origin: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawProfile {
    name: String,
    #[serde(default)]
    description: String,
    data: DataSection,
    #[serde(default)]
    run: toml::Table,
    #[serde(default)]
    sweep: SweepSection,
}

/// An ablation group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ablation {
    /// The NOL ablation of the purely neural models.
    Nol,
    /// Random swap and mapping, for the purely neural models.
    Reciprocity,
    /// The view-light parametrization, for the purely neural models.
    Angles,
    /// Albedo clamp and scalar specular, for the additive models.
    Nerfactor,
}

impl SweepProfile {
    /// A built-in profile by name, or the file at `name_or_path`.
    pub fn load(name_or_path: &str) -> Result<Self> {
        if let Some((_, text)) = BUILT_IN.iter().find(|(n, _)| *n == name_or_path) {
            return Self::parse(text, &format!("built-in profile {name_or_path}"));
        }
        let path = Path::new(name_or_path);
        if !path.is_file() {
            let names: Vec<&str> = BUILT_IN.iter().map(|(n, _)| *n).collect();
            return Err(Error::config(
                "profile",
                format!(
                    "{name_or_path} is neither a built-in profile ({}) nor a file",
                    names.join(", ")
                ),
            ));
        }
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Parses profile text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let raw: RawProfile = toml::from_str(text)
            .map_err(|e| Error::ConfigParse { path: origin.into(), message: e.to_string() })?;
        let run = toml::to_string(&raw.run)
            .map_err(|e| Error::ConfigParse { path: origin.into(), message: e.to_string() })?;
        let p = SweepProfile {
            name: raw.name,
            description: raw.description,
            data: raw.data,
            run,
            sweep: raw.sweep,
            origin: origin.into(),
        };
        p.validate().map_err(|e| e.in_file(origin))?;
        Ok(p)
    }

    /// Sets `train.matmul_precision` in the run configuration every run shares
    /// (`reproduce-tables --matmul-precision`). A bf16 run gets its own run id, so a sweep
    /// never mixes precisions in one run directory.
    pub fn with_matmul_precision(mut self, precision: MatmulPrecision) -> Result<Self> {
        let parse = |e: String| Error::ConfigParse { path: self.origin.clone().into(), message: e };
        let mut run: toml::Table = toml::from_str(&self.run).map_err(|e| parse(e.to_string()))?;
        let train = run.entry("train").or_insert_with(|| toml::Value::Table(Default::default()));
        let Some(train) = train.as_table_mut() else {
            return Err(Error::config("run.train", format!("is not a table (in {})", self.origin)));
        };
        train.insert("matmul_precision".into(), toml::Value::String(precision.name().into()));
        self.run = toml::to_string(&run).map_err(|e| parse(e.to_string()))?;
        self.validate()?;
        Ok(self)
    }

    fn validate(&self) -> Result<()> {
        let bad =
            |key: &str, why: String| Err(Error::config(key, format!("{why} (in {})", self.origin)));
        if self.data.meshes.is_empty() {
            return bad("data.meshes", "is empty".into());
        }
        if self.data.materials.is_empty() {
            return bad("data.materials", "is empty".into());
        }
        for m in &self.data.materials {
            if dataset_merl::catalogue::entry(m).is_err() {
                return bad("data.materials", format!("{m} is not a catalogue material"));
            }
        }
        if self.data.views < 2 || self.data.lights < 2 || self.data.size < 8 {
            return bad("data", "needs views >= 2, lights >= 2, size >= 8".into());
        }
        self.models()?;
        self.ablations()?;
        if self.sweep.runtime_curve && self.sweep.runtime_scene >= self.scene_count() {
            return bad(
                "sweep.runtime_scene",
                format!("{} but there are {} scenes", self.sweep.runtime_scene, self.scene_count()),
            );
        }
        crate::RunConfig::from_toml(&self.run, Path::new(&format!("{} [run]", self.origin)))?;
        Ok(())
    }

    /// Number of scenes.
    pub fn scene_count(&self) -> usize {
        let (a, b) = (self.data.meshes.len(), self.data.materials.len());
        match self.data.pairing {
            Pairing::Product => a * b,
            Pairing::Zip => a.max(b),
        }
    }

    /// (mesh source, material) of every scene, in order.
    pub fn scenes(&self) -> Vec<(String, String)> {
        let (m, t) = (&self.data.meshes, &self.data.materials);
        match self.data.pairing {
            Pairing::Product => {
                m.iter().flat_map(|a| t.iter().map(move |b| (a.clone(), b.clone()))).collect()
            }
            Pairing::Zip => (0..self.scene_count())
                .map(|i| (m[i % m.len()].clone(), t[i % t.len()].clone()))
                .collect(),
        }
    }

    /// The Table 1 models.
    pub fn models(&self) -> Result<Vec<ModelKind>> {
        let mut out = Vec::new();
        for name in &self.sweep.models {
            if name == "all" {
                out.extend(ModelKind::ALL);
            } else {
                out.push(ModelKind::from_name(name).map_err(|e| {
                    Error::config("sweep.models", format!("{e} (in {})", self.origin))
                })?);
            }
        }
        out.dedup();
        Ok(out)
    }

    /// The ablation groups.
    pub fn ablations(&self) -> Result<Vec<Ablation>> {
        self.sweep
            .ablations
            .iter()
            .map(|a| match a.as_str() {
                "nol" => Ok(Ablation::Nol),
                "reciprocity" => Ok(Ablation::Reciprocity),
                "angles" => Ok(Ablation::Angles),
                "nerfactor" => Ok(Ablation::Nerfactor),
                other => Err(Error::config(
                    "sweep.ablations",
                    format!(
                        "unknown group {other:?} (nol, reciprocity, angles, nerfactor; in {})",
                        self.origin
                    ),
                )),
            })
            .collect()
    }
}

/// Resolves a mesh source: `embedded:NAME` -> the mesh shipped in `data-manifests/embedded/`,
/// `data:PATH` -> `<data root>/PATH`, anything else a path.
pub fn resolve_mesh(source: &str, data_root: &Path) -> Result<PathBuf> {
    let path = if let Some(name) = source.strip_prefix("embedded:") {
        embedded_dir().join(name).join(format!("{name}.obj"))
    } else if let Some(rel) = source.strip_prefix("data:") {
        data_root.join(rel)
    } else {
        PathBuf::from(source)
    };
    if !path.is_file() {
        let hint = if source.starts_with("data:") {
            " (fetch it with `cargo xtask fetch-data meshes`, or set NEURAL_BRDF_DATA)"
        } else {
            ""
        };
        return Err(Error::format(&path, format!("mesh {source} not found{hint}")));
    }
    Ok(path)
}

/// The directory of the meshes shipped with the repository.
pub fn embedded_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data-manifests/embedded")
}

/// A short name of a mesh source (its file stem).
pub fn mesh_name(source: &str) -> String {
    let s = source.rsplit(':').next().unwrap_or(source);
    Path::new(s).file_stem().and_then(|n| n.to_str()).unwrap_or(s).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_profiles_parse() {
        for (name, _) in BUILT_IN {
            let p = SweepProfile::load(name).unwrap();
            assert_eq!(p.name, name);
            assert!(p.scene_count() >= 1);
            assert!(!p.models().unwrap().is_empty() || p.sweep.runtime_curve);
        }
        for name in ["default", "quick"] {
            let p = SweepProfile::load(name).unwrap();
            assert_eq!(p.models().unwrap().len(), 9);
            assert_eq!(p.scene_count(), 3);
        }
    }

    #[test]
    fn the_benches_one_scene_profile_parses_with_its_eval_table() {
        let path =
            concat!(env!("CARGO_MANIFEST_DIR"), "/../../benches/profiles/paper_one_scene.toml");
        let p = SweepProfile::load(path).unwrap();
        assert_eq!(p.scene_count(), 1);
        assert_eq!(p.models().unwrap().len(), 9);
        let config = crate::RunConfig::from_toml(&p.run, Path::new(path)).unwrap();
        assert_eq!(config.eval.energy_estimator, Some(crate::eval::EnergyEstimator::Fast));
    }

    #[test]
    fn bad_keys_are_named() {
        let text = BUILT_IN[0].1.replace("[sweep]", "[sweep]\nmodles = []");
        let e = SweepProfile::parse(&text, "x.toml").unwrap_err().to_string();
        assert!(e.contains("modles") && e.contains("x.toml"), "{e}");
        let text = BUILT_IN[0].1.replace("[run.train]", "[run.train]\nlearnig_rate = 1.0");
        let e = SweepProfile::parse(&text, "y.toml").unwrap_err().to_string();
        assert!(e.contains("learnig_rate"), "{e}");
        let e = SweepProfile::load("nonexistent-profile").unwrap_err().to_string();
        assert!(e.contains("built-in"), "{e}");
    }

    #[test]
    fn mesh_sources() {
        assert_eq!(mesh_name("embedded:spot"), "spot");
        assert_eq!(mesh_name("data:meshes/stanford-bunny.obj"), "stanford-bunny");
        assert!(resolve_mesh("embedded:spot", Path::new(".")).is_ok());
        let e = resolve_mesh("data:meshes/nope.obj", Path::new("/nonexistent")).unwrap_err();
        assert!(e.to_string().contains("fetch-data"), "{e}");
    }

    #[test]
    fn matmul_precision_reaches_every_run_config() {
        let p = SweepProfile::load("smoke").unwrap();
        let ids = |p: &SweepProfile| -> Vec<String> {
            let runs = crate::sweep::plan::runs(p).unwrap();
            runs.iter().map(|r| crate::sweep::plan::run_id(&r.config, "scene").unwrap()).collect()
        };
        let before = ids(&p);
        let bf16 = p.clone().with_matmul_precision(MatmulPrecision::Bf16).unwrap();
        let config = crate::RunConfig::from_toml(&bf16.run, Path::new("test")).unwrap();
        assert_eq!(config.train.matmul_precision, MatmulPrecision::Bf16);
        let after = ids(&bf16);
        assert_eq!(before.len(), after.len());
        assert!(before.iter().zip(&after).all(|(a, b)| a != b), "bf16 runs need their own ids");
        // f32 is the default: setting it explicitly changes no run id.
        assert_eq!(ids(&p.with_matmul_precision(MatmulPrecision::F32).unwrap()), before);
    }
}
