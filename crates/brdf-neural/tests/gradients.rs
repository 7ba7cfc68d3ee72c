//! One Adam step on a tiny batch changes every parameter tensor of every model and variant
//! (gradients reach everything, including FMBRDF's global alpha and beta).

mod common;

use brdf_neural::{ModelKind, Reciprocity, device};
use common::{parameters, rng, samples, small, train};

#[test]
fn one_step_changes_every_parameter_tensor() {
    let device = device::cpu_training();
    let mut r = rng(11);
    let mut configs: Vec<_> = ModelKind::ALL.into_iter().map(small).collect();
    for kind in [ModelKind::SingleMlp, ModelKind::AdditiveSeparate, ModelKind::AdditiveShared] {
        let mut c = small(kind);
        c.nol = true;
        c.angles.reciprocity = Reciprocity::Mapping;
        configs.push(c);
    }
    for c in configs {
        let model = c.init(&device).unwrap();
        let before = parameters(&model);
        let s = samples(&mut r, 64, c.spatial_dim);
        let target: Vec<f32> = (0..64 * 3).map(|i| 0.05 + 0.01 * (i % 7) as f32).collect();
        let (model, _) = train(model, &c, &[(s, target)], 1, 1e-3, &device);
        let after = parameters(&model);
        assert_eq!(before.len(), after.len());
        assert!(!before.is_empty());
        for (i, (b, a)) in before.iter().zip(&after).enumerate() {
            assert!(
                b.iter().zip(a).any(|(x, y)| x != y),
                "{:?}: parameter tensor {i} unchanged",
                c.kind
            );
        }
        if c.kind == ModelKind::Fmbrdf {
            assert!(after.iter().filter(|t| t.len() == 1).count() == 2, "alpha and beta");
        }
    }
}

#[test]
fn config_param_count_matches_the_module() {
    use burn::module::Module;
    let device = device::cpu();
    for kind in ModelKind::ALL {
        for nol in [false, true] {
            let mut c = brdf_neural::ModelConfig::new(kind);
            c.nol = nol;
            if c.validate().is_err() {
                continue;
            }
            assert_eq!(c.init(&device).unwrap().num_params(), c.param_count(), "{kind:?} {nol}");
        }
    }
}

#[test]
fn parameter_counts_match_the_crate_docs() {
    // The table in the crate-level docs (default configuration, 160 spatial inputs).
    let documented = [
        (ModelKind::Rp, 108_039, None, None),
        (ModelKind::Ts, 108_039, None, None),
        (ModelKind::Fmbrdf, 107_912, None, None),
        (ModelKind::Disney, 108_684, None, None),
        (ModelKind::SingleMlp, 112_899, Some(114_691), Some(110_211)),
        (ModelKind::AdditiveSeparate, 187_398, Some(189_190), Some(131_206)),
        (ModelKind::AdditiveShared, 160_134, Some(161_030), Some(172_678)),
        (ModelKind::AdditiveSeparateEnhanced, 187_785, Some(189_577), Some(131_593)),
        (ModelKind::AdditiveSharedEnhanced, 160_521, Some(161_417), Some(173_065)),
    ];
    for (kind, default, mapping, nol) in documented {
        let c = brdf_neural::ModelConfig::new(kind);
        assert_eq!(c.param_count(), default, "{kind:?}");
        if let (Some(m), Some(n)) = (mapping, nol) {
            let mut cm = c.clone();
            cm.angles.reciprocity = Reciprocity::Mapping;
            assert_eq!(cm.param_count(), m, "{kind:?} mapping");
            let mut cn = c.clone();
            cn.nol = true;
            assert_eq!(cn.param_count(), n, "{kind:?} nol");
        }
    }
}
