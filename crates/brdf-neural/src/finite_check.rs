//! Where a model stops being finite: one forward and backward pass on a batch, reporting the
//! first output (f, diffuse, specular, xi) entry that is NaN, infinite or negative, or the first
//! parameter whose gradient holds a NaN or an infinity, with the row of the batch it came from.
//! The adversarial-numerics tests drive it with millions of extreme direction pairs; the
//! training loop uses [`first_bad_output`] to name the part and the input of a non-finite loss.
//!
//! The backward pass differentiates the mean of every output the model has (f, and the
//! additive models' parts and xi), so every parameter that reaches an output gets a gradient.

use crate::{BrdfBatch, BrdfModel, ModelConfig, Result, Samples};
use burn::module::{Module, ModuleVisitor, Param};
use burn::optim::GradientsParams;
use burn::tensor::{Device, Tensor};

/// The first non-finite value found.
#[derive(Clone, Debug, PartialEq)]
pub struct NonFinite {
    /// `output f`, `output diffuse`, ..., or `gradient of <parameter path>`.
    pub part: String,
    /// The batch row of an output entry (gradients have none).
    pub row: Option<usize>,
    /// The value.
    pub value: f32,
}

impl std::fmt::Display for NonFinite {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.row {
            Some(r) => write!(f, "{} = {} at batch row {r}", self.part, self.value),
            None => write!(f, "{} holds {}", self.part, self.value),
        }
    }
}

/// The values of a tensor.
fn values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().convert::<f32>().try_to_vec::<f32>().unwrap_or_default()
}

/// The first output entry of `out` that is not finite (or is negative, for f and the parts),
/// with the row it belongs to. `xi` is allowed any finite value in [0, 1].
pub fn first_bad_output(out: &crate::BrdfOutput) -> Option<NonFinite> {
    let parts = [
        ("f", Some(&out.f)),
        ("diffuse", out.diffuse.as_ref()),
        ("specular", out.specular.as_ref()),
        ("xi", out.xi.as_ref()),
    ];
    for (name, t) in parts {
        let Some(t) = t else { continue };
        let cols = t.dims()[1].max(1);
        let bad = |x: f32| !x.is_finite() || x < 0.0 || (name == "xi" && x > 1.0);
        if let Some((i, &x)) = values(t.clone()).iter().enumerate().find(|(_, x)| bad(**x)) {
            return Some(NonFinite {
                part: format!("output {name}"),
                row: Some(i / cols),
                value: x,
            });
        }
    }
    None
}

/// Collects the gradient of every float parameter, with its module path.
struct GradientVisitor<'a> {
    grads: &'a GradientsParams,
    stack: Vec<String>,
    found: Option<NonFinite>,
    checked: usize,
}

impl ModuleVisitor for GradientVisitor<'_> {
    fn enter_module(&mut self, name: &str, _container_type: &str) {
        self.stack.push(name.to_string());
    }

    fn exit_module(&mut self, _name: &str, _container_type: &str) {
        self.stack.pop();
    }

    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        if self.found.is_some() {
            return;
        }
        let Some(g) = self.grads.get::<D>(param.id) else { return };
        self.checked += 1;
        if let Some(&x) = values(g).iter().find(|x| !x.is_finite()) {
            let path = if self.stack.is_empty() { "<root>".into() } else { self.stack.join(".") };
            self.found =
                Some(NonFinite { part: format!("gradient of {path}"), row: None, value: x });
        }
    }
}

/// What one checked batch gave.
#[derive(Clone, Debug, PartialEq)]
pub struct Checked {
    /// The first non-finite output or gradient, if any.
    pub problem: Option<NonFinite>,
    /// Parameter tensors whose gradient was checked.
    pub gradients: usize,
}

/// Runs `model` (built on an autodiff device) forward on `samples` and backward from the mean
/// of its outputs; reports the first bad output, else the first non-finite gradient.
pub fn check_forward_backward(
    model: &BrdfModel,
    config: &ModelConfig,
    samples: &Samples,
    device: &Device,
) -> Result<Checked> {
    let batch = BrdfBatch::new(config, samples, None, device)?;
    let out = model.forward(&batch);
    if let Some(problem) = first_bad_output(&out) {
        return Ok(Checked { problem: Some(problem), gradients: 0 });
    }
    let mut loss = out.f.mean();
    for t in [out.diffuse, out.specular, out.xi].into_iter().flatten() {
        loss = loss + t.mean();
    }
    let grads = GradientsParams::from_grads(loss.backward(), model);
    let mut v = GradientVisitor { grads: &grads, stack: Vec::new(), found: None, checked: 0 };
    model.visit(&mut v);
    Ok(Checked { problem: v.found, gradients: v.checked })
}
