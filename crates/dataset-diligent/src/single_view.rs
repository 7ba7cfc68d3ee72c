//! Importing a single-view DiLiGenT object (`pmsData/<obj>PNG/`) as a scene: the project's
//! real-data check until DiLiGenT-MV is available.
//!
//! The capture has one camera and 96 lights. The mesh is the ball's sphere ([`crate::ball`]);
//! other objects would need a surface from their normal map (normal integration), which is not
//! implemented, and are refused. The camera is a pinhole with DiLiGenT's calibrated intrinsics
//! ([`DILIGENT_INTRINSICS`]; the benchmark treats the data as orthographic, and at f ~ 3770 px
//! the ball subtends about 2 degrees, so the two agree to a fraction of a pixel).
//!
//! The split uses the one view twice: manifest view 0 (train) carries the training lights and
//! view 1 (test) the test lights, with the same camera, so `pairs(Train)` and `pairs(Test)`
//! never share a light ([`crate::split::split_lights`]).

use crate::ball::{fit_circle, icosphere, sphere_translation};
use crate::error::{Error, Result};
use crate::normal_check::{read_normal_map, summarize, view_errors};
use crate::pms_dir::Capture;
use crate::report::ImportReport;
use crate::scene_writer::{CapturedScene, ViewSpec, write_captured_scene};
use crate::split::split_lights;
use glam::{DMat3, Mat3};
use scene::Split;
use std::path::{Path, PathBuf};
use std::time::Instant;
use stdx::Limits;

/// DiLiGenT's calibrated intrinsics of its 612 x 512 images: fx, fy, cx, cy in pixels, with the
/// principal point in the convention where pixel centres are integers (OpenCV's). Source: the
/// `K.txt` shipped with DiLiGenT's pot2 normal map in the Bilateral Normal Integration
/// repository (xucao-42/bilateral_normal_integration, data/Fig7_diligent/pot2/K.txt), which
/// takes it from the benchmark's calibration.
pub const DILIGENT_INTRINSICS: [f64; 4] =
    [3_772.077_471_010_73, 3_759.005_431_071_33, 305.875, 255.125];

/// Options of [`import_single_view`].
///
/// | field | default | meaning |
/// | --- | --- | --- |
/// | `train_lights`, `test_lights` | 30, 12 | lights per split (as the paper's per-view counts) |
/// | `seed` | 0 | seed of the light split |
/// | `intrinsics` | [`DILIGENT_INTRINSICS`] | fx, fy, cx, cy, principal point with integer pixel centres |
/// | `principal_point_offset` | 0.5 | added to cx, cy (this project's pixel centres are at +0.5) |
/// | `sphere_level` | 5 | icosphere subdivisions (10 242 vertices) |
/// | `saturation_level` | 65535 | raw 16-bit value at which a channel counts as saturated |
/// | `shadow_bias_relative` | 1e-4 | shadow-ray offset, fraction of the mesh diagonal |
/// | `progress` | false | show a progress bar |
/// | `limits` | `Limits::DEFAULT` | what the image and MAT readers accept (`stdx::Limits`) |
#[derive(Clone, Debug, PartialEq)]
pub struct SingleViewOptions {
    /// Training lights.
    pub train_lights: usize,
    /// Test lights.
    pub test_lights: usize,
    /// Seed of the light split.
    pub seed: u64,
    /// fx, fy, cx, cy in pixels.
    pub intrinsics: [f64; 4],
    /// Added to cx and cy.
    pub principal_point_offset: f64,
    /// Icosphere subdivision level.
    pub sphere_level: u32,
    /// Saturation level of raw values.
    pub saturation_level: u16,
    /// Shadow bias.
    pub shadow_bias_relative: f32,
    /// Progress bar.
    pub progress: bool,
    /// What the image and MAT readers accept.
    pub limits: Limits,
}

impl Default for SingleViewOptions {
    fn default() -> Self {
        Self {
            train_lights: 30,
            test_lights: 12,
            seed: 0,
            intrinsics: DILIGENT_INTRINSICS,
            principal_point_offset: 0.5,
            sphere_level: 5,
            saturation_level: 65535,
            shadow_bias_relative: 1e-4,
            progress: false,
            limits: Limits::DEFAULT,
        }
    }
}

