//! Writes a captured scene in dataset-merl's scene format, so that
//! [`dataset_merl::SceneDataset::open`] and `samples(split)` read it with no special case.
//!
//! Per (view, light) of the manifest:
//! * `images/vVV_lLL.exr`: observed radiance for unit irradiance, raw / 65535 / intensity per
//!   channel, inside the captured mask (0 outside); the manifest's light intensity is (1, 1, 1).
//! * `brdf/vVV_lLL.exr`: zeros (a capture has no ground-truth BRDF; `GT_VALID` is never set).
//! * `flags/vVV_lLL.png`: for pixels in the mask whose camera ray hits the mesh, `LIT` when the
//!   ray-cast geometry says the light reaches the point with light and viewer above the shading
//!   surface (as the generator decides), else `SHADOWED` or `BACK_FACING`; `SATURATED` when a
//!   raw channel reaches the saturation level. Other pixels are 0 (no sample).
//!
//! plus `masks/vVV.png` (captured mask and mesh projection), `previews/vVV.png` (the view's first
//! light), `mesh.ply`, the `geometry/` ray-casting cache (computed exactly as `open` will, so
//! it is a cache hit there), and `manifest.json` (config with
//! [`MaterialSpec::Captured`], cameras, world light directions with their 1-based source image
//! numbers, file hashes, statistics). The directory is assembled under a temporary name beside
//! the target and renamed into place when complete.

use crate::capture::{Capture, diligent_to_opencv};
use crate::error::{Error, Result};
use crate::report::ViewReport;
use dataset_merl::scene::generate::sample_stem;
use dataset_merl::scene::manifest::{
    FORMAT, FileEntry, LightInfo, MANIFEST_FILE, Manifest, SceneStats, Split, VERSION, ViewInfo,
};
use dataset_merl::scene::render::flag;
use dataset_merl::scene::{MaterialSpec, SceneConfig, SceneSettings, UpAxis, images, mesh_file};
use glam::{Mat3, Vec3};
use mesh_encoding::TriMesh;
use raycast_precompute::{
    Camera, LightState, PrecomputeSettings, ScenePrecompute, ShadowBias, View, mat3_from_rows,
    precompute_cached,
};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// One view to write: a camera, the capture it shows and the lights used.
pub(crate) struct ViewSpec {
    /// OpenCV intrinsics, rows.
    pub k: [[f32; 3]; 3],
    /// World-to-camera rotation, rows.
    pub r: [[f32; 3]; 3],
    /// World-to-camera translation.
    pub t: [f32; 3],
    /// Train or test.
    pub split: Split,
    /// Index into the captures.
    pub capture: usize,
    /// 0-based image indices of the capture.
    pub lights: Vec<usize>,
}

/// Everything a captured scene is made of.
pub(crate) struct CapturedScene<'a> {
    pub benchmark: &'a str,
    pub object: &'a str,
    /// Where the mesh came from (recorded in the config).
    pub source_mesh: PathBuf,
    /// The mesh, in the world frame of the cameras.
    pub mesh: TriMesh,
    pub captures: &'a [Capture],
    pub views: Vec<ViewSpec>,
    pub seed: u64,
    pub train_lights: usize,
    pub saturation_level: u16,
    pub shadow_bias_relative: f32,
}

/// The written scene: its manifest, geometry and per-view mask agreement.
pub(crate) struct Written {
    pub manifest: Manifest,
    pub geometry: ScenePrecompute,
    pub views: Vec<ViewReport>,
}

fn world_light(r: Mat3, d: [f64; 3]) -> [f32; 3] {
    let c = diligent_to_opencv(d);
    (r.transpose() * Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32)).normalize().to_array()
}

