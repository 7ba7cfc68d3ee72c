//! Integration tests of the FMBRDF: shipped weights against the shared JSON, agreement with an
//! independent f64 evaluation of the spec's formulas, f32 against f64, finiteness under stress,
//! reciprocity and energy measurements, parameter validation.

mod common;
#[path = "fmbrdf/reference.rs"]
mod reference;
#[path = "fmbrdf/util.rs"]
mod util;

use brdf_analytic::{Brdf, Fmbrdf, FmbrdfParams, Real};
use reference::{RefNets, RefParams, reference_eval, shared_fmbrdf_dir};
use std::f64::consts::TAU;
use std::time::Instant;
use util::{
    Rng, adversarial_directions, extreme_params, hemisphere, near_mirror, normalize, par_map,
    params_t, quantile, random_params,
};

/// The crate's shipped weight file.
static SHIPPED: &[u8] = include_bytes!("../assets/fmbrdf/fmbrdf_weights.bin");

#[test]
fn shipped_weights_equal_shared_json() {
    let Some(dir) = shared_fmbrdf_dir() else { return };
    let encoded = reference::encode_weights(&dir);
    assert_eq!(encoded.len(), SHIPPED.len(), "shipped weight file has the wrong size");
    assert!(encoded == SHIPPED, "shipped weight file differs from the conversion of the JSON");
    // What the crate decodes is the JSON, bit for bit.
    let keys = reference::shipped_tensor_keys();
    let tensors: Vec<_> = Fmbrdf::<f32>::network_tensors().collect();
    assert_eq!(tensors.len(), keys.len());
    let mut json = std::collections::HashMap::new();
    for ((stem, key), (name, shape, values)) in keys.iter().zip(tensors) {
        let file = json
            .entry(*stem)
            .or_insert_with(|| reference::load_json(&dir.join(format!("{stem}.json"))));
        let t = &file[key];
        assert_eq!(name, format!("{stem}.{key}"));
        assert_eq!(shape, t.shape.as_slice());
        assert!(values.iter().zip(&t.data).all(|(&a, &b)| (a as f64).to_bits() == b.to_bits()));
        assert_eq!(values.len(), t.data.len());
    }
}

/// Regenerates `assets/fmbrdf/fmbrdf_weights.bin` from the shared JSON.
#[test]
#[ignore = "writes the shipped asset; run by hand after the JSON changes"]
fn regenerate_weights_bin() {
    let dir = shared_fmbrdf_dir().expect("regenerating the weights needs the shared data");
    let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/fmbrdf");
    std::fs::write(out.join("fmbrdf_weights.bin"), reference::encode_weights(&dir)).unwrap();
}

#[test]
fn agrees_with_independent_reference() {
    let Some(dir) = shared_fmbrdf_dir() else { return };
    let nets = RefNets::load(&dir);
    let mut rng = Rng::new(7);
    let mut cases: Vec<(RefParams, [f64; 3], [f64; 3])> = Vec::new();
    for i in 0..1500 {
        let p = random_params(&mut rng);
        let (l, v) = if i % 3 == 0 {
            near_mirror(&mut rng, p.alpha)
        } else {
            (hemisphere(&mut rng), hemisphere(&mut rng))
        };
        cases.push((p, l, v));
    }
    // Fixed angles at the default parameters (l = v excluded: see `l_equal_v_is_finite...`).
    let d = FmbrdfParams::<f64>::default();
    let dp = RefParams {
        eta: d.eta,
        rho: [0.2, 0.5, 0.9],
        k_s: d.k_s,
        alpha: d.alpha,
        beta: d.beta,
        kappa: d.kappa,
    };
    let deg: [f64; 8] = [0.0, 10.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0];
    for (i, &tl) in deg.iter().enumerate() {
        for (j, &tv) in deg.iter().enumerate() {
            for phi in [0.0_f64, 90.0, 180.0, 225.0] {
                if i == j && phi == 0.0 {
                    continue;
                }
                let (tl, tv, phi) = (tl.to_radians(), tv.to_radians(), phi.to_radians());
                let l = [tl.sin(), 0.0, tl.cos()];
                let v = [tv.sin() * phi.cos(), tv.sin() * phi.sin(), tv.cos()];
                cases.push((dp, l, v));
            }
        }
    }
    let errors: Vec<f64> = par_map(&cases, |(p, l, v)| {
        let model = Fmbrdf::try_new(params_t::<f64>(p)).unwrap();
        let inv_c = reference::inv_c_graded(p.alpha, p.beta);
        let want = reference_eval(&nets, p, inv_c, *l, *v);
        let got = model.eval(*l, *v);
        let mut worst = 0.0_f64;
        for (g, w) in got.iter().zip(want) {
            let err = (g - w).abs() / w.abs().max(1e-12);
            assert!(err <= 1e-5, "{p:?} l {l:?} v {v:?}: {got:?} vs {want:?}");
            worst = worst.max(err);
        }
        worst
    });
    let max = errors.iter().cloned().fold(0.0, f64::max);
    eprintln!("reference agreement: {} configurations, max relative error {max:.2e}", cases.len());
}

