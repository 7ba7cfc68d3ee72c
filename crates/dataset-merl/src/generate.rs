//! The semi-synthetic scene generator: mesh + MERL (or Lambert) material + seed + settings ->
//! a scene directory in the scene format (spec section 6), skipped when already complete.
//!
//! This module decides what the scene shows: the mesh (cleaned, normalised, turned z-up), the
//! material's ground truth, the orbit cameras and lights, the seeded split of views and lights,
//! and the sensor noise per image. The scene crate's [`write_scene`] writes it atomically.

use crate::catalogue::load_material;
use crate::error::Result;
use crate::render::{GroundTruth, Sensor, render_light};
use glam::{Mat3, Vec3};
use mesh_encoding::TriMesh;
use raycast_precompute::{Light, View};
use scene::manifest::{LightInfo, MANIFEST_FILE, Manifest, SceneStats, Split, ViewInfo};
use scene::{MaterialSpec, PairImages, Progress, SceneConfig, SceneContents, UpAxis, write_scene};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What [`generate_scene`] did.
#[derive(Clone, Debug)]
pub struct GenerateReport {
    /// The scene directory.
    pub dir: PathBuf,
    /// True when a complete scene with the same configuration was already there.
    pub skipped: bool,
    /// Wall time in seconds.
    pub seconds: f64,
    /// Size of the listed data files in bytes.
    pub bytes: u64,
    /// Provenance label.
    pub label: String,
    /// Sample statistics.
    pub stats: SceneStats,
}

