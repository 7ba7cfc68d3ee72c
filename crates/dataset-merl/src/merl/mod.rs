//! The MERL isotropic BRDF table (Matusik et al. 2003) in its real binary format (spec section 1).
//!
//! * [`format`](mod@format): reading, validating and writing the 90 x 90 x 180 channel-planar float64 file.
//! * [`lookup`]: the reference nearest-lower-bin indexing and trilinear interpolation, by
//!   Rusinkiewicz angles or by local-frame directions.

pub mod format;
pub mod lookup;

pub use format::{CHANNEL_SCALES, FILE_BYTES, MerlBrdf, N_PHI_D, N_THETA_D, N_THETA_H, TABLE_LEN};
pub use lookup::{Lookup, bin_lower_edges};
