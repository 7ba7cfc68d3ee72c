//! Properties of every model's `sample` and `pdf`, in f32 (the hot path) over random parameters,
//! view directions and uniforms: a returned l is a unit vector above the horizon, its pdf is
//! positive, finite and equal to `pdf(v, l)`, and its weight is f(l, v) cos(theta_l) / pdf.
//! Then f32 against f64 on the same inputs, as `precision.rs` does for `eval`.

mod common;

use brdf_analytic::*;
use common::*;
use proptest::prelude::*;
use stdx::rng::SplitMix64;

fn p32<const N: usize>(a: [f64; N]) -> [f32; N] {
    a.map(|x| x as f32)
}

fn phong32(p: RealisticPhongParams<f64>) -> RealisticPhong<f32> {
    RealisticPhong::new(RealisticPhongParams {
        kd: p32(p.kd),
        ks: p32(p.ks),
        exponent: p.exponent as f32,
    })
}

fn ts32(p: TorranceSparrowParams<f64>) -> TorranceSparrow<f32> {
    TorranceSparrow::new(TorranceSparrowParams {
        roughness: p.roughness as f32,
        diffuse: p32(p.diffuse),
        f0: p32(p.f0),
    })
}

fn disney32(p: DisneyParams<f64>) -> Disney<f32> {
    Disney::new(DisneyParams {
        base_color: p32(p.base_color),
        metallic: p.metallic as f32,
        subsurface: p.subsurface as f32,
        specular: p.specular as f32,
        roughness: p.roughness as f32,
        specular_tint: p.specular_tint as f32,
        sheen: p.sheen as f32,
        sheen_tint: p.sheen_tint as f32,
        clearcoat: p.clearcoat as f32,
        clearcoat_gloss: p.clearcoat_gloss as f32,
        gamma_base_color: p.gamma_base_color,
    })
}

/// Random FMBRDF parameters over the whole range (alpha and k_s log-uniform).
fn fmbrdf_params() -> impl Strategy<Value = FmbrdfParams<f64>> {
    (
        1.1..=2.5_f64,
        [0.0..=1.0_f64, 0.0..=1.0, 0.0..=1.0],
        -2.0..=2.0_f64,
        -3.0..=0.8_f64,
        0.5..=4.0_f64,
    )
        .prop_map(|(eta, rho, ks, alpha, beta)| FmbrdfParams {
            eta,
            rho,
            k_s: 10f64.powf(ks),
            alpha: 10f64.powf(alpha).min(std::f64::consts::TAU),
            beta,
            kappa: 0.0,
        })
}

fn fmbrdf32(p: FmbrdfParams<f64>) -> Fmbrdf<f32> {
    Fmbrdf::new(FmbrdfParams {
        eta: p.eta as f32,
        rho: p32(p.rho),
        k_s: p.k_s as f32,
        alpha: p.alpha as f32,
        beta: p.beta as f32,
        kappa: p.kappa as f32,
    })
}

/// A view direction: random in the upper hemisphere, or (one case in four) grazing.
fn view() -> impl Strategy<Value = [f64; 3]> {
    prop_oneof![
        3 => upper(),
        1 => (-7.0..-1.0_f64, 0.0..std::f64::consts::TAU).prop_map(|(e, phi)| {
            let z = 10f64.powf(e);
            let r = (1.0 - z * z).sqrt();
            [r * phi.cos(), r * phi.sin(), z]
        }),
    ]
}

/// Uniforms in [0, 1] (1 included: the samplers clamp it).
fn uniforms() -> impl Strategy<Value = [f64; 2]> {
    let one = || prop_oneof![8 => 0.0..1.0_f64, 1 => Just(0.0), 1 => Just(1.0)];
    [one(), one()]
}

