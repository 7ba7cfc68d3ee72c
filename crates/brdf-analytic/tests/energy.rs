//! Energy: Realistic Phong's directional albedo is at most 1 for every parameter value
//! (cosine-weighted Monte Carlo with a standard error), and Lambert's equals its albedo.

mod common;

use brdf_analytic::albedo::directional_albedo;
use brdf_analytic::*;
use common::*;
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// Over the whole parameter space (kd + ks <= 1, N in [1, 1e6] log-uniform) and every
    /// incidence angle, the estimate is not significantly above 1 (4 standard errors).
    #[test]
    fn realistic_phong_albedo_at_most_one(p in phong_params(), theta in 0.0..FRAC_PI_2, seed in any::<u64>()) {
        let m = RealisticPhong::new(p);
        let l = [theta.sin(), 0.0, theta.cos()];
        let e = directional_albedo(&m, l, 20_000, seed);
        prop_assert!(e.at_most(1.0, 4.0), "{p:?} theta {theta}: {e:?}");
    }
}

/// The extreme case kd = 0, ks = 1 at normal incidence integrates to exactly 1 for every N:
/// checked by deterministic quadrature, tight, for N from 1 to 1e4.
#[test]
fn realistic_phong_worst_case_is_exactly_one_by_quadrature() {
    for n in [1.0, 2.0, 10.0, 100.0, 1e4] {
        let m =
            RealisticPhong::new(RealisticPhongParams { kd: [0.0; 3], ks: [1.0; 3], exponent: n });
        // Azimuthal symmetry at normal incidence: a = 2 pi int f cos sin d theta; f depends on
        // cos(theta) only. Substitute u = cos(theta): a = 2 pi int_0^1 f(u) u du (midpoint rule).
        let steps = 2_000_000;
        let du = 1.0 / steps as f64;
        let a: f64 = (0..steps)
            .map(|i| {
                let u = (i as f64 + 0.5) * du;
                let v = [(1.0 - u * u).sqrt(), 0.0, u];
                m.eval([0.0, 0.0, 1.0], v)[0] * u * du
            })
            .sum::<f64>()
            * 2.0
            * PI;
        assert!((a - 1.0).abs() < 1e-6 * (1.0 + n / 100.0), "N = {n}: albedo {a}");
    }
}

#[test]
fn lambert_albedo_matches_parameter_within_error_bar() {
    let m = Lambert::new(LambertParams { albedo: [0.1_f32, 0.5, 0.95] });
    for theta in [0.0_f32, 0.7, 1.5] {
        let e = directional_albedo(&m, [theta.sin(), 0.0, theta.cos()], 1000, 3);
        for (c, a) in [0.1, 0.5, 0.95].into_iter().enumerate() {
            assert!((e.mean[c] - a).abs() <= 4.0 * e.std_error[c] + 1e-6, "{e:?}");
        }
    }
}

/// Not a bound (these models do not conserve energy in general): the estimate is finite and
/// positive, and the Disney diffuse lobe at default parameters stays in the expected range.
#[test]
fn ts_and_disney_albedo_are_finite() {
    let ts = TorranceSparrow::new(TorranceSparrowParams::<f64>::default());
    let disney = Disney::new(DisneyParams::<f64>::default());
    for theta in [0.0_f64, 0.5, 1.0, 1.4, 1.55] {
        let l = [theta.sin(), 0.0, theta.cos()];
        for e in
            [directional_albedo(&ts, l, 50_000, 11), directional_albedo(&disney, l, 50_000, 11)]
        {
            assert!(e.mean.iter().all(|m| m.is_finite() && *m > 0.0 && *m < 2.0), "{e:?}");
        }
    }
}
