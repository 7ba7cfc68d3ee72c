//! Agreement with independent f64 evaluations written literally from the spec's formulas
//! (spec section 3; Disney transcribed from the reference shader, anisotropic forms included),
//! plus closed-form values at fixed angles.

// Channel loops index several arrays at once; an index reads clearer there.
#![allow(clippy::needless_range_loop)]

mod common;

use brdf_analytic::*;
use common::*;
use proptest::prelude::*;
use std::f64::consts::PI;

type V = [f64; 3];
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn normalize(a: V) -> V {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}
const N: V = [0.0, 0.0, 1.0];
const X: V = [1.0, 0.0, 0.0];
const Y: V = [0.0, 1.0, 0.0];

fn mix(a: f64, b: f64, t: f64) -> f64 {
    a * (1.0 - t) + b * t
}

fn ref_phong(p: &RealisticPhongParams<f64>, l: V, v: V) -> V {
    if dot(N, l) <= 0.0 || dot(N, v) <= 0.0 {
        return [0.0; 3];
    }
    let nl = dot(N, l);
    let r = [2.0 * nl * N[0] - l[0], 2.0 * nl * N[1] - l[1], 2.0 * nl * N[2] - l[2]];
    let lobe = dot(r, v).max(0.0).powf(p.exponent);
    [0, 1, 2].map(|c| p.kd[c] / PI + p.ks[c] * (p.exponent + 2.0) / (2.0 * PI) * lobe)
}

