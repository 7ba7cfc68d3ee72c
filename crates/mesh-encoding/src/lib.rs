//! Mesh I/O (OBJ, glTF, PLY), cleanup, vertex normals and the Laplace-Beltrami eigenfunction
//! encoding of surface position (spec section 5.2).
//!
//! This crate sits above `brdf-analytic` and below `raycast-precompute` in the layering.
//!
//! Modules:
//! * [`mesh`]: the indexed triangle mesh [`TriMesh`], loading ([`load_mesh`]: OBJ via tobj, PLY
//!   via ply-rs-bw, glTF/GLB via gltf), cleanup with a report, topology statistics, angle- or
//!   area-weighted vertex normals and normalisation into the unit sphere.
//! * [`lbo`]: the Laplace-Beltrami eigenfunction encoding: cotangent/mixed-Voronoi assembly
//!   ([`LboMatrices`]), a shift-invert block Lanczos eigensolver on faer's sparse Cholesky
//!   ([`smallest_eigenpairs`]), an eigenpair cache and the per-point encoding ([`LboEncoding`]).
//! * [`error`]: the crate's [`Error`] (every message names the file and the fault) and
//!   [`Result`].
//!
//! ```no_run
//! use mesh_encoding::{LoadOptions, NormalWeighting, load_mesh};
//! let options = LoadOptions { normalize_unit_sphere: true, ..Default::default() };
//! let loaded = load_mesh("../shared/data/meshes/spot.obj", &options)?;
//! println!("{:?}", loaded.report.topology);
//! let normals = loaded.mesh.vertex_normals(NormalWeighting::Angle);
//! assert_eq!(normals.len(), loaded.mesh.vertex_count());
//! # Ok::<(), mesh_encoding::Error>(())
//! ```

/// In the unit tests, a single allocation beyond 4 GiB aborts: the cache decoders' corrupted
/// payloads (a length of 2^40 elements) must be errors, not out-of-memory kills.
#[cfg(test)]
#[global_allocator]
static ALLOC: test_support::corrupt::CappedAlloc = test_support::corrupt::CappedAlloc(1 << 32);

pub mod error;
pub mod lbo;
pub mod mesh;

pub use error::{Error, MeshFault, Result};
pub use glam;
pub use lbo::{
    EigenSettings, Eigenpairs, LboEncoding, LboEncodingConfig, LboMatrices, cached_eigenpairs,
    smallest_eigenpairs,
};
pub use mesh::{
    CleanupReport, LoadOptions, LoadReport, LoadedMesh, MeshFormat, NormalWeighting, Similarity,
    Topology, TriMesh, interpolate_normal, load_mesh,
};
