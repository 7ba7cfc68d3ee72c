//! Sweep profiles: which scenes, models, ablations and training budgets a reproduction runs.
//!
//! A profile is a TOML file. The built-in ones live in `crates/sweep/profiles/` and are
//! compiled in (`default`, `smoke`, `quick`, `runtime`, `full`, `real`, `figure`; `all-tables` is
//! an alias of `default`);
//! `--profile` takes one of those names or a path to a file of the same shape:
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
//! captures = ["diligent:ball"]    # real captures, imported as scenes (see [`CaptureSource`])
//! optional_captures = ["diligent-mv:bear"]   # the same, used when present under the data root
//!
//! [run]                           # a run configuration (see `run_format::config`), shared
//! seed = 1
//! [run.train]
//! iterations = 1000
//!
//! [sweep]
//! models = ["all"]                # Table 1 rows (paper names or config names)
//! ablations = ["nol", "reciprocity", "angles", "nerfactor"]
//! ablation_models = "paper"       # the paper's 14 rows a scene; "all": every neural model (28)
//! runtime_curve = true            # snapshots of the Table 1 runs on one scene, each scored
//! runtime_scene = 0               # which scene the curve runs on
//! ```
//!
//! Every key is checked: unknown keys are errors that name the key and the file.

pub use super::sources::{CaptureSource, mesh_name, resolve_mesh};
use brdf_neural::ModelKind;
use brdf_neural::precision::MatmulPrecision;
use experiments::{Error, Result};
use run_format::RunConfig;
use serde::Deserialize;
use std::path::Path;

/// The built-in profiles: (name, TOML text).
pub const BUILT_IN: [(&str, &str); 7] = [
    ("default", include_str!("../profiles/default.toml")),
    ("smoke", include_str!("../profiles/smoke.toml")),
    ("quick", include_str!("../profiles/quick.toml")),
    ("runtime", include_str!("../profiles/runtime.toml")),
    ("full", include_str!("../profiles/full.toml")),
    ("real", include_str!("../profiles/real.toml")),
    ("figure", include_str!("../profiles/figure.toml")),
];

/// Other names of built-in profiles: (alias, profile). `all-tables` was the every-table
/// profile before the default became it.
pub const ALIASES: [(&str, &str); 1] = [("all-tables", "default")];

/// The profile `reproduce-tables` runs without `--profile`: every table of the paper with every
/// run trained to its plateau, on three scenes of the shipped Spot mesh (no download) and on
/// the DiLiGenT ball when it is under the data root.
pub const DEFAULT_PROFILE: &str = "default";

/// The scenes of a profile: semi-synthetic ones (meshes x materials) and real captures.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataSection {
    /// Mesh sources: `embedded:NAME`, `data:PATH` (under the data root) or a file path.
    #[serde(default)]
    pub meshes: Vec<String>,
    /// Catalogue material names.
    #[serde(default)]
    pub materials: Vec<String>,
    /// `product` (default) or `zip`.
    #[serde(default)]
    pub pairing: Pairing,
    /// Image width and height of the semi-synthetic scenes.
    #[serde(default)]
    pub size: u32,
    /// Views per semi-synthetic scene (half train, half test).
    #[serde(default)]
    pub views: usize,
    /// Lights per view of the semi-synthetic scenes.
    #[serde(default)]
    pub lights: usize,
    /// Real captures, imported as scenes ([`CaptureSource`]); a missing one is an error that
    /// says where to get it.
    #[serde(default)]
    pub captures: Vec<String>,
    /// Real captures used when present under the data root, skipped with a note otherwise.
    #[serde(default)]
    pub optional_captures: Vec<String>,
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
    /// Which models the ablations run on: the paper's rows (default) or every neural model.
    pub ablation_models: AblationModels,
    /// Record the run-time curve: the Table 1 runs on `runtime_scene` keep weight snapshots
    /// (`train.snapshots`) and `eval` scores each of them (all nine models when `models` is
    /// empty).
    pub runtime_curve: bool,
    /// Index of the scene the curve runs on.
    pub runtime_scene: usize,
}

