//! Tests of the energy-conservation estimators.

#![allow(clippy::needless_range_loop)]

use super::*;
use brdf_analytic::FnSurface;
use brdf_analytic::{Brdf, Lambert, LambertParams, TorranceSparrow, TorranceSparrowParams};

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
    let brdf = Lambert::new(LambertParams { albedo: a });
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

#[test]
fn deterministic_for_a_seed() {
    let brdf = TorranceSparrow::new(TorranceSparrowParams::<f32>::default());
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
    let brdf = FnSurface(|p: u32, _l: [f32; 3], _v: [f32; 3]| {
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
    let brdf = Lambert::new(LambertParams::<f32>::default());
    let pairs = [EnergyPair { point: 0, l: light(0.0) }];
    let cfg =
        EnergyConfig { estimator: Estimator::MonteCarlo { samples: 0 }, ..Default::default() };
    assert!(energy_conservation(&brdf, &pairs, &cfg).is_err());
    assert!(energy_conservation(&brdf, &[], &EnergyConfig::default()).is_err());
}

/// An accurate, independent albedo of a Torrance-Sparrow model: one-sample MIS of the
/// cosine density (diffuse) and GGX half-vector sampling (specular), balance heuristic,
/// 2^18 stratified points, f64 accumulation. Returns (mean, standard error) per channel.
fn ts_reference(ts: &TorranceSparrow<f32>, roughness: f32, l: [f32; 3]) -> ([f64; 3], [f64; 3]) {
    use std::f64::consts::PI;
    let alpha = (roughness as f64 * roughness as f64).max(1e-3);
    let a2 = alpha * alpha;
    let d = |cos_h: f64| a2 / (PI * (cos_h * cos_h * (a2 - 1.0) + 1.0).powi(2));
    let l64 = l.map(f64::from);
    let n = 1 << 18;
    let (mut sum, mut sq) = ([0.0f64; 3], [0.0f64; 3]);
    let mut rng = stdx::rng::SplitMix64::new(12345);
    for i in 0..n {
        let u0 = rng.next_f64();
        let u1 = (i as f64 + rng.next_f64()) / n as f64;
        let u2 = rng.next_f64();
        let v: [f64; 3] = if u0 < 0.5 {
            brdf_analytic::albedo::cosine_sample(u1, u2)
        } else {
            let tan2 = a2 * u1 / (1.0 - u1).max(1e-300);
            let cos_h = 1.0 / (1.0 + tan2).sqrt();
            let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
            let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
            let h = [sin_h * c, sin_h * s, cos_h];
            let lh = l64[0] * h[0] + l64[1] * h[1] + l64[2] * h[2];
            std::array::from_fn(|k| 2.0 * lh * h[k] - l64[k])
        };
        let mut g = [0.0; 3];
        if v[2] > 0.0 {
            let h = {
                let s = [l64[0] + v[0], l64[1] + v[1], l64[2] + v[2]];
                let m = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
                s.map(|x| x / m)
            };
            let vh = (v[0] * h[0] + v[1] * h[1] + v[2] * h[2]).abs().max(1e-300);
            let p = 0.5 * v[2] / PI + 0.5 * d(h[2]) * h[2].max(0.0) / (4.0 * vh);
            let f = ts.eval(l, v.map(|x| x as f32));
            for c in 0..3 {
                g[c] = f[c] as f64 * v[2] / p;
            }
        }
        for c in 0..3 {
            sum[c] += g[c];
            sq[c] += g[c] * g[c];
        }
    }
    let nf = n as f64;
    let mean = sum.map(|s| s / nf);
    let se = std::array::from_fn(|c| ((sq[c] / nf - mean[c] * mean[c]).max(0.0) / nf).sqrt());
    (mean, se)
}

/// Glossy Torrance-Sparrow models from roughness 0.05 to 0.5 at light angles 0 to 80 degrees:
/// both estimators agree with an accurate independent reference (GGX importance sampling)
/// within 4 of their error bars (the paper's from roughness 0.3 up), and the fast one spends fewer evaluations than the paper's
/// 20,000 per pair in total while its error bars are smaller.
#[test]
fn estimators_agree_on_glossy_models() {
    let angles = [0.0f32, 30.0, 60.0, 80.0];
    let (mut fast_evals, mut mc_evals) = (0u64, 0u64);
    let (mut fast_se, mut mc_se) = (0.0f64, 0.0f64);
    for roughness in [0.05f32, 0.1, 0.3, 0.5] {
        let ts = TorranceSparrow::new(TorranceSparrowParams {
            roughness,
            diffuse: [0.6, 0.3, 0.1],
            f0: [0.9, 0.9, 0.9],
        });
        let brdf = ts;
        let pairs: Vec<EnergyPair> =
            angles.iter().map(|t| EnergyPair { point: 0, l: light(*t) }).collect();
        let slow = energy_conservation(&brdf, &pairs, &mc(20_000)).unwrap();
        let quick = energy_conservation(&brdf, &pairs, &fast()).unwrap();
        for (k, (s, q)) in slow.pairs.iter().zip(&quick.pairs).enumerate() {
            let (r, rs) = ts_reference(&ts, roughness, light(angles[k]));
            for c in 0..3 {
                let what = format!("roughness {roughness}, {} deg, channel {c}", angles[k]);
                // Below roughness 0.3 only a handful of the paper's 20,000 cosine samples hit
                // the peak: its estimate and its own error bar are both unreliable there.
                if roughness >= 0.3 {
                    let bound = 4.0 * (s.std_error[c] + rs[c]);
                    assert!((s.energy[c] - r[c]).abs() <= bound, "mc {what}");
                }
                assert!(
                    (q.energy[c] - r[c]).abs() <= 4.0 * (q.std_error[c] + rs[c]),
                    "fast {what}"
                );
                fast_se += q.std_error[c];
                mc_se += s.std_error[c];
            }
        }
        fast_evals += quick.evaluations;
        mc_evals += slow.evaluations;
    }
    assert!(fast_evals < mc_evals, "{fast_evals} vs {mc_evals}");
    assert!(fast_se < mc_se / 10.0, "{fast_se} vs {mc_se}");
}
