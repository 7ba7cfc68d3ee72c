//! Adversarial numerics (issue 19): every model kind and option, freshly initialised and after
//! 300 Adam steps on an analytic BRDF, run forward and backward on streams of extreme direction
//! pairs (`test_support::adversarial`: grazing down to 1e-7 rad, l = v, mirrored, l = -v,
//! n.l = 0 exactly, denormal components, below the horizon) with ordinary and extreme feature
//! rows. Every output must be finite and non-negative (xi in [0, 1]) and every parameter's
//! gradient finite. The pairs go through the same batch builder as training, so the angle
//! parametrizations, the reciprocity mapping and the positional encoding are covered too.
//!
//! `cargo test` runs 2^15 pairs per variant; the 1e7:
//! `NEURAL_BRDF_STRESS_PAIRS=10000000 cargo test --release -p brdf-neural --test adversarial_numerics -- --nocapture`

mod common;

use brdf_analytic::{Brdf, TorranceSparrow, TorranceSparrowParams};
use brdf_neural::finite_check::check_forward_backward;
use brdf_neural::{
    AngleParametrization, BrdfModel, ModelConfig, ModelKind, Reciprocity, Samples, device,
};
use common::{OwnedSamples, direction, rng, small, train};
use rand::Rng;
use std::time::Instant;
use test_support::adversarial::{direction_pairs, spatial_rows};

const SEED: u64 = 0x00ad_5e75;
const BATCH: usize = 1 << 14;

fn pairs_per_variant() -> usize {
    std::env::var("NEURAL_BRDF_STRESS_PAIRS").ok().and_then(|v| v.parse().ok()).unwrap_or(1 << 15)
}

/// Every kind, and the purely neural and additive models' options.
fn variants() -> Vec<ModelConfig> {
    let mut out = Vec::new();
    for kind in ModelKind::ALL {
        out.push(small(kind));
        if kind.analytic().is_none() {
            for (rec, par, nol) in [
                (Reciprocity::Mapping, AngleParametrization::Rusinkiewicz, true),
                (Reciprocity::None, AngleParametrization::ViewLight, false),
            ] {
                let mut c = small(kind);
                c.angles.reciprocity = rec;
                c.angles.parametrization = par;
                c.nol = nol;
                out.push(c);
            }
        }
        if kind.is_additive() {
            let mut c = small(kind);
            c.albedo_clamp = true;
            c.scalar_specular = true;
            out.push(c);
        }
    }
    out
}

fn label(c: &ModelConfig) -> String {
    format!(
        "{:?} ({:?}, {:?}, nol {}, clamp {})",
        c.kind, c.angles.parametrization, c.angles.reciprocity, c.nol, c.albedo_clamp
    )
}

/// Runs `n` adversarial pairs through `model`; panics naming the variant, the part and the
/// input row at the first non-finite value.
fn stress(model: &BrdfModel, c: &ModelConfig, what: &str, n: usize, device: &burn::tensor::Device) {
    let mut start = 0;
    while start < n {
        let m = BATCH.min(n - start);
        let (l, v) = direction_pairs(SEED, start as u64, m);
        let spatial = spatial_rows(SEED, start as u64, m, c.spatial_dim);
        let samples = Samples { spatial: &spatial, l: &l, v: &v };
        let checked = check_forward_backward(model, c, &samples, device).unwrap();
        if let Some(mut p) = checked.problem {
            if p.row.is_none() {
                p.row = Some(bisect(model, c, &spatial, &l, &v, device));
            }
            let input = p.row.map_or(String::new(), |r| {
                let d = c.spatial_dim;
                format!(
                    "; input row {} (stream row {}): l {:?}, v {:?}, features {:?}",
                    r,
                    start + r,
                    l[r],
                    v[r],
                    &spatial[r * d..(r + 1) * d]
                )
            });
            panic!("{} {what}: {p}{input}", label(c));
        }
        assert!(checked.gradients > 0, "{}: no gradient checked", label(c));
        start += m;
    }
}

/// The first row that alone gives a non-finite gradient (halving the batch).
fn bisect(
    model: &BrdfModel,
    c: &ModelConfig,
    spatial: &[f32],
    l: &[[f32; 3]],
    v: &[[f32; 3]],
    device: &burn::tensor::Device,
) -> usize {
    let d = c.spatial_dim;
    let bad = |a: usize, b: usize| {
        let s = Samples { spatial: &spatial[a * d..b * d], l: &l[a..b], v: &v[a..b] };
        check_forward_backward(model, c, &s, device).unwrap().problem.is_some()
    };
    let (mut a, mut b) = (0, l.len());
    while b - a > 1 {
        let m = (a + b) / 2;
        if bad(a, m) {
            b = m;
        } else if bad(m, b) {
            a = m;
        } else {
            break; // only the two halves together fail (a batch-level effect)
        }
    }
    a
}

