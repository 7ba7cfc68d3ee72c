//! What an import did: the scene written, per-view agreement between the captured mask and the
//! mesh, and the shape checks (circle fit, normal error, decimation).

use crate::decimate::DecimateReport;
use scene::{SceneStats, Split};
use std::path::PathBuf;

/// One view of the written scene.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewReport {
    /// The capture directory it came from.
    pub source: PathBuf,
    /// Its split.
    pub split: Split,
    /// The lights used, as 1-based image numbers of the capture.
    pub lights: Vec<u32>,
    /// Pixels in the captured mask.
    pub mask_pixels: u64,
    /// Pixels whose camera ray hits the mesh.
    pub mesh_pixels: u64,
    /// Pixels in both (the samples' support).
    pub both_pixels: u64,
}

impl ViewReport {
    /// Intersection over union of the captured mask and the mesh's projection.
    pub fn mask_iou(&self) -> f64 {
        let union = self.mask_pixels + self.mesh_pixels - self.both_pixels;
        self.both_pixels as f64 / union.max(1) as f64
    }
}

/// A circle fitted to a mask, pixel coordinates (pixel (i, j) covers [i, i + 1) x [j, j + 1)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CircleFit {
    /// Centre, x (column) and y (row).
    pub center: [f64; 2],
    /// Radius in pixels.
    pub radius: f64,
    /// RMS distance of the mask's boundary points from the circle, pixels.
    pub rms_residual: f64,
    /// Radius of the disc with the mask's area, for comparison.
    pub area_radius: f64,
    /// Boundary points used.
    pub boundary_points: usize,
}

/// Angular error between the mesh's shading normals and a ground-truth normal map, over the
/// pixels in both the mask and the mesh's projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalCheck {
    /// Pixels compared.
    pub pixels: usize,
    /// Mean error, degrees.
    pub mean_deg: f64,
    /// Median error, degrees.
    pub median_deg: f64,
    /// 95th percentile, degrees.
    pub p95_deg: f64,
    /// Largest error, degrees.
    pub max_deg: f64,
}

/// What [`import_single_view`](crate::import_single_view) or
/// [`import_multi_view`](crate::import_multi_view) did.
#[derive(Clone, Debug)]
pub struct ImportReport {
    /// The scene directory written.
    pub dir: PathBuf,
    /// Provenance label, for example "captured (DiLiGenT ball)".
    pub label: String,
    /// Wall time, seconds.
    pub seconds: f64,
    /// Size of the listed data files, bytes.
    pub bytes: u64,
    /// Sample statistics (as the semi-synthetic scenes report them; every lit sample counts as
    /// "invalid ground truth" since a capture has no ground-truth BRDF).
    pub stats: SceneStats,
    /// The views written, in manifest order.
    pub views: Vec<ViewReport>,
    /// The scene mesh's vertex count.
    pub mesh_vertices: usize,
    /// Its triangle count.
    pub mesh_triangles: usize,
    /// The decimation, when the source mesh was decimated.
    pub decimation: Option<DecimateReport>,
    /// The circle fitted to the mask (single view).
    pub circle: Option<CircleFit>,
    /// The mesh normals against the ground-truth normal map (single view, when present).
    pub normal_check: Option<NormalCheck>,
    /// Things the importer noticed but did not refuse (ignored lens distortion, ...).
    pub warnings: Vec<String>,
}
