//! Rusinkiewicz half/difference angles (Rusinkiewicz 1998; spec section 2).

use crate::Real;
use crate::frame::Frame;
use crate::vec3::{Vec3, add, dot, length, sub};

/// The half/difference angles of a direction pair, isotropic part.
///
/// With h = (l + v)/|l + v| and d the light direction l expressed in the frame that sends h to +z
/// (d = R_b(-theta_h) R_n(-phi_h) l):
///
/// | field | meaning | range |
/// | --- | --- | --- |
/// | `theta_h` | polar angle of h | [0, pi/2] for upper-hemisphere pairs |
/// | `theta_d` | polar angle of d, equal to arccos(l.h) | [0, pi/2] |
/// | `phi_d` | azimuth of d | [0, 2 pi) |
///
/// Swapping l and v leaves theta_h and theta_d unchanged and adds pi to phi_d (mod 2 pi).
/// Where phi_d is undefined (l = v) it is 0; where phi_h is undefined (h = n) it is 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rusinkiewicz<T> {
    /// Polar angle of the half vector, radians.
    pub theta_h: T,
    /// Polar angle of the difference vector, radians.
    pub theta_d: T,
    /// Azimuth of the difference vector, radians, in [0, 2 pi).
    pub phi_d: T,
}

/// The rotation `R_b(-theta_h) R_n(-phi_h)` of a pair, as cosines and sines.
#[derive(Clone, Copy)]
struct HalfFrame<T> {
    cos_phi_h: T,
    sin_phi_h: T,
    cos_theta_h: T,
    sin_theta_h: T,
}

impl<T: Real> HalfFrame<T> {
    /// Built from the unnormalized half vector a = l + v, so it is symmetric in l and v.
    #[inline(always)]
    fn of(a: Vec3<T>) -> Self {
        let (zero, one) = (T::zero(), T::one());
        let rho = a[0].hypot(a[1]);
        let (cos_phi_h, sin_phi_h) =
            if rho > zero { (a[0] / rho, a[1] / rho) } else { (one, zero) };
        let len = length(a);
        let (cos_theta_h, sin_theta_h) =
            if len > zero { (a[2] / len, rho / len) } else { (one, zero) };
        Self { cos_phi_h, sin_phi_h, cos_theta_h, sin_theta_h }
    }

    /// Applies the rotation to `w`, returning only the x and y components.
    #[inline(always)]
    fn rotate_xy(&self, w: Vec3<T>) -> (T, T) {
        let x1 = w[0] * self.cos_phi_h + w[1] * self.sin_phi_h;
        let y1 = w[1] * self.cos_phi_h - w[0] * self.sin_phi_h;
        (x1 * self.cos_theta_h - w[2] * self.sin_theta_h, y1)
    }
}

/// Wraps an angle from (-pi, pi] into [0, 2 pi), mapping -0 to +0.
#[inline(always)]
pub(crate) fn wrap_two_pi<T: Real>(phi: T) -> T {
    let wrapped = if phi < T::zero() { phi + T::TAU() } else { phi + T::zero() };
    // phi slightly below 0 can round to exactly 2 pi.
    if wrapped >= T::TAU() { T::zero() } else { wrapped }
}

impl<T: Real> Rusinkiewicz<T> {
    /// Angles of a pair of unit directions given in the local frame (normal +z).
    ///
    /// Computed symmetrically: theta_h from l + v, theta_d = atan2(|l - v|, |l + v|), and phi_d
    /// from the half-frame rotation of w = (l - v)/2 (whose x, y equal those of d).
    #[inline]
    pub fn from_local(l: Vec3<T>, v: Vec3<T>) -> Self {
        let a = add(l, v);
        let w = sub(l, v);
        let frame = HalfFrame::of(a);
        let theta_h = a[0].hypot(a[1]).atan2(a[2]);
        let theta_d = length(w).atan2(length(a));
        let (dx, dy) = frame.rotate_xy(w);
        Self { theta_h, theta_d, phi_d: wrap_two_pi(dy.atan2(dx)) }
    }

