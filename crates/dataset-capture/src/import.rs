//! Importing a capture: read and check every part, group images into views, check the mesh
//! against the masks, and write a scene directory through the scene crate's one writer.
//!
//! Per (view, light) the scene gets the observed radiance inside the view's mask (0 outside), a
//! zero BRDF (a capture has no ground truth, `GT_VALID` is never set) and flags: for pixels in
//! the mask whose camera ray hits the mesh, `LIT` where the shadow ray reaches the light (the
//! light's point itself for a point light) with light and viewer above the shading surface,
//! else `SHADOWED` or `BACK_FACING`; `SATURATED` where a channel reached the saturation level.

use crate::cameras::{self, Frame};
use crate::config::CaptureConfig;
use crate::error::{Error, Result};
use crate::images::{decode, decode_mask};
use crate::lights::{CaptureLight, Lights};
use glam::Vec3;
use raycast_precompute::{Camera, LightState, View, ViewPrecompute, mat3_from_rows};
use scene::manifest::{LightInfo, Manifest, Split, ViewInfo};
use scene::{
    MaterialSpec, PairImages, Progress, SceneConfig, SceneContents, SceneSettings, UpAxis,
};
use scene::{flag, shading};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use stdx::Limits;

/// How one view's mask and the mesh's silhouette agree.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ViewCheck {
    /// The view's images, in light order.
    pub images: Vec<String>,
    /// Its split.
    pub split: Split,
    /// Pixels of the mask (the silhouette's when there is no mask).
    pub mask_pixels: u64,
    /// Pixels where the camera ray hits the mesh.
    pub mesh_pixels: u64,
    /// Pixels in both.
    pub both_pixels: u64,
    /// Intersection over union; `None` without a mask.
    pub iou: Option<f64>,
}

/// What an import did.
pub struct ImportReport {
    /// The written scene's manifest.
    pub manifest: Manifest,
    /// Per view, the alignment check.
    pub views: Vec<ViewCheck>,
}

/// One view of the capture: a camera and the frames (images) it took, one per light.
struct CaptureView {
    frames: Vec<usize>,
    split: Split,
    mask: Option<Vec<bool>>,
}

/// Imports the capture in `dir` (its `capture.toml`) as a scene directory at `out`, reading
/// its images within `limits` (the cameras' image size is checked against them first; each
/// image and mask must then declare that size before it is decoded).
pub fn import_capture(
    dir: &Path,
    out: &Path,
    progress: bool,
    limits: &Limits,
) -> Result<ImportReport> {
    let config = CaptureConfig::read(dir)?;
    let frames = cameras::read(&config)?;
    let lights = Lights::read(&config.lights)?;
    check_counts(&config, &frames, &lights)?;
    let size = image_size(&config, &frames)?;
    limits
        .check_pixels(u64::from(size.0), u64::from(size.1))
        .map_err(|e| Error::input(&config.cameras, format!("the cameras' image size: {e}")))?;
    let views = group_views(&config, &frames, &lights, limits)?;
    let loaded = mesh_encoding::load_mesh(&config.mesh, &mesh_encoding::LoadOptions::default())?;
    let mesh = loaded.mesh;
    let (min, max) = mesh.bounding_box();
    let centre = 0.5 * (min + max);
    let radius = 0.5 * mesh.diagonal();

    let (ray_views, infos) = ray_views(&views, &frames, &lights, size, centre)?;
    let settings = scene_settings(&config, &views, &ray_views, size, (centre, radius));
    let object = object_name(dir);
    let scene_config = SceneConfig {
        mesh: config.mesh.clone(),
        material: MaterialSpec::Captured { benchmark: "capture".into(), object: object.clone() },
        seed: 0,
        settings,
        merl_dir: None,
    };
    scene_config.validate()?;

    // The masks' agreement with the silhouette, filled in as the writer traces each view; the
    // first pair refuses a misaligned capture before any image is written.
    let checks: Mutex<Vec<Option<ViewCheck>>> = Mutex::new(vec![None; views.len()]);
    let mask = |vi: usize, g: &ViewPrecompute| {
        let (m, check) = view_check(&views[vi], &frames, g);
        checks.lock().unwrap()[vi] = Some(check);
        m
    };
    let min_iou = config.check.min_iou;
    let pair = |vi: usize, li: usize, g: &ViewPrecompute| -> Result<PairImages> {
        if let Some(misaligned) = misaligned(&checks.lock().unwrap(), &views, &frames, min_iou) {
            return Err(misaligned);
        }
        let v = &views[vi];
        let f = &frames[v.frames[li]];
        pair_images(f, &config, v.mask.as_deref(), &infos[vi].lights[li], (g, li), limits)
    };
    let label = format!("importing capture {object}");
    let contents = SceneContents {
        config: &scene_config,
        generator: format!("dataset-capture {}", env!("CARGO_PKG_VERSION")),
        label: format!("captured ({object})"),
        mesh: &mesh,
        views: &ray_views,
        view_infos: infos.clone(),
        clean_renders: false,
    };
    let written = scene::write_scene(
        out,
        contents,
        mask,
        pair,
        Progress { label: &label, visible: progress },
    )?;
    let views =
        checks.into_inner().unwrap().into_iter().map(|c| c.expect("every view traced")).collect();
    Ok(ImportReport { manifest: written.manifest, views })
}

