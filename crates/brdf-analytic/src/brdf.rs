//! The one interface every analytic BRDF implements.

use angles::{Real, Vec3};

/// Linear RGB triple.
pub type Rgb<T> = [T; 3];

/// A BRDF evaluated in the local shading frame.
///
/// `l` points to the light and `v` to the viewer, both unit vectors in the frame whose +z axis is
/// the shading normal. The result is f_r(l, v) in 1/sr, linear RGB, **without** the cos(theta_l)
/// factor. Implementations return `[0; 3]` when `l.z <= 0` or `v.z <= 0`, and never NaN or Inf.
pub trait Brdf<T: Real>: Send + Sync {
    /// f_r(l, v), linear RGB in 1/sr.
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T>;

    /// The model's name as the paper's tables write it (for example "Disney").
    fn name(&self) -> &'static str;

    /// Whether f(l, v) = f(v, l) holds exactly in exact arithmetic.
    fn is_reciprocal(&self) -> bool {
        true
    }
}

impl<T: Real, B: Brdf<T> + ?Sized> Brdf<T> for &B {
    #[inline(always)]
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        (**self).eval(l, v)
    }
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn is_reciprocal(&self) -> bool {
        (**self).is_reciprocal()
    }
}

impl<T: Real> Brdf<T> for Box<dyn Brdf<T>> {
    #[inline(always)]
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        (**self).eval(l, v)
    }
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn is_reciprocal(&self) -> bool {
        (**self).is_reciprocal()
    }
}
