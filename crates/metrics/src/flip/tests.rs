//! Tests of HDR-FLIP: parity with NVIDIA's tool, and independent checks from the spec's formulas.

use super::*;
use crate::testimg::hdr_pair;

/// Reference values of NVIDIA's flip-evaluator 1.7 (PyPI; the C++ FLIP), obtained with
/// `devtools/reference_values.py`: `flip_evaluator.evaluate(ref, test, "HDR", applyMagma=False)`
/// on the same deterministic images. Columns: (w, h, seed, gain), its mean, then the map at
/// (0, 0), (7, 3), (w - 1, h - 1) and (w / 2, h / 2), and its start / stop exposures.
#[test]
fn flip_matches_flip_evaluator() {
    #[allow(clippy::type_complexity)]
    let cases: [((usize, usize, usize, f64), f64, [f32; 4], (f64, f64)); 3] = [
        (
            (24, 17, 5, 4.0),
            0.108_609_415_590_763_09,
            [0.191_770_36, 0.097_480_96, 0.184_568_64, 0.173_311_87],
            (-0.988_191_604_614_257_8, 0.810_393_929_481_506_3),
        ),
        (
            (40, 31, 9, 4.0),
            0.106_080_591_678_619_38,
            [0.112_765_74, 0.071_146_87, 0.180_447_98, 0.102_745_086],
            (-1.033_122_301_101_684_6, 0.702_446_460_723_877),
        ),
        (
            (33, 27, 2, 300.0),
            0.088_268_883_526_325_23,
            [0.245_824_68, 0.078_590_274, 0.222_175_7, 0.101_244_226],
            (-7.017_637_729_644_775, -4.701_739_311_218_262),
        ),
    ];
    for ((w, h, seed, gain), mean, px, (start, stop)) in cases {
        let (r, t) = hdr_pair(w, h, seed, gain);
        let res = hdr_flip_with(&t, &r, None, &FlipConfig::default()).unwrap();
        assert!((res.mean - mean).abs() < 1e-4, "{w}x{h}: mean {} vs {mean}", res.mean);
        for ((x, y), want) in [(0, 0), (7, 3), (w - 1, h - 1), (w / 2, h / 2)].into_iter().zip(px) {
            let got = res.map[y * w + x];
            assert!((got - want).abs() < 1e-3, "{w}x{h} ({x},{y}): {got} vs {want}");
        }
        assert!(
            (res.start_exposure - start).abs() < 1e-5 && (res.stop_exposure - stop).abs() < 1e-5
        );
    }
}

#[test]
fn aces_constants() {
    let x = aces_inverse(0.85);
    assert!((x - 2.118_87).abs() < 1e-5, "{x}");
    assert!((aces(x as f32) - 0.85).abs() < 1e-6);
    assert_eq!(aces(0.0), 0.0);
    assert_eq!(aces(1e30), 1.0);
    assert!((DEFAULT_PPD - 67.0206).abs() < 1e-4);
}

#[test]
fn identical_images_give_zero() {
    let (r, _) = hdr_pair(20, 15, 1, 10.0);
    let res = hdr_flip_with(&r, &r, None, &FlipConfig::default()).unwrap();
    assert!(
        res.map.iter().all(|v| *v == 0.0),
        "max {}",
        res.map.iter().fold(0.0f32, |a, b| a.max(*b))
    );
}

/// Uniform images: the CSF filters preserve constants and the feature filters vanish, so FLIP is
/// the remapped colour difference of the tone-mapped colours at the single exposure
/// start = stop = log2(x_max / Y_ref). Computed here independently in f64 from the spec's
/// formulas with the textbook sRGB-to-XYZ matrix (4 decimals), hence the 2e-3 tolerance.
#[test]
fn uniform_images_match_spec_formulas() {
    let cases = [([0.3f64, 0.5, 0.2], [0.35f64, 0.45, 0.3]), ([2.0, 1.0, 0.5], [1.0, 1.0, 1.0])];
    for (a, b) in cases {
        let r = Image::from_fn(24, 24, |_, _| a.map(|v| v as f32));
        let t = Image::from_fn(24, 24, |_, _| b.map(|v| v as f32));
        let got = hdr_flip(&t, &r, None).unwrap();
        let want = spec_uniform_flip(a, b);
        assert!((got - want).abs() < 2e-3, "{a:?} {b:?}: {got} vs spec {want}");
    }
}

