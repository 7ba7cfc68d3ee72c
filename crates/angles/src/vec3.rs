//! Minimal 3-vector helpers on plain arrays `[T; 3]`.
//!
//! Arrays keep the public API free of any math library: a glam user passes `v.to_array()` and
//! gets `Vec3::from(result)` back. Only what the parametrizations and BRDFs need lives here.

use crate::Real;

/// A 3-vector as a plain array, `[x, y, z]`.
pub type Vec3<T> = [T; 3];

/// Dot product.
#[inline(always)]
pub fn dot<T: Real>(a: Vec3<T>, b: Vec3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product `a x b`.
#[inline(always)]
pub fn cross<T: Real>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Component-wise sum.
#[inline(always)]
pub fn add<T: Real>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Component-wise difference `a - b`.
#[inline(always)]
pub fn sub<T: Real>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Scalar multiple `s a`.
#[inline(always)]
pub fn scale<T: Real>(a: Vec3<T>, s: T) -> Vec3<T> {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Euclidean length.
#[inline(always)]
pub fn length<T: Real>(a: Vec3<T>) -> T {
    dot(a, a).sqrt()
}

/// Unit vector along `a`, or `None` when `a` has zero, infinite or NaN length.
#[inline]
pub fn try_normalize<T: Real>(a: Vec3<T>) -> Option<Vec3<T>> {
    let len = length(a);
    if len > T::zero() && len.is_finite() { Some(scale(a, len.recip())) } else { None }
}

/// Unit vector along `a`, or the zero vector when `a` cannot be normalized.
#[inline]
pub fn normalize_or_zero<T: Real>(a: Vec3<T>) -> Vec3<T> {
    try_normalize(a).unwrap_or([T::zero(); 3])
}

/// Converts every component to another precision.
#[inline(always)]
pub fn cast<T: Real, U: Real>(a: Vec3<T>) -> Vec3<U> {
    [U::lit(a[0].to_f64_exact()), U::lit(a[1].to_f64_exact()), U::lit(a[2].to_f64_exact())]
}

/// Unit direction with polar angle `theta_rad` from +z and azimuth `phi_rad` from +x.
#[inline]
pub fn spherical<T: Real>(theta_rad: T, phi_rad: T) -> Vec3<T> {
    let (st, ct) = theta_rad.sin_cos();
    let (sp, cp) = phi_rad.sin_cos();
    [st * cp, st * sp, ct]
}

/// Polar angle of `a` from +z in [0, pi], computed with `atan2` (accurate near 0 and pi).
#[inline(always)]
pub fn polar_angle<T: Real>(a: Vec3<T>) -> T {
    a[0].hypot(a[1]).atan2(a[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basic_algebra() {
        let a = [1.0_f64, 2.0, 3.0];
        let b = [-2.0_f64, 0.5, 1.0];
        assert_eq!(dot(a, b), 2.0);
        assert_eq!(dot(cross(a, b), a), 0.0);
        assert!((length(normalize_or_zero(a)) - 1.0).abs() < 1e-15);
        assert_eq!(normalize_or_zero([0.0_f64; 3]), [0.0; 3]);
        assert!(try_normalize([f64::NAN, 0.0, 0.0]).is_none());
        assert!((polar_angle(spherical(0.7_f64, 2.0)) - 0.7).abs() < 1e-15);
    }
}
