//! One Adam step on a tiny batch changes every parameter tensor of every model and variant
//! (gradients reach everything, including FMBRDF's global alpha and beta).

mod common;

use brdf_neural::{BrdfModel, ModelKind, Reciprocity, device};
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
        let model = BrdfModel::init(&c, &device).unwrap();
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
            assert_eq!(
                BrdfModel::init(&c, &device).unwrap().num_params(),
                c.param_count(),
                "{kind:?} {nol}"
            );
        }
    }
}
