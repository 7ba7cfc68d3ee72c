//! White furnace through the samplers: the importance-sampled directional albedo
//! a(v) = E[weight] = int f(l, v) cos(theta_l) dl is at most 1 wherever the model conserves
//! energy (white Lambert, Realistic Phong with kd + ks = 1, and the microfacet lobes with
//! F = 1 and no diffuse term), grazing views included; and for every model it agrees with an
//! independent estimate, cosine-weighted Monte Carlo over l, within the two standard errors.
//!
//! `cargo test -p brdf-analytic --test sampling_furnace -- --nocapture` prints the albedos.

mod common;

use brdf_analytic::albedo::cosine_sample;
use brdf_analytic::*;
use common::{dir_deg, disney_all_lobes};
use stdx::rng::SplitMix64;

/// Per RGB channel and for their mean (index 3): the Monte Carlo mean and its standard error.
type Estimate = ([f64; 4], [f64; 4]);

/// Accumulates `n` RGB values into an [`Estimate`].
fn estimate(n: usize, mut value: impl FnMut() -> [f64; 3]) -> Estimate {
    let (mut s1, mut s2) = ([0.0; 4], [0.0; 4]);
    for _ in 0..n {
        let x = value();
        let x = [x[0], x[1], x[2], (x[0] + x[1] + x[2]) / 3.0];
        for c in 0..4 {
            s1[c] += x[c];
            s2[c] += x[c] * x[c];
        }
    }
    let n = n as f64;
    let mean = s1.map(|s| s / n);
    let err = [0, 1, 2, 3].map(|c| ((s2[c] / n - mean[c] * mean[c]).max(0.0) / (n - 1.0)).sqrt());
    (mean, err)
}

/// The directional albedo by the model's own sampler: the mean weight (a failed sample counts 0).
fn sampled_albedo<B: Brdf<f64> + ?Sized>(m: &B, v: [f64; 3], n: usize, seed: u64) -> Estimate {
    let mut rng = SplitMix64::new(seed);
    estimate(n, || m.sample(v, [rng.next_f64(), rng.next_f64()]).map_or([0.0; 3], |s| s.weight))
}

/// The same integral by cosine-weighted l (Malley's method, the crate's `cosine_sample`),
/// estimator pi f(l, v): independent of the model's sampler.
fn cosine_albedo<B: Brdf<f64> + ?Sized>(m: &B, v: [f64; 3], n: usize, seed: u64) -> Estimate {
    let mut rng = SplitMix64::new(seed);
    estimate(n, || {
        let l = cosine_sample(rng.next_f64(), rng.next_f64());
        m.eval(l, v).map(|f| std::f64::consts::PI * f)
    })
}

#[test]
fn white_lambert_weight_is_exactly_one() {
    let m64 = Lambert::new(LambertParams { albedo: [1.0_f64; 3] });
    let m32 = Lambert::new(LambertParams { albedo: [1.0_f32; 3] });
    let mut rng = SplitMix64::new(1);
    for theta in [0.0, 45.0, 89.9] {
        let v = dir_deg(theta);
        for _ in 0..10_000 {
            let u = [rng.next_f64(), rng.next_f64()];
            assert_eq!(m64.sample(v, u).unwrap().weight, [1.0; 3]);
            let s32 = m32.sample(v.map(|x| x as f32), u.map(|x| x as f32)).unwrap();
            assert_eq!(s32.weight, [1.0; 3]);
        }
    }
}

/// Realistic Phong with kd + ks = 1, exponents 1 to 3.2e5, views up to 89 degrees: a <= 1
/// within 4 standard errors; at normal incidence with kd = 0 the albedo is exactly 1.
#[test]
fn realistic_phong_furnace() {
    for (kd, ks) in [(0.0, 1.0), (0.5, 0.5), (0.9, 0.1)] {
        for n in [1.0, 10.0, 245.0, 1e4, 3.2e5] {
            let m =
                RealisticPhong::new(RealisticPhongParams { kd: [kd; 3], ks: [ks; 3], exponent: n });
            for theta in [0.0, 30.0, 60.0, 80.0, 89.0] {
                let (a, e) = sampled_albedo(&m, dir_deg(theta), 40_000, 7);
                eprintln!("RP kd {kd} ks {ks} N {n} theta {theta}: {:.5} +- {:.1e}", a[3], e[3]);
                assert!(a[3] - 4.0 * e[3] <= 1.0, "N {n} theta {theta}: {a:?} +- {e:?}");
                if kd == 0.0 && theta == 0.0 {
                    assert!((a[3] - 1.0).abs() <= 4.0 * e[3] + 1e-9, "N {n}: {a:?} +- {e:?}");
                }
            }
        }
    }
}

