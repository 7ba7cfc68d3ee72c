//! The per-scene precompute: for every view, the first hit of every (foreground) pixel and, for
//! every light, whether the light reaches it.
//!
//! Per pixel: the camera ray through the pixel centre is traced to its closest hit; pixels with no
//! hit (or outside the given mask) are background and are dropped. Per hit and light direction l
//! (world space, unit, from the surface towards the light): if n.l <= 0 with n the interpolated
//! vertex normal, the pair is back-facing and no ray is traced; otherwise a shadow ray starts at
//! x + eps n_g, with n_g the geometric normal turned towards the camera and eps the shadow bias,
//! and any hit marks the pair shadowed. A point light's direction l is taken per pixel, from the
//! shadow-ray origin to the light, and its shadow ray ends at the light. No interreflection
//! (spec section 6).
//!
//! The result is stored struct-of-arrays per view (see [`ViewPrecompute`]).

use glam::Vec3;
use mesh_encoding::{NormalWeighting, TriMesh, interpolate_normal};
use rayon::prelude::*;

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::light::Light;
use crate::shadows::{TILE, Traversal, tile_rows, trace_shadows};
use crate::tracer::{Hit, Tracer};
use crate::visibility::Visibility;

/// One view of a scene: a camera, its lights and an optional foreground mask.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// The camera.
    pub camera: Camera,
    /// The lights, in world space (directions normalised on use).
    pub lights: Vec<Light>,
    /// Optional mask, row-major, `width * height` entries: only pixels marked true are traced.
    pub mask: Option<Vec<bool>>,
}

/// The shadow-ray offset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShadowBias {
    /// A fraction of the mesh's bounding-box diagonal (the default, 1e-4).
    Relative(f32),
    /// An absolute distance in mesh units.
    Absolute(f32),
}

impl Default for ShadowBias {
    fn default() -> Self {
        ShadowBias::Relative(1e-4)
    }
}

/// Settings of [`precompute`]; part of the cache key.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PrecomputeSettings {
    /// Offset of shadow-ray origins along the geometric normal.
    pub shadow_bias: ShadowBias,
    /// How vertex normals are computed from the mesh.
    pub normal_weighting: NormalWeighting,
}

/// The precompute of one view, struct of arrays over its foreground pixels (those whose camera
/// ray hit the mesh), in increasing pixel order.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct ViewPrecompute {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Row-major pixel index (row * width + column) of each foreground pixel.
    pub pixels: Vec<u32>,
    /// Hit triangle.
    pub triangles: Vec<u32>,
    /// Barycentrics (b1, b2) of the hit, see [`crate::Hit`].
    pub barycentrics: Vec<[f32; 2]>,
    /// Hit position in world space.
    pub positions: Vec<Vec3>,
    /// Interpolated unit vertex normal at the hit (not flipped towards the camera).
    pub normals: Vec<Vec3>,
    /// Unit direction from the hit towards the camera centre.
    pub view_dirs: Vec<Vec3>,
    /// The view's lights (world space; directions unit, towards the light).
    pub lights: Vec<Light>,
    /// Per (foreground pixel, light) visibility.
    pub visibility: Visibility,
}

impl ViewPrecompute {
    /// Number of foreground pixels.
    pub fn len(&self) -> usize {
        self.pixels.len()
    }

    /// True when no pixel hit the mesh.
    pub fn is_empty(&self) -> bool {
        self.pixels.is_empty()
    }
}

/// Ray counts of a precompute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct TraceStats {
    /// Camera rays traced.
    pub primary_rays: u64,
    /// Shadow rays traced.
    pub shadow_rays: u64,
    /// (pixel, light) pairs skipped as back-facing.
    pub skipped_back_facing: u64,
}

/// The precompute of a scene.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct ScenePrecompute {
    /// One entry per input view, in order.
    pub views: Vec<ViewPrecompute>,
    /// The shadow bias used, in mesh units.
    pub shadow_bias: f32,
    /// Ray counts.
    pub stats: TraceStats,
}

