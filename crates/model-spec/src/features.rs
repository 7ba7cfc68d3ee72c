//! Direction features of the purely neural models: the angle parametrization, the reciprocity
//! option and the positional encoding (spec sections 2, 4.6 and 5.1).
//!
//! Features are computed on the CPU with the `angles` crate, in f32 (brdf-neural uploads them as
//! a tensor). `angles` computes every quantity symmetrically in l and v, so with
//! [`Reciprocity::Mapping`] the feature row of (l, v) is bit-identical to that of (v, l); any
//! network fed it is then exactly reciprocal. [`Reciprocity::RandomSwap`] swaps l and v in the
//! network input of a training sample with probability `swap_probability` (LitNeRF); rendering
//! keeps the true directions.

use angles::{PositionalEncoding, Rusinkiewicz, ViewLight, reciprocal_theta};
use serde::{Deserialize, Serialize};

/// Which angles describe the direction pair.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AngleParametrization {
    /// Rusinkiewicz (theta_h, theta_d, phi_d), phi_d in [0, 2 pi) (default).
    #[default]
    Rusinkiewicz,
    /// The view-light triplet (theta_v, theta_l, phi_v - phi_l) of the ablation.
    ViewLight,
}

/// How reciprocity f(l, v) = f(v, l) is encouraged or enforced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reciprocity {
    /// Nothing (default).
    #[default]
    None,
    /// Training-time random swap of l and v in the network input (LitNeRF).
    RandomSwap,
    /// The paper's mapping Theta = [theta_h, theta_d, phi_d mod pi, (phi_d mod pi) + pi]:
    /// exact reciprocity. Rusinkiewicz angles only.
    Mapping,
}

/// Configuration of the direction features.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AngleConfig {
    /// Angle parametrization (default `rusinkiewicz`).
    pub parametrization: AngleParametrization,
    /// Reciprocity option (default `none`).
    pub reciprocity: Reciprocity,
    /// Swap probability of [`Reciprocity::RandomSwap`] (default 0.5).
    pub swap_probability: f64,
    /// Positional encoding of the angles (default: 3 frequencies, input included, no pi).
    pub encoding: PositionalEncoding,
}

impl Default for AngleConfig {
    fn default() -> Self {
        Self {
            parametrization: AngleParametrization::Rusinkiewicz,
            reciprocity: Reciprocity::None,
            swap_probability: 0.5,
            encoding: PositionalEncoding::default(),
        }
    }
}

impl AngleConfig {
    /// Number of raw angles before the encoding (3, or 4 with the mapping).
    pub fn raw_dim(&self) -> usize {
        if self.reciprocity == Reciprocity::Mapping { 4 } else { 3 }
    }

    /// Number of feature values per sample after the encoding (21 or 28 by default).
    pub fn dim(&self) -> usize {
        self.encoding.output_len(self.raw_dim())
    }

    /// Checks the combination: the mapping needs Rusinkiewicz angles; the swap probability is
    /// in [0, 1].
    pub fn validate(&self) -> crate::Result<()> {
        if self.reciprocity == Reciprocity::Mapping
            && self.parametrization != AngleParametrization::Rusinkiewicz
        {
            return Err(crate::Error::InvalidConfig(
                "the reciprocity mapping is defined on Rusinkiewicz angles only".into(),
            ));
        }
        if !(0.0..=1.0).contains(&self.swap_probability) {
            return Err(crate::Error::InvalidConfig(format!(
                "swap_probability {} is outside [0, 1]",
                self.swap_probability
            )));
        }
        Ok(())
    }

    /// The raw angles of one local-frame pair (first `raw_dim()` entries are used).
    pub fn raw_angles(&self, l: [f32; 3], v: [f32; 3]) -> [f32; 4] {
        match (self.parametrization, self.reciprocity) {
            (_, Reciprocity::Mapping) => reciprocal_theta(l, v),
            (AngleParametrization::Rusinkiewicz, _) => {
                let [a, b, c] = Rusinkiewicz::from_local(l, v).to_array();
                [a, b, c, 0.0]
            }
            (AngleParametrization::ViewLight, _) => {
                let [a, b, c] = ViewLight::from_local(l, v).to_array();
                [a, b, c, 0.0]
            }
        }
    }

    /// Encodes one pair into `out` (`dim()` values).
    ///
    /// # Panics
    /// If `out.len() != self.dim()`.
    pub fn encode_into(&self, l: [f32; 3], v: [f32; 3], out: &mut [f32]) {
        let raw = self.raw_angles(l, v);
        self.encoding.encode_into(&raw[..self.raw_dim()], out);
    }

    /// Encodes a batch of pairs, row-major `[n, dim()]`; row i uses (v_i, l_i) instead of
    /// (l_i, v_i) where `swap[i]` is true.
    ///
    /// # Panics
    /// If `l`, `v` (and `swap`, when given) differ in length.
    pub fn encode_batch(&self, l: &[[f32; 3]], v: &[[f32; 3]], swap: Option<&[bool]>) -> Vec<f32> {
        assert_eq!(l.len(), v.len(), "encode_batch: l and v lengths");
        if let Some(s) = swap {
            assert_eq!(s.len(), l.len(), "encode_batch: swap mask length");
        }
        use rayon::prelude::*;
        let d = self.dim();
        let mut out = vec![0.0; l.len() * d];
        // Rows are independent: chunks of rows in parallel (the same values on any thread count).
        const ROWS: usize = 1024;
        out.par_chunks_mut(ROWS * d).enumerate().for_each(|(c, chunk)| {
            for (j, row) in chunk.chunks_exact_mut(d).enumerate() {
                let i = c * ROWS + j;
                let (a, b) = if swap.is_some_and(|s| s[i]) { (v[i], l[i]) } else { (l[i], v[i]) };
                self.encode_into(a, b, row);
            }
        });
        out
    }

    /// A random swap mask for a training batch of `n` samples: all false unless the option
    /// is [`Reciprocity::RandomSwap`], then each entry true with `swap_probability`.
    pub fn swap_mask<R: rand::Rng>(&self, n: usize, rng: &mut R) -> Vec<bool> {
        if self.reciprocity != Reciprocity::RandomSwap {
            return vec![false; n];
        }
        (0..n).map(|_| rng.random_bool(self.swap_probability)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dimensions_follow_the_spec() {
        let mut c = AngleConfig::default();
        assert_eq!(c.dim(), 21);
        c.reciprocity = Reciprocity::Mapping;
        assert_eq!(c.dim(), 28);
        c.parametrization = AngleParametrization::ViewLight;
        assert!(c.validate().is_err());
        c.reciprocity = Reciprocity::RandomSwap;
        assert!(c.validate().is_ok());
        assert_eq!(c.dim(), 21);
    }

    #[test]
    fn swap_is_a_feature_swap_and_mapping_is_symmetric() {
        let l = [0.3_f32, 0.1, 0.948_683_3];
        let v = [-0.2_f32, 0.4, 0.894_427_2];
        let c = AngleConfig::default();
        let swapped = c.encode_batch(&[l], &[v], Some(&[true]));
        assert_eq!(swapped, c.encode_batch(&[v], &[l], None));
        assert_ne!(swapped, c.encode_batch(&[l], &[v], None));
        let m = AngleConfig { reciprocity: Reciprocity::Mapping, ..Default::default() };
        assert_eq!(m.encode_batch(&[l], &[v], None), m.encode_batch(&[v], &[l], None));
    }
}
