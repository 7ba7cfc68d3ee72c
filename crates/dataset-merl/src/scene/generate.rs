//! The semi-synthetic scene generator: mesh + material + seed + settings -> a self-describing
//! scene directory (spec section 6), written atomically and skipped when already complete.
//!
//! Directory layout (all paths relative to the scene directory):
//!
//! | path | contents |
//! | --- | --- |
//! | `manifest.json` | [`Manifest`]: config, cameras, lights, splits, file hashes, statistics |
//! | `mesh.ply` | the cleaned mesh normalised into the unit sphere, binary PLY |
//! | `masks/vVV.png` | object mask of view VV, 8-bit (255 = object) |
//! | `images/vVV_lLL.exr` | observed linear HDR radiance, RGB float |
//! | `clean/vVV_lLL.exr` | test pairs only: the noise-free radiance, clipped like the observation (the noise ceiling's "perfect model") |
//! | `brdf/vVV_lLL.exr` | ground-truth BRDF (1/sr) where lit and valid, else 0 |
//! | `flags/vVV_lLL.png` | per-pixel [`flag`](super::render::flag) bits (lit, shadowed, back-facing, GT valid, saturated) |
//! | `previews/vVV.png` | sRGB preview of view VV under its first light, for looking at |
//! | `geometry/` | the ray-casting precompute, content-keyed cache (rebuilt if damaged) |
//!
//! The directory is assembled under a temporary name beside the target and renamed into place
//! when complete, so an interrupted run never leaves a half-written scene behind.

use super::config::{MaterialSpec, SceneConfig};
use super::manifest::{
    FileEntry, LightInfo, MANIFEST_FILE, Manifest, SceneStats, Split, VERSION, ViewInfo,
};
use super::render::{GroundTruth, Sensor, flag, render_light};
use super::{images, mesh_file};
use crate::catalogue::load_material;
use crate::error::{Error, Result};
use glam::{Mat3, Vec3};
use raycast_precompute::{Camera, PrecomputeSettings, ShadowBias, View, precompute_cached};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
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

