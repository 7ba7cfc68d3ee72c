//! The multilayer perceptron every model is built from: ReLU hidden layers of one width, an
//! optional linear output layer, an input skip connection and an optional late input.
//!
//! Layer `k` (0-based) is the k-th linear layer; layers `0..hidden_layers` are hidden
//! (Linear + ReLU), layer `hidden_layers` is the output layer (Linear, no activation) when
//! `d_output` is set. The spec's conventions (decisions table) map onto it as follows:
//!
//! * "6 layers of width 128, skip to layer 3" (intrinsic-neural-fields `TextureField`):
//!   `hidden_layers = 5`, `d_output = Some(n)`, `skip_into = Some(3)`: the raw input is
//!   concatenated to the input of linear layer 3.
//! * "4 layers of width 128, skip at 2" (NeRFactor): `hidden_layers = 4`, `skip_into = Some(3)`
//!   (the raw input is concatenated to the output of hidden layer 2, i.e. the input of layer 3),
//!   then the output layer.
//!
//! A concatenation [h, x] followed by a linear layer equals W_h h + W_x x + b; that is how it
//! is computed here (two matrix products, no copy), with the same parameter count.
//!
//! The late input (`d_late > 0`) enters at layer `late_into`: with `late_into = 0` it is simply
//! part of the raw input (and so of the skip), otherwise it is added to layer `late_into` only
//! (the NOL ablation of the Single MLP feeds the directions in there).
//!
//! Every linear layer runs through [`crate::split_k`], which splits the batch sum of the
//! weight gradients into parts on GPU backends.

use crate::linear_op::relu;
use crate::split_k::linear;
use burn::module::Module;
use burn::nn::{Linear, LinearConfig};
use burn::tensor::{Device, Tensor};
use serde::{Deserialize, Serialize};

/// Configuration of an [`Mlp`].
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MlpConfig {
    /// Width of the main input x (no default; set by the model).
    pub d_input: usize,
    /// Width of every hidden layer (default 128).
    pub width: usize,
    /// Number of hidden Linear + ReLU layers (default 5).
    pub hidden_layers: usize,
    /// Width of the linear output layer; `None` returns the last hidden activations
    /// (default `None`).
    pub d_output: Option<usize>,
    /// Index of the linear layer whose input also receives the raw input; `None` for no skip
    /// (default `None`). Must be in `1..=hidden_layers` (`hidden_layers` only with an output).
    pub skip_into: Option<usize>,
    /// Width of the late input, 0 for none (default 0).
    pub d_late: usize,
    /// Index of the linear layer the late input enters (default 0: part of the raw input).
    pub late_into: usize,
}

impl MlpConfig {
    /// A configuration with the defaults above and input width `d_input`.
    pub fn new(d_input: usize) -> Self {
        Self {
            d_input,
            width: 128,
            hidden_layers: 5,
            d_output: None,
            skip_into: None,
            d_late: 0,
            late_into: 0,
        }
    }

    /// Width of the raw input (x, plus the late input when it enters at layer 0).
    fn d_raw(&self) -> usize {
        self.d_input + if self.late_into == 0 { self.d_late } else { 0 }
    }

    /// Number of linear layers (hidden plus output).
    fn n_linear(&self) -> usize {
        self.hidden_layers + usize::from(self.d_output.is_some())
    }

    /// Width of the value this MLP returns.
    pub fn d_out(&self) -> usize {
        self.d_output.unwrap_or(self.width)
    }

    /// Whether the layer indices are consistent (skip and late input hit an existing layer > 0,
    /// at least one layer).
    pub fn is_valid(&self) -> bool {
        let n = self.n_linear();
        n > 0
            && self.d_input > 0
            && self.width > 0
            && self.skip_into.is_none_or(|k| k >= 1 && k < n)
            && (self.d_late == 0 || self.late_into < n)
    }