/// Checks the views and returns their light lists, directions normalised.
pub(crate) fn validate_views(views: &[View]) -> Result<Vec<Vec<Light>>> {
    views
        .iter()
        .enumerate()
        .map(|(i, v)| {
            if let Some(mask) = &v.mask
                && mask.len() != v.camera.pixel_count()
            {
                return Err(Error::View {
                    view: i,
                    message: format!(
                        "mask has {} entries, the image {}",
                        mask.len(),
                        v.camera.pixel_count()
                    ),
                });
            }
            v.lights
                .iter()
                .enumerate()
                .map(|(l, light)| {
                    light.validated().ok_or_else(|| Error::View {
                        view: i,
                        message: match light {
                            Light::Directional(d) => {
                                format!("light {l} direction {d} is not a finite non-zero vector")
                            }
                            Light::Point(p) => format!("light {l} position {p} is not finite"),
                        },
                    })
                })
                .collect()
        })
        .collect()
}

/// Shadow bias in mesh units.
pub(crate) fn bias_length(mesh: &TriMesh, bias: ShadowBias) -> f32 {
    match bias {
        ShadowBias::Relative(f) => f * mesh.diagonal(),
        ShadowBias::Absolute(d) => d,
    }
}

/// Runs the precompute (no cache), see the module documentation.
///
/// # Errors
/// [`Error::View`] when a mask has the wrong size or a light direction is zero or not finite.
pub fn precompute(
    mesh: &TriMesh,
    views: &[View],
    settings: &PrecomputeSettings,
) -> Result<ScenePrecompute> {
    let lights = validate_views(views)?;
    let tracer = Tracer::new(mesh);
    Ok(precompute_with(&tracer, views, &lights, settings, Traversal::default()))
}

/// [`precompute`] on an already built [`Tracer`] (to reuse one BVH for several calls).
///
/// # Errors
/// As [`precompute`].
pub fn precompute_with_tracer(
    tracer: &Tracer,
    views: &[View],
    settings: &PrecomputeSettings,
) -> Result<ScenePrecompute> {
    precompute_with_traversal(tracer, views, settings, Traversal::default())
}

/// [`precompute_with_tracer`] with a chosen shadow-ray [`Traversal`]; every choice gives the same
/// (bit-identical) result, [`Traversal::OneByOne`] is the simple reference path.
///
/// # Errors
/// As [`precompute`].
pub fn precompute_with_traversal(
    tracer: &Tracer,
    views: &[View],
    settings: &PrecomputeSettings,
    traversal: Traversal,
) -> Result<ScenePrecompute> {
    let lights = validate_views(views)?;
    Ok(precompute_with(tracer, views, &lights, settings, traversal))
}

/// The precompute on a built tracer with validated lights.
pub(crate) fn precompute_with(
    tracer: &Tracer,
    views: &[View],
    lights: &[Vec<Light>],
    settings: &PrecomputeSettings,
    traversal: Traversal,
) -> ScenePrecompute {
    let mesh = tracer.mesh();
    let vertex_normals = mesh.vertex_normals(settings.normal_weighting);
    let bias = bias_length(mesh, settings.shadow_bias);
    let bar = stdx::progress::bar(views.len() as u64, "views", "ray casting", true);
    let mut out = ScenePrecompute { shadow_bias: bias, ..Default::default() };
    for (view, lights) in views.iter().zip(lights) {
        let (vp, stats) = trace_view(tracer, &vertex_normals, view, lights, bias, traversal);
        out.stats.primary_rays += stats.primary_rays;
        out.stats.shadow_rays += stats.shadow_rays;
        out.stats.skipped_back_facing += stats.skipped_back_facing;
        out.views.push(vp);
        bar.inc(1);
    }
    bar.finish_and_clear();
    out
}

/// One foreground pixel's first hit.
struct PixelHit {
    pixel: u32,
    triangle: u32,
    barycentrics: [f32; 2],
    position: Vec3,
    normal: Vec3,
    view_dir: Vec3,
    /// Shadow-ray origin: the hit offset along the camera-facing geometric normal.
    shadow_origin: Vec3,
}

