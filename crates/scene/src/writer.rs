//! The one scene writer, used by the semi-synthetic generator (dataset-merl) and the capture
//! importers (dataset-diligent): a scene's views and per-(view, light) images in, a complete,
//! self-describing scene directory out, written atomically.
//!
//! Directory layout (all paths relative to the scene directory):
//!
//! | path | contents |
//! | --- | --- |
//! | `manifest.json` | [`Manifest`]: config, cameras, lights, splits, file hashes, statistics |
//! | `mesh.ply` | the scene's mesh (normalised for generated scenes), binary PLY |
//! | `masks/vVV.png` | object mask of view VV, 8-bit (255 = object) |
//! | `images/vVV_lLL.exr` | observed linear HDR radiance, RGB float |
//! | `clean/vVV_lLL.exr` | generated scenes, test pairs only: the noise-free radiance, clipped like the observation (the noise ceiling's "perfect model") |
//! | `brdf/vVV_lLL.exr` | ground-truth BRDF (1/sr) where lit and valid, else 0 (zeros for captures) |
//! | `flags/vVV_lLL.png` | per-pixel [`flag`](crate::flag) bits (lit, shadowed, back-facing, GT valid, saturated) |
//! | `previews/vVV.png` | sRGB preview of view VV under its first light, for looking at |
//! | `geometry/` | the ray-casting precompute, content-keyed cache (rebuilt if damaged) |
//!
//! The directory is assembled under a temporary name beside the target and renamed into place
//! when complete, so an interrupted run never leaves a half-written scene behind. Inside it,
//! files are written plainly: the rename is the commit.

use crate::config::SceneConfig;
use crate::error::{Error, Result};
use crate::manifest::{FORMAT, FileEntry, MANIFEST_FILE, Manifest, SceneStats, VERSION, ViewInfo};
use crate::{images, mesh_file};
use mesh_encoding::TriMesh;
use raycast_precompute::{
    PrecomputeSettings, ScenePrecompute, ShadowBias, View, ViewPrecompute, precompute_cached,
};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Mutex;

/// File stem of (view, light) data: `vVV_lLL`.
pub fn sample_stem(view: usize, light: usize) -> String {
    format!("v{view:02}_l{light:02}")
}

/// The images of one (view, light) pair, full frame, row-major.
pub struct PairImages {
    /// Observed linear radiance.
    pub observed: Vec<[f32; 3]>,
    /// Ground-truth BRDF (1/sr), 0 where unknown.
    pub brdf: Vec<[f32; 3]>,
    /// The noise-free radiance of a generated test pair (`clean/`), else `None`.
    pub clean: Option<Vec<[f32; 3]>>,
    /// [`flag`](crate::flag) bits per pixel, 0 where there is no sample.
    pub flags: Vec<u8>,
}

/// Everything of a scene but its images.
pub struct SceneContents<'a> {
    /// The scene's description (validated by the caller).
    pub config: &'a SceneConfig,
    /// The writing program and its version, for example "dataset-merl 0.1.0".
    pub generator: String,
    /// Provenance label of the data, for example "MERL-derived (NBRDF)".
    pub label: String,
    /// The mesh, in the cameras' world frame.
    pub mesh: &'a TriMesh,
    /// Cameras and light directions, as ray casting needs them.
    pub views: &'a [View],
    /// The same views as the manifest records them (splits, intrinsics, lights).
    pub view_infos: Vec<ViewInfo>,
    /// Whether some pairs carry a noise-free render (creates `clean/`).
    pub clean_renders: bool,
}

/// A written scene: its manifest and the ray-casting geometry it was written with.
pub struct Written {
    /// The manifest, as stored.
    pub manifest: Manifest,
    /// Per view: foreground pixels, hits, normals and light visibility.
    pub geometry: ScenePrecompute,
}

/// How [`write_scene`] shows progress: the bar's label and whether it is shown.
#[derive(Clone, Copy, Debug)]
pub struct Progress<'a> {
    /// Label before the bar, for example "rendering scenes/spot".
    pub label: &'a str,
    /// Whether the bar is drawn.
    pub visible: bool,
}

