//! The one interface of a fitted BRDF over surface points, [`SurfaceBrdf`]: what validation,
//! evaluation, export, the BRDF-space metrics and the probes take, whatever the model.
//!
//! A spatially varying material answers f(x, l, v) for a surface point x; a batch asks for many
//! at once, which is what a tensor model needs to be fast. Every [`Brdf`] is one (spatially
//! uniform: the points are ignored) by the blanket impl below, so the analytic models, MERL
//! tables and the ground truths need no adapter; `brdf-neural` implements it for its models.
//! As in Mitsuba 3, where one `BSDF` interface serves every variant, nothing here names a
//! tensor.

use crate::brdf::{Brdf, BrdfSample, Rgb};
use angles::Vec3;

/// A BRDF over surface points, evaluated in batches.
///
/// Entry `i` asks for f(x_i, l_i, v_i): `points[i]` identifies the surface point (an index the
/// caller defines, e.g. into its test records, which a spatially varying model uses to look up
/// its spatial input), `l[i]` and `v[i]` are unit vectors in that point's local frame (normal on
/// +z; `l` to the light, `v` to the viewer). The implementation writes f_r in 1/sr, linear RGB,
/// without the cosine, into `out[i]`. All four slices have the same length.
///
/// A tensor model builds one batch per call (callers pass about [`SurfaceBrdf::preferred_batch`]
/// entries at a time); the trait asks for `Sync` because callers may call it from several
/// threads when [`SurfaceBrdf::parallel`] is true.
pub trait SurfaceBrdf: Sync {
    /// f(x_i, l_i, v_i) for every i.
    fn eval_points(&self, points: &[u32], l: &[Vec3<f32>], v: &[Vec3<f32>], out: &mut [Rgb<f32>]);

    /// Batch size callers aim for (default 4096).
    fn preferred_batch(&self) -> usize {
        4096
    }

    /// Whether callers may call [`SurfaceBrdf::eval_points`] from several threads at once
    /// (default true; a model that parallelises internally, e.g. on a GPU, returns false).
    fn parallel(&self) -> bool {
        true
    }

    /// Draws a light direction for `v` at `point` from two uniforms, where the model has a
    /// sampler ([`Brdf::sample`]); `None` where it has none or no direction results.
    fn sample_at(&self, point: u32, v: Vec3<f32>, u: [f32; 2]) -> Option<BrdfSample<f32>> {
        let _ = (point, v, u);
        None
    }

    /// The density of [`SurfaceBrdf::sample_at`] in 1/sr; `None` where the model has no sampler.
    fn pdf_at(&self, point: u32, v: Vec3<f32>, l: Vec3<f32>) -> Option<f32> {
        let _ = (point, v, l);
        None
    }
}

/// Every analytic BRDF is a spatially uniform surface BRDF.
impl<B: Brdf<f32>> SurfaceBrdf for B {
    fn eval_points(&self, _points: &[u32], l: &[Vec3<f32>], v: &[Vec3<f32>], out: &mut [Rgb<f32>]) {
        crate::batch::eval_batch(self, l, v, out);
    }

    fn sample_at(&self, _point: u32, v: Vec3<f32>, u: [f32; 2]) -> Option<BrdfSample<f32>> {
        self.sample(v, u)
    }

    fn pdf_at(&self, _point: u32, v: Vec3<f32>, l: Vec3<f32>) -> Option<f32> {
        Some(self.pdf(v, l))
    }
}

/// A closure `f(point, l, v) -> rgb` as a [`SurfaceBrdf`] (tests, figures, synthetic BRDFs).
#[derive(Clone, Debug)]
pub struct FnSurface<F>(pub F);

impl<F: Fn(u32, Vec3<f32>, Vec3<f32>) -> Rgb<f32> + Sync> SurfaceBrdf for FnSurface<F> {
    fn eval_points(&self, points: &[u32], l: &[Vec3<f32>], v: &[Vec3<f32>], out: &mut [Rgb<f32>]) {
        assert!(
            points.len() == l.len() && l.len() == v.len() && v.len() == out.len(),
            "eval_points: slice lengths differ"
        );
        for i in 0..out.len() {
            out[i] = (self.0)(points[i], l[i], v[i]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Lambert, LambertParams, TorranceSparrow, TorranceSparrowParams};

    #[test]
    fn an_analytic_brdf_is_a_uniform_surface_brdf_with_its_sampler() {
        let ts = TorranceSparrow::new(TorranceSparrowParams::<f32>::default());
        let (l, v) = ([0.6f32, 0.0, 0.8], [0.0f32, 0.6, 0.8]);
        let mut out = [[0.0; 3]; 2];
        ts.eval_points(&[0, 7], &[l, l], &[v, v], &mut out);
        assert_eq!(out[0], ts.eval(l, v));
        assert_eq!(out[0], out[1], "points are ignored");
        let s = ts.sample_at(3, v, [0.3, 0.7]).expect("a sample");
        assert_eq!(Some(s.pdf), ts.pdf_at(3, v, s.l));
        // Through a reference and a box too.
        let boxed: Box<dyn Brdf<f32>> = Box::new(Lambert::new(LambertParams::<f32>::default()));
        boxed.eval_points(&[0], &[l], &[v], &mut out[..1]);
        assert_eq!(out[0], boxed.eval(l, v));
    }

    #[test]
    fn a_closure_sees_its_points_and_has_no_sampler() {
        let f = FnSurface(|p: u32, l: Vec3<f32>, _v: Vec3<f32>| [p as f32, l[2], 0.0]);
        let mut out = [[0.0; 3]; 2];
        f.eval_points(&[2, 5], &[[0.0, 0.0, 1.0]; 2], &[[0.0, 0.0, 1.0]; 2], &mut out);
        assert_eq!(out, [[2.0, 1.0, 0.0], [5.0, 1.0, 0.0]]);
        assert!(f.sample_at(0, [0.0, 0.0, 1.0], [0.5, 0.5]).is_none());
        assert!(f.pdf_at(0, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]).is_none());
    }
}