/// The properties every sample and pdf must have, for one model, v and u (f32).
fn check<B: Brdf<f32>>(m: &B, v: [f64; 3], u: [f64; 2]) -> Result<(), TestCaseError> {
    let (v, u) = (p32(v), p32(u));
    // pdf is finite and >= 0 everywhere, 0 below the horizon, and defined at l = v.
    for l in [v, [-v[0], -v[1], v[2]], [0.0, 0.0, 1.0], [v[0], v[1], -v[2]]] {
        let p = m.pdf(v, l);
        prop_assert!(p.is_finite() && p >= 0.0, "{}: pdf({v:?}, {l:?}) = {p}", m.name());
        prop_assert!(l[2] > 0.0 || p == 0.0);
    }
    let Some(s) = m.sample(v, u) else { return Ok(()) };
    let name = m.name();
    let len = (s.l.iter().map(|x| f64::from(*x).powi(2)).sum::<f64>()).sqrt();
    prop_assert!(s.l[2] > 0.0 && (len - 1.0).abs() < 1e-5, "{name}: l {:?} (|l| = {len})", s.l);
    prop_assert!(s.pdf > 0.0 && s.pdf.is_finite(), "{name}: pdf {}", s.pdf);
    prop_assert!(s.weight.iter().all(|w| w.is_finite() && *w >= 0.0), "{name}: {:?}", s.weight);
    let p = m.pdf(v, s.l);
    prop_assert!(rel_diff(p.into(), s.pdf.into(), 0.0) < 1e-6, "{name}: pdf {p} vs {}", s.pdf);
    if s.pdf > 1e-4 {
        let f = m.eval(s.l, v);
        for (c, (&w, &fc)) in s.weight.iter().zip(&f).enumerate() {
            let expect = f64::from(fc) * f64::from(s.l[2]) / f64::from(s.pdf);
            let d = rel_diff(w.into(), expect, 1e-6);
            prop_assert!(
                d < 1e-4,
                "{name}: weight {:?} vs f cos / pdf ({c}: {expect}); v {v:?} u {u:?}",
                s.weight
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3_000, ..ProptestConfig::default() })]

    #[test]
    fn lambert(a in [0.0..=1.0_f64, 0.0..=1.0, 0.0..=1.0], v in view(), u in uniforms()) {
        let m = Lambert::new(LambertParams { albedo: p32(a) });
        check(&m, v, u)?;
        // The weight is the albedo itself, computed without f or pdf.
        if let Some(s) = m.sample(p32(v), p32(u)) {
            prop_assert_eq!(s.weight, m.params().albedo);
        }
    }

    #[test]
    fn realistic_phong(p in phong_params(), v in view(), u in uniforms()) {
        check(&phong32(p), v, u)?;
    }

    #[test]
    fn torrance_sparrow(p in ts_params(), v in view(), u in uniforms()) {
        check(&ts32(p), v, u)?;
    }

    #[test]
    fn disney(p in disney_params(), v in view(), u in uniforms()) {
        check(&disney32(p), v, u)?;
    }
}

proptest! {
    // FMBRDF evaluates two networks per sample.
    #![proptest_config(ProptestConfig { cases: 500, ..ProptestConfig::default() })]

    #[test]
    fn fmbrdf(p in fmbrdf_params(), v in view(), u in uniforms()) {
        check(&fmbrdf32(p), v, u)?;
    }
}

