//! Importing a DiLiGenT-MV object (`mvpmsData/<obj>PNG/`) as a scene: 20 views x 96 calibrated
//! directional lights, the camera calibration and the ground-truth mesh.
//!
//! Layout read (names configurable where the release may differ):
//!
//! | path | contents |
//! | --- | --- |
//! | `view_01/ ... view_NN/` | one [`Capture`] each (images, light files, mask) |
//! | `Calib_Results.mat` | `KK` (3 x 3, shared) and per view `Rc_i` (3 x 3), `Tc_i` (3 x 1), i = 1..N (also `Rc_01`); `kc` distortion, if present and non-zero, is reported as ignored |
//! | `mesh_Gt.ply` (or the only `.ply`) | the ground-truth mesh in the calibration's world frame |
//!
//! Cameras: see [`crate::calibration`] (x_c = Rc x_w + Tc; the principal point gets
//! [`MultiViewOptions::principal_point_offset`]; non-orthonormal Rc are factored exactly into
//! the intrinsics). Light directions are in each view's camera frame (DiLiGenT's axes, see
//! [`crate::pms_dir`]) and go to the world as R^T (x, -y, -z). When a view ships its
//! `Normal_gt.mat`, the mesh's normals are compared with it ([`crate::normal_check`]).
//!
//! The mesh is cleaned, decimated to [`MultiViewOptions::target_vertices`] (quadric error, see
//! [`crate::decimate`]; normals are recomputed from the result by the ray casting), then moved
//! into the unit sphere with the cameras moved along (t' = s (R c + t) for x' = s (x - c)).
//! Split: alternate views (or a list) x seeded disjoint light sets, see [`crate::split`].

use crate::calibration::Calibration;
use crate::decimate::{DecimateOptions, decimate};
use crate::error::{Error, Result};
use crate::normal_check::{read_normal_map, summarize, view_errors};
use crate::pms_dir::Capture;
use crate::report::ImportReport;
use crate::scene_writer::{CapturedScene, ViewSpec, write_captured_scene};
use crate::single_view::object_name;
use crate::split::{split_lights, train_views};
use glam::DMat3;
use scene::Split;
use std::path::{Path, PathBuf};
use std::time::Instant;
use stdx::Limits;

/// Options of [`import_multi_view`].
///
/// | field | default | meaning |
/// | --- | --- | --- |
/// | `views` | 20 | views expected (`view_01` ..); a missing one is an error |
/// | `train_views` | alternate | 1-based training views; the rest test |
/// | `train_lights`, `test_lights` | 30, 12 | lights per training / test view (paper) |
/// | `seed` | 0 | seed of the light split |
/// | `calibration` | `<obj>/Calib_Results.mat` | the calibration file |
/// | `mesh` | `<obj>/mesh_Gt.ply`, else the only `.ply` | the ground-truth mesh |
/// | `target_vertices` | 100 000 | decimation target (`None`: keep the mesh) |
/// | `principal_point_offset` | 0.5 | added to KK's principal point |
/// | `saturation_level` | 65535 | raw value at which a channel counts as saturated |
/// | `shadow_bias_relative` | 1e-4 | shadow-ray offset, fraction of the mesh diagonal |
/// | `progress` | false | progress bars |
/// | `limits` | `Limits::DEFAULT` | what the image and MAT readers accept (`stdx::Limits`) |
#[derive(Clone, Debug, PartialEq)]
pub struct MultiViewOptions {
    /// Number of views expected.
    pub views: usize,
    /// Training views (1-based); `None` alternates.
    pub train_views: Option<Vec<usize>>,
    /// Lights per training view.
    pub train_lights: usize,
    /// Lights per test view.
    pub test_lights: usize,
    /// Seed of the light split.
    pub seed: u64,
    /// Calibration file; `None` is `<obj>/Calib_Results.mat`.
    pub calibration: Option<PathBuf>,
    /// Mesh file; `None` searches the object directory.
    pub mesh: Option<PathBuf>,
    /// Decimation target.
    pub target_vertices: Option<usize>,
    /// Added to the principal point.
    pub principal_point_offset: f64,
    /// Saturation level of raw values.
    pub saturation_level: u16,
    /// Shadow bias.
    pub shadow_bias_relative: f32,
    /// Progress bars.
    pub progress: bool,
    /// What the image and MAT readers accept.
    pub limits: Limits,
}

impl Default for MultiViewOptions {
    fn default() -> Self {
        Self {
            views: 20,
            train_views: None,
            train_lights: 30,
            test_lights: 12,
            seed: 0,
            calibration: None,
            mesh: None,
            target_vertices: Some(100_000),
            principal_point_offset: 0.5,
            saturation_level: 65535,
            shadow_bias_relative: 1e-4,
            progress: false,
            limits: Limits::DEFAULT,
        }
    }
}

/// The mesh file of an object directory.
fn find_mesh(dir: &Path) -> Result<PathBuf> {
    let gt = dir.join("mesh_Gt.ply");
    if gt.is_file() {
        return Ok(gt);
    }
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let plys: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("ply")))
        .collect();
    match plys.as_slice() {
        [one] => Ok(one.clone()),
        [] => Err(Error::input(dir, "no ground-truth mesh (mesh_Gt.ply or another .ply)")),
        _ => Err(Error::input(dir, format!("{} .ply files; name the mesh to use", plys.len()))),
    }
}

fn rows(m: DMat3) -> [[f32; 3]; 3] {
    let t = m.transpose();
    [t.x_axis, t.y_axis, t.z_axis].map(|r| r.as_vec3().to_array())
}