/// GGX lobes with F = 1 and nothing else (a TS or Disney perfect conductor): the
/// single-scattering albedo is at most 1 from roughness 0 to 1 and views up to 88 degrees, and
/// equals its closed form where it has one.
#[test]
fn microfacet_conductor_furnace() {
    for r in [0.0, 0.05, 0.3, 0.6, 1.0] {
        let ts = TorranceSparrow::new(TorranceSparrowParams {
            roughness: r,
            diffuse: [0.0; 3],
            f0: [1.0; 3],
        });
        let disney = Disney::new(DisneyParams {
            base_color: [1.0; 3],
            metallic: 1.0,
            roughness: r,
            ..Default::default()
        });
        for theta in [0.0, 45.0, 75.0, 88.0] {
            for m in [&ts as &dyn Brdf<f64>, &disney] {
                let (a, e) = sampled_albedo(m, dir_deg(theta), 40_000, 11);
                eprintln!(
                    "{} conductor r {r} theta {theta}: {:.5} +- {:.1e}",
                    m.name(),
                    a[3],
                    e[3]
                );
                let name = m.name();
                assert!(a[3] - 4.0 * e[3] <= 1.0, "{name} r {r} theta {theta}: {a:?} +- {e:?}");
                assert!(a[3] > 0.2, "{name} r {r} theta {theta}: {a:?}");
                // Closed forms. Roughness 0 (alpha = 1e-3): G1 ~ 1, a mirror, a = 1. Roughness 1
                // at normal incidence: D = 1/pi, G1(n) = 1, G1(l) = 2 mu / (1 + mu), so
                // a = int_0^1 mu / (1 + mu) d mu = 1 - ln 2.
                let exact = match (r, theta) {
                    (0.0, _) => Some(1.0),
                    (1.0, 0.0) => Some(1.0 - std::f64::consts::LN_2),
                    _ => None,
                };
                if let Some(x) = exact {
                    let tol = 4.0 * e[3] + 1e-3;
                    assert!((a[3] - x).abs() <= tol, "{name} r {r} theta {theta}: {a:?} vs {x}");
                }
            }
        }
    }
}

/// Every model, at roughnesses where cosine sampling of l still converges: the sampled albedo
/// equals the cosine-weighted estimate within 5 combined standard errors, per channel (an
/// unbiasedness check of the weights that does not trust the model's pdf).
#[test]
fn sampled_albedo_matches_cosine_estimate() {
    let phong = |n: f64| {
        RealisticPhong::new(RealisticPhongParams { kd: [0.3; 3], ks: [0.6; 3], exponent: n })
    };
    let ts = |r: f64| {
        TorranceSparrow::new(TorranceSparrowParams {
            roughness: r,
            diffuse: [0.5, 0.4, 0.3],
            f0: [0.04, 0.5, 0.9],
        })
    };
    let disney = |r: f64| Disney::new(DisneyParams { roughness: r, ..disney_all_lobes() });
    let fm = |alpha: f64, k_s: f64| Fmbrdf::new(FmbrdfParams { alpha, k_s, ..Default::default() });
    // (name, model, samples, glossy: importance sampling must beat cosine sampling).
    type Case = (&'static str, Box<dyn Brdf<f64>>, usize, bool);
    let models: Vec<Case> = vec![
        ("RP N 20", Box::new(phong(20.0)), 200_000, true),
        ("RP N 245", Box::new(phong(245.0)), 400_000, true),
        ("TS r 0.3", Box::new(ts(0.3)), 400_000, true),
        ("TS r 1", Box::new(ts(1.0)), 200_000, false),
        ("Disney r 0.3", Box::new(disney(0.3)), 400_000, true),
        ("Disney r 1", Box::new(disney(1.0)), 200_000, false),
        ("FMBRDF alpha 0.3", Box::new(fm(0.3, 5.0)), 30_000, true),
        ("FMBRDF alpha 1", Box::new(fm(1.0, 1.0)), 30_000, false),
    ];
    for (name, m, n, glossy) in &models {
        for theta in [0.0, 60.0, 85.0] {
            let v = dir_deg(theta);
            let (a, ea) = sampled_albedo(m.as_ref(), v, *n, 21);
            let (b, eb) = cosine_albedo(m.as_ref(), v, *n, 22);
            eprintln!(
                "{name} theta {theta}: sampled {:.4} +- {:.1e}, cosine {:.4} +- {:.1e} (mean of RGB)",
                a[3], ea[3], b[3], eb[3]
            );
            for c in 0..4 {
                let tol = 5.0 * (ea[c] * ea[c] + eb[c] * eb[c]).sqrt();
                assert!(
                    (a[c] - b[c]).abs() <= tol,
                    "{name} theta {theta} channel {c}: {a:?} +- {ea:?} vs {b:?} +- {eb:?}"
                );
            }
            // For glossy lobes importance sampling is not worse than cosine sampling, for the
            // channels' mean (the lobes are picked for the mean; one channel alone may be, for a
            // coloured model). For alpha ~ 1 it can be: f cos is then close to cos, and the
            // GGX reflection spreads its samples more evenly (and loses some below the horizon).
            if *glossy {
                assert!(
                    ea[3] <= 1.5 * eb[3],
                    "{name} theta {theta}: error {ea:?} vs cosine {eb:?}"
                );
            }
        }
    }
}