/// Writes a scene into `out` (replacing what is there once complete). `mask(view, geometry)`
/// gives a view's mask (255 = object), `pair(view, light, geometry)` a pair's images; pairs are
/// made in parallel. The statistics are counted from the flags and the masks.
pub fn write_scene<E>(
    out: &Path,
    contents: SceneContents<'_>,
    mask: impl Fn(usize, &ViewPrecompute) -> Vec<u8>,
    pair: impl Fn(usize, usize, &ViewPrecompute) -> std::result::Result<PairImages, E> + Sync,
    progress: Progress<'_>,
) -> std::result::Result<Written, E>
where
    E: From<Error> + From<stdx::fs::Error> + Send,
{
    let subdirs: &[&str] = if contents.clean_renders {
        &["images", "clean", "brdf", "flags", "masks", "previews"]
    } else {
        &["images", "brdf", "flags", "masks", "previews"]
    };
    stdx::fs::write_dir_atomic(out, subdirs, |tmp: &Path| -> std::result::Result<_, E> {
        let s = &contents.config.settings;
        let settings = PrecomputeSettings {
            shadow_bias: ShadowBias::Relative(s.shadow_bias_relative),
            ..Default::default()
        };
        let geometry =
            precompute_cached(contents.mesh, contents.views, &settings, &tmp.join("geometry"))
                .map_err(Error::from)?
                .0;
        let mut files = vec![write_file(tmp, "mesh.ply", mesh_file::ply_bytes(contents.mesh))?];
        let mut stats = SceneStats::default();
        for (vi, vp) in geometry.views.iter().enumerate() {
            let m = mask(vi, vp);
            stats.foreground_pixels += m.iter().filter(|&&x| x != 0).count() as u64;
            let rel = format!("masks/v{vi:02}.png");
            let bytes = images::write_png_gray(&tmp.join(&rel), vp.width, vp.height, &m)?;
            files.push(FileEntry::of(rel, &bytes));
        }
        let (pair_files, pair_stats) = write_pairs(tmp, &contents, &geometry, &pair, progress)?;
        files.extend(pair_files);
        stats.add_counts(&pair_stats);
        stats.update_saturated_fraction();
        files.sort_by(|a, b| a.path.cmp(&b.path));
        let mut manifest = Manifest {
            format: FORMAT.into(),
            version: VERSION,
            generator: contents.generator.clone(),
            label: contents.label.clone(),
            config: contents.config.clone(),
            mesh_file: "mesh.ply".into(),
            mesh_vertices: contents.mesh.positions.len(),
            mesh_triangles: contents.mesh.triangles.len(),
            views: contents.view_infos.clone(),
            files,
            stats,
            checksum: String::new(),
        };
        let json = manifest.to_json();
        let path = tmp.join(MANIFEST_FILE);
        std::fs::write(&path, json).map_err(|e| Error::io(&path, e))?;
        Ok(Written { manifest, geometry })
    })
}

/// Writes `bytes` to `rel` inside the scene directory and returns its manifest entry.
fn write_file(dir: &Path, rel: &str, bytes: Vec<u8>) -> Result<FileEntry> {
    let path = dir.join(rel);
    std::fs::write(&path, &bytes).map_err(|e| Error::io(&path, e))?;
    Ok(FileEntry::of(rel.into(), &bytes))
}

/// Makes and writes every (view, light) pair in parallel, with a progress bar: the pairs'
/// manifest entries and sample counts.
fn write_pairs<E>(
    tmp: &Path,
    contents: &SceneContents<'_>,
    geometry: &ScenePrecompute,
    pair: &(impl Fn(usize, usize, &ViewPrecompute) -> std::result::Result<PairImages, E> + Sync),
    progress: Progress<'_>,
) -> std::result::Result<(Vec<FileEntry>, SceneStats), E>
where
    E: From<Error> + Send,
{
    let jobs: Vec<(usize, usize)> = contents
        .views
        .iter()
        .enumerate()
        .flat_map(|(vi, v)| (0..v.lights.len()).map(move |li| (vi, li)))
        .collect();
    let bar = stdx::progress::bar(jobs.len() as u64, "images", progress.label, progress.visible);
    let files = Mutex::new(Vec::new());
    let stats = Mutex::new(SceneStats::default());
    jobs.par_iter().try_for_each(|&(vi, li)| -> std::result::Result<(), E> {
        let vp = &geometry.views[vi];
        let img = pair(vi, li, vp)?;
        let entries = write_pair_files(tmp, vi, li, vp, &img)?;
        files.lock().unwrap().extend(entries);
        stats.lock().unwrap().add_counts(&SceneStats::count_flags(&img.flags));
        bar.inc(1);
        Ok(())
    })?;
    bar.finish_and_clear();
    Ok((files.into_inner().unwrap(), stats.into_inner().unwrap()))
}

/// Writes one pair's `images/`, `brdf/`, `clean/` and `flags/` files, and the view's preview
/// under its first light.
fn write_pair_files(
    tmp: &Path,
    vi: usize,
    li: usize,
    vp: &ViewPrecompute,
    img: &PairImages,
) -> Result<Vec<FileEntry>> {
    let (w, h) = (vp.width as usize, vp.height as usize);
    let stem = sample_stem(vi, li);
    let mut entries = Vec::with_capacity(5);
    let mut exrs = vec![("images", &img.observed), ("brdf", &img.brdf)];
    if let Some(clean) = &img.clean {
        exrs.push(("clean", clean));
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
        let bytes = images::write_png_srgb(&tmp.join(&rel), vp.width, vp.height, &img.observed)?;
        entries.push(FileEntry::of(rel, &bytes));
    }
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flag;

    #[test]
    fn flags_count_into_the_statistics() {
        let flags = [
            0,
            flag::LIT | flag::GT_VALID,
            flag::LIT,
            flag::SHADOWED,
            flag::BACK_FACING | flag::SATURATED,
        ];
        let s = SceneStats::count_flags(&flags);
        assert_eq!((s.lit_samples, s.shadowed_samples, s.back_facing_samples), (2, 1, 1), "{s:?}");
        assert_eq!((s.saturated_samples, s.invalid_gt_samples), (1, 1));
        assert_eq!(sample_stem(3, 41), "v03_l41");
    }
}