#[test]
fn normalization_matches_quadrature_references() {
    let grid: Vec<(f64, f64)> = (0..40)
        .flat_map(|i| {
            let alpha = 0.001 * (TAU / 0.001_f64).powf(i as f64 / 39.0);
            (0..15).map(move |j| (alpha, 0.5 + 3.5 * j as f64 / 14.0))
        })
        .collect();
    let rows: Vec<(f64, f64, f64, f64)> = par_map(&grid, |&(alpha, beta)| {
        let m = Fmbrdf::try_new(FmbrdfParams { alpha, beta, ..Default::default() }).unwrap();
        let inv_c = 1.0 / m.normalization();
        let graded = reference::inv_c_graded(alpha, beta);
        let official = reference::inv_c_official(alpha, beta, 100_000);
        (alpha, beta, (inv_c / graded - 1.0).abs(), (inv_c / official - 1.0).abs())
    });
    let max_graded = rows.iter().map(|r| r.2).fold(0.0, f64::max);
    let max_official = rows.iter().map(|r| r.3).fold(0.0, f64::max);
    let max_official_wide = rows.iter().filter(|r| r.0 >= 0.01).map(|r| r.3).fold(0.0, f64::max);
    eprintln!(
        "c: max rel. difference to graded Simpson {max_graded:.2e}; to the official 100k-step \
         rectangle rule {max_official:.2e} overall, {max_official_wide:.2e} for alpha >= 0.01"
    );
    assert!(max_graded < 1e-7, "{max_graded}");
    assert!(max_official_wide < 1e-6, "{max_official_wide}");
    // The rectangle rule's own O(h^2) error, ~1.3e-10 absolute, is what remains at small alpha.
    assert!(max_official < 6e-5, "{max_official}");
}

/// Relative difference of `a` to `b`, with an absolute floor for values near 0.
fn rel(a: f64, b: f64, floor: f64) -> f64 {
    (a - b).abs() / b.abs().max(floor)
}

