//! Numerical stress: at least 1e6 random plus adversarial direction pairs per model, in f32 and
//! f64, with parameters at both ends of their ranges. No NaN or Inf, never negative, and exactly
//! zero outside the upper hemisphere.

use brdf_analytic::*;
use stdx::rng::SplitMix64;

const PAIRS: usize = 1_000_000;

/// Adversarial directions: normal, exact horizon, barely above it (incl. f32 subnormal), below.
fn special_dirs(rng: &mut SplitMix64) -> Vec<[f64; 3]> {
    let phi = std::f64::consts::TAU * rng.next_f64();
    let (s, c) = phi.sin_cos();
    let mut dirs = vec![[0.0, 0.0, 1.0], [c, s, 0.0], [-c, -s, 0.0], [0.0, 0.0, -1.0]];
    for z in [1e-45_f64, 1e-38, 1e-30, 1e-7, 1e-3, 1.0 - 1e-7] {
        let r = (1.0 - z * z).sqrt();
        dirs.push([r * c, r * s, z]);
    }
    dirs
}

/// Random unit vector on the whole sphere (lower half included).
fn sphere(rng: &mut SplitMix64) -> [f64; 3] {
    let z = 2.0 * rng.next_f64() - 1.0;
    let phi = std::f64::consts::TAU * rng.next_f64();
    let r = (1.0 - z * z).max(0.0).sqrt();
    [r * phi.cos(), r * phi.sin(), z]
}

/// The (l, v) pairs: random pairs, then for every 8th one the adversarial relatives:
/// l = v, l mirrored about n, l = -v, and pairs of special directions.
fn pairs(seed: u64) -> Vec<([f64; 3], [f64; 3])> {
    let mut rng = SplitMix64::new(seed);
    let mut out = Vec::with_capacity(PAIRS + PAIRS / 2);
    while out.len() < PAIRS {
        let (l, v) = (sphere(&mut rng), sphere(&mut rng));
        out.push((l, v));
        if out.len() % 8 == 0 {
            out.push((l, l));
            out.push((l, [-l[0], -l[1], l[2]]));
            out.push((l, [-l[0], -l[1], -l[2]]));
            let sp = special_dirs(&mut rng);
            let i = (rng.next_u64() % sp.len() as u64) as usize;
            let j = (rng.next_u64() % sp.len() as u64) as usize;
            out.push((sp[i], sp[j]));
            out.push((sp[i], v));
        }
    }
    out
}

fn check_model<T: Real>(models: &[Box<dyn Brdf<T>>], pairs: &[([f64; 3], [f64; 3])]) {
    let mut bad = 0usize;
    for (k, &(l, v)) in pairs.iter().enumerate() {
        let m = &models[k % models.len()];
        let (lt, vt) = (l.map(T::lit), v.map(T::lit));
        let f = m.eval(lt, vt);
        let outside = !(lt[2] > T::zero() && vt[2] > T::zero());
        let ok =
            f.iter().all(|x| x.is_finite() && *x >= T::zero()) && (!outside || f == [T::zero(); 3]);
        if !ok {
            bad += 1;
            if bad < 5 {
                eprintln!("{}: l {l:?} v {v:?} -> {f:?}", m.name());
            }
        }
    }
    assert_eq!(bad, 0, "{}: {bad} bad values of {}", models[0].name(), pairs.len());
}

/// Parameter sets at both ends of every range, plus NaN inputs that the constructors clamp.
fn model_sets<T: Real>() -> Vec<Vec<Box<dyn Brdf<T>>>> {
    let (z, o, h) = (T::zero(), T::one(), T::lit(0.5));
    let nan = T::nan();
    let mut lambert: Vec<Box<dyn Brdf<T>>> = Vec::new();
    let mut phong: Vec<Box<dyn Brdf<T>>> = Vec::new();
    let mut ts: Vec<Box<dyn Brdf<T>>> = Vec::new();
    let mut disney: Vec<Box<dyn Brdf<T>>> = Vec::new();
    for a in [z, h, o, nan] {
        lambert.push(Box::new(Lambert::new(LambertParams { albedo: [a; 3] })));
    }
    for (kd, ks, n) in [(z, o, o), (h, h, T::lit(1e6)), (o, z, T::lit(50.0)), (nan, nan, nan)] {
        phong.push(Box::new(RealisticPhong::new(RealisticPhongParams {
            kd: [kd; 3],
            ks: [ks; 3],
            exponent: n,
        })));
    }
    for r in [z, T::lit(1e-4), h, o, nan] {
        for f0 in [z, o] {
            ts.push(Box::new(TorranceSparrow::new(TorranceSparrowParams {
                roughness: r,
                diffuse: [o; 3],
                f0: [f0; 3],
            })));
        }
    }
    for r in [z, h, o] {
        for x in [z, o] {
            disney.push(Box::new(Disney::new(DisneyParams {
                base_color: [x, o, z],
                metallic: x,
                subsurface: o - x,
                specular: o,
                roughness: r,
                specular_tint: x,
                sheen: o,
                sheen_tint: x,
                clearcoat: o,
                clearcoat_gloss: x,
                gamma_base_color: x == o,
            })));
        }
    }
    disney.push(Box::new(Disney::new(DisneyParams {
        roughness: nan,
        subsurface: nan,
        base_color: [nan; 3],
        ..Default::default()
    })));
    vec![lambert, phong, ts, disney]
}

#[test]
fn stress_f64() {
    let pairs = pairs(0xB2DF);
    assert!(pairs.len() >= PAIRS);
    for models in model_sets::<f64>() {
        check_model(&models, &pairs);
    }
}

#[test]
fn stress_f32() {
    let pairs = pairs(0x5EED);
    for models in model_sets::<f32>() {
        check_model(&models, &pairs);
    }
}
