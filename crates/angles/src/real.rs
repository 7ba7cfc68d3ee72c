//! The floating-point scalar trait shared by every crate that is generic over precision.

use num_traits::{Float, FloatConst};
use std::fmt::{Debug, Display};

/// A floating-point scalar: `f32` on hot paths, `f64` for references.
///
/// A thin extension of [`num_traits::Float`] with the constants and conversions the BRDF code
/// needs. Implemented for `f32` and `f64` only.
pub trait Real:
    Float + FloatConst + Default + Debug + Display + Send + Sync + std::iter::Sum + 'static
{
    /// Converts an `f64` literal or value to this precision (rounding to nearest for `f32`).
    fn lit(x: f64) -> Self;
    /// Converts to `f64` exactly.
    fn to_f64_exact(self) -> f64;
    /// Converts an `f32` (for example a stored network weight) exactly.
    fn from_f32(x: f32) -> Self;
}

impl Real for f32 {
    #[inline(always)]
    fn lit(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn to_f64_exact(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn from_f32(x: f32) -> Self {
        x
    }
}

impl Real for f64 {
    #[inline(always)]
    fn lit(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn to_f64_exact(self) -> f64 {
        self
    }
    #[inline(always)]
    fn from_f32(x: f32) -> Self {
        x as f64
    }
}
