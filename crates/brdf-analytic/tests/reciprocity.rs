//! f(l, v) = f(v, l) to 1e-12 relative in f64 for the reciprocal models, over random parameters
//! and random upper-hemisphere pairs. The implementations go further: every factor is computed
//! symmetrically (l + v, |l + v| / 2, commutative products), so the swap is bit-exact, in f32 too.

mod common;

use brdf_analytic::*;
use common::*;
use proptest::prelude::*;

fn assert_reciprocal<B: Brdf<f64>>(m: &B, l: [f64; 3], v: [f64; 3]) -> Result<(), TestCaseError> {
    let (a, b) = (m.eval(l, v), m.eval(v, l));
    let d = rel_diff_rgb(a, b, 1e-300);
    prop_assert!(d <= 1e-12, "{}: f(l,v) = {:?}, f(v,l) = {:?}, rel {}", m.name(), a, b, d);
    prop_assert!(m.is_reciprocal());
    prop_assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{} not bit-exact", m.name());
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 5_000, ..ProptestConfig::default() })]

    #[test]
    fn lambert(a in [0.0..=1.0_f64, 0.0..=1.0, 0.0..=1.0], l in upper(), v in upper()) {
        assert_reciprocal(&Lambert::new(LambertParams { albedo: a }), l, v)?;
    }

    #[test]
    fn realistic_phong(p in phong_params(), l in upper(), v in upper()) {
        assert_reciprocal(&RealisticPhong::new(p), l, v)?;
    }

    #[test]
    fn torrance_sparrow(p in ts_params(), l in upper(), v in upper()) {
        assert_reciprocal(&TorranceSparrow::new(p), l, v)?;
    }

    #[test]
    fn disney(p in disney_params(), l in upper(), v in upper()) {
        assert_reciprocal(&Disney::new(p), l, v)?;
    }
}
