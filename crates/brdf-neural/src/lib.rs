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
//! use brdf_neural::{ModelConfig, Samples};
//! // Any model by its configuration name or its paper row name.
//! let mut config = ModelConfig::from_name("Enh. Add. Shared").unwrap();
//! config.spatial_dim = 4;
//! config.width = 16;
//! let device = brdf_neural::device::cpu();
//! // Seeded: the same seed gives the same initial weights, whatever other threads do.
//! let model = config.init_seeded(&device, 7, None).unwrap();
//! let (l, v) = ([[0.0, 0.6, 0.8_f32]], [[0.0, -0.6, 0.8_f32]]);
//! let samples = Samples { spatial: &[0.1, -0.2, 0.3, 0.0], l: &l, v: &v };
//! let out = model.forward(&config.batch(&samples, None, &device).unwrap());
//! assert_eq!(out.f.dims(), [1, 3]);
//! assert!(out.diffuse.is_some() && out.xi.is_some());
//! ```
//!
//! Configuration (serde, TOML): [`ModelConfig`] with `kind` one of the [`ModelKind`] names
//! (`rp`, `ts`, `fmbrdf`, `disney`, `single_mlp`, `additive_separate`, `additive_shared`,
//! `additive_separate_enhanced`, `additive_shared_enhanced`); [`ModelKind::from_name`] also takes
//! the paper's row names ("Single MLP", "Enh. Add. Sep.", ...).
//!
//! # Parameter counts
//!
//! Default configurations (160 spatial inputs, width 128; angle features 21 values, 28 with the
//! reciprocity mapping), printed by `cargo run -p brdf-neural --example param_counts` and
//! checked against the modules by the tests:
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
//! back to back. Measured on the 2-core AVX-512 machine: Single MLP step 165 ms on flex
//! against PyTorch 2.15's 213 to 221 ms in the same run (ratio 0.74 to 0.80), ndarray 1.8x
//! slower than PyTorch. Two things get flex there: the host-memory policy ([`host_memory`],
//! applied when a CPU device is made) and the allocation patch in `vendor/burn-flex`. Full
//! figures and conditions are in the bench's file documentation and `benches/README.md`.

pub mod additive_separate;
pub mod additive_shared;
pub mod batch;
pub mod device;
mod error;
pub mod features;
pub mod finite_check;
#[cfg(feature = "flex")]
mod flex_linear;
pub mod gpu_cache;
pub mod host_memory;
pub mod linear_op;
pub mod mlp;
pub mod model;
pub mod output;
pub mod output_init;
pub mod param_ids;
pub mod parametric;
pub mod precision;
pub mod record_table;
pub mod single_mlp;
pub mod split_k;
pub mod tensor_brdf;

pub use batch::{BrdfBatch, SPATIAL_LIMIT, Samples, SpatialTable};
pub use error::{Error, Result};
pub use features::{AngleConfig, AngleParametrization, Reciprocity};
pub use model::{BrdfModel, ModelConfig, ModelKind};
pub use output::BrdfOutput;
pub use parametric::{Analytic, BrdfParams, ParametricModel};
pub use record_table::{RecordIndex, RecordTable};
