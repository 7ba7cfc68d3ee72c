//! NBRDF networks (Sztrajman et al. 2021): the published fits of the MERL materials, evaluated in
//! plain Rust and tabulated into MERL tables.
//!
//! A network maps (h, d) of the Rusinkiewicz angles (phi_h = 0) through two ReLU layers to y,
//! and the BRDF (1/sr, channel scales included) is exp(y) - 1. The arithmetic is f32, as the
//! networks were trained; the output transform is f64.

use crate::error::{Error, Result};
use crate::merl::MerlBrdf;
use serde::Deserialize;

#[derive(Deserialize)]
struct FileJson {
    format: String,
    material: String,
    input: Vec<String>,
    hidden_activation: String,
    output_transform: String,
    layers: Vec<LayerJson>,
}

#[derive(Deserialize)]
struct LayerJson {
    #[serde(rename = "in")]
    n_in: usize,
    out: usize,
    weight: Vec<Vec<f32>>,
    bias: Vec<f32>,
}

/// One dense layer, weights row-major [out][in] (transposed from Keras' [in][out]).
#[derive(Clone, Debug)]
struct Dense {
    n_in: usize,
    w: Vec<f32>,
    b: Vec<f32>,
}

/// Widest layer supported (the published networks are 21 wide).
const MAX_WIDTH: usize = 64;

/// An NBRDF network of one material.
#[derive(Clone, Debug)]
pub struct Nbrdf {
    material: String,
    layers: Vec<Dense>,
}

/// What tabulating a network found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TabulationReport {
    /// Channel values below 0 that were clamped to 0 (the README says these should not occur).
    pub negatives_clamped: usize,
}

impl Nbrdf {
    /// Parses a network file's JSON text; `origin` names it in errors.
    pub fn from_json(text: &str, origin: &str) -> Result<Self> {
        let fault = |fault: String| Error::Nbrdf { origin: origin.into(), fault };
        let f: FileJson = serde_json::from_str(text).map_err(|e| fault(e.to_string()))?;
        if f.format != "nbrdf-mlp-v1" {
            return Err(fault(format!("format `{}`, expected `nbrdf-mlp-v1`", f.format)));
        }
        if f.input != ["hx", "hy", "hz", "dx", "dy", "dz"] {
            return Err(fault(format!("inputs {:?}, expected hx..dz", f.input)));
        }
        if f.hidden_activation != "relu" || f.output_transform != "exp(y)-1" {
            return Err(fault(format!(
                "activation `{}` / transform `{}`, expected relu / exp(y)-1",
                f.hidden_activation, f.output_transform
            )));
        }
        if f.layers.is_empty() {
            return Err(fault("no layers".into()));
        }
        let mut layers = Vec::with_capacity(f.layers.len());
        let mut width = 6;
        for (k, l) in f.layers.iter().enumerate() {
            if l.n_in != width || l.n_out_ok() || l.weight.len() != l.n_in || l.bias.len() != l.out
            {
                return Err(fault(format!(
                    "layer {k}: declared {} -> {}, weight {} rows, bias {}, previous width {width}",
                    l.n_in,
                    l.out,
                    l.weight.len(),
                    l.bias.len()
                )));
            }
            let mut w = vec![0.0; l.out * l.n_in];
            for (i, row) in l.weight.iter().enumerate() {
                if row.len() != l.out {
                    return Err(fault(format!(
                        "layer {k}: weight row {i} has {} values",
                        row.len()
                    )));
                }
                for (o, &x) in row.iter().enumerate() {
                    w[o * l.n_in + i] = x;
                }
            }
            if w.iter().chain(&l.bias).any(|x| !x.is_finite()) {
                return Err(fault(format!("layer {k}: non-finite weight")));
            }
            layers.push(Dense { n_in: l.n_in, w, b: l.bias.clone() });
            width = l.out;
        }
        if width != 3 {
            return Err(fault(format!("output width {width}, expected 3 (RGB)")));
        }
        Ok(Self { material: f.material, layers })
    }

    /// Reads a network file.
    pub fn read(path: &std::path::Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Self::from_json(&text, &path.display().to_string())
    }

    /// The material name stored in the file.
    pub fn material(&self) -> &str {
        &self.material
    }

    /// Number of weights and biases.
    pub fn parameter_count(&self) -> usize {
        self.layers.iter().map(|l| l.w.len() + l.b.len()).sum()
    }

    /// The network's raw output exp(y) - 1 (1/sr, may be slightly negative) at Rusinkiewicz
    /// angles with phi_h = 0.
    pub fn eval_raw(&self, theta_h: f64, theta_d: f64, phi_d: f64) -> [f64; 3] {
        let (sh, ch) = theta_h.sin_cos();
        let (sd, cd) = theta_d.sin_cos();
        let (sp, cp) = phi_d.sin_cos();
        let mut a = [0.0_f32; MAX_WIDTH];
        let mut b = [0.0_f32; MAX_WIDTH];
        let x = [sh, 0.0, ch, sd * cp, sd * sp, cd];
        for (ai, xi) in a.iter_mut().zip(x) {
            *ai = xi as f32;
        }
        let last = self.layers.len() - 1;
        for (k, layer) in self.layers.iter().enumerate() {
            let rows = layer.w.chunks_exact(layer.n_in);
            for ((out, row), bias) in b.iter_mut().zip(rows).zip(&layer.b) {
                let s = row.iter().zip(&a[..layer.n_in]).fold(*bias, |s, (w, x)| s + w * x);
                *out = if k < last { s.max(0.0) } else { s };
            }
            std::mem::swap(&mut a, &mut b);
        }
        [0, 1, 2].map(|c| f64::from(a[c]).exp() - 1.0)
    }

    /// The BRDF (1/sr) at Rusinkiewicz angles: [`Nbrdf::eval_raw`] clamped at 0.
    pub fn eval(&self, theta_h: f64, theta_d: f64, phi_d: f64) -> [f64; 3] {
        self.eval_raw(theta_h, theta_d, phi_d).map(|x| x.max(0.0))
    }

    /// Tabulates the network into a MERL table at the bins' lower edges; negative outputs are
    /// clamped to 0 and counted.
    pub fn tabulate(&self) -> Result<(MerlBrdf, TabulationReport)> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let negatives = AtomicUsize::new(0);
        let table = MerlBrdf::tabulate(&format!("NBRDF {}", self.material), |th, td, pd| {
            let raw = self.eval_raw(th, td, pd);
            let n = raw.iter().filter(|x| **x < 0.0).count();
            if n > 0 {
                negatives.fetch_add(n, Ordering::Relaxed);
            }
            raw.map(|x| x.max(0.0))
        })?;
        Ok((table, TabulationReport { negatives_clamped: negatives.into_inner() }))
    }
}

impl LayerJson {
    fn n_out_ok(&self) -> bool {
        self.out == 0 || self.out > MAX_WIDTH
    }
}
