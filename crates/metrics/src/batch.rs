//! The batched BRDF interface of the BRDF-space analyses, and adapters for analytic models and
//! closures.

use brdf_analytic::Brdf;

/// A BRDF evaluated in batches, in the **local** shading frame of each surface point.
///
/// Entry `i` asks for f(x_i, l_i, v_i): `points[i]` identifies the surface point (an index the
/// caller defines, e.g. into its test records, used by spatially varying models to look up their
/// spatial input), `l[i]` and `v[i]` are unit vectors in that point's local frame (normal on +z;
/// `l` to the light, `v` to the viewer). The implementation writes f_r in 1/sr, linear RGB,
/// without the cosine, into `out[i]`. All four slices have the same length.
///
/// A neural model implements this by building one tensor batch per call (the analyses call it
/// with [`BatchBrdf::preferred_batch`] entries at a time); it must be `Sync` because the analyses
/// call it from several threads when [`BatchBrdf::parallel`] is true.
pub trait BatchBrdf: Sync {
    /// f(x_i, l_i, v_i) for every i.
    fn eval_batch(&self, points: &[u32], l: &[[f32; 3]], v: &[[f32; 3]], out: &mut [[f32; 3]]);

    /// Batch size the analyses aim for (default 4096).
    fn preferred_batch(&self) -> usize {
        4096
    }

    /// Whether the analyses may call [`BatchBrdf::eval_batch`] from several threads at once
    /// (default true; a model that parallelises internally, e.g. on a GPU, returns false).
    fn parallel(&self) -> bool {
        true
    }
}

/// Any [`brdf_analytic::Brdf`] as a [`BatchBrdf`] (spatially uniform: `points` is ignored).
#[derive(Clone, Debug)]
pub struct AnalyticBatch<B>(pub B);

impl<B: Brdf<f32>> BatchBrdf for AnalyticBatch<B> {
    fn eval_batch(&self, _points: &[u32], l: &[[f32; 3]], v: &[[f32; 3]], out: &mut [[f32; 3]]) {
        for ((o, l), v) in out.iter_mut().zip(l).zip(v) {
            *o = self.0.eval(*l, *v);
        }
    }
}

/// A closure `f(point, l, v) -> rgb` as a [`BatchBrdf`].
#[derive(Clone, Debug)]
pub struct FnBatch<F>(pub F);

impl<F: Fn(u32, [f32; 3], [f32; 3]) -> [f32; 3] + Sync> BatchBrdf for FnBatch<F> {
    fn eval_batch(&self, points: &[u32], l: &[[f32; 3]], v: &[[f32; 3]], out: &mut [[f32; 3]]) {
        for i in 0..out.len() {
            out[i] = (self.0)(points[i], l[i], v[i]);
        }
    }
}