/// The capture's object name: its folder's (`capture` where it has none).
fn object_name(dir: &Path) -> String {
    dir.canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "capture".into())
}

/// The error for the first traced view whose mask agrees with the mesh's silhouette less
/// than `min_iou`, if any.
fn misaligned(
    checks: &[Option<ViewCheck>],
    views: &[CaptureView],
    frames: &[Frame],
    min_iou: f64,
) -> Option<Error> {
    let (view, c) = checks.iter().enumerate().find_map(|(i, c)| {
        c.as_ref().filter(|c| c.iou.is_some_and(|x| x < min_iou)).map(|c| (i, c))
    })?;
    Some(Error::Misaligned {
        path: frames[views[view].frames[0]].image.clone(),
        view,
        iou: c.iou.unwrap_or(0.0),
        min_iou,
        mask_pixels: c.mask_pixels,
        mesh_pixels: c.mesh_pixels,
    })
}

/// The capture's one image size (every image must have it).
fn image_size(config: &CaptureConfig, frames: &[Frame]) -> Result<(u32, u32)> {
    let size = frames[0].size;
    if let Some(f) = frames.iter().find(|f| f.size != size) {
        return Err(Error::input(
            &config.cameras,
            format!(
                "image `{}` is {} x {}, the first {} x {}: a scene has one image size",
                f.name, f.size.0, f.size.1, size.0, size.1
            ),
        ));
    }
    Ok(size)
}

/// Each view's camera and lights, as the ray caster and the manifest take them.
fn ray_views(
    views: &[CaptureView],
    frames: &[Frame],
    lights: &Lights,
    size: (u32, u32),
    centre: Vec3,
) -> Result<(Vec<View>, Vec<ViewInfo>)> {
    let mut ray_views = Vec::with_capacity(views.len());
    let mut infos = Vec::with_capacity(views.len());
    for v in views {
        let f = &frames[v.frames[0]];
        let k = f.k.map(|r| r.map(|x| x as f32));
        let r = f.r.map(|r| r.map(|x| x as f32));
        let t = f.t.map(|x| x as f32);
        let camera = Camera::from_opencv(
            mat3_from_rows(k),
            mat3_from_rows(r),
            Vec3::from_array(t),
            size.0,
            size.1,
        )
        .map_err(|e| Error::input(&f.image, format!("its camera: {e}")))?;
        let infos_l: Vec<LightInfo> = v
            .frames
            .iter()
            .map(|&i| {
                light_info(lights.get(&frames[i].name).expect("checked").light, v.split, centre)
            })
            .collect();
        ray_views.push(View {
            camera,
            lights: infos_l.iter().map(LightInfo::source).collect(),
            mask: None,
        });
        infos.push(ViewInfo { split: v.split, k, r, t, lights: infos_l });
    }
    Ok((ray_views, infos))
}

