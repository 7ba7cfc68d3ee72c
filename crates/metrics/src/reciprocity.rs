//! Reciprocity error (spec section 7): the RMSE between f(x, l, v) and f(x, v, l) over test pairs
//! and RGB channels, the model evaluated with its inputs swapped. Not scaled in the tables.

use crate::error::{Error, Result};
use brdf_analytic::SurfaceBrdf;
use rayon::prelude::*;

/// sqrt(mean over pairs and channels of (f(x, l, v) - f(x, v, l))^2), local-frame directions.
pub fn reciprocity_rmse(
    brdf: &impl SurfaceBrdf,
    points: &[u32],
    l: &[[f32; 3]],
    v: &[[f32; 3]],
) -> Result<f64> {
    if points.len() != l.len() || l.len() != v.len() {
        return Err(Error::LengthMismatch { what: "reciprocity_rmse", a: l.len(), b: v.len() });
    }
    if l.is_empty() {
        return Err(Error::Empty("reciprocity_rmse: no pairs"));
    }
    let batch = brdf.preferred_batch().max(1);
    let chunk_sum = |i: usize| -> f64 {
        let r = i * batch..((i + 1) * batch).min(l.len());
        let n = r.len();
        let (mut a, mut b) = (vec![[0.0f32; 3]; n], vec![[0.0f32; 3]; n]);
        brdf.eval_points(&points[r.clone()], &l[r.clone()], &v[r.clone()], &mut a);
        brdf.eval_points(&points[r.clone()], &v[r.clone()], &l[r], &mut b);
        a.iter()
            .zip(&b)
            .flat_map(|(p, q)| (0..3).map(move |c| (p[c] as f64 - q[c] as f64).powi(2)))
            .sum()
    };
    let chunks = l.len().div_ceil(batch);
    let sum: f64 = if brdf.parallel() {
        (0..chunks).into_par_iter().map(chunk_sum).sum()
    } else {
        (0..chunks).map(chunk_sum).sum()
    };
    if sum.is_nan() {
        return Err(Error::Config("reciprocity_rmse: the model returned NaN".into()));
    }
    Ok((sum / (3 * l.len()) as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use brdf_analytic::FnSurface;
    use brdf_analytic::{Disney, DisneyParams, TorranceSparrow, TorranceSparrowParams};

    fn pairs(n: usize) -> (Vec<u32>, Vec<[f32; 3]>, Vec<[f32; 3]>) {
        let dir = |i: usize, k: f32| {
            let u = (i as f32 * 0.618_034 * k).fract();
            let w = (i as f32 * 0.754_877_7 + k).fract();
            let (st, ct) = ((u * 0.99).sqrt(), (1.0 - u * 0.99).sqrt());
            let p = std::f32::consts::TAU * w;
            [st * p.cos(), st * p.sin(), ct]
        };
        (
            (0..n as u32).collect(),
            (0..n).map(|i| dir(i, 1.0)).collect(),
            (0..n).map(|i| dir(i, 2.3)).collect(),
        )
    }

    #[test]
    fn exactly_zero_for_the_theta_mapping() {
        // Any (nonlinear) function of the reciprocal Theta mapping is exactly reciprocal.
        let f = FnSurface(|_p: u32, l: [f32; 3], v: [f32; 3]| {
            let t = angles::reciprocal_theta(l, v);
            [t[0].sin() * t[2].cos() + 0.1, (t[1] * t[3]).exp(), t[2].mul_add(t[0], t[1]).tanh()]
        });
        let (p, l, v) = pairs(5000);
        assert_eq!(reciprocity_rmse(&f, &p, &l, &v).unwrap(), 0.0);
    }

    #[test]
    fn symmetric_parametric_models_are_zero() {
        let (p, l, v) = pairs(5000);
        let d = Disney::new(DisneyParams { roughness: 0.3, ..Default::default() });
        let t = TorranceSparrow::new(TorranceSparrowParams::<f32>::default());
        assert_eq!(reciprocity_rmse(&d, &p, &l, &v).unwrap(), 0.0);
        assert_eq!(reciprocity_rmse(&t, &p, &l, &v).unwrap(), 0.0);
    }

    #[test]
    fn non_reciprocal_closure_hand_computed() {
        // f = (l_z, 0, 0): the swap difference is l_z - v_z in one channel of three.
        let f = FnSurface(|_p: u32, l: [f32; 3], _v: [f32; 3]| [l[2], 0.0, 0.0]);
        let (p, l, v) = pairs(1000);
        let want =
            (l.iter().zip(&v).map(|(a, b)| (a[2] as f64 - b[2] as f64).powi(2)).sum::<f64>()
                / 3000.0)
                .sqrt();
        let got = reciprocity_rmse(&f, &p, &l, &v).unwrap();
        assert!(want > 0.1 && (got - want).abs() < 1e-12, "{got} {want}");
    }
}
