//! FMBRDF geometry as the official implementation writes it: the clamped Smith input tan(theta),
//! the clamped dielectric Fresnel term and the view-aligned frame of the body network.

use angles::{Real, Vec3};

/// The official code clamps n.w into [COS_EPS, 1 - COS_EPS] before the Smith network, and n.h
/// and v.h below 1 - COS_EPS before acos and the Fresnel equations.
pub(crate) const COS_EPS: f64 = 1e-6;

/// The official code's guard added to denominators (Fresnel amplitudes, 4 n.v n.h, n.l).
pub(crate) const DEN_EPS: f64 = 1e-9;

/// tan(arccos(clamp(c, 1e-6, 1 - 1e-6))), computed as sqrt((1 - c)(1 + c)) / c (exact in
/// exact arithmetic, free of the cancellation of 1 - c^2 and of acos near 1). At most ~1e6.
#[inline]
pub fn smith_tan<T: Real>(cos: T) -> T {
    let c = cos.max(T::lit(COS_EPS)).min(T::lit(1.0 - COS_EPS));
    ((T::one() - c) * (T::one() + c)).sqrt() / c
}

/// Unpolarised dielectric reflectance (R_s + R_p)/2 at the incidence cosine `cos_r`, for the
/// relative index `eta` (>= 1.1), with the official code's clamps (cos r in [0, 1 - 1e-6],
/// sin t in [0, 1 - 1e-6]) and its 1e-9 denominator guards.
#[inline]
pub(crate) fn fresnel<T: Real>(cos_r: T, eta: T) -> T {
    let one = T::one();
    let cap = T::lit(1.0 - COS_EPS);
    let a = eta.recip();
    let cos_r = cos_r.max(T::zero()).min(cap);
    let sin_r = ((one - cos_r) * (one + cos_r)).sqrt();
    let sin_t = (a * sin_r).max(T::zero()).min(cap);
    let cos_t = ((one - sin_t) * (one + sin_t)).sqrt();
    let eps = T::lit(DEN_EPS);
    let rs = (a * cos_r - cos_t) / (a * cos_r + cos_t + eps);
    let rp = (cos_r - a * cos_t) / (a * cos_t + cos_r + eps);
    T::lit(0.5) * (rs * rs + rp * rp)
}

/// The six varying inputs of the body network, [n''_x, n''_y, n''_z, l''_x, l''_z, n''.l''], for
/// unit `l`, `v` in the local frame (normal +z, v.z > 0).
///
/// Frame 1 rotates u = -v onto +z with R = Rx(-rot_x) Ry(-rot_y), rot_y = atan2(u_x, u_z),
/// rot_x = -asin(u_y). Written without trigonometry, with rho = hypot(u_x, u_z) = cos(rot_x):
///
/// ```text
/// R = [  u_z/rho        0     -u_x/rho      ]
///     [ -u_y u_x/rho   rho    -u_y u_z/rho  ]
///     [  u_x           u_y     u_z          ]
/// ```
///
/// (rho >= v.z > 0 on the upper hemisphere). Frame 2 rotates about z by -atan2(l'_y, l'_x), so that
/// l'' = (hypot(l'_x, l'_y), 0, l'_z); when l' lies on the z axis (l = v) the angle is
/// atan2(0, 0) = 0 and the rotation is the identity, as in the official code.
#[inline]
pub fn body_features<T: Real>(l: Vec3<T>, v: Vec3<T>) -> [T; 6] {
    let u = [-v[0], -v[1], -v[2]];
    let rho = u[0].hypot(u[2]);
    let (cy, sy) = if rho > T::zero() { (u[2] / rho, u[0] / rho) } else { (T::one(), T::zero()) };
    // n' = R (0, 0, 1).
    let n1 = [-sy, -u[1] * cy, u[2]];
    // l' = R l. Since R v = (0, 0, -1), the first two components are those of R (l - v): exactly 0
    // for l = v and free of cancellation near it.
    let d = [l[0] - v[0], l[1] - v[1], l[2] - v[2]];
    let l1 = [
        cy * d[0] - sy * d[2],
        -u[1] * (sy * d[0] + cy * d[2]) + rho * d[1],
        u[0] * l[0] + u[1] * l[1] + u[2] * l[2],
    ];
    let r = l1[0].hypot(l1[1]);
    let (cp, sp) = if r > T::zero() { (l1[0] / r, l1[1] / r) } else { (T::one(), T::zero()) };
    let n2 = [cp * n1[0] + sp * n1[1], -sp * n1[0] + cp * n1[1], n1[2]];
    let nl = n2[0] * r + n2[2] * l1[2];
    [n2[0], n2[1], n2[2], r, l1[2], nl]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smith_tan_matches_definition_and_clamps() {
        for c in [0.01_f64, 0.3, 0.7, 0.999] {
            assert!((smith_tan(c) - c.acos().tan()).abs() < 1e-13 * c.acos().tan());
        }
        assert!((smith_tan(0.0_f64) - (1.0 - 1e-12f64).sqrt() / 1e-6).abs() < 1e-3);
        assert!(smith_tan(1.0_f32) > 0.0 && smith_tan(1.0_f32) < 2e-3);
        assert!(smith_tan(0.0_f32).is_finite());
    }

    #[test]
    fn fresnel_limits() {
        let eta = 1.5_f64;
        // Normal incidence ((eta - 1)/(eta + 1))^2 = 0.04, grazing 1 (up to the clamps/guards).
        assert!((fresnel(1.0, eta) - 0.04).abs() < 1e-8);
        assert!((fresnel(0.0, eta) - 1.0).abs() < 1e-8);
        assert!((fresnel(0.5, eta) - crate::microfacet::fresnel_dielectric(0.5, eta)).abs() < 1e-9);
    }

    #[test]
    fn frame_maps_view_to_minus_z() {
        // The same rotation applied to v must give (0, 0, -1); check via a direct product.
        let v = [0.3_f64, -0.4, (1.0f64 - 0.25).sqrt()];
        let l = [-0.5_f64, 0.1, (1.0f64 - 0.26).sqrt()];
        let f = body_features(l, v);
        // n''.l'' = n.l and |l''| = 1, n''_z = n.u = -v.z, l''_z = -l.v.
        assert!((f[5] - l[2]).abs() < 1e-15);
        assert!((f[3] * f[3] + f[4] * f[4] - 1.0).abs() < 1e-15);
        assert!((f[2] + v[2]).abs() < 1e-15);
        assert!((f[4] + (l[0] * v[0] + l[1] * v[1] + l[2] * v[2])).abs() < 1e-15);
        assert!((f[0] * f[0] + f[1] * f[1] + f[2] * f[2] - 1.0).abs() < 1e-15);
        // l = v: l' on the z axis, identity second rotation.
        let g = body_features(v, v);
        assert_eq!(g[3], 0.0);
        assert!((g[4] + 1.0).abs() < 1e-15);
    }
}
