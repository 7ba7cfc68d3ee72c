//! The layer layout of the multilayer perceptron every model is built from, [`MlpConfig`]:
//! ReLU hidden layers of one width, an optional linear output layer, an input skip connection
//! and an optional late input (brdf-neural's `Mlp` is the network it describes).
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
//! A concatenation [h, x] followed by a linear layer equals W_h h + W_x x + b: the skip is a
//! projection of its own (no bias) added to the layer's output, with the same parameter count
//! as the concatenation ([`MlpConfig::param_count`] counts it that way).
//!
//! The late input (`d_late > 0`) enters at layer `late_into`: with `late_into = 0` it is simply
//! part of the raw input (and so of the skip), otherwise it is added to layer `late_into` only
//! (the NOL ablation of the Single MLP feeds the directions in there).

use serde::{Deserialize, Serialize};

/// Configuration of an MLP (see the module docs for the layer layout).
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
    pub fn d_raw(&self) -> usize {
        self.d_input + if self.late_into == 0 { self.d_late } else { 0 }
    }

    /// Number of linear layers (hidden plus output).
    pub fn n_linear(&self) -> usize {
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn param_count_is_the_concatenation_form() {
        let mut c = MlpConfig::new(10);
        c.width = 8;
        c.d_output = Some(3);
        c.skip_into = Some(3);
        c.d_late = 4;
        // Concatenation form: layer 0 (14 -> 8), 1, 2 (8 -> 8), 3 ([8, 14] -> 8), 4 (8 -> 8),
        // 5 (8 -> 3).
        let expect = (14 * 8 + 8) + 2 * (8 * 8 + 8) + (22 * 8 + 8) + (8 * 8 + 8) + (8 * 3 + 3);
        assert_eq!(c.param_count(), expect);
        // Late input at layer 3: it leaves layer 0 and the skip (both lose 4 x 8 weights) and
        // gets its own 4 x 8 projection.
        c.late_into = 3;
        assert_eq!(c.param_count(), expect - 4 * 8);
        assert_eq!((c.d_raw(), c.n_linear(), c.d_out()), (10, 6, 3));
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
