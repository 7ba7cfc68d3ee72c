//! The training loss (spec 6, 4.5; decisions table): the MSE between sRGB-gamma renderings,
//! plus the enhanced split's regularisers.
//!
//! gamma(c) = 12.92 c for c <= 0.0031308, else 1.055 c^(1/2.4) - 0.055, applied to
//! max(c, 0) and NOT clamped above 1 (the formula extends past 1, so highlights keep their
//! gradient). The rendering is clipped at the sensor's saturation level first (semi-synthetic
//! scenes clip their observations there; evaluation clips renders the same way).
//!
//! L = mean_{batch, RGB} (gamma(min(f E cos, clip)) - gamma(L_obs))^2
//!   + w_d mean |gamma(f_d E cos) - gamma(L_obs)| + w_s mean |f_s|   (enhanced models only)

use brdf_neural::BrdfOutput;
use burn::tensor::Tensor;

/// Below this the OETF is linear.
const LINEAR_LIMIT: f32 = 0.003_130_8;
/// Added under the power so its gradient stays finite at 0 (the branch is masked out there).
const POW_EPS: f32 = 1e-7;

/// The sRGB OETF on the CPU: negatives clamp to 0, no clamp above 1.
pub fn srgb_oetf(c: f32) -> f32 {
    let c = c.max(0.0);
    if c <= LINEAR_LIMIT { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// The sRGB OETF as a differentiable tensor expression (same definition as [`srgb_oetf`]).
///
/// # Shapes
/// any `[batch, 3]`, returned unchanged.
pub fn srgb_oetf_tensor(x: Tensor<2>) -> Tensor<2> {
    let c = x.clamp_min(0.0);
    let linear = c.clone().mul_scalar(12.92);
    let power =
        c.clone().add_scalar(POW_EPS).powf_scalar(1.0 / 2.4).mul_scalar(1.055).add_scalar(-0.055);
    let mask = c.lower_equal_elem(LINEAR_LIMIT);
    power.mask_where(mask, linear)
}

/// Weights of the loss terms, and the sensor's clip level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LossWeights {
    /// Enhanced split: weight of the diffuse regulariser.
    pub diffuse: f64,
    /// Enhanced split: weight of the specular regulariser.
    pub specular: f64,
    /// The rendering is clipped here before the comparison, like the sensor clipped the
    /// observation (semi-synthetic scenes; `None` for captures): a saturated observation is a
    /// lower bound, and a prediction above the clip is not penalised.
    pub clip: Option<f32>,
}

/// The loss of one batch.
///
/// # Arguments
/// - `out`: the model's output for the batch
/// - `weight`: E cos(theta_l), `[batch, 3]`
/// - `target_gamma`: gamma(L_obs), `[batch, 3]`
/// - `regularise`: whether to add the enhanced split's regularisers (enhanced models)
///
/// # Returns
/// The scalar loss, shape `[1]`.
pub fn loss(
    out: &BrdfOutput,
    weight: Tensor<2>,
    target_gamma: Tensor<2>,
    regularise: bool,
    w: LossWeights,
) -> Tensor<1> {
    let clipped = |x: Tensor<2>| match w.clip {
        Some(c) => x.clamp_max(c),
        None => x,
    };
    let pred = srgb_oetf_tensor(clipped(out.f.clone() * weight.clone()));
    let mut total = (pred - target_gamma.clone()).square().mean();
    if regularise {
        if let Some(fd) = &out.diffuse
            && w.diffuse > 0.0
        {
            let d = srgb_oetf_tensor(clipped(fd.clone() * weight)) - target_gamma;
            total = total + d.abs().mean().mul_scalar(w.diffuse);
        }
        if let Some(fs) = &out.specular
            && w.specular > 0.0
        {
            total = total + fs.clone().abs().mean().mul_scalar(w.specular);
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::TensorData;

    #[test]
    fn oetf_matches_the_formula_and_extends_past_one() {
        assert_eq!(srgb_oetf(-1.0), 0.0);
        assert!((srgb_oetf(0.001) - 0.01292).abs() < 1e-7);
        assert!((srgb_oetf(1.0) - 1.0).abs() < 1e-6);
        assert!(srgb_oetf(4.0) > 1.5);
        let xs = [-0.5_f32, 0.0, 0.002, 0.0031308, 0.01, 0.5, 1.0, 3.0];
        let device = brdf_neural::device::cpu();
        let t = Tensor::<2>::from_data(TensorData::new(xs.to_vec(), [xs.len(), 1]), &device);
        let got: Vec<f32> = srgb_oetf_tensor(t).into_data().try_to_vec::<f32>().unwrap();
        for (x, g) in xs.iter().zip(got) {
            assert!((srgb_oetf(*x) - g).abs() < 1e-5, "{x}: {g} vs {}", srgb_oetf(*x));
        }
    }

    #[test]
    fn gradient_is_finite_at_zero_and_below() {
        let device = brdf_neural::device::cpu_training();
        let xs = vec![-1.0_f32, 0.0, 1e-9, 0.5];
        let t = Tensor::<2>::from_data(TensorData::new(xs, [4, 1]), &device).require_grad();
        let y = srgb_oetf_tensor(t.clone()).sum();
        let grads = y.backward();
        let g: Vec<f32> = t.grad(&grads).unwrap().into_data().try_to_vec::<f32>().unwrap();
        assert!(g.iter().all(|v| v.is_finite()), "{g:?}");
        assert_eq!(g[0], 0.0);
        assert!((g[1] - 12.92).abs() < 1e-4 && (g[2] - 12.92).abs() < 1e-4, "{g:?}");
    }
}