/// File stem of (view, light) data.
pub fn sample_stem(view: usize, light: usize) -> String {
    format!("v{view:02}_l{light:02}")
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

/// Generates the scene of `config` into `out` (or keeps it, when a complete scene with the same
/// configuration is already there). Shows a progress bar when `progress` is true.
pub fn generate_scene(config: &SceneConfig, out: &Path, progress: bool) -> Result<GenerateReport> {
    let start = Instant::now();
    config.validate()?;
    if let Ok(m) = Manifest::read(&out.join(MANIFEST_FILE))
        && m.config == *config
        && m.verify_files(out).is_ok()
    {
        {
            let bytes = m.files.iter().map(|f| f.bytes).sum();
            return Ok(GenerateReport {
                dir: out.into(),
                skipped: true,
                seconds: start.elapsed().as_secs_f64(),
                bytes,
                label: m.label,
                stats: m.stats,
            });
        }
    }
    let s = &config.settings;
    let options = mesh_encoding::LoadOptions { cleanup: true, normalize_unit_sphere: true };
    let mut mesh = mesh_encoding::load_mesh(&config.mesh, &options)?.mesh;
    if s.up_axis == super::config::UpAxis::Y {
        // Rotation by +90 degrees about x: (x, y, z) -> (x, -z, y) sends +y to +z.
        for p in &mut mesh.positions {
            *p = Vec3::new(p.x, -p.z, p.y);
        }
    }

    let (label, gt): (String, Box<GroundTruth<'static>>) = match &config.material {
        MaterialSpec::Merl { name } => {
            let m = load_material(name, config.merl_dir.as_deref())?;
            let (table, lookup) = (m.table, s.lookup);
            (m.source.label().to_string(), Box::new(move |l, v| table.eval_dirs(l, v, lookup)))
        }
        MaterialSpec::Lambert { albedo } => {
            let f = albedo.map(|a| a as f64 / std::f64::consts::PI);
            ("analytic (Lambert)".to_string(), Box::new(move |_, _| Some(f)))
        }
        MaterialSpec::Captured { benchmark, object } => {
            return Err(Error::Config {
                key: "material".into(),
                fault: format!(
                    "captured data ({benchmark} {object}) is imported (dataset-diligent), \
                     not generated"
                ),
            });
        }
    };

    let orbit = raycast_precompute::scenes::orbit_views(
        s.views,
        s.lights_per_view,
        s.width,
        s.camera_distance,
        s.fov_y_deg,
        config.seed,
    );
    let views: Vec<View> = orbit
        .into_iter()
        .map(|v| {
            let camera = if s.width == s.height {
                v.camera
            } else {
                Camera::look_at(
                    v.camera.center(),
                    Vec3::ZERO,
                    Vec3::Z,
                    s.fov_y_deg,
                    s.width,
                    s.height,
                )?
            };
            Ok(View { camera, lights: v.lights, mask: None })
        })
        .collect::<Result<_>>()?;
    let is_train = train_views(s.views, s.train_views, config.seed);

    // Assemble under a temporary name beside the target.
    let subdirs = ["images", "clean", "brdf", "flags", "masks", "previews"];
    let manifest = stdx::fs::write_dir_atomic(out, &subdirs, |tmp: &Path| -> Result<_> {
        let settings = PrecomputeSettings {
            shadow_bias: ShadowBias::Relative(s.shadow_bias_relative),
            ..Default::default()
        };
        let (geometry, _) = precompute_cached(&mesh, &views, &settings, &tmp.join("geometry"))?;
        let mut files = Mutex::new(Vec::new());
        let mesh_bytes = mesh_file::ply_bytes(&mesh);
        let mesh_path = tmp.join("mesh.ply");
        std::fs::write(&mesh_path, &mesh_bytes).map_err(|e| Error::io(&mesh_path, e))?;
        files.get_mut().unwrap().push(FileEntry::of("mesh.ply".into(), &mesh_bytes));
        for (vi, vp) in geometry.views.iter().enumerate() {
            let mut mask = vec![0u8; (vp.width * vp.height) as usize];
            for &p in &vp.pixels {
                mask[p as usize] = 255;
            }
            let rel = format!("masks/v{vi:02}.png");
            let bytes = images::write_png_gray(&tmp.join(&rel), vp.width, vp.height, &mask)?;
            files.get_mut().unwrap().push(FileEntry::of(rel, &bytes));
        }

        let jobs: Vec<(usize, usize)> =
            (0..s.views).flat_map(|v| (0..s.lights_per_view).map(move |l| (v, l))).collect();
        let bar_label = format!("rendering {}", out.display());
        let bar = stdx::progress::bar(jobs.len() as u64, "images", &bar_label, progress);
        let stats = Mutex::new(SceneStats::default());
        jobs.par_iter().try_for_each(|&(vi, li)| -> Result<()> {
            let vp = &geometry.views[vi];
            let sensor = Sensor {
                noise_sigma: s.noise_sigma,
                saturation: s.saturation,
                seed: config.seed
                    ^ ((vi as u64) << 32 | li as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
            };
            let direction = views[vi].lights[li].to_array();
            let img = render_light(vp, li, direction, s.light_intensity, gt.as_ref(), sensor);
            let (w, h) = (vp.width as usize, vp.height as usize);
            let stem = sample_stem(vi, li);
            let mut entries = Vec::with_capacity(5);
            let test_pair = !is_train[vi] && li >= s.train_lights;
            let mut exrs = vec![("images", &img.observed), ("brdf", &img.brdf)];
            if test_pair {
                exrs.push(("clean", &img.clean));
            }
            for (dir, data) in exrs {
                let rel = format!("{dir}/{stem}.exr");
                let bytes = images::write_exr_rgb(&tmp.join(&rel), w, h, data)?;
                entries.push(FileEntry::of(rel, &bytes));
            }
            let rel = format!("flags/{stem}.png");
            let bytes = images::write_png_gray(&tmp.join(&rel), vp.width, vp.height, &img.flags)?;
            entries.push(FileEntry::of(rel, &bytes));
            if li == 0 {
                let rel = format!("previews/v{vi:02}.png");
                let bytes =
                    images::write_png_srgb(&tmp.join(&rel), vp.width, vp.height, &img.observed)?;
                entries.push(FileEntry::of(rel, &bytes));
            }
            files.lock().unwrap().extend(entries);
            let mut st = stats.lock().unwrap();
            for &f in &img.flags {
                st.lit_samples += u64::from(f & flag::LIT != 0);
                st.shadowed_samples += u64::from(f & flag::SHADOWED != 0);
                st.back_facing_samples += u64::from(f & flag::BACK_FACING != 0);
                st.saturated_samples += u64::from(f & flag::SATURATED != 0);
                st.invalid_gt_samples += u64::from(f & flag::LIT != 0 && f & flag::GT_VALID == 0);
            }
            bar.inc(1);
            Ok(())
        })?;
        bar.finish_and_clear();

        let mut stats = stats.into_inner().unwrap();
        stats.foreground_pixels = geometry.views.iter().map(|v| v.len() as u64).sum();
        stats.update_saturated_fraction();
        let mut files = files.into_inner().unwrap();
        files.sort_by(|a, b| a.path.cmp(&b.path));
        let view_infos = views
            .iter()
            .enumerate()
            .map(|(vi, v)| {
                let split = |train: bool| if train { Split::Train } else { Split::Test };
                ViewInfo {
                    split: split(is_train[vi]),
                    k: rows(v.camera.k),
                    r: rows(v.camera.r),
                    t: v.camera.t.to_array(),
                    lights: v
                        .lights
                        .iter()
                        .enumerate()
                        .map(|(li, d)| LightInfo {
                            direction: d.to_array(),
                            intensity: s.light_intensity,
                            split: split(li < s.train_lights),
                            source_index: None,
                        })
                        .collect(),
                }
            })
            .collect();
        let mut manifest = Manifest {
            format: super::manifest::FORMAT.into(),
            version: VERSION,
            generator: format!("dataset-merl {}", env!("CARGO_PKG_VERSION")),
            label: label.clone(),
            config: config.clone(),
            mesh_file: "mesh.ply".into(),
            mesh_vertices: mesh.positions.len(),
            mesh_triangles: mesh.triangles.len(),
            views: view_infos,
            files,
            stats,
            checksum: String::new(),
        };
        let json = manifest.to_json();
        let path = tmp.join(MANIFEST_FILE);
        std::fs::write(&path, json).map_err(|e| Error::io(&path, e))?;
        Ok(manifest)
    })?;
    Ok(GenerateReport {
        dir: out.into(),
        skipped: false,
        seconds: start.elapsed().as_secs_f64(),
        bytes: manifest.files.iter().map(|f| f.bytes).sum(),
        label,
        stats: manifest.stats,
    })
}
