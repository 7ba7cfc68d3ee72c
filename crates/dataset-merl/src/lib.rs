//! The MERL BRDF format (spec section 1), the MERL-derived material catalogue, and the
//! semi-synthetic scene generator, which renders them into the scene format (the `scene`
//! crate, which also reads scenes back for training).
//!
//! * [`merl`]: the real binary format (reader, validating parser, atomic writer), lookup by
//!   Rusinkiewicz angles or directions with the reference nearest-lower-bin rule or trilinear
//!   interpolation, and [`MerlMaterial`], a table usable as a [`brdf_analytic::Brdf`].
//! * [`nbrdf`]: the published NBRDF networks of the MERL materials (Sztrajman et al. 2021),
//!   evaluated in Rust and tabulated into MERL tables, so the real MERL code path is what runs.
//! * [`catalogue`]: the 25 materials the project uses, shipped as NBRDF networks (MIT); real
//!   MERL binaries from a configured directory take precedence. Results made from the networks
//!   are labelled "MERL-derived (NBRDF)".
//! * [`generate`]: [`generate_scene`], mesh + material + seed + settings -> a scene directory
//!   (orbit cameras, seeded splits, noise), skipped when already complete.
//! * [`render`]: one (view, light) image: radiance, ground truth, flags, noise, saturation.
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
pub mod generate;
pub mod merl;
pub mod nbrdf;
pub mod render;

pub use catalogue::{CATALOGUE, Material, MaterialClass, MaterialSource, load_material};
pub use error::{Error, Result};
pub use generate::{GenerateReport, generate_scene};
pub use merl::lookup::MerlMaterial;
pub use merl::{Lookup, MerlBrdf};
pub use nbrdf::Nbrdf;
