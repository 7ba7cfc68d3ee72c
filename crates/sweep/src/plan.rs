//! Expanding a profile into scenes and runs, each run content-addressed.
//!
//! A run's id is the xxh3-128 of its resolved configuration (without the scene path), the
//! checksum of its scene's manifest (which covers the scene's configuration and every data
//! file) and [`CODE_VERSION`]. Its directory is `runs/<object>__<model>__<options>__<id16>`: a
//! finished run with the same id is reused, a half-finished one resumes from its checkpoint,
//! and two profiles that share a run (the quick profile and the run-time curve) share its
//! directory.
//!
//! An ablation run is evaluated for what its tables read: its image metrics, and the
//! reciprocity RMSE in the reciprocity ablation. The energy analysis and the BRDF plots' probe
//! are off there (`ablation_eval`): the energy table and the BRDF figures show the default
//! options only.

use super::profile::{Ablation, AblationModels, CaptureSource, SweepProfile, mesh_name};
use brdf_neural::{AngleParametrization, ModelKind, Reciprocity};
use experiments::{Error, Result};
use report::RunOptions;
use run_format::config::RunConfig;
use run_format::run_dir::RunDir;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub use run_format::CODE_VERSION;

/// Why a run is in the sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Purpose {
    /// A Table 1 row.
    Table,
    /// An ablation (NOL, reciprocity, angles, NeRFactor changes).
    Ablation,
    /// A point of the run-time curve (`iterations` = the budget).
    Runtime,
}

/// One scene of the sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSpec {
    /// `<mesh>__<material>` for a semi-synthetic scene, the object's name for a capture.
    pub name: String,
    /// Where it comes from.
    pub source: SceneSource,
}

/// Where a scene of the sweep comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    /// Rendered from a mesh and a catalogue material.
    Generated {
        /// Mesh source as written in the profile.
        mesh: String,
        /// Catalogue material.
        material: String,
    },
    /// Imported from a real capture.
    Captured(CaptureSource),
}

impl SceneSpec {
    /// The data set label of its runs (`run.json`, the tables' column groups); `dir` is the
    /// capture's directory, for a capture given by path.
    pub fn dataset(&self, dir: Option<&Path>) -> String {
        match &self.source {
            SceneSource::Generated { .. } => "MERL-derived (NBRDF)".into(),
            SceneSource::Captured(c) => c.dataset(dir.unwrap_or(Path::new(""))).into(),
        }
    }
}

/// One run of the sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSpec {
    /// Index into the scene list.
    pub scene: usize,
    /// Why it runs.
    pub purposes: Vec<Purpose>,
    /// Its configuration (the scene path is filled in when the scene exists).
    pub config: RunConfig,
}

/// `run.json`: what a run directory is, for `collect`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunInfo {
    /// Content address.
    pub id: String,
    /// The object (scene name).
    pub object: String,
    /// The data set label (`MERL-derived (NBRDF)`, `DiLiGenT`, ...).
    pub dataset: String,
    /// Why it ran (union over the profiles that planned it).
    pub purposes: Vec<Purpose>,
    /// [`CODE_VERSION`] of the code that planned it.
    pub code_version: String,
}

/// The scenes of a profile, in order: the semi-synthetic ones, then the captures (the optional
/// ones as [`SweepProfile::with_captures_found`] left them).
pub fn scenes(profile: &SweepProfile) -> Vec<SceneSpec> {
    let generated = profile.scenes().into_iter().map(|(mesh, material)| SceneSpec {
        name: format!("{}__{material}", mesh_name(&mesh)),
        source: SceneSource::Generated { mesh, material },
    });
    let captured =
        profile.data.captures.iter().chain(&profile.data.optional_captures).filter_map(|c| {
            let source = CaptureSource::parse(c).ok()?;
            Some(SceneSpec { name: source.object(), source: SceneSource::Captured(source) })
        });
    generated.chain(captured).collect()
}

/// The purely neural models (the NOL, reciprocity and angle ablations apply to them).
pub fn purely_neural() -> [ModelKind; 5] {
    [
        ModelKind::SingleMlp,
        ModelKind::AdditiveSeparate,
        ModelKind::AdditiveShared,
        ModelKind::AdditiveSeparateEnhanced,
        ModelKind::AdditiveSharedEnhanced,
    ]
}

fn with_options(base: &RunConfig, kind: ModelKind, o: RunOptions) -> Result<RunConfig> {
    let mut c = base.clone();
    let model = &mut c.model;
    model.kind = kind;
    model.angles.reciprocity = o.reciprocity;
    model.angles.parametrization = o.parametrization;
    model.nol = o.nol;
    model.albedo_clamp = o.albedo_clamp;
    model.scalar_specular = o.scalar_specular;
    c.model.spatial_dim = c.spatial_dim();
    c.validate()?;
    Ok(c)
}