/// The camera rays of the candidate pixels that hit the mesh, in pixel order, each shaded by
/// `shade(pixel, direction, hit)`: one ray at a time, or rows of 8 x 8-tile packets.
fn trace_primary(
    tracer: &Tracer,
    cam: &Camera,
    candidates: &[u32],
    traversal: Traversal,
    shade: &(impl Fn(u32, Vec3, Hit) -> PixelHit + Sync),
) -> Vec<PixelHit> {
    match traversal {
        Traversal::OneByOne => candidates
            .par_iter()
            .filter_map(|&pixel| {
                let (origin, dir) = cam.pixel_ray(pixel as usize);
                let hit = tracer.closest_hit(origin, dir, f32::INFINITY)?;
                Some(shade(pixel, dir, hit))
            })
            .collect(),
        Traversal::Packets => {
            // Rows of 8 x 8 tiles in parallel, each tile's camera rays traced as packets.
            let rows: Vec<Vec<PixelHit>> = tile_rows(candidates, cam.width, TILE)
                .par_iter()
                .map(|row| {
                    let mut out = Vec::new();
                    let (mut origins, mut dirs, mut found) = (Vec::new(), Vec::new(), Vec::new());
                    for tile in row {
                        origins.clear();
                        dirs.clear();
                        for &pixel in tile {
                            let (o, d) = cam.pixel_ray(pixel as usize);
                            origins.push(o);
                            dirs.push(d);
                        }
                        found.clear();
                        found.resize(tile.len(), None);
                        tracer.closest_hits(&origins, &dirs, &mut found);
                        for ((&pixel, &dir), hit) in tile.iter().zip(&dirs).zip(&found) {
                            if let Some(hit) = hit {
                                out.push(shade(pixel, dir, *hit));
                            }
                        }
                    }
                    out.sort_unstable_by_key(|h| h.pixel);
                    out
                })
                .collect();
            rows.into_iter().flatten().collect()
        }
    }
}

fn trace_view(
    tracer: &Tracer,
    vertex_normals: &[Vec3],
    view: &View,
    lights: &[Light],
    bias: f32,
    traversal: Traversal,
) -> (ViewPrecompute, TraceStats) {
    let cam = &view.camera;
    let mesh = tracer.mesh();
    let candidates: Vec<u32> = match &view.mask {
        Some(mask) => (0..mask.len() as u32).filter(|&i| mask[i as usize]).collect(),
        None => (0..cam.pixel_count() as u32).collect(),
    };
    let shade = |pixel: u32, dir: Vec3, hit: Hit| {
        let [b1, b2] = hit.barycentrics;
        let tri = mesh.triangles[hit.triangle as usize];
        let [v0, v1, v2] = mesh.corners(hit.triangle as usize);
        let position = (1.0 - b1 - b2) * v0 + b1 * v1 + b2 * v2;
        let geometric = (v1 - v0).cross(v2 - v0).normalize_or(Vec3::Z);
        let facing = if geometric.dot(dir) > 0.0 { -geometric } else { geometric };
        let n = tri.map(|i| vertex_normals[i as usize]);
        PixelHit {
            pixel,
            triangle: hit.triangle,
            barycentrics: hit.barycentrics,
            position,
            normal: interpolate_normal(n, b1, b2, facing),
            view_dir: -dir,
            shadow_origin: position + bias * facing,
        }
    };
    let hits = trace_primary(tracer, cam, &candidates, traversal, &shade);

    let origins: Vec<Vec3> = hits.iter().map(|h| h.shadow_origin).collect();
    let normals: Vec<Vec3> = hits.iter().map(|h| h.normal).collect();
    let pixels: Vec<u32> = hits.iter().map(|h| h.pixel).collect();
    let (visibility, shadow_rays, skipped) =
        trace_shadows(tracer, &origins, &normals, &pixels, cam.width, lights, traversal);
    let stats = TraceStats {
        primary_rays: candidates.len() as u64,
        shadow_rays,
        skipped_back_facing: skipped,
    };
    let vp = ViewPrecompute {
        width: cam.width,
        height: cam.height,
        pixels,
        triangles: hits.iter().map(|h| h.triangle).collect(),
        barycentrics: hits.iter().map(|h| h.barycentrics).collect(),
        positions: hits.iter().map(|h| h.position).collect(),
        normals,
        view_dirs: hits.iter().map(|h| h.view_dir).collect(),
        lights: lights.to_vec(),
        visibility,
    };
    (vp, stats)
}