    /// Angles of world-space directions about the world-space normal `n`.
    #[inline]
    pub fn from_world(n: Vec3<T>, l: Vec3<T>, v: Vec3<T>) -> Self {
        let f = Frame::from_normal(n);
        Self::from_local(f.to_local(l), f.to_local(v))
    }

    /// The azimuth phi_h of the half vector in (-pi, pi], which the isotropic angles drop.
    pub fn phi_h_of(l: Vec3<T>, v: Vec3<T>) -> T {
        let a = add(l, v);
        a[1].atan2(a[0])
    }

    /// The pair (l, v) in the local frame for the half-vector azimuth phi_h = 0.
    #[inline]
    pub fn to_local(&self) -> (Vec3<T>, Vec3<T>) {
        let (st, ct) = self.theta_h.sin_cos();
        let (sd, cd) = self.theta_d.sin_cos();
        let (sp, cp) = self.phi_d.sin_cos();
        let d = [sd * cp, sd * sp, cd];
        let h = [st, T::zero(), ct];
        let l = [d[0] * ct + d[2] * st, d[1], d[2] * ct - d[0] * st];
        let two_lh = T::lit(2.0) * dot(l, h);
        let v = [two_lh * h[0] - l[0], two_lh * h[1] - l[1], two_lh * h[2] - l[2]];
        (l, v)
    }

    /// The pair (l, v) in the local frame, rotated about the normal by `phi_h_rad`.
    pub fn to_local_with_phi_h(&self, phi_h_rad: T) -> (Vec3<T>, Vec3<T>) {
        let (l, v) = self.to_local();
        let (s, c) = phi_h_rad.sin_cos();
        let rot = |w: Vec3<T>| [w[0] * c - w[1] * s, w[0] * s + w[1] * c, w[2]];
        (rot(l), rot(v))
    }

    /// The angles as an array `[theta_h, theta_d, phi_d]`.
    pub fn to_array(self) -> [T; 3] {
        [self.theta_h, self.theta_d, self.phi_d]
    }
}

/// Batched [`Rusinkiewicz::from_local`] over slices of local-frame directions.
///
/// # Panics
/// If the three slices differ in length.
pub fn rusinkiewicz_batch<T: Real>(l: &[Vec3<T>], v: &[Vec3<T>], out: &mut [Rusinkiewicz<T>]) {
    assert!(l.len() == v.len() && v.len() == out.len(), "rusinkiewicz_batch: slice lengths differ");
    for ((o, &l), &v) in out.iter_mut().zip(l).zip(v) {
        *o = Rusinkiewicz::from_local(l, v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    #[test]
    fn normal_incidence_and_mirror_configuration() {
        let n = [0.0, 0.0, 1.0_f64];
        let r = Rusinkiewicz::from_local(n, n);
        assert_eq!(r.to_array(), [0.0, 0.0, 0.0]);
        // Mirror pair about the normal: h = n, theta_d = theta_l.
        let t = 0.6_f64;
        let l = [t.sin(), 0.0, t.cos()];
        let v = [-t.sin(), 0.0, t.cos()];
        let r = Rusinkiewicz::from_local(l, v);
        assert!(r.theta_h.abs() < 1e-15 && (r.theta_d - t).abs() < 1e-15);
        assert!(r.phi_d.abs() < 1e-15);
        // Both at the horizon, opposite: l + v = 0.
        let r = Rusinkiewicz::from_local([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]);
        assert!((r.theta_d - FRAC_PI_2).abs() < 1e-15 && r.theta_h.is_finite());
        // Both at the horizon, same azimuth: h on the horizon.
        let r = Rusinkiewicz::from_local([1.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        assert!((r.theta_h - FRAC_PI_2).abs() < 1e-15 && r.theta_d == 0.0);
        assert!(r.phi_d >= 0.0 && r.phi_d < 2.0 * PI);
    }
}
