//! Learning tests (not timing tests): models trained with Adam for a few hundred steps on
//! samples of a known analytic BRDF reduce the MSE on held-out samples by a stated factor.
//!
//! Target: Torrance-Sparrow, roughness 0.6, F0 0.04, with a diffuse albedo that varies with the
//! first spatial feature s_0 in [-1, 1]: rho_d = (0.2 + 0.3 (s_0 + 1), 0.5, 0.3 - 0.1 s_0).

mod common;

use brdf_analytic::{Brdf, TorranceSparrow, TorranceSparrowParams};
use brdf_neural::{BrdfBatch, BrdfModel, ModelConfig, ModelKind, Reciprocity, device};
use burn::tensor::{Tensor, TensorData};
use common::{OwnedSamples, direction, parameters, rng, small, train, values};
use rand::Rng;

const SPATIAL: usize = 4;

/// Samples with theta_l, theta_v below 75.5 degrees (cos >= 0.25), like the paper's 80 degree
/// evaluation cutoff: the grazing Fresnel and 1/(n.l n.v) spikes would dominate a plain MSE.
fn samples(r: &mut impl Rng, n: usize) -> OwnedSamples {
    OwnedSamples {
        spatial: (0..n * SPATIAL).map(|_| r.random_range(-1.0..1.0)).collect(),
        l: (0..n).map(|_| direction(r, 0.25)).collect(),
        v: (0..n).map(|_| direction(r, 0.25)).collect(),
    }
}

fn target(s: &OwnedSamples) -> Vec<f32> {
    let mut out = Vec::with_capacity(s.l.len() * 3);
    for i in 0..s.l.len() {
        let s0 = s.spatial[i * SPATIAL];
        let brdf = TorranceSparrow::new(TorranceSparrowParams {
            roughness: 0.6,
            diffuse: [0.2 + 0.3 * (s0 + 1.0), 0.5, 0.3 - 0.1 * s0],
            f0: [0.04; 3],
        });
        out.extend(brdf.eval(s.l[i], s.v[i]));
    }
    out
}

fn held_out_mse(model: &BrdfModel, c: &ModelConfig, s: &OwnedSamples, t: &[f32]) -> f32 {
    let device = device::cpu_training();
    let out = model.forward(&BrdfBatch::new(c, &s.view(), None, &device).unwrap());
    let t = Tensor::<2>::from_data(TensorData::new(t.to_vec(), [s.l.len(), 3]), &device);
    values((out.f - t).square().mean())[0]
}

/// Trains `c` for `steps` and returns (held-out MSE before, after).
fn fit(c: &ModelConfig, steps: usize, lr: f64) -> (f32, f32) {
    let device = device::cpu_training();
    let mut r = rng(31);
    let data: Vec<_> = (0..8)
        .map(|_| {
            let s = samples(&mut r, 256);
            let t = target(&s);
            (s, t)
        })
        .collect();
    let test = samples(&mut r, 1024);
    let test_t = target(&test);
    let model = BrdfModel::init_seeded(c, &device, 5, None).unwrap();
    let before = held_out_mse(&model, c, &test, &test_t);
    let (model, losses) = train(model, c, &data, steps, lr, &device);
    assert!(losses.iter().all(|l| l.is_finite()));
    let after = held_out_mse(&model, c, &test, &test_t);
    eprintln!("{:?}: held-out MSE {before:.3e} -> {after:.3e} ({:.1}x)", c.kind, before / after);
    (before, after)
}

#[test]
fn single_mlp_learns_an_analytic_brdf() {
    let mut c = ModelConfig::new(ModelKind::SingleMlp);
    c.spatial_dim = SPATIAL;
    c.width = 64;
    c.angles.reciprocity = Reciprocity::Mapping;
    let (before, after) = fit(&c, 300, 3e-3);
    assert!(after < before / 10.0, "Single MLP: {before} -> {after}");
}

#[test]
fn enhanced_additive_shared_learns_an_analytic_brdf() {
    let mut c = ModelConfig::new(ModelKind::AdditiveSharedEnhanced);
    c.spatial_dim = SPATIAL;
    c.width = 64;
    let (before, after) = fit(&c, 300, 3e-3);
    assert!(after < before / 10.0, "Enh. Add. Shared: {before} -> {after}");
}

#[test]
fn parametric_torrance_sparrow_learns_its_own_family() {
    let mut c = ModelConfig::new(ModelKind::Ts);
    c.spatial_dim = SPATIAL;
    c.width = 64;
    let (before, after) = fit(&c, 300, 3e-3);
    assert!(after < before / 10.0, "TS: {before} -> {after}");
}

/// A seeded model gets the same initial weights when other threads build models at the same
/// time (two fits in one process, the tests of one binary): burn's generator is one per
/// process, and `init_seeded` holds it from the seed to the last draw. Seeding and then
/// calling `init` in two steps failed this about every other run.
#[test]
fn seeded_initial_weights_do_not_depend_on_other_threads() {
    let device = device::cpu_training();
    let kinds = [ModelKind::SingleMlp, ModelKind::Disney, ModelKind::AdditiveSharedEnhanced];
    let alone: Vec<_> = kinds
        .iter()
        .map(|&k| parameters(&BrdfModel::init_seeded(&small(k), &device, 7, None).unwrap()))
        .collect();
    std::thread::scope(|scope| {
        for (i, (&kind, want)) in kinds.iter().zip(&alone).enumerate() {
            let device = device.clone();
            scope.spawn(move || {
                let c = small(kind);
                for round in 0..40 {
                    // Unseeded builds draw from the same generator in between.
                    let _other =
                        BrdfModel::init(&small(kinds[(i + 1) % kinds.len()]), &device).unwrap();
                    let got = parameters(&BrdfModel::init_seeded(&c, &device, 7, None).unwrap());
                    assert!(
                        got == *want,
                        "{kind:?}: other threads changed round {round}'s weights"
                    );
                }
            });
        }
    });
}