/// Every run of `profile`, deduplicated (a run planned twice keeps one entry with both
/// purposes).
pub fn runs(profile: &SweepProfile) -> Result<Vec<RunSpec>> {
    let base = profile.run.clone();
    let n_scenes = profile.scene_count();
    let mut out: Vec<RunSpec> = Vec::new();
    let mut push = |scene: usize, purpose: Purpose, config: RunConfig| {
        if let Some(r) = out.iter_mut().find(|r| r.scene == scene && r.config == config) {
            if !r.purposes.contains(&purpose) {
                r.purposes.push(purpose);
            }
        } else {
            out.push(RunSpec { scene, purposes: vec![purpose], config });
        }
    };
    let d = RunOptions::DEFAULT;
    let models = profile.models()?;
    // The ablations apply to the profile's purely neural models (NeRFactor's to the additive
    // ones among them): the paper's rows (the three vanilla models; NeRFactor's on Add. Sep.)
    // or all of them.
    let paper_rows = profile.sweep.ablation_models == AblationModels::Paper;
    let vanilla = [ModelKind::SingleMlp, ModelKind::AdditiveSeparate, ModelKind::AdditiveShared];
    let neural: Vec<ModelKind> = purely_neural()
        .into_iter()
        .filter(|k| models.contains(k) && (!paper_rows || vanilla.contains(k)))
        .collect();
    let additive: Vec<ModelKind> = neural
        .iter()
        .copied()
        .filter(|&k| k.is_additive() && (!paper_rows || k == ModelKind::AdditiveSeparate))
        .collect();
    // The run-time curve: the Table 1 runs on its scene keep snapshots (the plateau schedule
    // does not depend on the budget, so a snapshot is what a shorter run would have given).
    let curve_scene = profile.sweep.runtime_curve.then_some(profile.sweep.runtime_scene);
    let mut with_curve = base.clone();
    with_curve.train.snapshots = true;
    let curve_models = if models.is_empty() { ModelKind::ALL.to_vec() } else { models.clone() };
    for scene in 0..n_scenes {
        let table_base = if curve_scene == Some(scene) { &with_curve } else { &base };
        for &kind in &models {
            push(scene, Purpose::Table, with_options(table_base, kind, d)?);
        }
        if curve_scene == Some(scene) {
            for &kind in &curve_models {
                push(scene, Purpose::Runtime, with_options(table_base, kind, d)?);
            }
        }
        for ablation in profile.ablations()? {
            let variants = ablation_variants(ablation, &neural, &additive);
            for (kind, o) in variants {
                // The ablation's baseline is the Table 1 run of the same model.
                push(scene, Purpose::Table, with_options(table_base, kind, d)?);
                let config = ablation_eval(with_options(&base, kind, o)?, ablation);
                push(scene, Purpose::Ablation, config);
            }
        }
    }
    Ok(out)
}

/// An ablation run's `[eval]`: off, what no table reads of it (the energy analysis, the BRDF
/// plots' probe, and outside the reciprocity ablation the reciprocity RMSE).
fn ablation_eval(mut config: RunConfig, ablation: Ablation) -> RunConfig {
    config.eval.energy_estimator = Some(run_format::EnergyEstimator::Off);
    config.eval.probe = Some(false);
    if ablation != Ablation::Reciprocity {
        config.eval.reciprocity_pairs = Some(0);
    }
    config
}

/// The runs of one ablation: its variants of the purely neural models `neural` (NeRFactor's of
/// the additive ones among them, `additive`).
fn ablation_variants(
    ablation: Ablation,
    neural: &[ModelKind],
    additive: &[ModelKind],
) -> Vec<(ModelKind, RunOptions)> {
    let d = RunOptions::DEFAULT;
    match ablation {
        Ablation::Nol => neural.iter().map(|&k| (k, RunOptions { nol: true, ..d })).collect(),
        Ablation::Reciprocity => neural
            .iter()
            .copied()
            .flat_map(|k| {
                [Reciprocity::RandomSwap, Reciprocity::Mapping]
                    .map(|r| (k, RunOptions { reciprocity: r, ..d }))
            })
            .collect(),
        Ablation::Angles => neural
            .iter()
            .copied()
            .map(|k| (k, RunOptions { parametrization: AngleParametrization::ViewLight, ..d }))
            .collect(),
        Ablation::Nerfactor => additive
            .iter()
            .flat_map(|&k| {
                [RunOptions { albedo_clamp: true, ..d }, RunOptions { scalar_specular: true, ..d }]
                    .map(|o| (k, o))
            })
            .collect(),
    }
}

/// The content address of a run on a scene whose manifest checksum is `scene_checksum`.
pub fn run_id(config: &RunConfig, scene_checksum: &str) -> Result<String> {
    let mut c = config.clone();
    c.scene = None;
    c.features.cache_dir = None;
    let text = format!("{}\n{scene_checksum}\n{CODE_VERSION}", c.to_toml()?);
    Ok(format!("{:032x}", xxhash_rust::xxh3::xxh3_128(text.as_bytes())))
}

