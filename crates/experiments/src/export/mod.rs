//! Fitted materials out of the tool: a MERL table at one surface point ([`merl`]), and for the
//! parametric fits (Disney, Torrance-Sparrow) the per-vertex parameters ([`material`]) written
//! as a glTF 2.0 asset ([`gltf`]), a Mitsuba 3 scene ([`mitsuba`]) and a pbrt-v4 scene
//! ([`pbrt`]), the last two with the scene's cameras and lights. [`round_trip`] re-renders the
//! test views from an exported file with `brdf-analytic` and scores it against the fit's own
//! renders. [`crate::portable`] (written by every fit) holds any fitted model's weights as safetensors with a JSON
//! description, for PyTorch and numpy users.
//!
//! Purely neural fits leave as MERL tables, and as Mitsuba 3 scenes whose `neural_brdf` BSDF
//! (the Python package's plugin, `neural_brdfs.mitsuba`) evaluates the network itself
//! ([`mitsuba::neural_bsdf`]). The RGL tabulated format (Dupuy and Jakob
//! 2018) that Mitsuba 3's and pbrt-v4's `measured` BSDFs read is not written: its readers take
//! spectral samples (`wavelengths`, `spectra`), while every fit here is RGB, so a file would
//! need invented spectra (an RGB-to-spectrum upsampling the renderer then integrates back, not
//! the fitted values), besides the format's NDF recovered by power iteration and its
//! visible-normal warps. A MERL table is the faithful tabulation of an RGB fit.

pub mod bundle;
pub mod gltf;
pub mod material;
pub mod merl;
pub mod mitsuba;
pub mod pbrt;
pub mod ply;
pub mod round_trip;

pub use bundle::{ExportSummary, Format, export};
pub use material::{ExportedMaterial, MaterialKind};
pub use merl::{MerlExport, export_merl, tabulate_merl};

pub use crate::data::vertex_features;
use scene::SceneDataset;

/// Which surface point the table describes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SurfacePoint {
    /// The vertex whose features are closest to the mean over all vertices.
    #[default]
    Representative,
    /// A given vertex index.
    Vertex(usize),
}

/// The row of `table` (`[n, dim]`) closest to the mean row.
pub fn representative_row(table: &[f32], dim: usize) -> Option<usize> {
    let n = table.len().checked_div(dim)?;
    if n == 0 {
        return None;
    }
    let mut mean = vec![0.0f64; dim];
    for row in table.chunks_exact(dim) {
        for (m, &x) in mean.iter_mut().zip(row) {
            *m += x as f64 / n as f64;
        }
    }
    let dist =
        |row: &[f32]| -> f64 { row.iter().zip(&mean).map(|(&x, m)| (x as f64 - m).powi(2)).sum() };
    (0..n).min_by(|&a, &b| {
        dist(&table[a * dim..(a + 1) * dim]).total_cmp(&dist(&table[b * dim..(b + 1) * dim]))
    })
}

/// A test view's pinhole camera in the terms renderers take (OpenCV axes in world space).
#[derive(Clone, Debug, PartialEq)]
pub struct ExportCamera {
    /// Camera centre C = -R^T t.
    pub center: [f64; 3],
    /// World directions of the image's x (right), y (down) and viewing axes (rows of R).
    pub right: [f64; 3],
    /// See `right`.
    pub down: [f64; 3],
    /// See `right`.
    pub forward: [f64; 3],
    /// Focal lengths and principal point, pixels.
    pub fx: f64,
    /// See `fx`.
    pub fy: f64,
    /// See `fx`.
    pub cx: f64,
    /// See `fx`.
    pub cy: f64,
    /// Image size, pixels.
    pub width: u32,
    /// See `width`.
    pub height: u32,
}

impl ExportCamera {
    /// Vertical field of view, degrees.
    pub fn fov_y_deg(&self) -> f64 {
        2.0 * (0.5 * self.height as f64 / self.fy).atan().to_degrees()
    }

    /// Horizontal field of view, degrees.
    pub fn fov_x_deg(&self) -> f64 {
        2.0 * (0.5 * self.width as f64 / self.fx).atan().to_degrees()
    }
}

/// One test (view, light) pair of a scene, as a renderer needs it.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportPair {
    /// View index.
    pub view: usize,
    /// Light index within the view.
    pub light: usize,
    /// The view's camera.
    pub camera: ExportCamera,
    /// Unit world direction from the surface towards the light (a point light: from the scene's
    /// centre, for display).
    pub direction: [f32; 3],
    /// Irradiance on a surface facing the light, RGB (a point light: its radiant intensity).
    pub irradiance: [f32; 3],
    /// A point light's position (None: directional).
    pub position: Option<[f32; 3]>,
}

impl ExportPair {
    /// File stem, the one of the run's renders (`view003_light002`).
    pub fn stem(&self) -> String {
        format!("view{:03}_light{:03}", self.view, self.light)
    }
}

/// The test pairs of a scene with their cameras and lights.
pub fn test_pairs(scene: &SceneDataset) -> Vec<ExportPair> {
    let s = &scene.manifest.config.settings;
    scene
        .pairs(scene::Split::Test)
        .into_iter()
        .map(|(vi, li)| {
            let v = &scene.manifest.views[vi];
            let row = |i: usize| v.r[i].map(f64::from);
            let t = v.t.map(f64::from);
            let mut center = [0.0; 3];
            for (j, c) in center.iter_mut().enumerate() {
                *c = -(0..3).map(|i| v.r[i][j] as f64 * t[i]).sum::<f64>();
            }
            let light = &v.lights[li];
            ExportPair {
                view: vi,
                light: li,
                camera: ExportCamera {
                    center,
                    right: row(0),
                    down: row(1),
                    forward: row(2),
                    fx: v.k[0][0] as f64,
                    fy: v.k[1][1] as f64,
                    cx: v.k[0][2] as f64,
                    cy: v.k[1][2] as f64,
                    width: s.width,
                    height: s.height,
                },
                direction: light.direction,
                irradiance: light.intensity,
                position: light.position,
            }
        })
        .collect()
}