#[test]
fn f32_matches_f64() {
    let mut rng = Rng::new(11);
    let mut groups = Vec::new();
    for _ in 0..400 {
        // Parameters rounded to f32 first, so both models use identical values.
        let p = random_params(&mut rng);
        let p = RefParams {
            eta: p.eta as f32 as f64,
            rho: p.rho.map(|r| r as f32 as f64),
            k_s: p.k_s as f32 as f64,
            alpha: p.alpha as f32 as f64,
            beta: p.beta as f32 as f64,
            kappa: p.kappa as f32 as f64,
        };
        let pairs: Vec<_> = (0..50)
            .map(|j| {
                let (l, v) = if j % 2 == 0 {
                    near_mirror(&mut rng, p.alpha)
                } else {
                    (hemisphere(&mut rng), hemisphere(&mut rng))
                };
                (l.map(|x| x as f32), v.map(|x| x as f32))
            })
            .collect();
        groups.push((p, pairs));
    }
    // (relative error, alpha, n.l, n.v) per channel value.
    let errs: Vec<Vec<(f64, f64, f64, f64)>> = par_map(&groups, |(p, pairs)| {
        let m32 = Fmbrdf::try_new(params_t::<f32>(p)).unwrap();
        // `new`: alpha = f32 TAU lies 2.8e-8 above the f64 range end and is clamped there.
        let m64 = Fmbrdf::new(params_t::<f64>(p));
        let mut out = Vec::new();
        for (l, v) in pairs {
            let a = m32.eval(*l, *v);
            let b = m64.eval(l.map(f64::from), v.map(f64::from));
            let peak = b.iter().cloned().fold(0.0, f64::max);
            for c in 0..3 {
                out.push((rel(a[c] as f64, b[c], 1e-6 * peak), p.alpha, l[2] as f64, v[2] as f64));
            }
        }
        out
    });
    let all: Vec<_> = errs.into_iter().flatten().collect();
    let mut e: Vec<f64> = all.iter().map(|x| x.0).collect();
    let mut wide: Vec<f64> = all.iter().filter(|x| x.1 >= 0.01).map(|x| x.0).collect();
    let worst =
        all.iter().cloned().fold((0.0, 0.0, 0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    eprintln!(
        "f32 vs f64 over {} values: median {:.1e}, p99 {:.1e}, p99.9 {:.1e}, max {:.1e} \
         (at alpha {:.4}, n.l {:.2e}, n.v {:.2e}); alpha >= 0.01: p99.9 {:.1e}, max {:.1e}",
        e.len(),
        quantile(&mut e, 0.5),
        quantile(&mut e, 0.99),
        quantile(&mut e, 0.999),
        quantile(&mut e, 1.0),
        worst.1,
        worst.2,
        worst.3,
        quantile(&mut wide, 0.999),
        quantile(&mut wide, 1.0),
    );
    // Measured: median 1.6e-7, p99 1.1e-4, max 1.8e-4 for alpha >= 0.01. The largest differences
    // (~1e-2) are at alpha ~ 0.001 in grazing mirror configurations, where the f64 model's
    // renormalisation of the f32 input (a 1e-8 change of the direction) alone moves theta_h by
    // ~1e-3 alpha: input conditioning, not f32 arithmetic.
    assert!(quantile(&mut e, 0.5) < 1e-6);
    assert!(quantile(&mut e, 0.99) < 1e-3);
    assert!(quantile(&mut wide, 1.0) < 1e-3);
    assert!(quantile(&mut e, 1.0) < 5e-2);
}

/// A (light, view) direction pair.
type Pair = ([f64; 3], [f64; 3]);

/// Evaluates every pair in `T` and checks the value: finite, >= 0, and 0 off the hemisphere.
fn stress_model<T: Real>(p: &RefParams, pairs: &[Pair]) -> (usize, Vec<String>) {
    let m = Fmbrdf::<T>::try_new(params_t::<T>(p)).unwrap();
    let mut bad = Vec::new();
    for (l, v) in pairs {
        let (lt, vt) = (l.map(T::lit), v.map(T::lit));
        let f = m.eval(lt, vt);
        let below = !(lt[2] > T::zero() && vt[2] > T::zero());
        let ok =
            f.iter().all(|x| x.is_finite() && *x >= T::zero()) && (!below || f == [T::zero(); 3]);
        if !ok && bad.len() < 5 {
            bad.push(format!("{p:?} l {lt:?} v {vt:?}: {f:?}"));
        }
    }
    (pairs.len(), bad)
}

#[test]
fn stress_finite_and_nonnegative() {
    let start = Instant::now();
    let dirs = adversarial_directions();
    let mut rng = Rng::new(3);
    let params = extreme_params();
    let per_model = 1_000_000usize.div_ceil(params.len());
    let jobs: Vec<(RefParams, Vec<Pair>)> = params
        .iter()
        .map(|p| {
            let mut pairs: Vec<_> =
                dirs.iter().flat_map(|&l| dirs.iter().map(move |&v| (l, v))).collect();
            while pairs.len() < per_model {
                let k = pairs.len() % 4;
                pairs.push(match k {
                    0 => (hemisphere(&mut rng), hemisphere(&mut rng)),
                    1 => near_mirror(&mut rng, p.alpha),
                    2 => {
                        // Grazing light, polar cosine down to 1e-12.
                        let z = 10f64.powf(-12.0 * rng.next_f64());
                        let v = hemisphere(&mut rng);
                        let phi = TAU * rng.next_f64();
                        let r = (1.0 - z * z).sqrt();
                        ([r * phi.cos(), r * phi.sin(), z], v)
                    }
                    _ => {
                        let v = hemisphere(&mut rng);
                        (v, v)
                    }
                });
            }
            (*p, pairs)
        })
        .collect();
    let r32 = par_map(&jobs, |(p, pairs)| stress_model::<f32>(p, pairs));
    let r64 = par_map(&jobs, |(p, pairs)| stress_model::<f64>(p, pairs));
    let count32: usize = r32.iter().map(|r| r.0).sum();
    let count64: usize = r64.iter().map(|r| r.0).sum();
    let bad: Vec<&String> = r32.iter().chain(&r64).flat_map(|r| &r.1).collect();
    eprintln!(
        "stress: {count32} pairs in f32 and {count64} in f64 ({} models) in {:.1} s",
        jobs.len(),
        start.elapsed().as_secs_f64()
    );
    assert!(count32 >= 1_000_000 && count64 >= 1_000_000);
    assert!(bad.is_empty(), "{} failures, first: {:#?}", bad.len(), &bad[..bad.len().min(5)]);
}

#[test]
fn reciprocity_violation_is_as_documented() {
    let m = Fmbrdf::<f64>::new(FmbrdfParams::default());
    let mut rng = Rng::new(5);
    let pairs: Vec<_> = (0..4000).map(|_| (hemisphere(&mut rng), hemisphere(&mut rng))).collect();
    let mut d: Vec<f64> = par_map(&pairs, |(l, v)| {
        let a: f64 = m.eval(*l, *v).iter().sum();
        let b: f64 = m.eval(*v, *l).iter().sum();
        (a - b).abs() / (0.5 * (a + b))
    });
    let (median, p90) = (quantile(&mut d, 0.5), quantile(&mut d, 0.9));
    eprintln!(
        "reciprocity |f(l,v) - f(v,l)| / mean: median {median:.4}, p90 {p90:.4}, max {:.3}",
        quantile(&mut d, 1.0)
    );
    // The spec reports median 0.4 %, p90 13 %; the model documents its own measurement.
    assert!((1e-3..2e-2).contains(&median), "median {median}");
    assert!((4e-2..0.4).contains(&p90), "p90 {p90}");
}

#[test]
fn directional_albedo_is_plausible() {
    let n = 20_000;
    let mut rng = Rng::new(9);
    let samples: Vec<[f64; 3]> = (0..n).map(|_| util::cosine_hemisphere(&mut rng)).collect();
    let albedo = |m: &Fmbrdf<f64>, theta_deg: f64| {
        let t = theta_deg.to_radians();
        let l = [t.sin(), 0.0, t.cos()];
        let sums = par_map(&samples, |v| m.eval(l, *v)[0]);
        std::f64::consts::PI * sums.iter().sum::<f64>() / n as f64
    };
    let default = Fmbrdf::new(FmbrdfParams::default());
    let body = Fmbrdf::new(FmbrdfParams { rho: [1.0; 3], k_s: 0.0, ..Default::default() });
    let spec = Fmbrdf::new(FmbrdfParams { rho: [0.0; 3], k_s: 1.0, ..Default::default() });
    for theta in [0.0, 30.0, 45.0, 60.0, 75.0, 85.0] {
        let (a, b, s) = (albedo(&default, theta), albedo(&body, theta), albedo(&spec, theta));
        eprintln!(
            "albedo at {theta} deg: default {a:.4}, body (rho 1) {b:.4}, specular (k_s 1) {s:.4}"
        );
        // Measured 0.46..0.58, 0.63..0.84 and 0.04..0.27 (Monte Carlo error ~1 %).
        assert!(a.is_finite() && (0.3..1.0).contains(&a), "{a}");
        assert!(b.is_finite() && (0.5..0.95).contains(&b), "{b}");
        assert!(s.is_finite() && (0.01..0.5).contains(&s), "{s}");
        // The two terms add up.
        assert!((a - (0.5 * b + s)).abs() < 1e-9 * a);
    }
}

#[test]
fn l_equal_v_is_finite_and_close_to_its_neighbourhood() {
    // At l = v the second frame rotation is the identity; nearby, it follows the azimuth of
    // l - v around v. The body network is not rotation invariant there, so f jumps a little.
    let m = Fmbrdf::<f64>::new(FmbrdfParams::default());
    let mut worst = 0.0_f64;
    for theta in [0.0_f64, 10.0, 30.0, 50.0, 70.0, 85.0] {
        let t = theta.to_radians();
        let v = [t.sin(), 0.0, t.cos()];
        let at = m.eval(v, v)[0];
        assert!(at.is_finite() && at > 0.0);
        // Two unit vectors orthogonal to v.
        let e1 = [t.cos(), 0.0, -t.sin()];
        let e2 = [0.0, 1.0, 0.0];
        for k in 0..16 {
            let psi = TAU * k as f64 / 16.0;
            let d = 1e-7;
            let (c, s) = (psi.cos() * d, psi.sin() * d);
            let l = normalize([
                v[0] + c * e1[0] + s * e2[0],
                v[1] + c * e1[1] + s * e2[1],
                v[2] + c * e1[2] + s * e2[2],
            ]);
            worst = worst.max(rel(m.eval(l, v)[0], at, 0.0));
        }
    }
    eprintln!("l = v: largest relative jump to a neighbour 1e-7 away: {worst:.2e}");
    // Measured 2.9 % (documented on the model).
    assert!(worst < 0.06, "{worst}");
}

#[test]
fn try_new_rejects_and_new_clamps() {
    type P = FmbrdfParams<f64>;
    let d = P::default();
    type Setter = fn(&mut P, f64);
    let cases: [(&str, Setter, f64, f64); 6] = [
        ("eta", |p, x| p.eta = x, 1.1, 2.5),
        ("rho", |p, x| p.rho[1] = x, 0.0, 1.0),
        ("k_s", |p, x| p.k_s = x, 0.0, 100.0),
        ("alpha", |p, x| p.alpha = x, 0.001, TAU),
        ("beta", |p, x| p.beta = x, 0.5, 4.0),
        ("kappa", |p, x| p.kappa = x, 0.0, 100.0),
    ];
    for (name, set, lo, hi) in cases {
        for (x, ok) in
            [(lo, true), (hi, true), (lo - 1e-9, false), (hi + 1e-9, false), (f64::NAN, false)]
        {
            let mut p = d;
            set(&mut p, x);
            match Fmbrdf::try_new(p) {
                Ok(m) => assert!(ok && m.params() == &p, "{name} = {x} accepted"),
                Err(e) => assert!(!ok && e.param == name, "{name} = {x}: {e}"),
            }
        }
        // `new` clamps to the ends; NaN becomes the default.
        for (x, want) in [(lo - 1.0, lo), (hi + 1.0, hi)] {
            let mut p = d;
            set(&mut p, x);
            let mut expect = d;
            set(&mut expect, want);
            assert_eq!(Fmbrdf::new(p).params(), &expect, "{name} = {x}");
        }
        let mut p = d;
        set(&mut p, f64::NAN);
        assert_eq!(Fmbrdf::new(p).params(), &d, "{name} = NaN");
    }
    // In f32 the range ends are rounded to f32: 2 pi rounds up to f32::consts::TAU.
    let p = FmbrdfParams::<f32> { alpha: std::f32::consts::TAU, eta: 1.1, ..Default::default() };
    assert!(Fmbrdf::try_new(p).is_ok());
    assert!(Fmbrdf::try_new(FmbrdfParams::<f32> { alpha: 6.2833, ..Default::default() }).is_err());
}

/// Release-build throughput: `cargo test --release -p brdf-analytic --test fmbrdf -- --ignored
/// --nocapture throughput`.
#[test]
#[ignore = "timing only; run in release"]
fn throughput() {
    fn run<T: Real>(name: &str) {
        let mut rng = Rng::new(1);
        let pairs: Vec<_> = (0..200_000)
            .map(|_| (hemisphere(&mut rng).map(T::lit), hemisphere(&mut rng).map(T::lit)))
            .collect();
        // Construction (the Lambda fold and c depend on alpha, beta; the memory is reused).
        let start = Instant::now();
        let n_build = 200;
        for i in 0..n_build {
            let alpha = T::lit(0.01 + 0.01 * i as f64);
            std::hint::black_box(Fmbrdf::<T>::new(FmbrdfParams { alpha, ..Default::default() }));
        }
        let build = start.elapsed().as_secs_f64() / n_build as f64;
        let m = Fmbrdf::<T>::new(FmbrdfParams::default());
        // Derived per-point models (same alpha, beta) reuse the fold and c.
        let start = Instant::now();
        for i in 0..n_build {
            let eta = T::lit(1.2 + 0.001 * i as f64);
            std::hint::black_box(m.with_params(FmbrdfParams { eta, ..*m.params() }));
        }
        let derive = start.elapsed().as_secs_f64() / n_build as f64;
        let start = Instant::now();
        let mut sum = T::zero();
        for (l, v) in &pairs {
            sum = sum + m.eval(*l, *v)[0];
        }
        let secs = start.elapsed().as_secs_f64();
        eprintln!(
            "{name}: {:.0} evaluations/s single-threaded ({:.2} us each); construction {:.1} us, \
             with_params {:.2} us (checksum {sum})",
            pairs.len() as f64 / secs,
            secs / pairs.len() as f64 * 1e6,
            build * 1e6,
            derive * 1e6,
        );
    }
    run::<f32>("f32");
    run::<f64>("f64");
}