/// The scene settings a capture implies: its image size, views and lights, the cameras' field
/// of view and mean distance (in mesh radii from the mesh's centre), its saturation.
fn scene_settings(
    config: &CaptureConfig,
    views: &[CaptureView],
    ray_views: &[View],
    size: (u32, u32),
    (centre, radius): (Vec3, f32),
) -> SceneSettings {
    let mean_distance =
        ray_views.iter().map(|v| (v.camera.center() - centre).length()).sum::<f32>()
            / ray_views.len() as f32;
    let f_y = ray_views[0].camera.k.y_axis.y;
    let train_views = views.iter().filter(|v| v.split == Split::Train).count();
    let lights_per_view = views.iter().map(|v| v.frames.len()).max().unwrap_or(0);
    SceneSettings {
        width: size.0,
        height: size.1,
        views: views.len(),
        train_views,
        lights_per_view,
        train_lights: lights_per_view,
        fov_y_deg: 2.0 * (0.5 * size.1 as f32 / f_y).atan().to_degrees(),
        // In mesh radii from the mesh's centre (recorded for information; at least just above 1).
        camera_distance: (mean_distance / radius.max(f32::MIN_POSITIVE)).max(1.0001),
        light_intensity: [1.0; 3],
        noise_sigma: 0.0,
        saturation: config.image.saturation.unwrap_or(f32::MAX),
        up_axis: UpAxis::Z,
        ..SceneSettings::default()
    }
}

/// A view's object mask as the scene stores it (the capture's mask within the mesh's
/// silhouette, 255 inside) and the two's agreement.
fn view_check(v: &CaptureView, frames: &[Frame], g: &ViewPrecompute) -> (Vec<u8>, ViewCheck) {
    let mut m = vec![0u8; (g.width * g.height) as usize];
    let mut both = 0u64;
    for &p in &g.pixels {
        if v.mask.as_ref().is_none_or(|mask| mask[p as usize]) {
            m[p as usize] = 255;
            both += 1;
        }
    }
    let mesh_pixels = g.pixels.len() as u64;
    let mask_pixels =
        v.mask.as_ref().map_or(mesh_pixels, |mk| mk.iter().filter(|&&b| b).count() as u64);
    let union = mask_pixels + mesh_pixels - both;
    let iou = v.mask.as_ref().map(|_| if union == 0 { 0.0 } else { both as f64 / union as f64 });
    let check = ViewCheck {
        images: v.frames.iter().map(|&i| frames[i].name.clone()).collect(),
        split: v.split,
        mask_pixels,
        mesh_pixels,
        both_pixels: both,
        iou,
    };
    (m, check)
}

/// Every image has exactly one light and every light an image.
fn check_counts(config: &CaptureConfig, frames: &[Frame], lights: &Lights) -> Result<()> {
    let missing: Vec<&str> =
        frames.iter().map(|f| f.name.as_str()).filter(|n| lights.get(n).is_none()).collect();
    let mut names: Vec<&str> = frames.iter().map(|f| f.name.as_str()).collect();
    names.sort_unstable();
    let extra: Vec<&str> =
        lights.images().into_iter().filter(|n| names.binary_search(n).is_err()).collect();
    let dup = names.windows(2).find(|w| w[0] == w[1]).map(|w| w[0]);
    if let Some(d) = dup {
        return Err(Error::input(&config.cameras, format!("image `{d}` appears twice")));
    }
    if missing.is_empty() && extra.is_empty() {
        return Ok(());
    }
    let list = |v: &[&str]| {
        let mut s = v.iter().take(5).map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ");
        if v.len() > 5 {
            s.push_str(&format!(" and {} more", v.len() - 5));
        }
        s
    };
    let mut fault = format!("{} lights for {} camera images", lights.len(), frames.len());
    if !missing.is_empty() {
        fault.push_str(&format!("; no light for {}", list(&missing)));
    }
    if !extra.is_empty() {
        fault.push_str(&format!("; lights for images the cameras do not name: {}", list(&extra)));
    }
    Err(Error::input(&config.lights, fault))
}