fn spec_uniform_flip(r: [f64; 3], t: [f64; 3]) -> f64 {
    let k = [0.36 * 2.51, 0.6 * 0.03, 0.0, 0.36 * 2.43, 0.6 * 0.59, 0.14];
    let tm = |x: f64| {
        ((k[0] * x * x + k[1] * x + k[2]) / (k[3] * x * x + k[4] * x + k[5])).clamp(0.0, 1.0)
    };
    // x_max: the larger root of tm(x) = 0.85, by bisection on [1, 10].
    let (mut lo, mut hi) = (1.0, 10.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if tm(mid) < 0.85 { lo = mid } else { hi = mid }
    }
    let y = 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2];
    let scale = lo / y; // 2^start with start = log2(x_max / Y)
    let lab = |c: [f64; 3]| {
        let c = c.map(|v| tm(scale * v));
        let m = [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]];
        let xyz: Vec<f64> =
            (0..3).map(|i| m[i][0] * c[0] + m[i][1] * c[1] + m[i][2] * c[2]).collect();
        let wp = [0.950_428_545, 1.0, 1.088_900_371];
        let d: f64 = 6.0 / 29.0;
        let f = |v: f64| if v > d.powi(3) { v.cbrt() } else { v / (3.0 * d * d) + 4.0 / 29.0 };
        let (fx, fy, fz) = (f(xyz[0] / wp[0]), f(xyz[1] / wp[1]), f(xyz[2] / wp[2]));
        let l = 116.0 * fy - 16.0;
        [l, 0.01 * l * 500.0 * (fx - fy), 0.01 * l * 200.0 * (fy - fz)]
    };
    let hyab = |p: [f64; 3], q: [f64; 3]| {
        (p[0] - q[0]).abs() + ((p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    let e = hyab(lab(r), lab(t)).powf(0.7);
    let lab0 = |c: [f64; 3]| {
        // Green and blue primaries are not exposed or tone-mapped.
        let m = [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]];
        let xyz: Vec<f64> =
            (0..3).map(|i| m[i][0] * c[0] + m[i][1] * c[1] + m[i][2] * c[2]).collect();
        let wp = [0.950_428_545, 1.0, 1.088_900_371];
        let f = |v: f64| v.cbrt();
        let (fx, fy, fz) = (f(xyz[0] / wp[0]), f(xyz[1] / wp[1]), f(xyz[2] / wp[2]));
        let l = 116.0 * fy - 16.0;
        [l, 0.01 * l * 500.0 * (fx - fy), 0.01 * l * 200.0 * (fy - fz)]
    };
    let cmax = hyab(lab0([0.0, 1.0, 0.0]), lab0([0.0, 0.0, 1.0])).powf(0.7);
    let pc = 0.4 * cmax;
    if e < pc { 0.95 * e / pc } else { 0.95 + (e - pc) / (cmax - pc) * 0.05 }
}

#[test]
fn mask_changes_only_exposure_range_and_mean() {
    let (r, t) = hdr_pair(30, 22, 4, 50.0);
    let all = vec![true; 30 * 22];
    let full = hdr_flip_with(&t, &r, None, &FlipConfig::default()).unwrap();
    let with_all = hdr_flip_with(&t, &r, Some(&all), &FlipConfig::default()).unwrap();
    assert_eq!(full, with_all);
    let mask: Vec<bool> = (0..30 * 22).map(|p| (p % 30) < 12).collect();
    let masked = hdr_flip_with(&t, &r, Some(&mask), &FlipConfig::default()).unwrap();
    let (s, e) = exposure_range(&r, Some(&mask)).unwrap();
    assert_eq!((masked.start_exposure, masked.stop_exposure), (s, e));
    let cfg = FlipConfig { start_exposure: Some(s), stop_exposure: Some(e), ..Default::default() };
    let explicit = hdr_flip_with(&t, &r, None, &cfg).unwrap();
    assert_eq!(masked.map, explicit.map);
    let want: f64 =
        mask.iter().zip(&explicit.map).filter(|(m, _)| **m).map(|(_, v)| *v as f64).sum::<f64>()
            / mask.iter().filter(|m| **m).count() as f64;
    assert!((masked.mean - want).abs() < 1e-12);
}

#[test]
fn black_background_without_mask_is_a_clear_error() {
    let r = Image::from_fn(16, 16, |x, _| if x < 10 { [0.0; 3] } else { [1.0; 3] });
    let e = hdr_flip(&r, &r, None).unwrap_err();
    assert!(matches!(e, Error::Exposure(_)), "{e}");
    let mask: Vec<bool> = (0..256).map(|p| p % 16 >= 10).collect();
    assert_eq!(hdr_flip(&r, &r, Some(&mask)).unwrap(), 0.0);
}

/// Images prepared once and compared in every pairing give the maps and means of
/// `hdr_flip_with` at the same exposures, bit for bit; images prepared at other exposures, or of
/// other sizes, are refused.
#[test]
fn prepared_images_compare_as_the_direct_call() {
    let (r, t) = hdr_pair(24, 17, 5, 4.0);
    let (_, u) = hdr_pair(24, 17, 8, 4.0);
    let mask: Vec<bool> = (0..24 * 17).map(|p| p % 3 != 0).collect();
    let range = exposure_range(&r, Some(&mask)).unwrap();
    let at = FlipExposures::new(range, DEFAULT_PPD).unwrap();
    let cfg = FlipConfig {
        start_exposure: Some(range.0),
        stop_exposure: Some(range.1),
        ..Default::default()
    };
    let prepared: Vec<FlipImage> =
        [&r, &t, &u].iter().map(|i| FlipImage::new(i, &at).unwrap()).collect();
    let images = [&r, &t, &u];
    for (a, b) in [(1, 0), (2, 0), (1, 2), (0, 1)] {
        for m in [None, Some(&mask[..])] {
            let direct = hdr_flip_with(images[a], images[b], m, &cfg).unwrap();
            let via = hdr_flip_prepared(&prepared[a], &prepared[b], m).unwrap();
            assert_eq!(
                direct.mean.to_bits(),
                via.mean.to_bits(),
                "{a} vs {b}, mask {}",
                m.is_some()
            );
            assert!(direct.map.iter().zip(&via.map).all(|(x, y)| x.to_bits() == y.to_bits()));
            assert_eq!(
                (direct.exposures, direct.start_exposure),
                (via.exposures, via.start_exposure)
            );
        }
    }
    let other = FlipExposures::new((range.0 - 1.0, range.1), DEFAULT_PPD).unwrap();
    let elsewhere = FlipImage::new(&t, &other).unwrap();
    assert!(matches!(hdr_flip_prepared(&elsewhere, &prepared[0], None), Err(Error::Config(_))));
    let (small, _) = hdr_pair(8, 8, 1, 4.0);
    let small = FlipImage::new(&small, &at).unwrap();
    assert!(matches!(
        hdr_flip_prepared(&small, &prepared[0], None),
        Err(Error::SizeMismatch { .. })
    ));
    assert!(FlipExposures::new((f64::NEG_INFINITY, 1.0), DEFAULT_PPD).is_err());
    assert!(FlipExposures::new(range, 0.0).is_err());
}
