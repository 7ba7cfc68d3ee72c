//! Pinhole cameras, BVH ray casting (obvhs), primary and shadow rays, and the content-addressed
//! on-disk cache of the per-scene precompute (spec section 6).
//!
//! Input -> output: a [`TriMesh`](mesh_encoding::TriMesh) and a list of [`View`]s (an OpenCV
//! [`Camera`], light directions, optional mask) -> a [`ScenePrecompute`]: per view, the
//! foreground pixels with their hit triangle, barycentrics, position, interpolated vertex normal
//! and view direction, and a per (pixel, light) [`Visibility`] (lit / shadowed / back-facing).
//!
//! Modules:
//! * [`camera`]: OpenCV pinhole cameras (x right, y down, z forward; x_c = R x_w + t; pixel
//!   centres at +0.5) and a look-at constructor.
//! * [`tracer`]: the obvhs CWBVH, closest hit and any hit.
//! * [`packet`]: any-hit traversal of up to 64 shadow rays sharing one direction at once.
//! * `packet_closest`: closest-hit traversal of up to 64 camera rays at once (AVX-512, x86-64).
//! * [`brute_force`]: the f64 all-triangles reference the tracer is tested against.
//! * [`precompute`](mod@precompute): primary and shadow rays for a scene, skipping background pixels and
//!   back-facing lights.
//! * [`shadows`]: the shadow-ray stage, in 8 x 8-tile packets per light or one ray at a time.
//! * [`visibility`]: the (pixel, light) bitsets.
//! * [`cache`]: the content-keyed, checksummed on-disk cache.
//! * [`rig`]: camera directions on an orbit and light directions in a cone (the scene crate
//!   builds the dataset's camera rig from them).
//!
//! Conventions: directions are unit world-space vectors; light directions point from the
//! surface towards the light; view directions from the surface towards the camera.
//!
//! ```
//! use mesh_encoding::{TriMesh, glam::Vec3};
//! use raycast_precompute::{Camera, PrecomputeSettings, View, precompute};
//! let quad = TriMesh::new(
//!     vec![Vec3::new(-1., -1., 0.), Vec3::new(1., -1., 0.), Vec3::new(1., 1., 0.), Vec3::new(-1., 1., 0.)],
//!     vec![[0, 1, 2], [0, 2, 3]],
//! )?;
//! let camera = Camera::look_at(Vec3::new(0., 0., 3.), Vec3::ZERO, Vec3::Y, 30.0, 16, 16)?;
//! let view = View { camera, lights: vec![Vec3::Z.into(), (-Vec3::Z).into()], mask: None };
//! let scene = precompute(&quad, &[view], &PrecomputeSettings::default())?;
//! let v = &scene.views[0];
//! assert_eq!(v.len(), 16 * 16); // the quad fills the image
//! assert!(v.visibility.is_lit(0, 0) && !v.visibility.is_lit(0, 1)); // light 1 is below
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

/// In the unit tests, a single allocation beyond 4 GiB aborts: the cache decoders' corrupted
/// payloads (a length of 2^40 elements) must be errors, not out-of-memory kills.
#[cfg(test)]
#[global_allocator]
static ALLOC: test_support::corrupt::CappedAlloc = test_support::corrupt::CappedAlloc(1 << 32);

pub mod brute_force;
pub mod cache;
pub mod camera;
pub mod error;
pub mod light;
pub mod packet;
#[cfg(target_arch = "x86_64")]
pub mod packet_closest;
mod packet_kernels;
pub mod precompute;
pub mod rig;
pub mod shadows;
pub mod tracer;
pub mod visibility;

pub use brute_force::BruteForce;
pub use cache::{CacheOutcome, FORMAT_VERSION, cache_key, cache_path, precompute_cached};
pub use camera::{Camera, intrinsics, mat3_from_rows};
pub use error::{Error, Result};
pub use light::Light;
pub use packet::PACKET_SIZE;
pub use precompute::{
    PrecomputeSettings, ScenePrecompute, ShadowBias, TraceStats, View, ViewPrecompute, precompute,
    precompute_with_tracer, precompute_with_traversal,
};
pub use shadows::Traversal;
pub use tracer::{Hit, Tracer};
pub use visibility::{LightState, Visibility};
