//! Loaders for the real DiLiGenT (single view) and DiLiGenT-MV captures, producing the same
//! dataset API as the semi-synthetic scenes: an importer writes a scene directory in the scene
//! format, so [`scene::SceneDataset::open`] and `samples(split)` (and
//! the experiments crate's `fit` / `eval`) read real captures with no special case.
//!
//! Entry points:
//! * [`import_single_view`]: a `pmsData/<obj>PNG/` capture (the ball: a sphere fitted to the
//!   mask, DiLiGenT's intrinsics, 96 lights split into train and test, checked against
//!   `Normal_gt.mat`).
//! * [`import_multi_view`]: a `mvpmsData/<obj>PNG/` object (20 views, `Calib_Results.mat`, the
//!   ground-truth mesh decimated to 1e5 vertices; the paper's 10 views x 30 lights / other 10
//!   views x 12 lights split).
//!
//! Modules:
//! * [`pms_dir`]: one capture directory (16-bit PNGs, light files, mask) with its checks and
//!   DiLiGenT's camera axes.
//! * [`calibration`]: DiLiGenT-MV's `Calib_Results.mat` cameras (non-orthonormal rotations
//!   factored into the intrinsics).
//! * [`mat5`]: a MATLAB v5 reader (numeric arrays, compressed variables) and a writer.
//! * [`decimate`]: quadric-error edge collapse to a target vertex count.
//! * [`ball`]: the ball's sphere model (circle fit, icosphere, placement, normal check).
//! * [`normal_check`]: the mesh's normals against the benchmark's `Normal_gt.mat` maps.
//! * [`split`]: the train/test choice of views and lights.
//! * [`report`]: what an import did.
//!
//! What a captured scene holds: observed radiance for unit irradiance (raw / 65535 / light
//! intensity, per channel; manifest intensities are 1), no ground-truth BRDF (zero images,
//! `GT_VALID` never set), `SATURATED` where a raw channel reaches the saturation level, `LIT`
//! where the pixel is in the mask and the ray-cast geometry says the light reaches it; the
//! manifest's material is [`MaterialSpec::Captured`](scene::MaterialSpec).
//!
//! ```no_run
//! use dataset_diligent::{SingleViewOptions, import_single_view};
//! use scene::{SceneDataset, Split};
//! let src = std::path::Path::new("../shared/data/diligent/pmsData/ballPNG");
//! let report = import_single_view(src, "scenes/diligent-ball".as_ref(), &SingleViewOptions::default())?;
//! println!("{} lit samples, sphere normals {:?}", report.stats.lit_samples, report.normal_check);
//! let train = SceneDataset::open(&report.dir)?.samples(Split::Train)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod ball;
pub mod calibration;
pub mod decimate;
mod error;
pub mod mat5;
pub mod multi_view;
pub mod normal_check;
pub mod pms_dir;
pub mod report;
mod scene_writer;
pub mod single_view;
pub mod split;

pub use error::{Error, Result};
pub use multi_view::{MultiViewOptions, import_multi_view};
pub use report::{CircleFit, ImportReport, NormalCheck, ViewReport};
pub use single_view::{DILIGENT_INTRINSICS, SingleViewOptions, import_single_view};