/// Writes the scene into `out` (replacing what is there once complete).
pub(crate) fn write_scene(s: &CapturedScene<'_>, out: &Path, progress: bool) -> Result<Written> {
    let (width, height) = (s.captures[0].width, s.captures[0].height);
    let mut views = Vec::with_capacity(s.views.len());
    let mut infos = Vec::with_capacity(s.views.len());
    for v in &s.views {
        let cap = &s.captures[v.capture];
        let camera = Camera::from_opencv(
            mat3_from_rows(v.k),
            mat3_from_rows(v.r),
            Vec3::from_array(v.t),
            width,
            height,
        )?;
        let lights: Vec<LightInfo> = v
            .lights
            .iter()
            .map(|&i| LightInfo {
                direction: world_light(camera.r, cap.directions[i]),
                intensity: [1.0; 3],
                split: v.split,
                source_index: Some(i as u32 + 1),
            })
            .collect();
        views.push(View {
            camera,
            lights: lights.iter().map(|l| Vec3::from_array(l.direction)).collect(),
            mask: None,
        });
        infos.push(ViewInfo { split: v.split, k: v.k, r: v.r, t: v.t, lights });
    }
    let f_y = views[0].camera.k.y_axis.y;
    let settings = SceneSettings {
        width,
        height,
        views: s.views.len(),
        train_views: s.views.iter().filter(|v| v.split == Split::Train).count(),
        lights_per_view: s.captures.iter().map(Capture::len).max().unwrap_or(0),
        train_lights: s.train_lights,
        fov_y_deg: 2.0 * (0.5 * height as f32 / f_y).atan().to_degrees(),
        camera_distance: views.iter().map(|v| v.camera.center().length()).sum::<f32>()
            / views.len() as f32,
        light_intensity: [1.0; 3],
        noise_sigma: 0.0,
        saturation: s.saturation_level as f32 / 65535.0,
        shadow_bias_relative: s.shadow_bias_relative,
        up_axis: UpAxis::Z,
        ..SceneSettings::default()
    };
    let config = SceneConfig {
        mesh: s.source_mesh.clone(),
        material: MaterialSpec::Captured { benchmark: s.benchmark.into(), object: s.object.into() },
        seed: s.seed,
        settings,
        merl_dir: None,
    };
    config.validate()?;

    let subdirs = ["images", "brdf", "flags", "masks", "previews"];
    stdx::fs::write_dir_atomic(out, &subdirs, |tmp: &Path| {
        assemble(s, &config, &views, infos, tmp, progress)
    })
}