/// Frames that share a camera (intrinsics and pose to 1e-6) form one view; splits per view.
fn group_views(
    config: &CaptureConfig,
    frames: &[Frame],
    lights: &Lights,
    limits: &Limits,
) -> Result<Vec<CaptureView>> {
    let same = |a: &Frame, b: &Frame| {
        let close = |x: &[f64], y: &[f64]| {
            x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-6 * (1.0 + q.abs()))
        };
        a.size == b.size
            && close(a.k.as_flattened(), b.k.as_flattened())
            && close(a.r.as_flattened(), b.r.as_flattened())
            && close(&a.t, &b.t)
    };
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, f) in frames.iter().enumerate() {
        match groups.iter_mut().find(|g| same(&frames[g[0]], f)) {
            Some(g) => g.push(i),
            None => groups.push(vec![i]),
        }
    }
    let any_split = frames.iter().any(|f| lights.get(&f.name).is_some_and(|e| e.split.is_some()));
    let mut views = Vec::with_capacity(groups.len());
    for (vi, g) in groups.into_iter().enumerate() {
        let split = if any_split {
            let splits: Vec<Split> = g
                .iter()
                .map(|&i| lights.get(&frames[i].name).and_then(|e| e.split).unwrap_or(Split::Train))
                .collect();
            if let Some(k) = splits.iter().position(|s| *s != splits[0]) {
                return Err(Error::input(
                    &config.lights,
                    format!(
                        "images `{}` and `{}` share a camera (view {vi}) but not a split: a view is \
                         either train or test",
                        frames[g[0]].name, frames[g[k]].name
                    ),
                ));
            }
            splits[0]
        } else if vi % config.test_every == 0 && config.test_every > 1 {
            Split::Test
        } else {
            Split::Train
        };
        let mut mask: Option<Vec<bool>> = None;
        for &i in &g {
            if let Some(path) = &frames[i].mask {
                let m = decode_mask(path, frames[i].size, limits)?;
                mask = Some(match mask {
                    None => m,
                    Some(prev) => prev.iter().zip(&m).map(|(a, b)| *a && *b).collect(),
                });
            }
        }
        views.push(CaptureView { frames: g, split, mask });
    }
    for (split, name) in [(Split::Train, "train"), (Split::Test, "test")] {
        if !views.iter().any(|v| v.split == split) {
            return Err(Error::input(
                &config.lights,
                format!(
                    "no {name} view among {} views: mark images with \"split\" or set test_every",
                    views.len()
                ),
            ));
        }
    }
    Ok(views)
}

/// The manifest's record of a capture light; a point light's `direction` is the direction from
/// the mesh's bounding-box centre (for display; shading uses the position).
fn light_info(light: CaptureLight, split: Split, centre: Vec3) -> LightInfo {
    match light {
        CaptureLight::Directional { direction, intensity } => LightInfo {
            direction: Vec3::from_array(direction).normalize().to_array(),
            intensity,
            split,
            source_index: None,
            position: None,
        },
        CaptureLight::Point { position, intensity } => LightInfo {
            direction: (Vec3::from_array(position) - centre).normalize_or(Vec3::Z).to_array(),
            intensity,
            split,
            source_index: None,
            position: Some(position),
        },
    }
}

/// The scene images of one capture image.
fn pair_images(
    frame: &Frame,
    config: &CaptureConfig,
    mask: Option<&[bool]>,
    light: &LightInfo,
    (g, li): (&ViewPrecompute, usize),
    limits: &Limits,
) -> Result<PairImages> {
    let img = decode(&frame.image, frame.size, &config.image, limits)?;
    let n_pix = img.radiance.len();
    let inside = |p: usize| mask.is_none_or(|m| m[p]);
    let mut observed = vec![[0.0_f32; 3]; n_pix];
    for (p, o) in observed.iter_mut().enumerate() {
        if inside(p) {
            *o = img.radiance[p];
        }
    }
    let mut flags = vec![0u8; n_pix];
    for k in 0..g.len() {
        let p = g.pixels[k] as usize;
        if !inside(p) {
            continue;
        }
        let n = g.normals[k].to_array();
        let v = g.view_dirs[k].to_array();
        let above = shading::light_at(light, g.positions[k].to_array())
            .is_some_and(|(l, _)| shading::facing(n, l) && shading::facing(n, v));
        let mut f = match g.visibility.get(k, li) {
            LightState::Lit if above => flag::LIT,
            LightState::Shadowed => flag::SHADOWED,
            _ => flag::BACK_FACING,
        };
        if img.saturated[p] {
            f |= flag::SATURATED;
        }
        flags[p] = f;
    }
    Ok(PairImages { observed, brdf: vec![[0.0; 3]; n_pix], clean: None, flags })
}

/// `import-report.json` beside a scene: the per-view checks.
pub fn report_json(report: &ImportReport) -> String {
    serde_json::to_string_pretty(&report.views).expect("the report serialises")
}

/// The path of the report beside the scene directory `out`.
pub fn report_path(out: &Path) -> PathBuf {
    let mut name = out.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".import-report.json");
    out.with_file_name(name)
}
