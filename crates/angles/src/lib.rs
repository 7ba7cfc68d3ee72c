//! Angle parametrizations of a BRDF's two directions, in f32 and f64 (spec sections 2 and 5.1).
//!
//! Every function works in the **local shading frame**: the normal is +z, `l` points to the light
//! and `v` to the viewer, both unit vectors pointing away from the surface. [`Frame`] moves world
//! vectors into that frame. From a pair (l, v) this crate computes
//!
//! * the Rusinkiewicz half/difference angles [`Rusinkiewicz`] (theta_h, theta_d, phi_d), with
//!   phi_d in [0, 2 pi) as the paper uses it, and their inverse;
//! * the paper's reciprocity mapping [`reciprocal_theta`]
//!   Theta = [theta_h, theta_d, phi_d mod pi, (phi_d mod pi) + pi], bit-identical under swapping l
//!   and v;
//! * the view-light triplet [`ViewLight`] (theta_v, theta_l, phi_v - phi_l) of the ablation;
//! * the NeRF positional encoding [`PositionalEncoding`].
//!
//! All results are finite for every pair of unit vectors, including l = v, theta_h = 0 and
//! grazing directions (n.l = 0): degenerate azimuths are defined as 0. The computations are
//! written symmetrically in l and v (via l + v and l - v) so that swapping the two changes the
//! result exactly as the mathematics says, bit for bit where the mathematics says "unchanged".
//!
//! ```
//! use angles::{Rusinkiewicz, reciprocal_theta};
//! let l = [0.3_f64, 0.1, 0.948_683_298_050_513_8];
//! let v = [-0.2_f64, 0.4, 0.894_427_190_999_915_9];
//! let r = Rusinkiewicz::from_local(l, v);
//! let (l2, v2) = r.to_local_with_phi_h(Rusinkiewicz::phi_h_of(l, v));
//! assert!((l2[0] - l[0]).abs() < 1e-12 && (v2[2] - v[2]).abs() < 1e-12);
//! assert_eq!(reciprocal_theta(l, v), reciprocal_theta(v, l));
//! ```

mod encoding;
mod frame;
mod real;
mod reciprocity;
mod rusinkiewicz;
pub mod vec3;
mod view_light;

pub use encoding::PositionalEncoding;
pub use frame::Frame;
pub use real::Real;
pub use reciprocity::{reciprocal_theta, reciprocal_theta_batch};
pub use rusinkiewicz::{Rusinkiewicz, rusinkiewicz_batch};
pub use vec3::Vec3;
pub use view_light::{ViewLight, view_light_batch};
