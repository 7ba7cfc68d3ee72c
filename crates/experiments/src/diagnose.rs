//! Which parameter group of a model holds non-finite (or the largest) values, and which input of
//! the batch made the outputs go bad: the message a non-finite loss stops the run with.

use brdf_neural::BrdfModel;
use burn::module::{Module, ModuleVisitor, Param};
use burn::tensor::Tensor;

/// Summary of one parameter tensor.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamHealth {
    /// Module path, e.g. `SingleMlp.mlp.layers.0.weight`.
    pub path: String,
    /// Number of NaN or infinite entries.
    pub non_finite: usize,
    /// Largest finite magnitude.
    pub max_abs: f32,
}

#[derive(Default)]
struct Visitor {
    stack: Vec<String>,
    out: Vec<ParamHealth>,
}

impl ModuleVisitor for Visitor {
    fn enter_module(&mut self, name: &str, _container_type: &str) {
        self.stack.push(name.to_string());
    }

    fn exit_module(&mut self, _name: &str, _container_type: &str) {
        self.stack.pop();
    }

    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        let values: Vec<f32> =
            param.val().into_data().convert::<f32>().try_to_vec::<f32>().unwrap_or_default();
        let non_finite = values.iter().filter(|v| !v.is_finite()).count();
        let max_abs = values.iter().filter(|v| v.is_finite()).fold(0.0_f32, |m, v| m.max(v.abs()));
        let path = if self.stack.is_empty() { "<root>".into() } else { self.stack.join(".") };
        self.out.push(ParamHealth { path, non_finite, max_abs });
    }
}

/// Health of every float parameter of `model`, in visiting order.
pub fn param_health(model: &BrdfModel) -> Vec<ParamHealth> {
    let mut v = Visitor::default();
    model.visit(&mut v);
    v.out
}

/// A sentence naming the parameter groups with non-finite values, or, when all are finite,
/// the group with the largest magnitude (the forward pass overflowed or the inputs were bad).
pub fn diagnose(model: &BrdfModel) -> String {
    let health = param_health(model);
    let bad: Vec<String> = health
        .iter()
        .filter(|h| h.non_finite > 0)
        .map(|h| format!("{} ({} non-finite)", h.path, h.non_finite))
        .collect();
    if !bad.is_empty() {
        const SHOWN: usize = 4;
        let more = bad.len().saturating_sub(SHOWN);
        let mut list = bad[..bad.len().min(SHOWN)].join(", ");
        if more > 0 {
            list.push_str(&format!(" and {more} more of {} groups", health.len()));
        }
        return format!("non-finite parameters in {list}");
    }
    match health.iter().max_by(|a, b| a.max_abs.total_cmp(&b.max_abs)) {
        Some(h) => format!(
            "all parameters finite; largest magnitude {:e} in {} (the forward pass overflowed: \
             lower train.learning_rate)",
            h.max_abs, h.path
        ),
        None => "the model has no parameter".into(),
    }
}

/// Whether every parameter of `model` is finite.
pub fn all_finite(model: &BrdfModel) -> bool {
    param_health(model).iter().all(|h| h.non_finite == 0)
}

/// The batch's worst input: the first row whose output (f, or an additive model's part) is not
/// finite, else the row with the largest f, with its directions and the size of its features.
pub fn worst_input(out: &brdf_neural::BrdfOutput, inputs: &brdf_neural::Samples) -> String {
    let (what, row) = match brdf_neural::finite_check::first_bad_output(out) {
        Some(p) => (p.to_string(), p.row.unwrap_or(0)),
        None => {
            let f: Vec<f32> =
                out.f.clone().into_data().convert::<f32>().try_to_vec::<f32>().unwrap_or_default();
            let (i, max) = f
                .iter()
                .copied()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap_or((0, 0.0));
            let row = i / 3;
            (format!("outputs finite, largest f = {max:e} at batch row {row}"), row)
        }
    };
    let (Some(l), Some(v)) = (inputs.l.get(row), inputs.v.get(row)) else {
        return format!("the batch's worst input: {what}");
    };
    let dim = inputs.spatial.len() / inputs.l.len().max(1);
    let features = inputs.spatial.get(row * dim..(row + 1) * dim).unwrap_or(&[]);
    let max_abs =
        features.iter().fold(0.0_f32, |m, x| if x.is_nan() { f32::NAN } else { m.max(x.abs()) });
    format!(
        "the batch's worst input: {what}: l = {l:?}, v = {v:?} (n.l = {:.3e}, n.v = {:.3e}), \
         largest feature magnitude {max_abs:e}",
        l[2], v[2]
    )
}
