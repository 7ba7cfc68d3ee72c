//! Semi-synthetic scenes (spec section 6): a mesh rendered with a material under calibrated
//! directional lights from 20 cameras, with noise, saturation and the ground-truth BRDF stored
//! per pixel; and the dataset API that reads them back.
//!
//! * [`config`]: the scene description ([`SceneConfig`]) with the paper's defaults.
//! * [`generate`]: [`generate_scene`], the atomic, resumable generator, and the directory layout.
//! * [`render`]: one (view, light) image: radiance, ground truth, flags.
//! * [`manifest`]: the versioned, self-checking manifest.
//! * [`dataset`]: [`SceneDataset`] and [`SampleSet`], the records training uses.
//! * [`images`], [`mesh_file`]: the file formats.

pub mod config;
pub mod dataset;
pub mod generate;
pub mod images;
pub mod manifest;
pub mod mesh_file;
pub mod render;

pub use config::{MaterialSpec, SceneConfig, SceneSettings, UpAxis};
pub use dataset::{SampleSet, SceneDataset};
pub use generate::{GenerateReport, generate_scene};
pub use manifest::{Manifest, Split};
