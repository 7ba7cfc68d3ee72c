//! The mesh against the benchmark's ground-truth normal maps (`Normal_gt.mat`, one per capture
//! directory: a rows x cols x 3 double array of unit normals in DiLiGenT's camera frame, zero
//! outside the object): the angle between the ray-cast interpolated normal and the map's
//! normal, over the pixels that are in the mask, hit the mesh and have a ground-truth normal.

use crate::error::{Error, Result};
use crate::mat5::{MatFile, MatVariable};
use crate::pms_dir::diligent_to_opencv;
use crate::report::NormalCheck;
use glam::{DVec3, Mat3};
use raycast_precompute::ViewPrecompute;
use std::path::Path;
use stdx::Limits;

/// The ground-truth normal map file of a capture directory.
pub const NORMAL_GT: &str = "Normal_gt.mat";

/// Reads `dir/Normal_gt.mat` when present (within `limits`) and checks it is `height` x `width`
/// x 3.
pub fn read_normal_map(
    dir: &Path,
    width: u32,
    height: u32,
    limits: &Limits,
) -> Result<Option<MatVariable>> {
    let path = dir.join(NORMAL_GT);
    if !path.is_file() {
        return Ok(None);
    }
    let mat = MatFile::read(&path, limits)?;
    let var = mat.numeric(&["Normal_gt"])?.clone();
    let (h, w) = (height as usize, width as usize);
    if var.dims != [h, w, 3] {
        return Err(Error::Mat {
            path,
            fault: format!("`Normal_gt` is {}, expected {h} x {w} x 3", var.shape()),
        });
    }
    Ok(Some(var))
}

/// Angular errors (degrees) of one view: mesh normals (world frame) rotated into the camera by
/// `r`, against `gt` at the view's foreground pixels inside `mask`.
pub fn view_errors(g: &ViewPrecompute, mask: &[bool], r: Mat3, gt: &MatVariable) -> Vec<f64> {
    let w = g.width as usize;
    let mut errs = Vec::with_capacity(g.len());
    for k in 0..g.len() {
        let p = g.pixels[k] as usize;
        if !mask[p] {
            continue;
        }
        let (row, col) = (p / w, p % w);
        let truth = DVec3::from_array([0, 1, 2].map(|c| gt.at(&[row, col, c]).unwrap_or(0.0)));
        let Some(truth) = truth.try_normalize() else { continue };
        let n_cam = (r * g.normals[k]).as_dvec3().to_array();
        let Some(m) = DVec3::from_array(diligent_to_opencv(n_cam)).try_normalize() else {
            continue;
        };
        errs.push(m.dot(truth).clamp(-1.0, 1.0).acos().to_degrees());
    }
    errs
}

/// Mean, median, 95th percentile and maximum of angular errors; `None` when empty.
pub fn summarize(mut errs: Vec<f64>) -> Option<NormalCheck> {
    if errs.is_empty() {
        return None;
    }
    errs.sort_by(f64::total_cmp);
    let q = |f: f64| errs[((errs.len() - 1) as f64 * f).round() as usize];
    Some(NormalCheck {
        pixels: errs.len(),
        mean_deg: errs.iter().sum::<f64>() / errs.len() as f64,
        median_deg: q(0.5),
        p95_deg: q(0.95),
        max_deg: errs[errs.len() - 1],
    })
}