/// The object name of a `<obj>PNG` directory.
pub(crate) fn object_name(dir: &Path) -> String {
    let name = dir.file_name().and_then(|n| n.to_str()).unwrap_or("object");
    name.strip_suffix("PNG").unwrap_or(name).to_string()
}

/// Intrinsics rows from fx, fy, cx, cy and the principal-point offset.
pub(crate) fn k_rows(i: [f64; 4], offset: f64) -> [[f32; 3]; 3] {
    [
        [i[0] as f32, 0.0, (i[2] + offset) as f32],
        [0.0, i[1] as f32, (i[3] + offset) as f32],
        [0.0, 0.0, 1.0],
    ]
}

/// Imports the single-view capture in `src` (a `pmsData/<obj>PNG` directory) into the scene
/// directory `out`, and checks the sphere against `Normal_gt.mat` when present.
///
/// # Errors
/// Bad input ([`Error::Input`], [`Error::Mat`]) naming the file and the fault; an object other
/// than the ball; invalid options; failures writing the scene.
pub fn import_single_view(src: &Path, out: &Path, o: &SingleViewOptions) -> Result<ImportReport> {
    let start = Instant::now();
    if o.sphere_level > 7 {
        return Err(Error::option("sphere_level", format!("{} is above 7", o.sphere_level)));
    }
    if o.intrinsics.iter().any(|x| !x.is_finite())
        || o.intrinsics[0] <= 0.0
        || o.intrinsics[1] <= 0.0
    {
        return Err(Error::option("intrinsics", format!("{:?} is not a camera", o.intrinsics)));
    }
    let capture = Capture::open(src, &o.limits)?;
    let object = object_name(src);
    if object != "ball" {
        return Err(Error::input(
            src,
            format!(
                "object `{object}`: only the ball has a shape model here (a sphere fitted to the \
                 mask); other single-view objects need normal integration, not implemented"
            ),
        ));
    }
    let circle = fit_circle(&capture.mask, capture.width as usize).ok_or_else(|| {
        Error::input(src.join(crate::pms_dir::MASK), "the mask has no circular outline to fit")
    })?;
    let k = k_rows(o.intrinsics, o.principal_point_offset);
    let k64 = DMat3::from_cols_array_2d(&k.map(|r| r.map(f64::from))).transpose();
    let t = sphere_translation(k64, &circle);
    // The ground-truth normal map, read (and checked) before anything is written.
    let gt = read_normal_map(src, capture.width, capture.height, &o.limits)?;
    let (train, test) = split_lights(capture.len(), o.train_lights, o.test_lights, o.seed)?;
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let t32 = t.as_vec3().to_array();
    let views = vec![
        ViewSpec { k, r: identity, t: t32, split: Split::Train, capture: 0, lights: train },
        ViewSpec { k, r: identity, t: t32, split: Split::Test, capture: 0, lights: test },
    ];
    let captures = [capture];
    let scene = CapturedScene {
        benchmark: "DiLiGenT",
        object: &object,
        source_mesh: PathBuf::from(format!(
            "<unit icosphere level {} fitted to {}>",
            o.sphere_level,
            src.join(crate::pms_dir::MASK).display()
        )),
        mesh: icosphere(o.sphere_level),
        captures: &captures,
        views,
        seed: o.seed,
        train_lights: o.train_lights,
        saturation_level: o.saturation_level,
        shadow_bias_relative: o.shadow_bias_relative,
    };
    let written = write_captured_scene(&scene, out, o.progress)?;

    let normal_check = gt.and_then(|var| {
        summarize(view_errors(&written.geometry.views[0], &captures[0].mask, Mat3::IDENTITY, &var))
    });
    Ok(ImportReport {
        dir: out.into(),
        label: written.manifest.label.clone(),
        seconds: start.elapsed().as_secs_f64(),
        bytes: written.manifest.files.iter().map(|f| f.bytes).sum(),
        stats: written.manifest.stats.clone(),
        views: written.views,
        mesh_vertices: scene.mesh.positions.len(),
        mesh_triangles: scene.mesh.triangles.len(),
        decimation: None,
        circle: Some(circle),
        normal_check,
        warnings: Vec::new(),
    })
}
