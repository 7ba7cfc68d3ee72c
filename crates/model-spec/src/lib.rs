//! The vocabulary of the neural BRDF models of the comparison (spec sections 3 and 4,
//! decisions table), without tensors: which models there are ([`ModelKind`]), how one is
//! configured ([`ModelConfig`], serde, TOML), the direction features of the purely neural
//! models ([`features`]: angle parametrizations, reciprocity options, positional encoding,
//! computed on the CPU), the layer tables every model is built from ([`MlpConfig`], one
//! [`layers`]), the names of the backends and product precisions ([`backend`]), and how the linear layers
//! run on a GPU ([`gpu_tuning`]). brdf-neural builds and trains the models on burn from these
//! tables and re-exports every item under its old path; crates that only name models (the
//! report's tables) depend on this crate and compile no tensor library.
//!
//! ```
//! use model_spec::{ModelConfig, ModelKind};
//! // Any model by its configuration name or its paper row name.
//! let config = ModelConfig::from_name("Enh. Add. Shared").unwrap();
//! assert_eq!(config.kind, ModelKind::AdditiveSharedEnhanced);
//! config.validate().unwrap();
//! // Trunk, diffuse head, specular head (f_s and xi).
//! let mlps = config.mlp_configs();
//! assert_eq!(mlps.iter().map(|m| m.d_out()).collect::<Vec<_>>(), [128, 3, 6]);
//! assert_eq!(config.param_count(), 160_521);
//! ```
//!
//! Configuration names of [`ModelKind`]: `rp`, `ts`, `fmbrdf`, `disney`, `single_mlp`,
//! `additive_separate`, `additive_shared`, `additive_separate_enhanced`,
//! `additive_shared_enhanced`; [`ModelKind::from_name`] also takes the paper's row names
//! ("Single MLP", "Enh. Add. Sep.", ...).
//!
//! # Parameter counts
//!
//! Default configurations (160 spatial inputs, width 128; angle features 21 values, 28 with the
//! reciprocity mapping), printed by `cargo run -p model-spec --example param_counts`, checked
//! against this table by the tests and against the built modules by brdf-neural's tests:
//!
//! | model | default | mapping | NOL |
//! | --- | ---: | ---: | ---: |
//! | RP | 108,039 | | |
//! | TS | 108,039 | | |
//! | FMBRDF | 107,912 (incl. 2 global) | | |
//! | Disney | 108,684 | | |
//! | Single MLP | 112,899 | 114,691 | 110,211 |
//! | Add. Sep. | 187,398 | 189,190 | 131,206 |
//! | Add. Shared | 160,134 | 161,030 | 172,678 |
//! | Enh. Add. Sep. | 187,785 | 189,577 | 131,593 |
//! | Enh. Add. Shared | 160,521 | 161,417 | 173,065 |

pub mod backend;
pub mod config;
mod error;
pub mod features;
pub mod gpu_tuning;
pub mod kind;
pub mod layers;
pub mod mlp;

pub use backend::{Backend, MatmulPrecision};
pub use config::ModelConfig;
pub use error::{Error, Result};
pub use features::{AngleConfig, AngleParametrization, Reciprocity};
pub use gpu_tuning::{GpuLinear, GpuTile, GpuTuning};
pub use kind::Analytic;
pub use kind::ModelKind;
pub use mlp::MlpConfig;
