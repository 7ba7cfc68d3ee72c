//! `cargo xtask generate-scenes`: renders semi-synthetic scenes (every mesh x every material)
//! with the scene generator of `dataset-merl`, skipping scenes that are already complete.

use anyhow::{Context, Result};
use dataset_merl::{CATALOGUE, generate_scene};
use scene::{MaterialSpec, SceneConfig, SceneSettings};
use std::path::PathBuf;

/// Options of the command.
pub struct Options {
    /// Mesh files.
    pub meshes: Vec<PathBuf>,
    /// Catalogue material names ("all" for the whole catalogue).
    pub materials: Vec<String>,
    /// Seed.
    pub seed: u64,
    /// Image size (square).
    pub size: u32,
    /// Views per scene.
    pub views: usize,
    /// Lights per view.
    pub lights: usize,
    /// Point lights at this distance from the origin (mesh radii) instead of directional ones.
    pub point_light_distance: Option<f32>,
    /// Directory with real MERL binaries, which take precedence.
    pub merl_dir: Option<PathBuf>,
    /// Output directory; scenes go to `<out>/<mesh>__<material>`.
    pub out: PathBuf,
}

/// Runs the command.
pub fn run(opts: Options) -> Result<()> {
    let materials: Vec<String> = if opts.materials.iter().any(|m| m == "all") {
        CATALOGUE.iter().map(|e| e.name.to_string()).collect()
    } else {
        opts.materials.clone()
    };
    anyhow::ensure!(!opts.meshes.is_empty(), "give at least one --mesh");
    anyhow::ensure!(!materials.is_empty(), "give at least one --material");
    anyhow::ensure!(opts.views >= 2, "--views must be at least 2 (half train, half test)");
    anyhow::ensure!(opts.lights >= 2, "--lights must be at least 2");
    let settings = SceneSettings {
        point_light_distance: opts.point_light_distance,
        ..SceneSettings::with_counts(opts.size, opts.views, opts.lights)
    };
    let total = opts.meshes.len() * materials.len();
    let mut done = 0;
    for mesh in &opts.meshes {
        let stem = mesh.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh").to_string();
        for material in &materials {
            done += 1;
            let config = SceneConfig {
                mesh: mesh.clone(),
                material: MaterialSpec::Merl { name: material.clone() },
                seed: opts.seed,
                settings: settings.clone(),
                merl_dir: opts.merl_dir.clone(),
            };
            let out = opts.out.join(format!("{stem}__{material}"));
            eprintln!("[{done}/{total}] {stem} x {material}");
            let r = generate_scene(&config, &out, true)
                .with_context(|| format!("generating {}", out.display()))?;
            let what = if r.skipped { "complete already, kept" } else { "written" };
            eprintln!(
                "    {what}: {} ({}), {:.1} MB, {:.1} s, {} lit samples, {:.3} % saturated",
                out.display(),
                r.label,
                r.bytes as f64 / 1e6,
                r.seconds,
                r.stats.lit_samples,
                100.0 * r.stats.saturated_fraction
            );
        }
    }
    Ok(())
}
