//! Reading a scene directory back: the dataset API that training and evaluation use.
//!
//! [`SceneDataset::open`] checks the manifest (format, version, its own checksum) and every
//! listed file (size and hash), loads the mesh and the ray-casting geometry (from the scene's
//! cache, rebuilt if damaged), and [`SceneDataset::samples`] gathers the lit foreground
//! (pixel, light) records of a split as a struct of arrays.

use crate::error::{Error, Result};
use crate::flag;
use crate::images;
use crate::manifest::{LightInfo, MANIFEST_FILE, Manifest, Split};
use crate::mesh_file;
use crate::shading::light_at;
use crate::writer::sample_stem;
use glam::Vec3;
use mesh_encoding::TriMesh;
use raycast_precompute::{
    Camera, PrecomputeSettings, ScenePrecompute, ShadowBias, View, mat3_from_rows,
    precompute_cached,
};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use stdx::Limits;

/// An opened, verified scene.
pub struct SceneDataset {
    /// The scene directory.
    pub dir: PathBuf,
    /// Its manifest.
    pub manifest: Manifest,
    /// The mesh the scene was rendered with (normalised).
    pub mesh: TriMesh,
    /// Per view: foreground pixels, hits, normals, view directions and light visibility.
    pub geometry: ScenePrecompute,
}

/// Lit foreground (pixel, light) samples of one split, struct of arrays (index i across all
/// fields is one sample). Directions are world-space unit vectors.
#[derive(Clone, Debug, Default)]
pub struct SampleSet {
    /// View index.
    pub view: Vec<u16>,
    /// Light index within the view.
    pub light: Vec<u16>,
    /// Pixel index (row-major) within the view.
    pub pixel: Vec<u32>,
    /// Hit triangle.
    pub triangle: Vec<u32>,
    /// Barycentrics (b1, b2) of the hit: P = (1 - b1 - b2) v0 + b1 v1 + b2 v2.
    pub barycentric: Vec<[f32; 2]>,
    /// Hit position.
    pub position: Vec<[f32; 3]>,
    /// Interpolated unit shading normal.
    pub normal: Vec<[f32; 3]>,
    /// Unit direction to the light.
    pub l: Vec<[f32; 3]>,
    /// Unit direction to the camera.
    pub v: Vec<[f32; 3]>,
    /// Light irradiance E (RGB) at the sample (a point light's falls off with the square of
    /// its distance); the rendering is L = f E cos(theta_l).
    pub irradiance: Vec<[f32; 3]>,
    /// Observed radiance.
    pub observed: Vec<[f32; 3]>,
    /// Ground-truth BRDF (1/sr); meaningful where `gt_valid`.
    pub gt_brdf: Vec<[f32; 3]>,
    /// Whether the ground-truth BRDF is valid.
    pub gt_valid: Vec<bool>,
    /// Whether a channel of the observation is saturated.
    pub saturated: Vec<bool>,
}

impl SampleSet {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.pixel.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.pixel.is_empty()
    }
}

impl SceneDataset {
    /// Opens and verifies a scene directory.
    pub fn open(dir: &Path) -> Result<Self> {
        let manifest = Manifest::read(&dir.join(MANIFEST_FILE))?;
        manifest.verify_files(dir)?;
        let mesh_path = dir.join(&manifest.mesh_file);
        let mesh = mesh_file::load(&mesh_path)?;
        if mesh.positions.len() != manifest.mesh_vertices
            || mesh.triangles.len() != manifest.mesh_triangles
        {
            return Err(Error::Dataset {
                path: mesh_path,
                fault: format!(
                    "{} vertices / {} triangles, the manifest says {} / {}",
                    mesh.positions.len(),
                    mesh.triangles.len(),
                    manifest.mesh_vertices,
                    manifest.mesh_triangles
                ),
            });
        }
        let s = &manifest.config.settings;
        let views = manifest
            .views
            .iter()
            .map(|v| {
                let camera = Camera::from_opencv(
                    mat3_from_rows(v.k),
                    mat3_from_rows(v.r),
                    Vec3::from_array(v.t),
                    s.width,
                    s.height,
                )?;
                let lights = v.lights.iter().map(LightInfo::source).collect();
                Ok(View { camera, lights, mask: None })
            })
            .collect::<Result<Vec<_>>>()?;
        let settings = PrecomputeSettings {
            shadow_bias: ShadowBias::Relative(s.shadow_bias_relative),
            ..Default::default()
        };
        let (geometry, _) = precompute_cached(&mesh, &views, &settings, &dir.join("geometry"))?;
        Ok(Self { dir: dir.into(), manifest, mesh, geometry })
    }

