//! The reciprocity mapping makes every purely neural model's output bit-identical under
//! swapping l and v (plain, enhanced and NOL variants, with the NeRFactor options), while
//! without it the models are not reciprocal.

mod common;

use brdf_neural::{BrdfBatch, BrdfModel, ModelKind, Reciprocity, device};
use common::{rng, samples, small, values};

const NEURAL: [ModelKind; 5] = [
    ModelKind::SingleMlp,
    ModelKind::AdditiveSeparate,
    ModelKind::AdditiveShared,
    ModelKind::AdditiveSeparateEnhanced,
    ModelKind::AdditiveSharedEnhanced,
];

#[test]
fn mapping_gives_bit_identical_outputs_under_swap() {
    let device = device::cpu();
    let mut r = rng(7);
    for kind in NEURAL {
        for (nol, nerfactor) in [(false, false), (true, false), (false, true)] {
            if nerfactor && !kind.is_additive() {
                continue;
            }
            let mut c = small(kind);
            c.angles.reciprocity = Reciprocity::Mapping;
            c.nol = nol;
            c.albedo_clamp = nerfactor;
            c.scalar_specular = nerfactor;
            let model = BrdfModel::init(&c, &device).unwrap();
            let s = samples(&mut r, 256, c.spatial_dim);
            let a = model.forward(&BrdfBatch::new(&c, &s.view(), None, &device).unwrap());
            let b = model.forward(&BrdfBatch::new(&c, &s.swapped().view(), None, &device).unwrap());
            let (fa, fb) = (values(a.f), values(b.f));
            assert!(
                fa.iter().zip(&fb).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{kind:?} nol {nol}"
            );
            if let (Some(x), Some(y)) = (a.specular, b.specular) {
                assert_eq!(values(x), values(y), "{kind:?} specular");
            }
        }
    }
}

#[test]
fn without_mapping_outputs_change_under_swap() {
    let device = device::cpu();
    let mut r = rng(8);
    for kind in NEURAL {
        let c = small(kind);
        let model = BrdfModel::init(&c, &device).unwrap();
        let s = samples(&mut r, 64, c.spatial_dim);
        let a = values(model.forward(&BrdfBatch::new(&c, &s.view(), None, &device).unwrap()).f);
        let b = values(
            model.forward(&BrdfBatch::new(&c, &s.swapped().view(), None, &device).unwrap()).f,
        );
        assert!(a.iter().zip(&b).any(|(x, y)| x != y), "{kind:?} is reciprocal by accident");
    }
}

#[test]
fn random_swap_mask_swaps_the_network_input_only() {
    let device = device::cpu();
    let mut c = small(ModelKind::SingleMlp);
    c.angles.reciprocity = Reciprocity::RandomSwap;
    let model = BrdfModel::init(&c, &device).unwrap();
    let s = samples(&mut rng(9), 100, c.spatial_dim);
    let mask = c.angles.swap_mask(100, &mut rng(10));
    let swapped = mask.iter().filter(|&&m| m).count();
    assert!((30..=70).contains(&swapped), "{swapped} of 100 swapped at p = 0.5");
    let all = vec![true; 100];
    let a = values(model.forward(&BrdfBatch::new(&c, &s.view(), Some(&all), &device).unwrap()).f);
    let b =
        values(model.forward(&BrdfBatch::new(&c, &s.swapped().view(), None, &device).unwrap()).f);
    assert_eq!(a, b);
}