    /// Number of trainable scalars.
    pub fn param_count(&self) -> usize {
        let mut count = 0;
        for k in 0..self.n_linear() {
            let d_in = if k == 0 { self.d_raw() } else { self.width };
            let d_out = if k < self.hidden_layers { self.width } else { self.d_out() };
            count += d_in * d_out + d_out;
            if self.skip_into == Some(k) {
                count += self.d_raw() * d_out;
            }
            if self.d_late > 0 && self.late_into == k && k > 0 {
                count += self.d_late * d_out;
            }
        }
        count
    }

    /// Builds the MLP (PyTorch-style uniform initialisation of every linear layer).
    ///
    /// # Panics
    /// If [`MlpConfig::is_valid`] is false (model configurations validate first).
    pub fn init(&self, device: &Device) -> Mlp {
        assert!(self.is_valid(), "invalid MLP configuration {self:?}");
        let n = self.n_linear();
        let out_of = |k: usize| if k < self.hidden_layers { self.width } else { self.d_out() };
        let layers = (0..n)
            .map(|k| {
                let d_in = if k == 0 { self.d_raw() } else { self.width };
                LinearConfig::new(d_in, out_of(k)).init(device)
            })
            .collect();
        let skip = self
            .skip_into
            .map(|k| LinearConfig::new(self.d_raw(), out_of(k)).with_bias(false).init(device));
        let late = (self.d_late > 0 && self.late_into > 0).then(|| {
            LinearConfig::new(self.d_late, out_of(self.late_into)).with_bias(false).init(device)
        });
        Mlp {
            layers,
            skip,
            late,
            hidden_layers: self.hidden_layers,
            skip_into: self.skip_into.unwrap_or(usize::MAX),
            late_into: if self.d_late > 0 { self.late_into } else { usize::MAX },
        }
    }
}

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
    pub fn forward(&self, x: Tensor<2>, late: Option<Tensor<2>>) -> Tensor<2> {
        assert_eq!(late.is_some(), self.late_into != usize::MAX, "Mlp: late input mismatch");
        let (raw, mut late) = match late {
            Some(l) if self.late_into == 0 => (Tensor::cat(vec![x, l], 1), None),
            other => (x, other),
        };
        let mut h = raw.clone();
        for (k, layer) in self.layers.iter().enumerate() {
            let mut z = linear(layer, h);
            if k == self.skip_into
                && let Some(skip) = &self.skip
            {
                z = z + linear(skip, raw.clone());
            }
            if k == self.late_into
                && let (Some(proj), Some(l)) = (&self.late, late.take())
            {
                z = z + linear(proj, l);
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
    fn param_count_matches_module_and_concatenation_form() {
        // Its forward pass below draws the initial weights: under the lock the model tests of
        // this binary compare their draws under.
        let _draws = crate::model::initial_draws();
        let device = crate::device::cpu();
        let mut c = MlpConfig::new(10);
        c.width = 8;
        c.d_output = Some(3);
        c.skip_into = Some(3);
        c.d_late = 4;
        // Concatenation form: layer 0 (14 -> 8), 1, 2 (8 -> 8), 3 ([8, 14] -> 8), 4 (8 -> 8),
        // 5 (8 -> 3).
        let expect = (14 * 8 + 8) + 2 * (8 * 8 + 8) + (22 * 8 + 8) + (8 * 8 + 8) + (8 * 3 + 3);
        assert_eq!(c.param_count(), expect);
        assert_eq!(c.init(&device).num_params(), expect);
        // Late input at layer 3: it leaves layer 0 and the skip (both lose 4 x 8 weights) and
        // gets its own 4 x 8 projection.
        c.late_into = 3;
        assert_eq!(c.init(&device).num_params(), c.param_count());
        assert_eq!(c.param_count(), expect - 4 * 8);
        let y = c
            .init(&device)
            .forward(Tensor::<2>::ones([2, 10], &device), Some(Tensor::<2>::ones([2, 4], &device)));
        assert_eq!(y.dims(), [2, 3]);
    }

    #[test]
    fn invalid_layer_indices_are_rejected() {
        let mut c = MlpConfig::new(4);
        c.skip_into = Some(5); // no output layer: layers 0..5
        assert!(!c.is_valid());
        c.skip_into = Some(0);
        assert!(!c.is_valid());
        c.skip_into = Some(4);
        assert!(c.is_valid());
    }
}
