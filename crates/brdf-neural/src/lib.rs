//! The neural BRDF models of the comparison (spec sections 3 and 4, decisions table) on burn:
//! parametric models driven by an MLP (RP, TS, FMBRDF, Disney), Single MLP, and the additive
//! split models (Separate, Shared, and their enhanced variants), with the reciprocity options,
//! the angle parametrizations, the NOL and NeRFactor ablations.
//!
//! A model maps (spatial features of x, l, v in the local frame of n) to an RGB BRDF value
//! f_r in 1/sr; the trainer renders L = f E shadow cos and fits it. Models never name a
//! backend: they run on whatever [`Device`](burn::tensor::Device) they are given
//! ([`device`] picks one at run time: flex by default, ndarray or wgpu behind features);
//! training uses the same device with `.autodiff()`.
//!
//! ```
//! use brdf_neural::{BrdfBatch, BrdfModel, ModelConfig, Samples};
//! // Any model by its configuration name or its paper row name.
//! let mut config = ModelConfig::from_name("Enh. Add. Shared").unwrap();
//! config.spatial_dim = 4;
//! config.width = 16;
//! let device = brdf_neural::device::cpu();
//! // Seeded: the same seed gives the same initial weights, whatever other threads do.
//! let model = BrdfModel::init_seeded(&config, &device, 7, None).unwrap();
//! let (l, v) = ([[0.0, 0.6, 0.8_f32]], [[0.0, -0.6, 0.8_f32]]);
//! let samples = Samples { spatial: &[0.1, -0.2, 0.3, 0.0], l: &l, v: &v };
//! let out = model.forward(&BrdfBatch::new(&config, &samples, None, &device).unwrap());
//! assert_eq!(out.f.dims(), [1, 3]);
//! assert!(out.diffuse.is_some() && out.xi.is_some());
//! ```
//!
//! The models' vocabulary without tensors lives in the `model-spec` crate and is re-exported
//! here under its old paths: [`ModelKind`], [`ModelConfig`] (serde, TOML; `kind` one of the
//! [`ModelKind`] names `rp`, `ts`, `fmbrdf`, `disney`, `single_mlp`, `additive_separate`,
//! `additive_shared`, `additive_separate_enhanced`, `additive_shared_enhanced`;
//! [`ModelKind::from_name`] also takes the paper's row names "Single MLP", "Enh. Add. Sep.",
//! ...), the direction features ([`features`]: [`AngleConfig`], [`AngleParametrization`],
//! [`Reciprocity`]), [`Analytic`] and the layer tables ([`mlp::MlpConfig`] and
//! [`ModelConfig::mlp_configs`]). This crate builds the models from them:
//! [`BrdfModel::init`] and [`BrdfModel::init_seeded`], batches with [`BrdfBatch::new`] (and
//! [`BrdfBatch::from_owned`], [`BrdfBatch::from_table`], [`BrdfBatch::from_records`]).
//! A fitted model over surface points is [`fitted`]: its predictions on records, the inputs
//! kept on the device, and the model as a [`brdf_analytic::SurfaceBrdf`]
//! ([`fitted::NeuralSurface`]); what a training run keeps on the device is
//! [`training_inputs::TrainingInputs`].
//!
//! # Parameter counts
//!
//! The parameter count of every default configuration is tabulated in the crate docs of
//! [`model_spec`] (`cargo run -p model-spec --example param_counts` prints it); the tests here
//! check [`ModelConfig::param_count`] against the modules built.
//!
//! # Backends and performance
//!
//! | feature | default | backend |
//! | --- | --- | --- |
//! | `flex` | on | burn-flex (pure Rust, SIMD, rayon) |
//! | `x86-v4` | on | flex's AVX-512 matrix kernels (gemm), selected at run time only where the CPU has avx512f |
//! | `ndarray` | off | burn-ndarray (the design's original choice), for comparison |
//! | `wgpu` | off | GPU through wgpu; not built in CI |
//!
//! `cargo bench -p brdf-neural --bench train_step` times one training step (forward, MSE on
//! the rendered radiance, backward, Adam) at batch 32768 and prints samples/s and GFLOP/s
//! against the matmul rate measured in the same run; `benches/pytorch_step.py` (repository
//! root) is the same Single MLP step in PyTorch, and `BRDF_BENCH_PYTORCH=python3` runs the two
//! back to back. Two things make flex's step faster than PyTorch's on the CPU: the host-memory
//! policy ([`host_memory`], applied when a CPU device is made) and the allocation patch in
//! `vendor/burn-flex`. The dated figures and their conditions are in `benches/README.md`.

pub mod additive_separate;
pub mod additive_shared;
pub mod batch;
pub mod device;
mod error;
// The direction features, defined in model-spec, under their old path.
pub use model_spec::features;
pub mod batch_split;
#[cfg(any(feature = "wgpu", feature = "cuda"))]
mod cube_linear;
pub mod finite_check;
pub mod fitted;
#[cfg(feature = "flex")]
mod flex_linear;
pub mod gpu_cache;
pub mod gpu_linear;
pub mod host_memory;
pub mod linear_op;
pub mod mlp;
pub mod model;
pub mod output;
pub mod output_init;
pub mod param_ids;
pub mod parametric;
pub mod precision;
pub mod products;
pub mod record_table;
pub mod single_mlp;
pub mod tensor_brdf;
pub mod training_inputs;

pub use batch::{BrdfBatch, SPATIAL_LIMIT, Samples, SpatialTable};
pub use error::{Error, Result};
pub use features::{AngleConfig, AngleParametrization, Reciprocity};
pub use model::{BrdfModel, ModelConfig, ModelKind};
pub use output::BrdfOutput;
pub use parametric::{Analytic, BrdfParams, ParametricModel};
pub use record_table::{RecordIndex, RecordTable};
