//! The Laplace-Beltrami (intrinsic) encoding of surface position (spec section 5.2, Koestler et
//! al. 2022): eigenfunctions of the mesh's Laplace-Beltrami operator, interpolated
//! barycentrically at surface points.
//!
//! Pipeline, one module a step:
//! * [`assembly`]: cotangent stiffness `L` and mixed-Voronoi lumped mass `M` ([`LboMatrices`]).
//! * [`eigen`]: the `k` smallest pairs of `L phi = lambda M phi` ([`smallest_eigenpairs`],
//!   shift-invert block Lanczos on a sparse Cholesky factor (`lanczos`), an inertia count as
//!   completeness check, spectrum slicing (`slicing`) as an option; [`dense_eigenpairs`] as
//!   reference). Timings: the crate's `PERFORMANCE.md`.
//! * [`encoding`]: index selection, range rescaling, barycentric interpolation ([`LboEncoding`]).
//! * [`cache`]: eigenpairs on disk under a content key ([`cached_eigenpairs`]).
//!
//! ```no_run
//! use mesh_encoding::lbo::{EigenSettings, LboMatrices, smallest_eigenpairs};
//! let loaded = mesh_encoding::load_mesh("../shared/data/meshes/spot.obj", &Default::default())?;
//! let matrices = LboMatrices::from_mesh(&loaded.mesh)?;
//! let (pairs, _report) = smallest_eigenpairs(&matrices, 65, &EigenSettings::default())?;
//! assert!(pairs.values[0].abs() < 1e-8);
//! # Ok::<(), mesh_encoding::Error>(())
//! ```

pub mod assembly;
pub mod cache;
pub mod eigen;
pub mod encoding;
mod factor;
mod lanczos;
mod slicing;

pub use assembly::LboMatrices;
pub use cache::{CacheOutcome, cache_key, cached_eigenpairs};
pub use eigen::{
    EigenSettings, Eigenpairs, SolveReport, dense_eigenpairs, eigenvalue_count_below,
    smallest_eigenpairs,
};
pub use encoding::{LboEncoding, LboEncodingConfig, block_selection};
pub use factor::MEMORY_BUDGET_VAR;
