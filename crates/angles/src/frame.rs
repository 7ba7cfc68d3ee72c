//! The local shading frame: normal on +z, with a tangent and bitangent built from the normal alone.

use crate::Real;
use crate::vec3::{Vec3, dot, normalize_or_zero};

/// An orthonormal frame (t, b, n) with the normal `n` as its z axis.
///
/// The tangent is chosen by the branchless construction of Duff et al. 2017 ("Building an
/// Orthonormal Basis, Revisited", JCGT 6(1)), which is continuous except across n_z = 0's sign
/// flip. The parametrizations of this crate are isotropic in the tangent choice except for the
/// half-vector azimuth phi_h, which no isotropic BRDF uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame<T> {
    /// Tangent, the local +x axis.
    pub t: Vec3<T>,
    /// Bitangent `n x t`, the local +y axis.
    pub b: Vec3<T>,
    /// Normal, the local +z axis.
    pub n: Vec3<T>,
}

impl<T: Real> Frame<T> {
    /// Builds the frame of a normal. The normal is normalized first; a zero or non-finite normal
    /// gives the identity frame (normal +z) rather than NaN.
    pub fn from_normal(normal: Vec3<T>) -> Self {
        let n = normalize_or_zero(normal);
        if n == [T::zero(); 3] {
            return Self::identity();
        }
        let one = T::one();
        let sign = one.copysign(n[2]);
        let a = -one / (sign + n[2]);
        let bb = n[0] * n[1] * a;
        let t = [one + sign * n[0] * n[0] * a, sign * bb, -sign * n[0]];
        let b = [bb, sign + n[1] * n[1] * a, -n[1]];
        Self { t, b, n }
    }

    /// The frame whose axes are the world axes.
    pub fn identity() -> Self {
        let (o, z) = (T::one(), T::zero());
        Self { t: [o, z, z], b: [z, o, z], n: [z, z, o] }
    }

    /// Expresses a world vector in this frame: `(w.t, w.b, w.n)`.
    #[inline]
    pub fn to_local(&self, w: Vec3<T>) -> Vec3<T> {
        [dot(w, self.t), dot(w, self.b), dot(w, self.n)]
    }

    /// Maps a local vector back to world coordinates.
    #[inline]
    pub fn to_world(&self, w: Vec3<T>) -> Vec3<T> {
        let mut out = [T::zero(); 3];
        for (i, o) in out.iter_mut().enumerate() {
            *o = w[0] * self.t[i] + w[1] * self.b[i] + w[2] * self.n[i];
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vec3::{cross, length};

    #[test]
    fn frames_are_orthonormal_and_right_handed() {
        for n in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 2.0, -3.0], [0.3, -0.2, 0.0]] {
            let f = Frame::<f64>::from_normal(n);
            for (a, b) in [(f.t, f.b), (f.b, f.n), (f.t, f.n)] {
                assert!(dot(a, b).abs() < 1e-14);
            }
            for a in [f.t, f.b, f.n] {
                assert!((length(a) - 1.0).abs() < 1e-14);
            }
            let c = cross(f.n, f.t);
            assert!((0..3).all(|i| (c[i] - f.b[i]).abs() < 1e-14));
            let w = [0.1, -0.7, 0.2];
            let back = f.to_world(f.to_local(w));
            assert!((0..3).all(|i| (back[i] - w[i]).abs() < 1e-14));
        }
        assert_eq!(Frame::<f32>::from_normal([0.0; 3]), Frame::identity());
        assert_eq!(Frame::<f32>::from_normal([f32::NAN, 0.0, 1.0]), Frame::identity());
    }
}
