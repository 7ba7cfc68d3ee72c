//! The view-light parametrization of the angle ablation ([P supp. "Influence of the Angle
//! Parametrization"]).

use crate::Real;
use crate::rusinkiewicz::wrap_two_pi;
use crate::vec3::{Vec3, polar_angle};

/// The triplet (theta_v, theta_l, phi_v - phi_l) of a local-frame pair.
///
/// | field | meaning | range |
/// | --- | --- | --- |
/// | `theta_v` | polar angle of v | [0, pi/2] in the upper hemisphere |
/// | `theta_l` | polar angle of l | [0, pi/2] |
/// | `delta_phi` | azimuth difference phi_v - phi_l | [0, 2 pi) |
///
/// delta_phi is computed as atan2((l x v)_z, l_xy . v_xy), which needs no frame azimuth and is 0
/// where undefined (either direction along the normal).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewLight<T> {
    /// Polar angle of the view direction, radians.
    pub theta_v: T,
    /// Polar angle of the light direction, radians.
    pub theta_l: T,
    /// Azimuth difference phi_v - phi_l, radians, in [0, 2 pi).
    pub delta_phi: T,
}

impl<T: Real> ViewLight<T> {
    /// The triplet of a pair of local-frame unit directions.
    #[inline]
    pub fn from_local(l: Vec3<T>, v: Vec3<T>) -> Self {
        let cross_z = l[0] * v[1] - l[1] * v[0];
        let dot_xy = l[0] * v[0] + l[1] * v[1];
        Self {
            theta_v: polar_angle(v),
            theta_l: polar_angle(l),
            delta_phi: wrap_two_pi(cross_z.atan2(dot_xy)),
        }
    }

    /// The triplet as an array `[theta_v, theta_l, delta_phi]`.
    pub fn to_array(self) -> [T; 3] {
        [self.theta_v, self.theta_l, self.delta_phi]
    }
}

/// Batched [`ViewLight::from_local`].
///
/// # Panics
/// If the three slices differ in length.
pub fn view_light_batch<T: Real>(l: &[Vec3<T>], v: &[Vec3<T>], out: &mut [ViewLight<T>]) {
    assert!(l.len() == v.len() && v.len() == out.len(), "view_light_batch: lengths differ");
    for ((o, &l), &v) in out.iter_mut().zip(l).zip(v) {
        *o = ViewLight::from_local(l, v);
    }
}