    /// The (view, light) pairs of a split: the split's views with the split's lights.
    pub fn pairs(&self, split: Split) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for (vi, v) in self.manifest.views.iter().enumerate() {
            if v.split != split {
                continue;
            }
            for (li, l) in v.lights.iter().enumerate() {
                if l.split == split {
                    out.push((vi, li));
                }
            }
        }
        out
    }

    /// What the scene's image readers accept: no image larger than the (checksummed)
    /// manifest's own size, so that a header that disagrees with it is refused before the
    /// reader allocates.
    fn image_limits(&self) -> Limits {
        let s = &self.manifest.config.settings;
        Limits { max_image_pixels: u64::from(s.width) * u64::from(s.height), ..Limits::DEFAULT }
    }

    /// The observed image of (view, light), row-major.
    pub fn observed_image(&self, view: usize, light: usize) -> Result<Vec<[f32; 3]>> {
        self.read_exr("images", view, light)
    }

    fn read_exr(&self, dir: &str, view: usize, light: usize) -> Result<Vec<[f32; 3]>> {
        let path = self.dir.join(format!("{dir}/{}.exr", sample_stem(view, light)));
        let (w, h, px) = images::read_exr_rgb(&path, &self.image_limits())?;
        let s = &self.manifest.config.settings;
        if (w, h) != (s.width as usize, s.height as usize) {
            return Err(Error::Dataset {
                path,
                fault: format!("{w} x {h} pixels, the manifest says {} x {}", s.width, s.height),
            });
        }
        Ok(px)
    }

    /// The noise-free render of a test (view, light) pair, clipped like the observation:
    /// `None` when the scene has none (captured data, or a training pair).
    pub fn clean_image(&self, view: usize, light: usize) -> Result<Option<Vec<[f32; 3]>>> {
        let rel = format!("clean/{}.exr", sample_stem(view, light));
        if !self.manifest.files.iter().any(|f| f.path == rel) {
            return Ok(None);
        }
        self.read_exr("clean", view, light).map(Some)
    }

    /// Whether the scene carries noise-free renders of its test pairs (semi-synthetic scenes).
    pub fn has_clean_renders(&self) -> bool {
        self.manifest.files.iter().any(|f| f.path.starts_with("clean/"))
    }

    /// The flags image of (view, light).
    pub fn flags_image(&self, view: usize, light: usize) -> Result<Vec<u8>> {
        let path = self.dir.join(format!("flags/{}.png", sample_stem(view, light)));
        let (_, _, px) = images::read_png_gray(&path, &self.image_limits())?;
        Ok(px)
    }

    /// Gathers the lit samples of a split (shadowed and back-facing samples carry no
    /// information about the BRDF and are left out).
    pub fn samples(&self, split: Split) -> Result<SampleSet> {
        let parts: Vec<SampleSet> = self
            .pairs(split)
            .par_iter()
            .map(|&(vi, li)| self.pair_samples(vi, li))
            .collect::<Result<_>>()?;
        let mut all = SampleSet::default();
        for p in parts {
            all.view.extend(p.view);
            all.light.extend(p.light);
            all.pixel.extend(p.pixel);
            all.triangle.extend(p.triangle);
            all.barycentric.extend(p.barycentric);
            all.position.extend(p.position);
            all.normal.extend(p.normal);
            all.l.extend(p.l);
            all.v.extend(p.v);
            all.irradiance.extend(p.irradiance);
            all.observed.extend(p.observed);
            all.gt_brdf.extend(p.gt_brdf);
            all.gt_valid.extend(p.gt_valid);
            all.saturated.extend(p.saturated);
        }
        Ok(all)
    }

    fn pair_samples(&self, vi: usize, li: usize) -> Result<SampleSet> {
        let observed = self.read_exr("images", vi, li)?;
        let brdf = self.read_exr("brdf", vi, li)?;
        let flags = self.flags_image(vi, li)?;
        let g = &self.geometry.views[vi];
        let light = &self.manifest.views[vi].lights[li];
        let mut s = SampleSet::default();
        for k in 0..g.len() {
            let p = g.pixels[k] as usize;
            let f = flags[p];
            if f & flag::LIT == 0 {
                continue;
            }
            let Some((l, irradiance)) = light_at(light, g.positions[k].to_array()) else {
                continue; // a point light at the surface point itself: never lit
            };
            s.view.push(vi as u16);
            s.light.push(li as u16);
            s.pixel.push(p as u32);
            s.triangle.push(g.triangles[k]);
            s.barycentric.push(g.barycentrics[k]);
            s.position.push(g.positions[k].to_array());
            s.normal.push(g.normals[k].to_array());
            s.l.push(l);
            s.v.push(g.view_dirs[k].to_array());
            s.irradiance.push(irradiance);
            s.observed.push(observed[p]);
            s.gt_brdf.push(brdf[p]);
            s.gt_valid.push(f & flag::GT_VALID != 0);
            s.saturated.push(f & flag::SATURATED != 0);
        }
        Ok(s)
    }
}