fn ref_ts(p: &TorranceSparrowParams<f64>, l: V, v: V) -> V {
    let (nl, nv) = (dot(N, l), dot(N, v));
    if nl <= 0.0 || nv <= 0.0 {
        return [0.0; 3];
    }
    let h = normalize([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
    let alpha = (p.roughness * p.roughness).max(1e-3);
    let a2 = alpha * alpha;
    let nh = dot(N, h);
    let d = a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
    let g1 = |c: f64| 2.0 * c / (c + (a2 + (1.0 - a2) * c * c).sqrt());
    let g = g1(nl) * g1(nv);
    [0, 1, 2].map(|c| {
        let f = p.f0[c] + (1.0 - p.f0[c]) * (1.0 - dot(v, h)).powi(5);
        (1.0 - f) * p.diffuse[c] / PI + d * f * g / (4.0 * nl * nv)
    })
}

/// wdas/brdf `disney.brdf`, transcribed with its anisotropic helpers and anisotropic = 0.
fn ref_disney(p: &DisneyParams<f64>, l: V, v: V) -> V {
    let schlick = |u: f64| (1.0 - u).clamp(0.0, 1.0).powi(5);
    let gtr1 = |ndoth: f64, a: f64| {
        if a >= 1.0 {
            return 1.0 / PI;
        }
        let a2 = a * a;
        let t = 1.0 + (a2 - 1.0) * ndoth * ndoth;
        (a2 - 1.0) / (PI * a2.ln() * t)
    };
    let gtr2_aniso = |ndoth: f64, hx: f64, hy: f64, ax: f64, ay: f64| {
        1.0 / (PI * ax * ay * ((hx / ax).powi(2) + (hy / ay).powi(2) + ndoth * ndoth).powi(2))
    };
    let smith_g_ggx = |ndotv: f64, alpha_g: f64| {
        let a = alpha_g * alpha_g;
        let b = ndotv * ndotv;
        1.0 / (ndotv + (a + b - a * b).sqrt())
    };
    let smith_g_aniso = |ndotv: f64, vx: f64, vy: f64, ax: f64, ay: f64| {
        1.0 / (ndotv + ((vx * ax).powi(2) + (vy * ay).powi(2) + ndotv * ndotv).sqrt())
    };
    let (ndotl, ndotv) = (dot(N, l), dot(N, v));
    if ndotl <= 0.0 || ndotv <= 0.0 {
        return [0.0; 3];
    }
    let h = normalize([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
    let (ndoth, ldoth) = (dot(N, h), dot(l, h));
    let cdlin = if p.gamma_base_color { p.base_color.map(|x| x.powf(2.2)) } else { p.base_color };
    let cdlum = 0.3 * cdlin[0] + 0.6 * cdlin[1] + 0.1 * cdlin[2];
    let ctint = if cdlum > 0.0 { cdlin.map(|x| x / cdlum) } else { [1.0; 3] };
    let cspec0 = [0, 1, 2].map(|c| {
        mix(p.specular * 0.08 * mix(1.0, ctint[c], p.specular_tint), cdlin[c], p.metallic)
    });
    let csheen = ctint.map(|t| mix(1.0, t, p.sheen_tint));
    let (fl, fv) = (schlick(ndotl), schlick(ndotv));
    let fd90 = 0.5 + 2.0 * ldoth * ldoth * p.roughness;
    let fd = mix(1.0, fd90, fl) * mix(1.0, fd90, fv);
    let fss90 = ldoth * ldoth * p.roughness;
    let fss = mix(1.0, fss90, fl) * mix(1.0, fss90, fv);
    let ss = 1.25 * (fss * (1.0 / (ndotl + ndotv) - 0.5) + 0.5);
    let anisotropic = 0.0_f64;
    let aspect = (1.0 - anisotropic * 0.9).sqrt();
    let ax = (p.roughness * p.roughness / aspect).max(0.001);
    let ay = (p.roughness * p.roughness * aspect).max(0.001);
    let ds = gtr2_aniso(ndoth, dot(h, X), dot(h, Y), ax, ay);
    let fh = schlick(ldoth);
    let gs = smith_g_aniso(ndotl, dot(l, X), dot(l, Y), ax, ay)
        * smith_g_aniso(ndotv, dot(v, X), dot(v, Y), ax, ay);
    let dr = gtr1(ndoth, mix(0.1, 0.001, p.clearcoat_gloss));
    let fr = mix(0.04, 1.0, fh);
    let gr = smith_g_ggx(ndotl, 0.25) * smith_g_ggx(ndotv, 0.25);
    [0, 1, 2].map(|c| {
        let fs = mix(cspec0[c], 1.0, fh);
        let fsheen = fh * p.sheen * csheen[c];
        ((1.0 / PI) * mix(fd, ss, p.subsurface) * cdlin[c] + fsheen) * (1.0 - p.metallic)
            + gs * fs * ds
            + 0.25 * p.clearcoat * gr * fr * dr
    })
}

/// Tolerance: the reference uses the textbook forms (1 + (a^2 - 1) cos^2, arccos-free dot
/// products), which lose up to ~1e-16 / alpha^2 relative near the specular peak.
const TOL: f64 = 1e-9;

proptest! {
    #![proptest_config(ProptestConfig { cases: 20_000, ..ProptestConfig::default() })]

    #[test]
    fn phong_matches_reference(p in phong_params(), l in upper(), v in upper()) {
        let (a, b) = (RealisticPhong::try_new(p).unwrap().eval(l, v), ref_phong(&p, l, v));
        prop_assert!(rel_diff_rgb(a, b, 1e-300) < TOL, "{a:?} vs {b:?}");
    }

    #[test]
    fn ts_matches_reference(p in ts_params(), l in upper(), v in upper()) {
        let (a, b) = (TorranceSparrow::try_new(p).unwrap().eval(l, v), ref_ts(&p, l, v));
        prop_assert!(rel_diff_rgb(a, b, 1e-300) < TOL, "{a:?} vs {b:?}");
    }

    #[test]
    fn disney_matches_reference(p in disney_params(), l in upper(), v in upper()) {
        let (a, b) = (Disney::try_new(p).unwrap().eval(l, v), ref_disney(&p, l, v));
        prop_assert!(rel_diff_rgb(a, b, 1e-300) < TOL, "{a:?} vs {b:?}");
    }
}

fn dir_deg(theta: f64, phi: f64) -> V {
    let (t, p) = (theta.to_radians(), phi.to_radians());
    [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]
}

#[test]
fn fixed_angles_match_reference() {
    let angles = [
        (0.0, 0.0, 0.0, 0.0),
        (30.0, 0.0, 30.0, 180.0),
        (45.0, 10.0, 60.0, 250.0),
        (85.0, 90.0, 5.0, 0.0),
        (89.9, 0.0, 89.9, 180.0),
    ];
    let disney = [DisneyParams::default(), common::disney_all_lobes()];
    for (tl, pl, tv, pv) in angles {
        let (l, v) = (dir_deg(tl, pl), dir_deg(tv, pv));
        for p in &disney {
            let (a, b) = (Disney::new(*p).eval(l, v), ref_disney(p, l, v));
            assert!(rel_diff_rgb(a, b, 1e-300) < TOL, "Disney {tl} {tv}: {a:?} vs {b:?}");
        }
        let ts = TorranceSparrowParams {
            roughness: 0.3,
            diffuse: [0.2, 0.4, 0.6],
            f0: [0.04, 0.5, 0.9],
        };
        let (a, b) = (TorranceSparrow::new(ts).eval(l, v), ref_ts(&ts, l, v));
        assert!(rel_diff_rgb(a, b, 1e-300) < TOL, "TS {tl} {tv}: {a:?} vs {b:?}");
        let rp = RealisticPhongParams { kd: [0.1, 0.2, 0.3], ks: [0.5, 0.4, 0.3], exponent: 20.0 };
        let (a, b) = (RealisticPhong::new(rp).eval(l, v), ref_phong(&rp, l, v));
        assert!(rel_diff_rgb(a, b, 1e-300) < TOL, "RP {tl} {tv}: {a:?} vs {b:?}");
    }
}

#[test]
fn closed_forms_at_normal_incidence() {
    // l = v = n: D = 1 / (pi alpha^2), G = 1, F = F0 for Torrance-Sparrow.
    let p = TorranceSparrowParams { roughness: 0.5, diffuse: [0.3; 3], f0: [0.1, 0.5, 1.0] };
    let f = TorranceSparrow::new(p).eval(N, N);
    let alpha2 = 0.0625_f64;
    for c in 0..3 {
        let expect = (1.0 - p.f0[c]) * 0.3 / PI + p.f0[c] / (4.0 * PI * alpha2);
        assert!(rel_diff(f[c], expect, 0.0) < 1e-14, "TS channel {c}: {} vs {expect}", f[c]);
    }
    // Disney defaults at l = v = n: FL = FV = FH = 0, Fd = 1, Gs = 1/4, Ds = 1/(pi a^2),
    // Fs = Cspec0 = 0.04 (specular 0.5, untinted, dielectric).
    let f = Disney::new(DisneyParams::<f64>::default()).eval(N, N);
    let base = [0.82, 0.67, 0.16];
    for c in 0..3 {
        let expect = base[c] / PI + 0.25 * 0.04 / (PI * alpha2);
        assert!(rel_diff(f[c], expect, 0.0) < 1e-14, "Disney channel {c}: {} vs {expect}", f[c]);
    }
    // Realistic Phong at the mirror direction: kd/pi + ks (N + 2)/(2 pi).
    let p = RealisticPhongParams { kd: [0.25; 3], ks: [0.5; 3], exponent: 100.0 };
    let f = RealisticPhong::new(p).eval(dir_deg(40.0, 30.0), dir_deg(40.0, 210.0));
    assert!(rel_diff(f[0], 0.25 / PI + 0.5 * 102.0 / (2.0 * PI), 0.0) < 1e-12);
}
