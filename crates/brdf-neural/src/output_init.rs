//! Output-bias initialisation: start a purely neural model at a plausible reflectance.
//!
//! With burn's default (PyTorch-style) initialisation the Single MLP's untrained output is
//! softplus(~0) = 0.69 / sr, an albedo of about 2.2: the first renders are far too bright, the
//! early gradients are large and coherent, and at learning rates above 5e-4 Adam pushes every
//! softplus into its flat region, where the model collapses to f = 0. Setting the output
//! biases so that the untrained model predicts a given BRDF `f0` (the trainer uses the
//! least-squares constant BRDF of the training data) removes that transient:
//!
//! | model | output | bias |
//! | --- | --- | --- |
//! | Single MLP | s softplus(z) | softplus^-1(f0 / s) |
//! | additive, diffuse | sigmoid(z) / pi | logit(pi f_d), f_d = 0.9 f0 / (1 - xi0), albedo clamped to [0.02, 0.98] |
//! | additive, specular | k softplus(z) | softplus^-1(0.1 f0 / k) (channel mean for a scalar specular) |
//! | enhanced, xi | sigmoid(z) | logit(xi0), xi0 = 0.1 |
//!
//! so that f = (1 - xi0) f_d + f_s = f0 at the start. The parametric models are left as they
//! are: their sigmoid-bounded parameters already start inside their physical ranges.
//! Weights keep their initialisation; only the output biases change, so the untrained model
//! still varies with its inputs around `f0`.

use crate::model::BrdfModel;
use crate::output::AdditiveHead;

/// Initial enhanced-split xi: a small attenuation of the diffuse part.
const XI0: f32 = 0.1;
/// Share of the initial BRDF given to the diffuse part of the additive models.
const DIFFUSE_SHARE: f32 = 0.9;

/// Inverse of softplus, for y > 0: ln(e^y - 1), computed stably.
pub fn softplus_inverse(y: f32) -> f32 {
    let y = y.max(1e-6);
    if y > 20.0 { y } else { y + (-(-y).exp_m1()).ln() }
}

/// Inverse of the logistic sigmoid, for p in (0, 1).
pub fn logit(p: f32) -> f32 {
    (p / (1.0 - p)).ln()
}

/// The biases of an additive model's diffuse and specular output layers for an initial BRDF
/// `f0`.
fn additive_biases(head: &AdditiveHead, f0: [f32; 3]) -> (Vec<f32>, Vec<f32>) {
    let xi0 = if head.enhanced { XI0 } else { 0.0 };
    let diffuse = f0
        .iter()
        .map(|&f| {
            let albedo = std::f32::consts::PI * DIFFUSE_SHARE * f / (1.0 - xi0);
            logit(albedo.clamp(0.02, 0.98))
        })
        .collect();
    let spec = |f: f32| softplus_inverse((1.0 - DIFFUSE_SHARE) * f / head.specular_scale);
    let mut specular: Vec<f32> = if head.scalar_specular {
        vec![spec(f0.iter().sum::<f32>() / 3.0)]
    } else {
        f0.iter().map(|&f| spec(f)).collect()
    };
    if head.enhanced {
        specular.extend([logit(XI0); 3]);
    }
    (diffuse, specular)
}

impl BrdfModel {
    /// The same model with its output biases set so that, at its initial weights, it predicts
    /// about `f0` (1/sr, linear RGB) everywhere (see the module documentation). Parametric
    /// models are returned unchanged.
    pub fn with_initial_brdf(self, f0: [f32; 3]) -> Self {
        let f0 = f0.map(|f| if f.is_finite() { f.clamp(1e-3, 10.0) } else { 0.1 });
        match self {
            BrdfModel::Parametric(m) => BrdfModel::Parametric(m),
            BrdfModel::SingleMlp(mut m) => {
                let bias: Vec<f32> = f0.iter().map(|&f| softplus_inverse(f / m.scale())).collect();
                m.mlp = m.mlp.with_output_bias(&bias);
                BrdfModel::SingleMlp(m)
            }
            BrdfModel::AdditiveSeparate(mut m) => {
                let (d, s) = additive_biases(m.head(), f0);
                m.diffuse = m.diffuse.with_output_bias(&d);
                m.specular = m.specular.with_output_bias(&s);
                BrdfModel::AdditiveSeparate(m)
            }
            BrdfModel::AdditiveShared(mut m) => {
                let (d, s) = additive_biases(m.head(), f0);
                m.diffuse = m.diffuse.with_output_bias(&d);
                m.specular = m.specular.with_output_bias(&s);
                BrdfModel::AdditiveShared(m)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ModelConfig, ModelKind, Samples};

    #[test]
    fn inverses_invert() {
        for y in [1e-4_f32, 0.01, 0.3, 1.0, 5.0, 30.0] {
            let x = softplus_inverse(y);
            let back = if x > 20.0 { x } else { x.exp().ln_1p() };
            assert!((back - y).abs() <= 1e-4 * y.max(1.0), "{y}: {x} -> {back}");
        }
        let p = 0.37_f32;
        assert!((1.0 / (1.0 + (-logit(p)).exp()) - p).abs() < 1e-6);
    }

    /// The untrained models with the initialisation predict about f0 on average over random
    /// inputs (exactly f0 where the last hidden activations vanish; the weights scatter the
    /// rest around it).
    #[test]
    fn untrained_models_start_near_the_initial_brdf() {
        let device = crate::device::cpu();
        let f0 = [0.2_f32, 0.1, 0.03];
        let n = 512;
        let spatial: Vec<f32> = (0..n * 8).map(|i| ((i * 37 % 101) as f32 / 101.0) - 0.5).collect();
        let dirs: Vec<[f32; 3]> = (0..n)
            .map(|i| {
                let t = i as f32 * 0.37;
                let (s, c) = (0.5 * t.sin(), 0.5 * t.cos());
                [s, c, (1.0 - s * s - c * c).sqrt()]
            })
            .collect();
        let samples = Samples { spatial: &spatial, l: &dirs, v: &dirs };
        for kind in [
            ModelKind::SingleMlp,
            ModelKind::AdditiveSeparate,
            ModelKind::AdditiveShared,
            ModelKind::AdditiveSeparateEnhanced,
            ModelKind::AdditiveSharedEnhanced,
        ] {
            let mut config = ModelConfig::new(kind);
            config.spatial_dim = 8;
            let model = config.init(&device).unwrap().with_initial_brdf(f0);
            let batch = config.batch(&samples, None, &device).unwrap();
            let f: Vec<f32> = model.forward(&batch).f.into_data().try_to_vec::<f32>().unwrap();
            for (c, want) in f0.iter().enumerate() {
                let mean = f.iter().skip(c).step_by(3).sum::<f32>() / n as f32;
                let ratio = mean / want;
                assert!((0.5..2.0).contains(&ratio), "{kind:?} channel {c}: {mean} vs {want}");
            }
        }
    }
}
