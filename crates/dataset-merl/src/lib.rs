//! The MERL BRDF format (spec section 1), the MERL-derived material catalogue, and the
//! semi-synthetic scene generator with the dataset API training reads.
//!
//! * [`merl`]: the real binary format (reader, validating parser, atomic writer), lookup by
//!   Rusinkiewicz angles or directions with the reference nearest-lower-bin rule or trilinear
//!   interpolation, and [`MerlMaterial`], a table usable as a [`brdf_analytic::Brdf`].
//! * [`nbrdf`]: the published NBRDF networks of the MERL materials (Sztrajman et al. 2021),
//!   evaluated in Rust and tabulated into MERL tables, so the real MERL code path is what runs.
//! * [`catalogue`]: the 25 materials the project uses, shipped as NBRDF networks (MIT); real
//!   MERL binaries from a configured directory take precedence. Results made from the networks
//!   are labelled "MERL-derived (NBRDF)".
//! * [`scene`]: semi-synthetic scenes: generation into a self-describing directory (EXR images,
//!   masks, ground-truth BRDF, flags, manifest) and [`SceneDataset`] to read them back.
//!
//! ```
//! use dataset_merl::{Lookup, load_material};
//! let m = load_material("blue-acrylic", None)?;
//! assert_eq!(m.source.label(), "MERL-derived (NBRDF)");
//! let f = m.table.eval_dirs([0.0, 0.6, 0.8], [0.0, -0.6, 0.8], Lookup::NearestLower);
//! assert!(f.unwrap().iter().all(|x| *x > 0.0));
//! # Ok::<(), dataset_merl::Error>(())
//! ```

pub mod catalogue;
mod error;
pub mod merl;
pub mod nbrdf;
pub mod scene;

pub use catalogue::{CATALOGUE, Material, MaterialClass, MaterialSource, load_material};
pub use error::{Error, Result};
pub use merl::lookup::MerlMaterial;
pub use merl::{Lookup, MerlBrdf};
pub use nbrdf::Nbrdf;
pub use scene::{SampleSet, SceneConfig, SceneDataset, generate_scene};
