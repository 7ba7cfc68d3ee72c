//! Pinhole cameras, BVH ray casting (obvhs), primary and shadow rays, and the content-addressed
//! on-disk cache of the per-scene precompute (spec section 6).
//!
//! Not built yet: see the geometry issue.