/// Samples of Torrance-Sparrow (roughness 0.3) with a feature-dependent albedo, as targets.
fn analytic_data(n: usize, dim: usize) -> (OwnedSamples, Vec<f32>) {
    let mut r = rng(5);
    let s = OwnedSamples {
        spatial: (0..n * dim).map(|_| r.random_range(-1.0..1.0)).collect(),
        l: (0..n).map(|_| direction(&mut r, 0.05)).collect(),
        v: (0..n).map(|_| direction(&mut r, 0.05)).collect(),
    };
    let mut target = Vec::with_capacity(n * 3);
    for i in 0..n {
        let s0 = s.spatial[i * dim];
        let brdf = TorranceSparrow::new(TorranceSparrowParams {
            roughness: 0.3,
            diffuse: [0.3 + 0.2 * s0, 0.4, 0.2],
            f0: [0.04; 3],
        });
        target.extend(brdf.eval(s.l[i], s.v[i]));
    }
    (s, target)
}

#[test]
fn fresh_models_are_finite_forward_and_backward_on_adversarial_inputs() {
    let device = device::cpu_training();
    let n = pairs_per_variant();
    let t = Instant::now();
    let variants = variants();
    for c in &variants {
        let model = BrdfModel::init_seeded(c, &device, SEED, None).unwrap();
        stress(&model, c, "fresh", n, &device);
    }
    eprintln!(
        "fresh: {} variants x {n} pairs, no NaN or Inf, in {:.1} s",
        variants.len(),
        t.elapsed().as_secs_f64()
    );
}

#[test]
fn trained_models_stay_finite_forward_and_backward_on_adversarial_inputs() {
    let device = device::cpu_training();
    let n = pairs_per_variant();
    let t = Instant::now();
    let variants = variants();
    for c in &variants {
        let data = [analytic_data(256, c.spatial_dim)];
        let model = BrdfModel::init_seeded(c, &device, SEED, None).unwrap();
        let (model, losses) = train(model, c, &data, 300, 3e-3, &device);
        assert!(losses[299] < losses[0], "{}: did not learn ({:?})", label(c), &losses[..3]);
        stress(&model, c, "after 300 steps", n, &device);
    }
    eprintln!(
        "trained: {} variants x {n} pairs, no NaN or Inf, in {:.1} s",
        variants.len(),
        t.elapsed().as_secs_f64()
    );
}

/// The angle parametrizations, the reciprocity mapping and the positional encoding on their own,
/// in f32 (the hot path) and f64, on the same adversarial pairs: every value finite, and the
/// f32 results within 1e-3 rad of the f64 ones where the directions are valid (upper
/// hemisphere, not degenerate).
#[test]
fn angle_features_are_finite_on_adversarial_pairs() {
    use angles::{PositionalEncoding, Rusinkiewicz, ViewLight, reciprocal_theta};
    let n = pairs_per_variant() * 8;
    let pe = PositionalEncoding { frequencies: 10, ..PositionalEncoding::default() };
    let (mut checked, mut worst) = (0usize, 0.0_f64);
    let mut start = 0;
    while start < n {
        let m = BATCH.min(n - start);
        let (l, v) = direction_pairs(SEED, start as u64, m);
        for (i, (l, v)) in l.iter().zip(&v).enumerate() {
            let (l64, v64) = (l.map(f64::from), v.map(f64::from));
            let r = Rusinkiewicz::from_local(*l, *v).to_array();
            let w = ViewLight::from_local(*l, *v).to_array();
            let t = reciprocal_theta(*l, *v);
            let mut features: Vec<f32> = r.iter().chain(&w).chain(&t).copied().collect();
            features.extend(pe.encode(&features.clone()));
            let r64 = Rusinkiewicz::from_local(l64, v64).to_array();
            let t64 = reciprocal_theta(l64, v64);
            let features64: Vec<f64> = r64.iter().chain(&t64).copied().collect();
            let bad = features.iter().any(|x| !x.is_finite())
                || features64.iter().any(|x| !x.is_finite());
            assert!(!bad, "row {}: l {l:?}, v {v:?}: {features:?}", start + i);
            let valid = l[2] > 1e-3 && v[2] > 1e-3;
            if valid {
                // theta_h, theta_d and the reciprocal thetas (phi_d wraps: left out).
                for (a, b) in
                    [(r[0], r64[0]), (r[1], r64[1])].into_iter().chain(t.iter().copied().zip(t64))
                {
                    worst = worst.max((f64::from(a) - b).abs());
                }
            }
            checked += 1;
        }
        start += m;
    }
    assert!(worst < 1e-3, "f32 angles differ from f64 by {worst} rad");
    eprintln!("angle features: {checked} pairs finite; f32 vs f64 at most {worst:.2e} rad");
}
