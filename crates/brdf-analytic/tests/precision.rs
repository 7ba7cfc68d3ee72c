//! f32 (hot path) against f64 (reference) on the same inputs: the f32 inputs are rounded first
//! and the f64 model is evaluated on exactly those rounded values, so only arithmetic differs.

mod common;

use brdf_analytic::*;
use common::*;
use proptest::prelude::*;

fn to32(a: [f64; 3]) -> [f32; 3] {
    a.map(|x| x as f32)
}
fn to64(a: [f32; 3]) -> [f64; 3] {
    a.map(f64::from)
}

/// Relative bound, with an absolute floor of 1e-6 (1/sr) for values near zero.
const TOL: f64 = 2e-4;

fn compare<B32: Brdf<f32>, B64: Brdf<f64>>(
    m32: &B32,
    m64: &B64,
    l: [f64; 3],
    v: [f64; 3],
) -> Result<(), TestCaseError> {
    let (l32, v32) = (to32(l), to32(v));
    let a = to64(m32.eval(l32, v32));
    let b = m64.eval(to64(l32), to64(v32));
    let d = rel_diff_rgb(a, b, 1e-6);
    prop_assert!(d < TOL, "{}: f32 {a:?} f64 {b:?} rel {d}", m64.name());
    Ok(())
}

fn p32<const N: usize>(a: [f64; N]) -> [f32; N] {
    a.map(|x| x as f32)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, ..ProptestConfig::default() })]

    #[test]
    fn phong(p in phong_params(), l in upper(), v in upper()) {
        // powf(N) amplifies the f32 rounding of r.v by N: compare up to N = 1e3 (cap the
        // log-uniform exponent), where that stays within f32's reach.
        let p = RealisticPhongParams { exponent: p.exponent.min(1e3), ..p };
        // The f32 model's parameters are the f64 ones rounded; evaluate f64 on those too.
        let q = RealisticPhongParams { kd: p32(p.kd), ks: p32(p.ks), exponent: p.exponent as f32 };
        let r = RealisticPhongParams { kd: to64(q.kd), ks: to64(q.ks), exponent: q.exponent as f64 };
        compare(&RealisticPhong::new(q), &RealisticPhong::new(r), l, v)?;
    }

    #[test]
    fn torrance_sparrow(p in ts_params(), l in upper(), v in upper()) {
        let q = TorranceSparrowParams { roughness: p.roughness as f32, diffuse: p32(p.diffuse), f0: p32(p.f0) };
        let r = TorranceSparrowParams { roughness: q.roughness as f64, diffuse: to64(q.diffuse), f0: to64(q.f0) };
        compare(&TorranceSparrow::new(q), &TorranceSparrow::new(r), l, v)?;
    }

    #[test]
    fn disney(p in disney_params(), l in upper(), v in upper()) {
        let q = DisneyParams {
            base_color: p32(p.base_color), metallic: p.metallic as f32, subsurface: p.subsurface as f32,
            specular: p.specular as f32, roughness: p.roughness as f32, specular_tint: p.specular_tint as f32,
            sheen: p.sheen as f32, sheen_tint: p.sheen_tint as f32, clearcoat: p.clearcoat as f32,
            clearcoat_gloss: p.clearcoat_gloss as f32, gamma_base_color: p.gamma_base_color,
        };
        let r = DisneyParams {
            base_color: to64(q.base_color), metallic: q.metallic.into(), subsurface: q.subsurface.into(),
            specular: q.specular.into(), roughness: q.roughness.into(), specular_tint: q.specular_tint.into(),
            sheen: q.sheen.into(), sheen_tint: q.sheen_tint.into(), clearcoat: q.clearcoat.into(),
            clearcoat_gloss: q.clearcoat_gloss.into(), gamma_base_color: q.gamma_base_color,
        };
        compare(&Disney::new(q), &Disney::new(r), l, v)?;
    }
}
