//! Users' own captures: posed images of one object, its mesh and the calibrated light of every
//! image, in standard formats, imported as a scene directory that training and evaluation read
//! like any other (docs/capture-format.md).
//!
//! A capture is a folder with `capture.toml`, cameras as nerfstudio / instant-ngp
//! `transforms.json` or a COLMAP text model ([`cameras`], [`colmap`]), `lights.json` with a
//! directional or point light per image ([`lights`]), EXR or 8/16-bit PNG images with a stated
//! response and optional masks ([`images`]), and the mesh (OBJ, PLY, glTF) in the cameras'
//! world frame. [`import_capture`] checks every part, groups images that share a camera into
//! views, compares each view's mask with the mesh's silhouette (IoU, an error below
//! `[check] min_iou`) and writes the scene atomically: a bad capture is an error naming the
//! file and the fault, and nothing is written. [`export_capture`] writes any scene in this
//! format.
//!
//! Stage: beside `dataset-diligent`, above `scene` (it writes scenes through the scene crate's
//! one writer) and below `experiments`.
//!
//! ```no_run
//! let report = dataset_capture::import_capture(
//!     std::path::Path::new("my-capture"),
//!     std::path::Path::new("scenes/my-object"),
//!     true,
//!     &stdx::Limits::default(),
//! )?;
//! for (i, v) in report.views.iter().enumerate() {
//!     println!("view {i}: IoU {:?}", v.iou);
//! }
//! # Ok::<(), dataset_capture::Error>(())
//! ```

pub mod cameras;
pub mod colmap;
pub mod config;
pub mod error;
pub mod export;
pub mod images;
pub mod import;
pub mod lights;

pub use config::{CAPTURE_FILE, CaptureConfig, Response};
pub use error::{Error, Result};
pub use export::export_capture;
pub use import::{ImportReport, ViewCheck, import_capture, report_json, report_path};
pub use lights::{CaptureLight, LightEntry, Lights};
