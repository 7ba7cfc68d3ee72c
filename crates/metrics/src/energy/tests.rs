//! Tests of the energy-conservation estimators.

#![allow(clippy::needless_range_loop)]

use super::*;
use crate::batch::{AnalyticBatch, FnBatch};
use brdf_analytic::{Lambert, LambertParams, TorranceSparrow, TorranceSparrowParams};

fn light(theta_deg: f32) -> [f32; 3] {
    let (s, c) = theta_deg.to_radians().sin_cos();
    [s, 0.0, c]
}

fn mc(samples: usize) -> EnergyConfig {
    EnergyConfig { estimator: Estimator::MonteCarlo { samples }, seed: 7, progress: false }
}

fn fast() -> EnergyConfig {
    EnergyConfig { estimator: Estimator::fast(), seed: 7, progress: false }
}

#[test]
fn lambert_gives_its_albedo_within_the_error_bar() {
    let a = [0.2f32, 0.55, 0.9];
    let brdf = AnalyticBatch(Lambert::new(LambertParams { albedo: a }));
    let pairs: Vec<EnergyPair> =
        (0..10).map(|i| EnergyPair { point: i, l: light(8.0 * i as f32) }).collect();
    for cfg in [mc(2000), fast()] {
        let rep = energy_conservation(&brdf, &pairs, &cfg).unwrap();
        for p in &rep.pairs {
            for c in 0..3 {
                let err = (p.energy[c] - a[c] as f64).abs();
                assert!(err <= 4.0 * p.std_error[c] + 1e-6, "{:?}: {p:?}", cfg.estimator);
            }
        }
        assert_eq!(rep.percent_above_one, 0.0);
        assert_eq!(rep.median_above_one, None);
    }
}

/// A glossy Torrance-Sparrow model: both estimators agree with a long independent Monte Carlo
/// reference (brdf_analytic::albedo, 400k samples) within their combined error bars, and the
/// fast one spends fewer evaluations.
#[test]
fn estimators_agree_on_a_glossy_model() {
    let ts = TorranceSparrow::new(TorranceSparrowParams {
        roughness: 0.4,
        diffuse: [0.6, 0.3, 0.1],
        f0: [0.9, 0.9, 0.9],
    });
    let brdf = AnalyticBatch(ts);
    let pairs: Vec<EnergyPair> =
        [10.0f32, 45.0, 70.0].iter().map(|t| EnergyPair { point: 0, l: light(*t) }).collect();
    let slow = energy_conservation(&brdf, &pairs, &mc(20_000)).unwrap();
    let quick = energy_conservation(&brdf, &pairs, &fast()).unwrap();
    for (k, (s, q)) in slow.pairs.iter().zip(&quick.pairs).enumerate() {
        let l = light([10.0f32, 45.0, 70.0][k]);
        let reference = brdf_analytic::albedo::directional_albedo(&ts, l, 400_000, 99);
        for c in 0..3 {
            let r = reference.mean[c];
            let rs = reference.std_error[c];
            assert!((s.energy[c] - r).abs() <= 4.0 * (s.std_error[c] + rs), "mc {k} {c}");
            assert!((q.energy[c] - r).abs() <= 4.0 * (q.std_error[c] + rs) + 1e-4, "qmc {k} {c}");
            let settled =
                q.std_error[c] <= 1e-3 + 1e-12 || q.energy[c] + 4.0 * q.std_error[c] < 1.0;
            assert!(settled || q.evaluations == 8 * 2048);
        }
    }
    assert!(quick.evaluations < slow.evaluations, "{} vs {}", quick.evaluations, slow.evaluations);
}

#[test]
fn deterministic_for_a_seed() {
    let brdf = AnalyticBatch(TorranceSparrow::new(TorranceSparrowParams::<f32>::default()));
    let pairs: Vec<EnergyPair> =
        (0..5).map(|i| EnergyPair { point: i, l: light(15.0 * i as f32) }).collect();
    for cfg in [mc(500), fast()] {
        let a = energy_conservation(&brdf, &pairs, &cfg).unwrap();
        let b = energy_conservation(&brdf, &pairs, &cfg).unwrap();
        assert_eq!(a.pairs, b.pairs);
        let other = EnergyConfig { seed: 8, ..cfg };
        let c = energy_conservation(&brdf, &pairs, &other).unwrap();
        assert_ne!(a.pairs, c.pairs);
    }
}

#[test]
fn violation_summary() {
    // f = k / pi: E = k exactly. Points 0..3 have k = 0.5, 1.5, 2.5, and one channel only.
    let brdf = FnBatch(|p: u32, _l: [f32; 3], _v: [f32; 3]| {
        [0.2, (0.5 + p as f32) / std::f32::consts::PI, 0.1]
    });
    let pairs: Vec<EnergyPair> = (0..3).map(|i| EnergyPair { point: i, l: light(30.0) }).collect();
    let rep = energy_conservation(&brdf, &pairs, &mc(64)).unwrap();
    assert!((rep.percent_above_one - 200.0 / 3.0).abs() < 1e-9);
    assert!((rep.median_above_one.unwrap() - 2.0).abs() < 1e-5);
    assert_eq!(rep.evaluations, 3 * 64);
}

#[test]
fn sobol_points_are_a_net() {
    // The first 2^m points have exactly one point in every 2^a x 2^(m-a) elementary box.
    let m = 6;
    for a in 0..=m {
        let mut seen = vec![false; 1 << m];
        for i in 0..(1u32 << m) {
            let (x, y) = sobol2(i);
            let top = |v: u32, bits: u32| if bits == 0 { 0 } else { (v >> (32 - bits)) as usize };
            let (bx, by) = (top(x, a), top(y, m - a));
            let cell = (bx << (m - a)) | by;
            assert!(!seen[cell], "a = {a}, i = {i}");
            seen[cell] = true;
        }
    }
}

#[test]
fn sample_pairs_is_deterministic_and_distinct() {
    let a = sample_pairs(1000, 50, 3);
    assert_eq!(a, sample_pairs(1000, 50, 3));
    assert_eq!(a.len(), 50);
    assert!(a.windows(2).all(|w| w[0] < w[1]));
    assert_eq!(sample_pairs(10, 50, 3).len(), 10);
}

#[test]
fn bad_configuration_is_an_error() {
    let brdf = AnalyticBatch(Lambert::new(LambertParams::<f32>::default()));
    let pairs = [EnergyPair { point: 0, l: light(0.0) }];
    let cfg =
        EnergyConfig { estimator: Estimator::MonteCarlo { samples: 0 }, ..Default::default() };
    assert!(energy_conservation(&brdf, &pairs, &cfg).is_err());
    assert!(energy_conservation(&brdf, &[], &EnergyConfig::default()).is_err());
}
