//! The scene format: one directory per scene, the same for generated (semi-synthetic) and
//! captured data, so training and evaluation read both with no special case (spec section 6).
//!
//! A scene is a mesh, calibrated cameras, directional lights and, per (view, light), an HDR
//! image with per-pixel flags (and, for generated data, the ground-truth BRDF), described by a
//! versioned, self-checking manifest. This crate owns the format and nothing about where the
//! data comes from: dataset-merl renders MERL materials into it, dataset-diligent imports
//! captures into it, both through [`write_scene`].
//!
//! Modules:
//! * [`config`]: what a scene is made of ([`SceneConfig`], [`SceneSettings`]) with the paper's
//!   defaults, and its validation.
//! * [`manifest`]: the versioned, self-checking manifest (cameras, lights, splits, file hashes,
//!   statistics).
//! * [`writer`]: [`write_scene`], the one atomic writer, and the directory layout.
//! * [`dataset`]: [`SceneDataset`], which opens and verifies a scene, and [`SampleSet`], the lit
//!   (pixel, light) records training uses.
//! * [`flag`]: the per-sample flag bits; [`shading`]: L = f E cos(theta_l), the one rendering
//!   equation of generation, training and evaluation.
//! * [`orbit`]: the camera rig of generated scenes.
//! * [`images`], [`mesh_file`]: the file formats (EXR, PNG, binary PLY).
//!
//! ```no_run
//! use scene::{SceneDataset, Split};
//! let scene = SceneDataset::open("out/reproduce/scenes/spot__blue-acrylic".as_ref())?;
//! let train = scene.samples(Split::Train)?;
//! println!("{} lit training samples of {}", train.len(), scene.manifest.label);
//! # Ok::<(), scene::Error>(())
//! ```

pub mod config;
pub mod dataset;
mod error;
pub mod flag;
pub mod images;
pub mod manifest;
pub mod mesh_file;
pub mod orbit;
pub mod shading;
pub mod writer;

pub use config::{Lookup, MaterialSpec, SceneConfig, SceneSettings, UpAxis};
pub use dataset::{SampleSet, SceneDataset};
pub use error::{Error, Result};
pub use manifest::{MANIFEST_FILE, Manifest, SceneStats, Split};
pub use writer::{PairImages, Progress, SceneContents, Written, sample_stem, write_scene};
