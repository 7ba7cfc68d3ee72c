//! Writes a captured scene in the scene format (through the scene crate's one writer), so that
//! [`scene::SceneDataset::open`] and `samples(split)` read it with no special case.
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
//! numbers, file hashes, statistics).

use crate::error::Result;
use crate::pms_dir::{Capture, diligent_to_opencv};
use crate::report::ViewReport;
use glam::{Mat3, Vec3};
use mesh_encoding::TriMesh;
use raycast_precompute::{
    Camera, LightState, ScenePrecompute, View, ViewPrecompute, mat3_from_rows,
};
use scene::flag;
use scene::manifest::{LightInfo, Manifest, Split, ViewInfo};
use scene::{
    MaterialSpec, PairImages, Progress, SceneConfig, SceneContents, SceneSettings, UpAxis,
};
use std::path::{Path, PathBuf};

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

/// The cameras and lights of the views, as ray casting needs them and as the manifest records
/// them (world light directions, 1-based source image numbers).
fn views(s: &CapturedScene<'_>) -> Result<(Vec<View>, Vec<ViewInfo>)> {
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
                position: None,
            })
            .collect();
        views.push(View {
            camera,
            lights: lights.iter().map(LightInfo::source).collect(),
            mask: None,
        });
        infos.push(ViewInfo { split: v.split, k: v.k, r: v.r, t: v.t, lights });
    }
    Ok((views, infos))
}

/// The scene description a captured scene records: the capture's image size, views, lights,
/// field of view and camera distance, no noise, its saturation level.
fn scene_config(s: &CapturedScene<'_>, views: &[View]) -> Result<SceneConfig> {
    let (width, height) = (s.captures[0].width, s.captures[0].height);
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
    Ok(config)
}

/// Writes the scene into `out` (replacing what is there once complete).
pub(crate) fn write_captured_scene(
    s: &CapturedScene<'_>,
    out: &Path,
    progress: bool,
) -> Result<Written> {
    let (views, infos) = views(s)?;
    let config = scene_config(s, &views)?;
    let contents = SceneContents {
        config: &config,
        generator: format!("dataset-diligent {}", env!("CARGO_PKG_VERSION")),
        label: format!("captured ({} {})", s.benchmark, s.object),
        mesh: &s.mesh,
        views: &views,
        view_infos: infos,
        clean_renders: false,
    };
    let mask = |vi: usize, g: &ViewPrecompute| {
        let cap = &s.captures[s.views[vi].capture];
        let mut mask = vec![0u8; cap.mask.len()];
        for &p in &g.pixels {
            if cap.mask[p as usize] {
                mask[p as usize] = 255;
            }
        }
        mask
    };
    let message = format!("importing {} {}", s.benchmark, s.object);
    let progress = Progress { label: &message, visible: progress };
    let pair = |vi, li, g: &ViewPrecompute| pair_images(s, vi, li, g);
    let written = scene::write_scene(out, contents, mask, pair, progress)?;
    let reports = s
        .views
        .iter()
        .zip(&written.geometry.views)
        .map(|(spec, g)| view_report(&s.captures[spec.capture], spec, g))
        .collect();
    Ok(Written { manifest: written.manifest, geometry: written.geometry, views: reports })
}

/// How the view's captured mask and the mesh's projection agree.
fn view_report(cap: &Capture, spec: &ViewSpec, g: &ViewPrecompute) -> ViewReport {
    ViewReport {
        source: cap.dir.clone(),
        split: spec.split,
        lights: spec.lights.iter().map(|&i| i as u32 + 1).collect(),
        mask_pixels: cap.mask.iter().filter(|&&m| m).count() as u64,
        mesh_pixels: g.len() as u64,
        both_pixels: g.pixels.iter().filter(|&&p| cap.mask[p as usize]).count() as u64,
    }
}

/// The images of light `li` of view `vi`: the captured radiance inside the mask, zero BRDF, and
/// the flags of the ray-cast geometry where mask and mesh agree.
fn pair_images(
    s: &CapturedScene<'_>,
    vi: usize,
    li: usize,
    g: &ViewPrecompute,
) -> Result<PairImages> {
    let spec = &s.views[vi];
    let cap = &s.captures[spec.capture];
    let img_index = spec.lights[li];
    let raw = cap.raw_image(img_index)?;
    let n_pix = raw.len();
    let mut observed = vec![[0.0_f32; 3]; n_pix];
    for (p, o) in observed.iter_mut().enumerate() {
        if cap.mask[p] {
            *o = cap.radiance(img_index, raw[p]);
        }
    }
    let mut flags = vec![0u8; n_pix];
    let l = g.lights[li].direction().expect("DiLiGenT lights are directional");
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
        flags[p] = f;
    }
    Ok(PairImages { observed, brdf: vec![[0.0; 3]; n_pix], clean: None, flags })
}
