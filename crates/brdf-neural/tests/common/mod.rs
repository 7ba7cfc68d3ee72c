//! Helpers shared by the integration tests: random directions and samples, reading tensors
//! back, and a small Adam training loop.

#![allow(dead_code)]

use brdf_neural::{BrdfBatch, BrdfModel, ModelConfig, Samples};
use burn::module::{Module, ModuleVisitor, Param};
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Tensor};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// A seeded generator.
pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// A random unit direction with z >= `min_z` (uniform in z, so grazing ones occur).
pub fn direction(rng: &mut impl Rng, min_z: f32) -> [f32; 3] {
    let z: f32 = rng.random_range(min_z..1.0);
    let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    let s = (1.0 - z * z).max(0.0).sqrt();
    [s * phi.cos(), s * phi.sin(), z]
}

/// Owned samples.
pub struct OwnedSamples {
    pub spatial: Vec<f32>,
    pub l: Vec<[f32; 3]>,
    pub v: Vec<[f32; 3]>,
}

impl OwnedSamples {
    pub fn view(&self) -> Samples<'_> {
        Samples { spatial: &self.spatial, l: &self.l, v: &self.v }
    }

    /// The same samples with l and v exchanged.
    pub fn swapped(&self) -> OwnedSamples {
        OwnedSamples { spatial: self.spatial.clone(), l: self.v.clone(), v: self.l.clone() }
    }
}

/// `n` random samples with features in [-1, 1] and directions in the upper hemisphere.
pub fn samples(rng: &mut impl Rng, n: usize, spatial_dim: usize) -> OwnedSamples {
    OwnedSamples {
        spatial: (0..n * spatial_dim).map(|_| rng.random_range(-1.0..1.0)).collect(),
        l: (0..n).map(|_| direction(rng, 0.0)).collect(),
        v: (0..n).map(|_| direction(rng, 0.0)).collect(),
    }
}

/// A tensor's values.
pub fn values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().convert::<f32>().try_into_vec::<f32>().expect("f32 data")
}

/// A small configuration of `kind` for fast tests.
pub fn small(kind: brdf_neural::ModelKind) -> ModelConfig {
    ModelConfig { spatial_dim: 8, width: 32, ..ModelConfig::new(kind) }
}

/// Every float parameter tensor of a module, flattened, in visiting order.
pub fn parameters<M: Module>(m: &M) -> Vec<Vec<f32>> {
    struct Collect(Vec<Vec<f32>>);
    impl ModuleVisitor for Collect {
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            self.0.push(values(param.val()));
        }
    }
    let mut c = Collect(Vec::new());
    m.visit(&mut c);
    c.0
}

/// Adam on the MSE between `model(batch).f * weight` and `target`; returns the trained model
/// and the loss of every step.
pub fn train(
    model: BrdfModel,
    config: &ModelConfig,
    data: &[(OwnedSamples, Vec<f32>)],
    steps: usize,
    lr: f64,
    device: &Device,
) -> (BrdfModel, Vec<f32>) {
    train_with(model, config, data, (steps, lr), device, brdf_neural::products::Products::F32)
}

/// [`train`] with the batches' linear-layer products as `products` say.
pub fn train_with(
    mut model: BrdfModel,
    config: &ModelConfig,
    data: &[(OwnedSamples, Vec<f32>)],
    (steps, lr): (usize, f64),
    device: &Device,
    products: brdf_neural::products::Products,
) -> (BrdfModel, Vec<f32>) {
    let mut optim = AdamConfig::new().init();
    let batches: Vec<_> = data
        .iter()
        .map(|(s, t)| {
            let b = BrdfBatch::new(config, &s.view(), None, device).unwrap();
            let b = b.with_products(products);
            let target = Tensor::<2>::from_data(
                burn::tensor::TensorData::new(t.clone(), [s.l.len(), 3]),
                device,
            );
            (b, target)
        })
        .collect();
    let mut losses = Vec::with_capacity(steps);
    for step in 0..steps {
        let (batch, target) = &batches[step % batches.len()];
        let out = model.forward(batch);
        let loss = (out.f - target.clone()).square().mean();
        losses.push(values(loss.clone())[0]);
        let grads = GradientsParams::from_grads(loss.backward(), &model);
        model = optim.step(lr, model, grads);
    }
    (model, losses)
}