/// Opens the captures of views 1..=`views` (`view_VV/`) within `limits`, which must agree in
/// light count and image size.
fn open_views(src: &Path, views: usize, limits: &Limits) -> Result<Vec<Capture>> {
    let mut captures: Vec<Capture> = Vec::with_capacity(views);
    for v in 1..=views {
        let dir = src.join(format!("view_{v:02}"));
        if !dir.is_dir() {
            return Err(Error::input(&dir, format!("view {v} of {views} is missing")));
        }
        let c = Capture::open(&dir, limits)?;
        if let Some(first) = captures.first() {
            if c.len() != first.len() {
                return Err(Error::input(
                    &c.dir,
                    format!("{} lights, but {} has {}", c.len(), first.dir.display(), first.len()),
                ));
            }
            if (c.width, c.height) != (first.width, first.height) {
                return Err(Error::input(
                    c.dir.join(crate::pms_dir::MASK),
                    format!(
                        "{} x {} pixels, but {} has {} x {}",
                        c.width,
                        c.height,
                        first.dir.display(),
                        first.width,
                        first.height
                    ),
                ));
            }
        }
        captures.push(c);
    }
    Ok(captures)
}

/// The ground-truth mesh, decimated to the target vertex count when it has more, and checked.
fn load_decimated(
    mesh_path: &Path,
    o: &MultiViewOptions,
) -> Result<(mesh_encoding::TriMesh, Option<crate::decimate::DecimateReport>)> {
    let loaded = mesh_encoding::load_mesh(mesh_path, &mesh_encoding::LoadOptions::default())?;
    let (mesh, decimation) = match o.target_vertices {
        Some(target) if loaded.mesh.positions.len() > target => {
            let message = format!("decimating {} to {target} vertices", mesh_path.display());
            let bar = stdx::progress::spinner(&message, o.progress);
            let (m, r) = decimate(
                &loaded.mesh,
                &DecimateOptions { target_vertices: target, ..Default::default() },
            );
            bar.finish_and_clear();
            (m, Some(r))
        }
        _ => (loaded.mesh, None),
    };
    mesh.validate()
        .map_err(|fault| Error::input(mesh_path, format!("after decimation: {fault}")))?;
    Ok((mesh, decimation))
}

/// Imports the DiLiGenT-MV object in `src` (a `mvpmsData/<obj>PNG` directory) into the scene
/// directory `out`.
///
/// # Errors
/// Bad input naming the file and the fault: a missing view, calibration variable or mesh,
/// light counts that differ between files or views, bad intensities, images or masks of the
/// wrong size, damaged PNG or MAT files; invalid options; failures writing the scene.
pub fn import_multi_view(src: &Path, out: &Path, o: &MultiViewOptions) -> Result<ImportReport> {
    let start = Instant::now();
    if !src.is_dir() {
        return Err(Error::input(src, "object directory is missing"));
    }
    let is_train = train_views(o.views, o.train_views.as_deref())?;
    let captures = open_views(src, o.views, &o.limits)?;
    let (train, test) = split_lights(captures[0].len(), o.train_lights, o.test_lights, o.seed)?;

    let calib_path = o.calibration.clone().unwrap_or_else(|| src.join("Calib_Results.mat"));
    let calib = Calibration::read(&calib_path, o.views, o.principal_point_offset, &o.limits)?;
    let mut warnings = calib.warnings.clone();
    // Ground-truth normal maps of the views, when shipped, read before anything is written.
    let normal_maps = captures
        .iter()
        .map(|c| read_normal_map(&c.dir, c.width, c.height, &o.limits))
        .collect::<Result<Vec<_>>>()?;

    let mesh_path = match &o.mesh {
        Some(p) => p.clone(),
        None => find_mesh(src)?,
    };
    let (mut mesh, decimation) = load_decimated(&mesh_path, o)?;
    let sim = mesh.normalize_unit_sphere();
    let (c, s) = (sim.center.as_dvec3(), sim.scale as f64);

    let views = calib
        .cameras
        .iter()
        .enumerate()
        .map(|(v, cam)| {
            let split = if is_train[v] { Split::Train } else { Split::Test };
            let lights = if is_train[v] { train.clone() } else { test.clone() };
            let t = s * (cam.r * c + cam.t);
            ViewSpec {
                k: rows(cam.k),
                r: rows(cam.r),
                t: t.as_vec3().to_array(),
                split,
                capture: v,
                lights,
            }
        })
        .collect();
    let object = object_name(src);
    let scene = CapturedScene {
        benchmark: "DiLiGenT-MV",
        object: &object,
        source_mesh: mesh_path,
        mesh,
        captures: &captures,
        views,
        seed: o.seed,
        train_lights: o.train_lights,
        saturation_level: o.saturation_level,
        shadow_bias_relative: o.shadow_bias_relative,
    };
    let written = write_captured_scene(&scene, out, o.progress)?;
    let mut errs = Vec::new();
    for (v, map) in normal_maps.iter().enumerate() {
        if let Some(map) = map {
            let r = calib.cameras[v].r.as_mat3();
            errs.extend(view_errors(&written.geometry.views[v], &captures[v].mask, r, map));
        }
    }
    if normal_maps.iter().any(Option::is_some) && normal_maps.iter().any(Option::is_none) {
        warnings.push("only some views have Normal_gt.mat; the normal check covers those".into());
    }
    Ok(ImportReport {
        dir: out.into(),
        label: written.manifest.label.clone(),
        seconds: start.elapsed().as_secs_f64(),
        bytes: written.manifest.files.iter().map(|f| f.bytes).sum(),
        stats: written.manifest.stats.clone(),
        views: written.views,
        mesh_vertices: scene.mesh.positions.len(),
        mesh_triangles: scene.mesh.triangles.len(),
        decimation,
        circle: None,
        normal_check: summarize(errs),
        warnings,
    })
}
