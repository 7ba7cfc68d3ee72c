//! Numerical stress of `sample` and `pdf`: every model with parameters at the ends of their
//! ranges (roughness 0 and 1, Phong exponent 1 and 1e6, FMBRDF alpha 0.001 and 2 pi, ...), view
//! directions from the normal down to f32-subnormal heights above the horizon (and at or below
//! it), uniforms at 0, 1, just below 1, outside [0, 1] and NaN, in f32 and f64. No NaN or Inf,
//! every returned direction a unit vector above the horizon with pdf > 0 equal to `pdf(v, l)`,
//! `None` for a view at or below the horizon, and pdf 0 below it (and finite at l = v).

use brdf_analytic::*;
use stdx::rng::SplitMix64;

/// Models at the ends of their parameter ranges (NaN parameters included: the constructors
/// clamp them).
fn models<T: Real>() -> Vec<Box<dyn Brdf<T>>> {
    let (z, o, h, nan) = (T::zero(), T::one(), T::lit(0.5), T::nan());
    let mut out: Vec<Box<dyn Brdf<T>>> = Vec::new();
    for a in [z, o] {
        out.push(Box::new(Lambert::new(LambertParams { albedo: [a; 3] })));
    }
    for (kd, ks, n) in
        [(z, o, o), (z, o, T::lit(1e6)), (h, h, T::lit(1e3)), (o, z, o), (nan, nan, nan)]
    {
        out.push(Box::new(RealisticPhong::new(RealisticPhongParams {
            kd: [kd; 3],
            ks: [ks; 3],
            exponent: n,
        })));
    }
    for r in [z, T::lit(0.05), o, nan] {
        for (d, f0) in [(o, z), (z, o), (h, T::lit(0.04))] {
            out.push(Box::new(TorranceSparrow::new(TorranceSparrowParams {
                roughness: r,
                diffuse: [d; 3],
                f0: [f0; 3],
            })));
        }
    }
    for r in [z, o] {
        for x in [z, o] {
            out.push(Box::new(Disney::new(DisneyParams {
                base_color: [x, o, z],
                metallic: x,
                subsurface: o - x,
                specular: o - x,
                roughness: r,
                specular_tint: x,
                sheen: o,
                sheen_tint: x,
                clearcoat: o,
                clearcoat_gloss: o - x,
                gamma_base_color: x == o,
            })));
        }
    }
    out.push(Box::new(Disney::new(DisneyParams {
        base_color: [z; 3],
        specular: z,
        roughness: nan,
        ..Default::default()
    })));
    for (alpha, beta) in [(0.001, 0.5), (0.001, 4.0), (std::f64::consts::TAU, 2.0)] {
        for (k_s, rho, eta) in [(0.0, 1.0, 1.1), (100.0, 0.0, 2.5)] {
            out.push(Box::new(Fmbrdf::new(FmbrdfParams {
                eta: T::lit(eta),
                rho: [T::lit(rho); 3],
                k_s: T::lit(k_s),
                alpha: T::lit(alpha),
                beta: T::lit(beta),
                kappa: z,
            })));
        }
    }
    out
}

/// View directions at heights z above the horizon (f32 subnormal included) and several
/// azimuths, plus the horizon itself and a direction below it.
fn views() -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for (k, z) in
        [1.0, 1.0 - 1e-7, 0.5, 1e-3, 1e-7, 1e-30, 1e-40, 0.0, -0.3].into_iter().enumerate()
    {
        let phi = 0.7 * k as f64;
        let r = (1.0_f64 - z * z).sqrt();
        out.push([r * phi.cos(), r * phi.sin(), z]);
    }
    out
}

fn uniforms<T: Real>(rng: &mut SplitMix64) -> Vec<[T; 2]> {
    let edge = [0.0, 1e-7, 0.5, 1.0 - 1e-7, 1.0 - 2f64.powi(-24), 1.0, -0.5, 2.0, f64::NAN];
    let mut out: Vec<[T; 2]> =
        edge.iter().flat_map(|&a| edge.iter().map(move |&b| [T::lit(a), T::lit(b)])).collect();
    out.extend((0..300).map(|_| [T::lit(rng.next_f64()), T::lit(rng.next_f64())]));
    out
}

fn stress<T: Real>() {
    let mut rng = SplitMix64::new(0x57E55);
    let us = uniforms::<T>(&mut rng);
    let mut bad = Vec::new();
    let mut report = |msg: String| {
        if bad.len() < 8 {
            bad.push(msg);
        }
    };
    for m in models::<T>() {
        for v in views() {
            let vt = v.map(T::lit);
            let name = m.name();
            // pdf at special light directions.
            let mirror = [-vt[0], -vt[1], vt[2]];
            let below = [vt[0], vt[1], -vt[2].abs() - T::lit(0.1)];
            for l in [
                vt,
                mirror,
                [T::zero(), T::zero(), T::one()],
                [T::one(), T::zero(), T::zero()],
                below,
            ] {
                let p = m.pdf(vt, l);
                let ok = p.is_finite()
                    && p >= T::zero()
                    && (l[2] > T::zero() && vt[2] > T::zero() || p == T::zero());
                if !ok {
                    report(format!("{name}: pdf(v {v:?}, l {l:?}) = {p}"));
                }
            }
            let mut successes = 0;
            for &u in &us {
                let Some(s) = m.sample(vt, u) else { continue };
                successes += 1;
                let len = s.l.iter().map(|x| x.to_f64_exact().powi(2)).sum::<f64>().sqrt();
                let p = m.pdf(vt, s.l);
                let ok = vt[2] > T::zero()
                    && s.l[2] > T::zero()
                    && (len - 1.0).abs() < 1e-5
                    && s.pdf > T::zero()
                    && s.pdf.is_finite()
                    && s.weight.iter().all(|w| w.is_finite() && *w >= T::zero())
                    && (p - s.pdf).abs() <= T::lit(1e-6) * s.pdf;
                if !ok {
                    report(format!(
                        "{name}: v {v:?} u {u:?} -> {s:?} (pdf(v, l) = {p}, |l| = {len})"
                    ));
                }
            }
            // A view well above the horizon always yields some samples.
            if v[2] >= 1e-3 && successes == 0 {
                report(format!("{name}: no sample at all for v {v:?}"));
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn stress_f64() {
    stress::<f64>();
}

#[test]
fn stress_f32() {
    stress::<f32>();
}
