//! Property tests of the parametrizations over random upper-hemisphere pairs.

use angles::vec3::{Vec3, cast, dot, spherical};
use angles::{PositionalEncoding, Rusinkiewicz, ViewLight, reciprocal_theta};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// A uniformly random direction in the closed upper hemisphere (cos theta uniform in [0, 1]).
fn upper() -> impl Strategy<Value = Vec3<f64>> {
    (0.0..=1.0_f64, 0.0..TAU).prop_map(|(c, phi)| {
        let s = (1.0 - c * c).max(0.0).sqrt();
        [s * phi.cos(), s * phi.sin(), c]
    })
}

fn max_abs_diff(a: Vec3<f64>, b: Vec3<f64>) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max)
}

/// Angle difference modulo 2 pi, in [0, pi].
fn angle_dist(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20_000, ..ProptestConfig::default() })]

    #[test]
    fn round_trip_f64(l in upper(), v in upper()) {
        let r = Rusinkiewicz::from_local(l, v);
        prop_assert!(r.theta_h >= 0.0 && r.theta_h <= FRAC_PI_2 + 1e-15);
        prop_assert!(r.theta_d >= 0.0 && r.theta_d <= FRAC_PI_2 + 1e-15);
        prop_assert!(r.phi_d >= 0.0 && r.phi_d < TAU);
        let (l2, v2) = r.to_local_with_phi_h(Rusinkiewicz::phi_h_of(l, v));
        prop_assert!(max_abs_diff(l, l2) < 1e-12, "l {:?} -> {:?}", l, l2);
        prop_assert!(max_abs_diff(v, v2) < 1e-12, "v {:?} -> {:?}", v, v2);
        // theta_d is arccos(l.h).
        let h = angles::vec3::normalize_or_zero(angles::vec3::add(l, v));
        prop_assert!((r.theta_d.cos() - dot(l, h)).abs() < 1e-12);
    }

    #[test]
    fn inverse_round_trip(th in 0.0..FRAC_PI_2, td in 0.0..FRAC_PI_2, pd in 0.0..TAU) {
        let r = Rusinkiewicz { theta_h: th, theta_d: td, phi_d: pd };
        let (l, v) = r.to_local();
        let back = Rusinkiewicz::from_local(l, v);
        prop_assert!((back.theta_d - td).abs() < 1e-12);
        // As theta_d -> pi/2, l -> -v and the half vector (hence theta_h and phi_d) is defined
        // only to about eps / (2 cos theta_d): compare where that is below the bound.
        if td.cos() > 1e-3 {
            prop_assert!((back.theta_h - th).abs() < 1e-12, "theta_h {} vs {th}", back.theta_h);
            if td > 1e-6 && th > 1e-6 {
                prop_assert!(angle_dist(back.phi_d, pd) < 1e-9);
            }
        }
    }

    #[test]
    fn swap_adds_pi_to_phi_d(l in upper(), v in upper()) {
        let a = Rusinkiewicz::from_local(l, v);
        let b = Rusinkiewicz::from_local(v, l);
        prop_assert_eq!(a.theta_h.to_bits(), b.theta_h.to_bits());
        prop_assert_eq!(a.theta_d.to_bits(), b.theta_d.to_bits());
        if a.theta_d > 1e-9 {
            prop_assert!(angle_dist(b.phi_d, a.phi_d + PI) < 1e-12);
        }
        let va = ViewLight::from_local(l, v);
        let vb = ViewLight::from_local(v, l);
        prop_assert_eq!(va.theta_v, vb.theta_l);
        prop_assert!(angle_dist(va.delta_phi, -vb.delta_phi) < 1e-12);
    }

    #[test]
    fn reciprocal_theta_is_bit_identical_under_swap(l in upper(), v in upper()) {
        let a = reciprocal_theta(l, v);
        let b = reciprocal_theta(v, l);
        prop_assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        prop_assert!(a[2] >= 0.0 && a[2] < PI && a[3] >= PI && a[3] < TAU);
        let r = Rusinkiewicz::from_local(l, v);
        prop_assert_eq!(a[0], r.theta_h);
        if r.theta_d > 1e-9 {
            prop_assert!(angle_dist(2.0 * a[2], 2.0 * r.phi_d) < 1e-11);
        }
        let f = [l, v].map(cast::<f64, f32>);
        let (a32, b32) = (reciprocal_theta(f[0], f[1]), reciprocal_theta(f[1], f[0]));
        prop_assert_eq!(a32.map(f32::to_bits), b32.map(f32::to_bits));
    }

    #[test]
    fn f32_agrees_with_f64(l in upper(), v in upper()) {
        let (l32, v32) = (cast::<f64, f32>(l), cast::<f64, f32>(v));
        // Compare against f64 evaluated at the same (rounded) inputs.
        let r64 = Rusinkiewicz::from_local(cast::<f32, f64>(l32), cast::<f32, f64>(v32));
        let r32 = Rusinkiewicz::from_local(l32, v32);
        prop_assert!((r32.theta_h as f64 - r64.theta_h).abs() < 2e-6);
        prop_assert!((r32.theta_d as f64 - r64.theta_d).abs() < 2e-6);
        // phi_d is ill-conditioned as theta_d -> 0 (undefined at l = v): scale the bound.
        let tol = 4e-6 / r64.theta_d.sin().max(1e-9);
        prop_assert!(angle_dist(r32.phi_d as f64, r64.phi_d) < tol.max(4e-6),
            "phi_d {} vs {}", r32.phi_d, r64.phi_d);
        let vl32 = ViewLight::from_local(l32, v32);
        let vl64 = ViewLight::from_local(cast::<f32, f64>(l32), cast::<f32, f64>(v32));
        prop_assert!((vl32.theta_v as f64 - vl64.theta_v).abs() < 2e-6);
    }

    #[test]
    fn encoding_is_finite_and_bounded(x in proptest::collection::vec(-1e6..1e6_f64, 1..8)) {
        let pe = PositionalEncoding::default();
        let e = pe.encode(&x);
        prop_assert_eq!(e.len(), 7 * x.len());
        prop_assert!(e[x.len()..].iter().all(|s| s.abs() <= 1.0));
    }
}

