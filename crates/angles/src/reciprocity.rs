//! The paper's reciprocity mapping of the Rusinkiewicz angles (spec section 2, [P §4.3]).

use crate::Real;
use crate::rusinkiewicz::Rusinkiewicz;
use crate::vec3::{Vec3, add, sub};

/// Theta = [theta_h, theta_d, phi_d mod pi, (phi_d mod pi) + pi] of a local-frame pair.
///
/// Theta(l, v) == Theta(v, l) **bit for bit**: the function is computed from l + v and from
/// l - v with its sign canonicalized (the azimuth of (d_x, d_y) taken modulo pi), never from the
/// already-wrapped phi_d. Any network fed Theta is therefore exactly reciprocal. The third
/// component lies in [0, pi), the fourth in [pi, 2 pi).
#[inline]
pub fn reciprocal_theta<T: Real>(l: Vec3<T>, v: Vec3<T>) -> [T; 4] {
    let r = Rusinkiewicz::from_local(l, v);
    // Under the swap, w = l - v becomes exactly -w, and so do its rotated x, y components.
    let w = sub(l, v);
    let (mut dx, mut dy) = half_rotated_xy(add(l, v), w);
    if dy < T::zero() || (dy == T::zero() && dx < T::zero()) {
        dx = -dx;
        dy = -dy;
    }
    // -0 and +0 must not differ.
    let dy = dy + T::zero();
    let mut phi = dy.atan2(dx + T::zero());
    if phi >= T::PI() {
        phi = T::zero();
    }
    [r.theta_h, r.theta_d, phi, phi + T::PI()]
}

/// x, y of `w` after the rotation that sends a = l + v to +z (as in [`Rusinkiewicz`]).
#[inline(always)]
fn half_rotated_xy<T: Real>(a: Vec3<T>, w: Vec3<T>) -> (T, T) {
    let (zero, one) = (T::zero(), T::one());
    let rho = a[0].hypot(a[1]);
    let (c, s) = if rho > zero { (a[0] / rho, a[1] / rho) } else { (one, zero) };
    let len = (rho * rho + a[2] * a[2]).sqrt();
    let (ct, st) = if len > zero { (a[2] / len, rho / len) } else { (one, zero) };
    let x1 = w[0] * c + w[1] * s;
    let y1 = w[1] * c - w[0] * s;
    (x1 * ct - w[2] * st, y1)
}

/// Batched [`reciprocal_theta`].
///
/// # Panics
/// If the three slices differ in length.
pub fn reciprocal_theta_batch<T: Real>(l: &[Vec3<T>], v: &[Vec3<T>], out: &mut [[T; 4]]) {
    assert!(l.len() == v.len() && v.len() == out.len(), "reciprocal_theta_batch: lengths differ");
    for ((o, &l), &v) in out.iter_mut().zip(l).zip(v) {
        *o = reciprocal_theta(l, v);
    }
}