fn assemble(
    s: &CapturedScene<'_>,
    config: &SceneConfig,
    views: &[View],
    infos: Vec<ViewInfo>,
    tmp: &Path,
    progress: bool,
) -> Result<Written> {
    let settings = PrecomputeSettings {
        shadow_bias: ShadowBias::Relative(s.shadow_bias_relative),
        ..Default::default()
    };
    let (geometry, _) = precompute_cached(&s.mesh, views, &settings, &tmp.join("geometry"))?;
    let files = Mutex::new(Vec::new());
    let mesh_bytes = mesh_file::ply_bytes(&s.mesh);
    let mesh_path = tmp.join("mesh.ply");
    std::fs::write(&mesh_path, &mesh_bytes).map_err(|e| Error::io(&mesh_path, e))?;
    files.lock().unwrap().push(FileEntry::of("mesh.ply".into(), &mesh_bytes));

    // Masks: captured mask and mesh projection; per-view agreement.
    let mut reports = Vec::with_capacity(s.views.len());
    for (vi, (spec, g)) in s.views.iter().zip(&geometry.views).enumerate() {
        let cap = &s.captures[spec.capture];
        let mut mask = vec![0u8; cap.mask.len()];
        let mut both = 0;
        for &p in &g.pixels {
            if cap.mask[p as usize] {
                mask[p as usize] = 255;
                both += 1;
            }
        }
        let rel = format!("masks/v{vi:02}.png");
        let bytes = images::write_png_gray(&tmp.join(&rel), g.width, g.height, &mask)?;
        files.lock().unwrap().push(FileEntry::of(rel, &bytes));
        reports.push(ViewReport {
            source: cap.dir.clone(),
            split: spec.split,
            lights: spec.lights.iter().map(|&i| i as u32 + 1).collect(),
            mask_pixels: cap.mask.iter().filter(|&&m| m).count() as u64,
            mesh_pixels: g.len() as u64,
            both_pixels: both,
        });
    }

    let jobs: Vec<(usize, usize)> = s
        .views
        .iter()
        .enumerate()
        .flat_map(|(vi, v)| (0..v.lights.len()).map(move |li| (vi, li)))
        .collect();
    let message = format!("importing {} {}", s.benchmark, s.object);
    let bar = stdx::progress::bar(jobs.len() as u64, "images", &message, progress);
    let stats = Mutex::new(SceneStats::default());
    jobs.par_iter().try_for_each(|&(vi, li)| -> Result<()> {
        let spec = &s.views[vi];
        let cap = &s.captures[spec.capture];
        let img_index = spec.lights[li];
        let raw = cap.raw_image(img_index)?;
        let g = &geometry.views[vi];
        let n_pix = raw.len();
        let mut observed = vec![[0.0_f32; 3]; n_pix];
        for (p, o) in observed.iter_mut().enumerate() {
            if cap.mask[p] {
                *o = cap.radiance(img_index, raw[p]);
            }
        }
        let mut flags = vec![0u8; n_pix];
        let l = g.lights[li];
        let mut st = SceneStats::default();
        for k in 0..g.len() {
            let p = g.pixels[k] as usize;
            if !cap.mask[p] {
                continue;
            }
            let n = g.normals[k];
            let mut f = match g.visibility.get(k, li) {
                LightState::Lit if n.dot(l) > 0.0 && n.dot(g.view_dirs[k]) > 0.0 => flag::LIT,
                LightState::Shadowed => flag::SHADOWED,
                _ => flag::BACK_FACING,
            };
            if raw[p].iter().any(|&c| c >= s.saturation_level) {
                f |= flag::SATURATED;
            }
            st.lit_samples += u64::from(f & flag::LIT != 0);
            st.shadowed_samples += u64::from(f & flag::SHADOWED != 0);
            st.back_facing_samples += u64::from(f & flag::BACK_FACING != 0);
            st.saturated_samples += u64::from(f & flag::SATURATED != 0);
            flags[p] = f;
        }
        st.invalid_gt_samples = st.lit_samples;
        let (w, h) = (g.width, g.height);
        let stem = sample_stem(vi, li);
        let zeros = vec![[0.0_f32; 3]; n_pix];
        let mut entries = Vec::with_capacity(4);
        for (dir, data) in [("images", &observed), ("brdf", &zeros)] {
            let rel = format!("{dir}/{stem}.exr");
            let bytes = images::write_exr_rgb(&tmp.join(&rel), w as usize, h as usize, data)?;
            entries.push(FileEntry::of(rel, &bytes));
        }
        let rel = format!("flags/{stem}.png");
        let bytes = images::write_png_gray(&tmp.join(&rel), w, h, &flags)?;
        entries.push(FileEntry::of(rel, &bytes));
        if li == 0 {
            let rel = format!("previews/v{vi:02}.png");
            let bytes = images::write_png_srgb(&tmp.join(&rel), w, h, &observed)?;
            entries.push(FileEntry::of(rel, &bytes));
        }
        files.lock().unwrap().extend(entries);
        let mut all = stats.lock().unwrap();
        all.lit_samples += st.lit_samples;
        all.shadowed_samples += st.shadowed_samples;
        all.back_facing_samples += st.back_facing_samples;
        all.saturated_samples += st.saturated_samples;
        all.invalid_gt_samples += st.invalid_gt_samples;
        bar.inc(1);
        Ok(())
    })?;
    bar.finish_and_clear();

    let mut stats = stats.into_inner().unwrap();
    stats.foreground_pixels = reports.iter().map(|r| r.both_pixels).sum();
    stats.update_saturated_fraction();
    let mut files = files.into_inner().unwrap();
    files.sort_by(|a, b| a.path.cmp(&b.path));
    let mut manifest = Manifest {
        format: FORMAT.into(),
        version: VERSION,
        generator: format!("dataset-diligent {}", env!("CARGO_PKG_VERSION")),
        label: format!("captured ({} {})", s.benchmark, s.object),
        config: config.clone(),
        mesh_file: "mesh.ply".into(),
        mesh_vertices: s.mesh.positions.len(),
        mesh_triangles: s.mesh.triangles.len(),
        views: infos,
        files,
        stats,
        checksum: String::new(),
    };
    let json = manifest.to_json();
    stdx::fs::write_atomic(&tmp.join(MANIFEST_FILE), json.as_bytes())?;
    Ok(Written { manifest, geometry, views: reports })
}