/// f32 against f64 on the same uniforms, view and parameters (the f64 model built from the
/// f32-rounded values): both succeed or both fail, the directions agree, and the f32 pdf and
/// weight agree with the f64 model's at the f32 direction. Roughness is
/// kept >= 0.05 and the Phong exponent <= 1e3, where f32 resolves the lobes (as in
/// `precision.rs`); a sample within 1e-3 of the horizon may succeed in one precision only.
#[test]
fn f32_agrees_with_f64() {
    let mut rng = SplitMix64::new(0xF32F64);
    let mut worst = [0.0_f64; 3];
    let mut boundary = 0;
    for k in 0..40_000 {
        let r = |rng: &mut SplitMix64| rng.next_f64() as f32;
        let (rough, c3) = (0.05 + 0.95 * r(&mut rng), [r(&mut rng), r(&mut rng), r(&mut rng)]);
        let z = r(&mut rng).max(1e-3);
        let phi = std::f32::consts::TAU * r(&mut rng);
        let v32 = [(1.0 - z * z).sqrt() * phi.cos(), (1.0 - z * z).sqrt() * phi.sin(), z];
        let u32 = [r(&mut rng), r(&mut rng)];
        let (v64, u64) = (v32.map(f64::from), u32.map(f64::from));
        let pair: (Box<dyn Brdf<f32>>, Box<dyn Brdf<f64>>) = match k % 5 {
            0 => {
                let p = RealisticPhongParams {
                    kd: c3.map(|x| 0.5 * x),
                    ks: [0.5; 3],
                    exponent: 1e3f32.powf(rough),
                };
                (
                    Box::new(RealisticPhong::new(p)),
                    Box::new(RealisticPhong::new(RealisticPhongParams {
                        kd: p.kd.map(f64::from),
                        ks: [0.5; 3],
                        exponent: p.exponent.into(),
                    })),
                )
            }
            1 => {
                let p = TorranceSparrowParams { roughness: rough, diffuse: c3, f0: [c3[1]; 3] };
                (
                    Box::new(TorranceSparrow::new(p)),
                    Box::new(TorranceSparrow::new(TorranceSparrowParams {
                        roughness: rough.into(),
                        diffuse: c3.map(f64::from),
                        f0: [c3[1].into(); 3],
                    })),
                )
            }
            2 => {
                let p = DisneyParams { roughness: rough, ..disney_all_lobes::<f32>() };
                (
                    Box::new(Disney::new(p)),
                    Box::new(Disney::new(DisneyParams {
                        roughness: rough.into(),
                        ..disney_all_lobes::<f64>()
                    })),
                )
            }
            3 => (
                Box::new(Lambert::new(LambertParams { albedo: c3 })),
                Box::new(Lambert::new(LambertParams { albedo: c3.map(f64::from) })),
            ),
            _ => {
                let p = FmbrdfParams {
                    alpha: 0.05 + 2.0 * rough,
                    k_s: 10.0 * c3[0],
                    ..Default::default()
                };
                (
                    Box::new(Fmbrdf::new(p)),
                    Box::new(Fmbrdf::new(FmbrdfParams {
                        alpha: p.alpha.into(),
                        k_s: p.k_s.into(),
                        ..Default::default()
                    })),
                )
            }
        };
        let (a, b) = (pair.0.sample(v32, u32), pair.1.sample(v64, u64));
        let name = pair.1.name();
        match (a, b) {
            (Some(a), Some(b)) => {
                // The maps u -> l agree; then pdf and weight are compared with the f64 model's
                // at the f32 sample's own direction, so that only arithmetic differs (near the
                // horizon l.z cancels, and a 1e-5 change of l.z alone moves the weight by 0.3 %).
                let dl = (0..3).map(|i| (f64::from(a.l[i]) - b.l[i]).abs()).fold(0.0, f64::max);
                if dl >= 1e-4 && lobe_boundary(pair.1.as_ref(), v64, u64) {
                    boundary += 1;
                    continue;
                }
                let la = a.l.map(f64::from);
                let pdf = pair.1.pdf(v64, la);
                let f = pair.1.eval(la, v64);
                let dp = rel_diff(a.pdf.into(), pdf, 1e-6);
                let dw = rel_diff_rgb(a.weight.map(f64::from), f.map(|x| x * la[2] / pdf), 1e-6);
                worst = [worst[0].max(dl), worst[1].max(dp), worst[2].max(dw)];
                assert!(
                    dl < 1e-4 && dp < 2e-3 && dw < 2e-3,
                    "{name} #{k}: f32 {a:?} f64 {b:?} (dl {dl}, dpdf {dp}, dw {dw}) v {v32:?} u {u32:?} rough {rough}"
                );
            }
            (None, None) => {}
            (Some(s), None) => assert!(s.l[2] < 1e-3, "{name} #{k}: only f32 succeeded: {s:?}"),
            (None, Some(s)) => assert!(s.l[2] < 1e-3, "{name} #{k}: only f64 succeeded: {s:?}"),
        }
    }
    eprintln!(
        "f32 vs f64 sample: max |dl| {:.2e}, max rel dpdf {:.2e}, max rel dweight {:.2e}, {boundary} at a lobe boundary",
        worst[0], worst[1], worst[2]
    );
    assert!(boundary <= 4, "{boundary} of 40,000 samples picked different lobes");
}

/// Whether the f64 sampler's map u -> l jumps within 1e-6 of u0: the one-sample mixture's lobe
/// boundaries, which rounding moves between f32 and f64 (both draws are then correct, from
/// different lobes; at most a few such cases are accepted).
fn lobe_boundary(m: &dyn Brdf<f64>, v: [f64; 3], u: [f64; 2]) -> bool {
    let at = |u0: f64| m.sample(v, [u0, u[1]]).map(|s| s.l);
    match (at(u[0] - 1e-6), at(u[0] + 1e-6)) {
        (Some(a), Some(b)) => (0..3).any(|i| (a[i] - b[i]).abs() > 1e-2),
        _ => true,
    }
}
