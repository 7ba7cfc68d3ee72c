//! Mesh I/O (OBJ, glTF, PLY), cleanup, vertex normals and the Laplace-Beltrami eigenfunction
//! encoding of surface position (spec section 5.2).
//!
//! Not built yet: see the geometry and LBO issues. This crate sits above `brdf-analytic` and below
//! `raycast-precompute` in the layering.