/// The directory name of a run: object, model, options and steps, then the first 16 digits
/// of its id.
pub fn run_dir_name(object: &str, config: &RunConfig, id: &str) -> String {
    let options = RunOptions::of(&config.model).label().replace([',', ' '], "");
    let steps = config.train.iterations;
    let kind = config.model.kind.config_name();
    format!("{object}__{kind}__{options}__{steps}__{}", &id[..16.min(id.len())])
}

/// Reads `run.json`.
pub fn read_info(run: &RunDir) -> Result<RunInfo> {
    let path = run.info();
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::format(&path, e.to_string()))
}

/// Writes `run.json` atomically.
pub fn write_info(run: &RunDir, info: &RunInfo) -> Result<()> {
    let path = run.info();
    let text =
        serde_json::to_string_pretty(info).map_err(|e| Error::format(&path, e.to_string()))?;
    Ok(stdx::fs::write_atomic(&path, text.as_bytes())?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plans_have_the_expected_runs() {
        let quick = SweepProfile::load("quick").unwrap();
        let r = runs(&quick).unwrap();
        assert_eq!(r.len(), 27, "9 models x 3 scenes");
        // Table 1 alone from the default: the quick profile's scenes and models, trained to
        // their plateaus.
        let default = SweepProfile::load("default").unwrap();
        let d = runs(&default.clone().with_tables(&["table1".into()]).unwrap()).unwrap();
        assert_eq!(d.iter().filter(|r| r.scene < 3).count(), 27, "9 models x 3 scenes");
        assert!(d.iter().all(|r| r.purposes == [Purpose::Table] && !r.config.train.snapshots));
        let smoke = SweepProfile::load("smoke").unwrap();
        let r = runs(&smoke).unwrap();
        // Per scene: 9 Table 1 runs and the paper's 14 ablation rows (3 NOL, 6 reciprocity, 3
        // angle, 2 NeRFactor); the run-time curve is the Table 1 runs of scene 0, with
        // snapshots.
        assert_eq!(r.len(), 2 * (9 + 3 + 6 + 3 + 2));
        let mut every = smoke.clone();
        every.sweep.ablation_models = AblationModels::All;
        assert_eq!(runs(&every).unwrap().len(), 2 * (9 + 5 + 10 + 5 + 8));
        let curve: Vec<&RunSpec> =
            r.iter().filter(|r| r.purposes.contains(&Purpose::Runtime)).collect();
        assert_eq!(curve.len(), 9);
        assert!(curve.iter().all(|r| r.scene == 0 && r.config.train.snapshots));
        assert!(curve.iter().all(|r| r.purposes.contains(&Purpose::Table)));
        // The paper's scale (docs/reproduce.md sizes its cost from this count): 25 scenes
        // (materials zipped with the 9 meshes), each with the smoke profile's 23 runs.
        let full = SweepProfile::load("full").unwrap();
        assert_eq!(scenes(&full).len(), 25);
        assert_eq!(runs(&full).unwrap().len(), 25 * (9 + 14));
        // Every table at the default's scale: Table 1's 27 runs (the same ones) and 14
        // ablation rows on each of its 3 scenes; the ball joins when present.
        let all = default;
        let a = runs(&all).unwrap();
        assert_eq!(a.iter().filter(|r| r.scene < 3).count(), 3 * (9 + 14));
        // The ablation runs skip what no table reads of them; the Table 1 runs keep it all.
        for r in &a {
            let e = &r.config.eval;
            let ablation = r.purposes == [Purpose::Ablation];
            let reciprocity = r.config.model.angles.reciprocity != Reciprocity::None;
            assert_eq!(e.probe, ablation.then_some(false));
            assert_eq!(e.energy_estimator.is_some(), ablation);
            assert_eq!(e.reciprocity_pairs, (ablation && !reciprocity).then_some(0));
        }
        assert!(d.iter().all(|r| a.iter().any(|x| x.config == r.config && x.scene == r.scene)));
        let runtime = SweepProfile::load("runtime").unwrap();
        let rt = runs(&runtime).unwrap();
        assert_eq!(rt.len(), 9);
        // The patient rule of the cpu training profile.
        assert!(rt.iter().all(|r| r.config.train.patience == 600 && r.config.train.snapshots));
    }

    #[test]
    fn ids_depend_on_config_and_data_only() {
        let smoke = SweepProfile::load("smoke").unwrap();
        let r = runs(&smoke).unwrap();
        let a = run_id(&r[0].config, "abc").unwrap();
        let mut moved = r[0].config.clone();
        moved.scene = Some("/somewhere/else".into());
        assert_eq!(run_id(&moved, "abc").unwrap(), a);
        assert_ne!(run_id(&r[0].config, "abd").unwrap(), a);
        assert_ne!(run_id(&r[1].config, "abc").unwrap(), a);
        let name = run_dir_name("spot__blue-acrylic", &r[0].config, &a);
        assert!(name.starts_with("spot__blue-acrylic__rp__default__30__"), "{name}");
    }
}
