//! Parameter validation shared by the models: every model has a `new` that clamps into the
//! documented range (NaN becomes the range's default) and a `try_new` that rejects.

use angles::Real;
use std::fmt;

/// A model parameter outside its documented range, or NaN.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    /// The model, for example "Disney".
    pub model: &'static str,
    /// The parameter's name, for example "roughness".
    pub param: &'static str,
    /// The offending value.
    pub value: f64,
    /// The allowed closed range.
    pub range: (f64, f64),
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} parameter `{}` = {} is outside its range [{}, {}]",
            self.model, self.param, self.value, self.range.0, self.range.1
        )
    }
}

impl std::error::Error for ParamError {}

/// Clamps `x` into [lo, hi]; NaN becomes `fallback`.
#[inline]
pub(crate) fn clamp_or<T: Real>(x: T, lo: f64, hi: f64, fallback: f64) -> T {
    if x.is_nan() { T::lit(fallback) } else { x.max(T::lit(lo)).min(T::lit(hi)) }
}

/// Checks that `x` lies in [lo, hi] (and is not NaN).
#[inline]
pub(crate) fn check<T: Real>(
    model: &'static str,
    param: &'static str,
    x: T,
    lo: f64,
    hi: f64,
) -> Result<(), ParamError> {
    let xv = x.to_f64_exact();
    if xv >= lo && xv <= hi {
        Ok(())
    } else {
        Err(ParamError { model, param, value: xv, range: (lo, hi) })
    }
}

/// [`check`] for each channel of an RGB parameter.
#[inline]
pub(crate) fn check_rgb<T: Real>(
    model: &'static str,
    param: &'static str,
    x: [T; 3],
    lo: f64,
    hi: f64,
) -> Result<(), ParamError> {
    x.iter().try_for_each(|&c| check(model, param, c, lo, hi))
}

/// [`clamp_or`] for each channel.
#[inline]
pub(crate) fn clamp_rgb<T: Real>(x: [T; 3], lo: f64, hi: f64, fallback: f64) -> [T; 3] {
    x.map(|c| clamp_or(c, lo, hi, fallback))
}
