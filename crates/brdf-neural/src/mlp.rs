//! The multilayer perceptron every model is built from, [`Mlp`]: ReLU hidden layers of one
//! width, an optional linear output layer, an input skip connection and an optional late input,
//! laid out as its [`MlpConfig`] says (defined in `model-spec`, whose `mlp` module documents the
//! layer indices and the spec's conventions; re-exported here).
//!
//! A concatenation [h, x] followed by a linear layer equals W_h h + W_x x + b; that is how it
//! is computed here (two matrix products, no copy), with the same parameter count.
//!
//! Every linear layer runs through [`crate::batch_split`], which splits the batch sum of the
//! weight gradients into parts on GPU backends. A hidden layer with nothing added before its
//! ReLU (no skip, no late input) is one fused operation, `relu(x W + b)`
//! ([`crate::linear_op::linear_relu`]).

use crate::batch_split::{linear, linear_relu};
use crate::linear_op::relu;
use crate::products::Products;
use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::{Device, Tensor};
pub use model_spec::mlp::MlpConfig;

/// A ReLU MLP with an input skip connection and an optional late input (see the module docs).
#[derive(Module, Debug)]
pub struct Mlp {
    /// The linear layers, hidden then output.
    pub layers: Vec<Linear>,
    /// The skip projection of the raw input (no bias), added to layer `skip_into`.
    pub skip: Option<Linear>,
    /// The projection of the late input (no bias), added to layer `late_into` (> 0).
    pub late: Option<Linear>,
    #[module(skip)]
    hidden_layers: usize,
    #[module(skip)]
    skip_into: usize,
    #[module(skip)]
    late_into: usize,
}

impl Mlp {
    /// Builds the MLP (PyTorch-style uniform initialisation of every linear layer).
    ///
    /// # Panics
    /// If [`MlpConfig::is_valid`] is false for `config` (model configurations validate first).
    pub fn new(config: &MlpConfig, device: &Device) -> Mlp {
        assert!(config.is_valid(), "invalid MLP configuration {config:?}");
        let n = config.n_linear();
        let out_of =
            |k: usize| if k < config.hidden_layers { config.width } else { config.d_out() };
        let layers = (0..n)
            .map(|k| {
                let d_in = if k == 0 { config.d_raw() } else { config.width };
                LinearConfig::new(d_in, out_of(k)).init(device)
            })
            .collect();
        let skip = config
            .skip_into
            .map(|k| LinearConfig::new(config.d_raw(), out_of(k)).with_bias(false).init(device));
        let late = (config.d_late > 0 && config.late_into > 0).then(|| {
            LinearConfig::new(config.d_late, out_of(config.late_into)).with_bias(false).init(device)
        });
        Mlp {
            layers,
            skip,
            late,
            hidden_layers: config.hidden_layers,
            skip_into: config.skip_into.unwrap_or(usize::MAX),
            late_into: if config.d_late > 0 { config.late_into } else { usize::MAX },
        }
    }

    /// The same MLP with the bias of its last linear layer set to `bias` (one value per
    /// output), the parameter keeping its id and gradient setting.
    ///
    /// # Panics
    /// If `bias.len()` is not the last layer's output width, or the layer has no bias.
    pub fn with_output_bias(mut self, bias: &[f32]) -> Self {
        let last = self.layers.pop().expect("an MLP has a layer");
        let param = last.bias.clone().expect("output layer with a bias");
        assert_eq!(param.val().dims(), [bias.len()], "output bias width");
        let data = burn::tensor::TensorData::new(bias.to_vec(), [bias.len()]);
        let param = param.map(|t| {
            let fresh = Tensor::<1>::from_data(data, &t.device());
            if t.is_require_grad() { fresh.require_grad() } else { fresh }
        });
        self.layers.push(Linear { bias: Some(param), ..last });
        self
    }

    /// Applies the MLP.
    ///
    /// # Arguments
    /// - `x`: the main input.
    /// - `late`: the late input; required exactly when the configuration has `d_late > 0`.
    ///
    /// # Shapes
    /// - x: `[batch, d_input]`
    /// - late: `[batch, d_late]`
    /// - output: `[batch, d_output]` (or `[batch, width]` without an output layer)
    ///
    /// # Returns
    /// The output layer's pre-activation, or the last hidden ReLU activations.
    ///
    /// # Panics
    /// If `late` is given or missing against the configuration, or widths mismatch.
    pub fn forward(&self, x: Tensor<2>, late: Option<Tensor<2>>, products: Products) -> Tensor<2> {
        assert_eq!(late.is_some(), self.late_into != usize::MAX, "Mlp: late input mismatch");
        let (raw, mut late) = match late {
            Some(l) if self.late_into == 0 => (Tensor::cat(vec![x, l], 1), None),
            other => (x, other),
        };
        let mut h = raw.clone();
        for (k, layer) in self.layers.iter().enumerate() {
            if k < self.hidden_layers && k != self.skip_into && k != self.late_into {
                // A hidden layer with nothing added before its ReLU: one fused product.
                h = linear_relu(layer, h, products);
                continue;
            }
            let mut z = linear(layer, h, products);
            if k == self.skip_into
                && let Some(skip) = &self.skip
            {
                z = z + linear(skip, raw.clone(), products);
            }
            if k == self.late_into
                && let (Some(proj), Some(l)) = (&self.late, late.take())
            {
                z = z + linear(proj, l, products);
            }
            h = if k < self.hidden_layers { relu(z) } else { z };
        }
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::module::Module;

    #[test]
    fn param_count_matches_module() {
        // Its forward pass below draws the initial weights: under the lock the model tests of
        // this binary compare their draws under.
        let _draws = crate::model::initial_draws();
        let device = crate::device::cpu();
        // model-spec's tests hold `param_count` to the concatenation form; here the built
        // module has exactly that many scalars, with the late input at layer 0 and at layer 3.
        let mut c = MlpConfig::new(10);
        c.width = 8;
        c.d_output = Some(3);
        c.skip_into = Some(3);
        c.d_late = 4;
        assert_eq!(Mlp::new(&c, &device).num_params(), c.param_count());
        c.late_into = 3;
        assert_eq!(Mlp::new(&c, &device).num_params(), c.param_count());
        let y = Mlp::new(&c, &device).forward(
            Tensor::<2>::ones([2, 10], &device),
            Some(Tensor::<2>::ones([2, 4], &device)),
            Products::F32,
        );
        assert_eq!(y.dims(), [2, 3]);
    }
}