#[test]
fn degenerate_configurations_are_finite() {
    let n = [0.0, 0.0, 1.0];
    let grazing = |phi: f64| spherical(FRAC_PI_2, phi);
    let cases: Vec<(Vec3<f64>, Vec3<f64>)> = vec![
        (n, n),                                          // theta_h = 0, theta_d = 0, l = v
        (grazing(0.0), grazing(0.0)),                    // l = v at the horizon
        (grazing(0.0), grazing(PI)),                     // l = -v (l + v = 0)
        (grazing(0.3), n),                               // n.l = 0
        (grazing(1.0), grazing(2.5)),                    // both n.l = 0 and n.v = 0
        (spherical(0.4, 1.0), spherical(0.4, 1.0 + PI)), // mirror pair: theta_h = 0
        ([0.0, 0.0, 0.0], n),                            // invalid zero vector: still finite
    ];
    for (l, v) in cases {
        for (a, b) in [(l, v), (v, l)] {
            let r = Rusinkiewicz::from_local(a, b);
            assert!(r.to_array().iter().all(|x| x.is_finite()), "{a:?} {b:?} -> {r:?}");
            assert!(reciprocal_theta(a, b).iter().all(|x| x.is_finite()));
            assert!(ViewLight::from_local(a, b).to_array().iter().all(|x| x.is_finite()));
            let (l2, v2) = r.to_local();
            assert!(l2.iter().chain(&v2).all(|x| x.is_finite()));
            let r32 = Rusinkiewicz::from_local(cast::<f64, f32>(a), cast::<f64, f32>(b));
            assert!(r32.to_array().iter().all(|x| x.is_finite()));
        }
    }
}

#[test]
fn world_frame_matches_local_frame_for_any_normal() {
    let n = angles::vec3::normalize_or_zero([0.3_f64, -0.5, 0.8]);
    let f = angles::Frame::from_normal(n);
    let (l_loc, v_loc) = (spherical(0.7, 0.2), spherical(0.3, 2.9));
    let (l, v) = (f.to_world(l_loc), f.to_world(v_loc));
    let a = Rusinkiewicz::from_world(n, l, v);
    let b = Rusinkiewicz::from_local(l_loc, v_loc);
    assert!((a.theta_h - b.theta_h).abs() < 1e-14);
    assert!((a.theta_d - b.theta_d).abs() < 1e-14);
    assert!(angle_dist(a.phi_d, b.phi_d) < 1e-12);
}