/// Indices of the training views: a seeded shuffle of 0..views, first `train` of them, sorted.
/// Its generator is a PCG-constant LCG, not the workspace's SplitMix64, and stays so: the split
/// is part of every generated scene's bytes, so of every run id.
fn train_views(views: usize, train: usize, seed: u64) -> Vec<bool> {
    let mut order: Vec<usize> = (0..views).collect();
    let mut state = seed ^ 0x5CE9_E5EE_D000_0001;
    for i in (1..views).rev() {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let j = ((state >> 33) % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    let mut is_train = vec![false; views];
    for &v in &order[..train] {
        is_train[v] = true;
    }
    is_train
}

fn rows(m: Mat3) -> [[f32; 3]; 3] {
    [m.row(0).to_array(), m.row(1).to_array(), m.row(2).to_array()]
}

/// The scene already in `out`, when it is complete and made from the same configuration.
fn existing_scene(config: &SceneConfig, out: &Path, start: Instant) -> Option<GenerateReport> {
    let m = Manifest::read(&out.join(MANIFEST_FILE)).ok()?;
    if m.config != *config || m.verify_files(out).is_err() {
        return None;
    }
    Some(GenerateReport {
        dir: out.into(),
        skipped: true,
        seconds: start.elapsed().as_secs_f64(),
        bytes: m.files.iter().map(|f| f.bytes).sum(),
        label: m.label,
        stats: m.stats,
    })
}

/// The configured mesh, cleaned, normalised into the unit sphere and turned so that its up axis
/// is +z (the orbit's up).
fn scene_mesh(config: &SceneConfig) -> Result<TriMesh> {
    let options = mesh_encoding::LoadOptions { cleanup: true, normalize_unit_sphere: true };
    let mut mesh = mesh_encoding::load_mesh(&config.mesh, &options)?.mesh;
    if config.settings.up_axis == UpAxis::Y {
        // Rotation by +90 degrees about x: (x, y, z) -> (x, -z, y) sends +y to +z.
        for p in &mut mesh.positions {
            *p = Vec3::new(p.x, -p.z, p.y);
        }
    }
    Ok(mesh)
}

/// The ground-truth BRDF of a scene's material (local-frame `l`, `v` -> f_r, `None` where the
/// table is invalid) and its provenance label; captured scenes have none (an error).
pub fn ground_truth(config: &SceneConfig) -> Result<(String, Box<GroundTruth<'static>>)> {
    match &config.material {
        MaterialSpec::Merl { name } => {
            let m = load_material(name, config.merl_dir.as_deref())?;
            let (table, lookup) = (m.table, config.settings.lookup);
            Ok((m.source.label().to_string(), Box::new(move |l, v| table.eval_dirs(l, v, lookup))))
        }
        MaterialSpec::Lambert { albedo } => {
            let f = albedo.map(|a| a as f64 / std::f64::consts::PI);
            Ok(("analytic (Lambert)".to_string(), Box::new(move |_, _| Some(f))))
        }
        MaterialSpec::Captured { benchmark, object } => Err(scene::Error::Config {
            key: "material".into(),
            fault: format!(
                "captured data ({benchmark} {object}) is imported (dataset-diligent), not generated"
            ),
        }
        .into()),
    }
}

/// The manifest's record of the views: split, camera and lights.
fn view_infos(config: &SceneConfig, views: &[View], is_train: &[bool]) -> Vec<ViewInfo> {
    let s = &config.settings;
    let split = |train: bool| if train { Split::Train } else { Split::Test };
    views
        .iter()
        .enumerate()
        .map(|(vi, v)| ViewInfo {
            split: split(is_train[vi]),
            k: rows(v.camera.k),
            r: rows(v.camera.r),
            t: v.camera.t.to_array(),
            lights: v
                .lights
                .iter()
                .enumerate()
                .map(|(li, light)| match *light {
                    Light::Directional(d) => LightInfo {
                        direction: d.to_array(),
                        intensity: s.light_intensity,
                        split: split(li < s.train_lights),
                        source_index: None,
                        position: None,
                    },
                    // The orbit's point lights: radiant intensity E d^2 gives the configured
                    // irradiance E at the origin.
                    Light::Point(p) => LightInfo {
                        direction: p.normalize_or(glam::Vec3::Z).to_array(),
                        intensity: s.light_intensity.map(|e| e * p.length_squared()),
                        split: split(li < s.train_lights),
                        source_index: None,
                        position: Some(p.to_array()),
                    },
                })
                .collect(),
        })
        .collect()
}

/// Generates the scene of `config` into `out` (or keeps it, when a complete scene with the same
/// configuration is already there). Shows a progress bar when `progress` is true.
pub fn generate_scene(config: &SceneConfig, out: &Path, progress: bool) -> Result<GenerateReport> {
    let start = Instant::now();
    config.validate()?;
    if let MaterialSpec::Merl { name } = &config.material {
        crate::catalogue::entry(name)?;
    }
    if let Some(report) = existing_scene(config, out, start) {
        return Ok(report);
    }
    let s = &config.settings;
    let mesh = scene_mesh(config)?;
    let (label, gt) = ground_truth(config)?;
    let views = scene::orbit::orbit_views(s, config.seed)?;
    let is_train = train_views(s.views, s.train_views, config.seed);
    let infos = view_infos(config, &views, &is_train);
    let contents = SceneContents {
        config,
        generator: format!("dataset-merl {}", env!("CARGO_PKG_VERSION")),
        label: label.clone(),
        mesh: &mesh,
        views: &views,
        view_infos: infos.clone(),
        clean_renders: true,
    };
    let mask = |_: usize, vp: &raycast_precompute::ViewPrecompute| {
        let mut mask = vec![0u8; (vp.width * vp.height) as usize];
        for &p in &vp.pixels {
            mask[p as usize] = 255;
        }
        mask
    };
    let pair = |vi: usize, li: usize, vp: &raycast_precompute::ViewPrecompute| -> Result<_> {
        let sensor = Sensor {
            noise_sigma: s.noise_sigma,
            saturation: s.saturation,
            seed: config.seed ^ ((vi as u64) << 32 | li as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
        };
        let img = render_light(vp, li, &infos[vi].lights[li], gt.as_ref(), sensor);
        let test_pair = !is_train[vi] && li >= s.train_lights;
        Ok(PairImages {
            observed: img.observed,
            brdf: img.brdf,
            clean: test_pair.then_some(img.clean),
            flags: img.flags,
        })
    };
    let bar_label = format!("rendering {}", out.display());
    let progress = Progress { label: &bar_label, visible: progress };
    let written = write_scene(out, contents, mask, pair, progress)?;
    let manifest = written.manifest;
    Ok(GenerateReport {
        dir: out.into(),
        skipped: false,
        seconds: start.elapsed().as_secs_f64(),
        bytes: manifest.files.iter().map(|f| f.bytes).sum(),
        label,
        stats: manifest.stats,
    })
}