/// Which models the ablation groups run on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AblationModels {
    /// The paper's rows: NOL, reciprocity and view-light on Single MLP, Add. Sep. and Add.
    /// Shared, NeRFactor's changes on Add. Sep. (14 runs a scene with every group).
    #[default]
    Paper,
    /// Every purely neural model, the enhanced splits too, and NeRFactor's changes on every
    /// additive model (28 runs a scene).
    All,
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
    /// The run configuration every run shares (the profile's `[run]` table); each run sets
    /// its model on a copy.
    pub run: RunConfig,
    /// What runs.
    pub sweep: SweepSection,
    /// Where it came from (a built-in name or a path), for errors.
    pub origin: String,
    /// Whether its `[run.train]` names `matmul_precision` (otherwise the command line may
    /// choose one for the machine: `reproduce-tables` takes bf16 where the CPU runs it
    /// natively).
    pub names_precision: bool,
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

/// A profile that is not TOML of the expected shape, named with its origin.
fn parse_error(origin: &str, e: impl std::fmt::Display) -> Error {
    run_format::Error::ConfigParse { path: origin.into(), message: e.to_string() }.into()
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
        let name =
            ALIASES.iter().find(|(a, _)| *a == name_or_path).map_or(name_or_path, |(_, n)| n);
        if let Some((_, text)) = BUILT_IN.iter().find(|(n, _)| *n == name) {
            return Self::parse(text, &format!("built-in profile {name}"));
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
        let raw: RawProfile = toml::from_str(text).map_err(|e| parse_error(origin, e))?;
        let names_precision = raw
            .run
            .get("train")
            .and_then(|t| t.as_table())
            .is_some_and(|t| t.contains_key("matmul_precision"));
        let run = toml::to_string(&raw.run).map_err(|e| parse_error(origin, e))?;
        let run = RunConfig::from_toml(&run, Path::new(&format!("{origin} [run]")))?;
        let p = SweepProfile {
            name: raw.name,
            description: raw.description,
            data: raw.data,
            run,
            sweep: raw.sweep,
            origin: origin.into(),
            names_precision,
        };
        p.validate().map_err(|e| e.in_file(origin))?;
        Ok(p)
    }

    /// Sets `train.matmul_precision` in the run configuration every run shares
    /// (`reproduce-tables --matmul-precision`). A bf16 run gets its own run id, so a sweep
    /// never mixes precisions in one run directory.
    pub fn with_matmul_precision(mut self, precision: MatmulPrecision) -> Self {
        self.run.train.matmul_precision = precision;
        self.names_precision = true;
        self
    }

    /// Only the runs of the paper's tables named in `tables` (`reproduce-tables --tables`):
    /// `table1` and `energy` need Table 1's runs alone, which every profile plans; `nol`,
    /// `reciprocity`, `view-light` and `nerfactor` keep their ablation group where the
    /// profile has it, and a group not named is dropped.
    pub fn with_tables(mut self, tables: &[String]) -> Result<Self> {
        let mut keep = Vec::new();
        for t in tables {
            let group = match t.as_str() {
                "table1" | "energy" => None,
                "nol" => Some("nol"),
                "reciprocity" => Some("reciprocity"),
                "view-light" => Some("angles"),
                "nerfactor" => Some("nerfactor"),
                other => {
                    return Err(Error::config(
                        "--tables",
                        format!(
                            "unknown table {other:?} (table1, energy, nol, reciprocity, \
                             view-light, nerfactor)"
                        ),
                    ));
                }
            };
            keep.extend(group);
        }
        self.sweep.ablations.retain(|a| keep.contains(&a.as_str()));
        Ok(self)
    }

    fn validate(&self) -> Result<()> {
        let bad =
            |key: &str, why: String| Err(Error::config(key, format!("{why} (in {})", self.origin)));
        let d = &self.data;
        let captured = d.captures.len() + d.optional_captures.len();
        if d.meshes.is_empty() != d.materials.is_empty() {
            let (key, other) = if d.meshes.is_empty() {
                ("data.meshes", "data.materials")
            } else {
                ("data.materials", "data.meshes")
            };
            return bad(key, format!("is empty, but {other} is not"));
        }
        if d.meshes.is_empty() && captured == 0 {
            return bad("data", "has no scenes: give meshes and materials, or captures".into());
        }
        for m in &d.materials {
            if dataset_merl::catalogue::entry(m).is_err() {
                return bad("data.materials", format!("{m} is not a catalogue material"));
            }
        }
        if !d.meshes.is_empty() && (d.views < 2 || d.lights < 2 || d.size < 8) {
            return bad("data", "needs views >= 2, lights >= 2, size >= 8".into());
        }
        for (key, list) in
            [("data.captures", &d.captures), ("data.optional_captures", &d.optional_captures)]
        {
            for c in list {
                if let Err(e) = CaptureSource::parse(c) {
                    return bad(key, e);
                }
            }
        }
        self.models()?;
        self.ablations()?;
        if self.sweep.runtime_curve && self.sweep.runtime_scene >= self.scene_count() {
            return bad(
                "sweep.runtime_scene",
                format!("{} but there are {} scenes", self.sweep.runtime_scene, self.scene_count()),
            );
        }
        Ok(())
    }

    /// Number of scenes: the semi-synthetic ones, then the captures (optional ones included
    /// until [`SweepProfile::with_captures_found`] has dropped the missing ones).
    pub fn scene_count(&self) -> usize {
        let (a, b) = (self.data.meshes.len(), self.data.materials.len());
        let generated = match self.data.pairing {
            _ if a == 0 || b == 0 => 0,
            Pairing::Product => a * b,
            Pairing::Zip => a.max(b),
        };
        generated + self.data.captures.len() + self.data.optional_captures.len()
    }

    /// The profile with its captures looked up under `data_root`: the optional ones present
    /// join the captures, the missing ones are dropped (each with a note saying where to get
    /// it); a missing required capture is an error saying what is missing and where to get it.
    pub fn with_captures_found(mut self, data_root: &Path) -> Result<(Self, Vec<String>)> {
        let mut notes = Vec::new();
        for c in &self.data.captures {
            CaptureSource::parse(c)
                .map_err(|e| Error::config("data.captures", e))?
                .find(data_root)?;
        }
        // Missing optional captures of one benchmark make one note: (benchmark, names, error).
        let mut missing: Vec<(&'static str, Vec<String>, String)> = Vec::new();
        for c in std::mem::take(&mut self.data.optional_captures) {
            let source =
                CaptureSource::parse(&c).map_err(|e| Error::config("data.optional_captures", e))?;
            match source.find(data_root) {
                Ok(_) => self.data.captures.push(c),
                Err(e) => {
                    let kind = source.dataset(Path::new(""));
                    match missing.iter_mut().find(|m| m.0 == kind) {
                        Some(m) => m.1.push(c),
                        None => missing.push((kind, vec![c], e.to_string())),
                    }
                }
            }
        }
        for (_, names, error) in missing {
            let what = if names.len() > 1 { "optional captures" } else { "optional capture" };
            notes.push(format!("skipped {} {what} ({}): {error}", names.len(), names.join(", ")));
        }
        Ok((self, notes))
    }

    /// (mesh source, material) of every semi-synthetic scene, in order (the captures follow
    /// them in the sweep's scene list).
    pub fn scenes(&self) -> Vec<(String, String)> {
        let (m, t) = (&self.data.meshes, &self.data.materials);
        if m.is_empty() || t.is_empty() {
            return Vec::new();
        }
        match self.data.pairing {
            Pairing::Product => {
                m.iter().flat_map(|a| t.iter().map(move |b| (a.clone(), b.clone()))).collect()
            }
            Pairing::Zip => (0..m.len().max(t.len()))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_keep_their_ablations_only() {
        let all = SweepProfile::load("default").unwrap();
        assert_eq!(SweepProfile::load("all-tables").unwrap(), all, "the alias");
        let t1 = all.clone().with_tables(&["table1".into()]).unwrap();
        assert!(t1.sweep.ablations.is_empty());
        assert_eq!(t1.models().unwrap().len(), 9);
        let some = all.clone().with_tables(&["view-light".into(), "nol".into()]).unwrap();
        assert_eq!(some.sweep.ablations, ["nol", "angles"]);
        let e = all.with_tables(&["table9".into()]).unwrap_err().to_string();
        assert!(e.contains("table9") && e.contains("view-light"), "{e}");
    }

    #[test]
    fn built_in_profiles_parse() {
        for (name, _) in BUILT_IN {
            let p = SweepProfile::load(name).unwrap();
            assert_eq!(p.name, name);
            assert!(p.scene_count() >= 1);
            assert!(!p.models().unwrap().is_empty() || p.sweep.runtime_curve);
        }
        for (name, scenes) in [("default", 4), ("quick", 3)] {
            let p = SweepProfile::load(name).unwrap();
            assert_eq!(p.models().unwrap().len(), 9);
            assert_eq!(p.scene_count(), scenes, "{name}: 3 Spot scenes, the ball optional");
            assert!(!p.names_precision, "{name}: the machine chooses");
        }
        let mut named =
            BUILT_IN[0].1.replace("[run.train]", "[run.train]\nmatmul_precision = \"f32\"");
        assert!(SweepProfile::parse(&named, "test").unwrap().names_precision);
        named = BUILT_IN[0].1.to_string();
        let p = SweepProfile::parse(&named, "test").unwrap();
        assert!(p.with_matmul_precision(MatmulPrecision::F32).names_precision);
    }

    #[test]
    fn the_benches_one_scene_profile_parses_with_its_eval_table() {
        let path =
            concat!(env!("CARGO_MANIFEST_DIR"), "/../../benches/profiles/paper_one_scene.toml");
        let p = SweepProfile::load(path).unwrap();
        assert_eq!(p.scene_count(), 1);
        assert_eq!(p.models().unwrap().len(), 9);
        assert_eq!(p.run.eval.energy_estimator, Some(run_format::EnergyEstimator::Fast));
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
    fn capture_sources_parse_and_missing_ones_say_where_to_get_them() {
        assert_eq!(
            CaptureSource::parse("diligent:ball"),
            Ok(CaptureSource::Diligent("ball".into()))
        );
        assert_eq!(
            CaptureSource::parse("diligent-mv:bear"),
            Ok(CaptureSource::DiligentMv("bear".into()))
        );
        assert!(CaptureSource::parse("diligent:../x").is_err());
        assert_eq!(CaptureSource::parse("data:caps/potPNG").unwrap().object(), "pot");
        let root = Path::new("/nonexistent-data-root");
        let e = CaptureSource::parse("diligent:ball").unwrap().find(root).unwrap_err().to_string();
        assert!(e.contains("fetch-data diligent") && e.contains("ballPNG"), "{e}");
        // The real profile: the ball is required, DiLiGenT-MV's objects are optional.
        let real = SweepProfile::load("real").unwrap();
        assert!(
            real.clone().with_captures_found(root).unwrap_err().to_string().contains("ballPNG")
        );
        let mut ball_only = real.clone();
        ball_only.data.captures.clear();
        let (found, notes) = ball_only.with_captures_found(root).unwrap();
        assert!(found.data.captures.is_empty() && found.data.optional_captures.is_empty());
        assert_eq!(notes.len(), 1, "one note for DiLiGenT-MV's five objects: {notes:?}");
        assert!(
            notes[0].starts_with("skipped 5 optional captures (diligent-mv:bear, "),
            "{notes:?}"
        );
        assert!(notes[0].contains("fetch-data diligent-mv"), "{}", notes[0]);
    }

    #[test]
    fn a_profile_needs_scenes() {
        let text = "name = \"x\"\n[data]\n[sweep]\nmodels = [\"all\"]\n";
        let e = SweepProfile::parse(text, "x.toml").unwrap_err().to_string();
        assert!(e.contains("no scenes"), "{e}");
        let text = "name = \"x\"\n[data]\nmeshes = [\"embedded:spot\"]\n";
        let e = SweepProfile::parse(text, "x.toml").unwrap_err().to_string();
        assert!(e.contains("data.materials"), "{e}");
    }

    #[test]
    fn matmul_precision_reaches_every_run_config() {
        let p = SweepProfile::load("smoke").unwrap();
        let ids = |p: &SweepProfile| -> Vec<String> {
            let runs = crate::plan::runs(p).unwrap();
            runs.iter().map(|r| crate::plan::run_id(&r.config, "scene").unwrap()).collect()
        };
        let before = ids(&p);
        let bf16 = p.clone().with_matmul_precision(MatmulPrecision::Bf16);
        assert_eq!(bf16.run.train.matmul_precision, MatmulPrecision::Bf16);
        let after = ids(&bf16);
        assert_eq!(before.len(), after.len());
        assert!(before.iter().zip(&after).all(|(a, b)| a != b), "bf16 runs need their own ids");
        // f32 is the default: setting it explicitly changes no run id.
        assert_eq!(ids(&p.with_matmul_precision(MatmulPrecision::F32)), before);
    }
}
