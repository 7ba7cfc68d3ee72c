//! Outputs are finite and non-negative for extreme inputs (grazing and below-horizon
//! directions, l = v, l = v = n, huge, infinite and NaN features), for every model and option;
//! parametric models' parameters stay in their ranges.

mod common;

use brdf_neural::{
    AngleParametrization, BrdfBatch, BrdfModel, BrdfParams, ModelConfig, ModelKind, Reciprocity,
    Samples, device,
};
use common::{direction, rng, small, values};

/// Extreme direction pairs and feature rows.
fn extreme(spatial_dim: usize) -> (Vec<f32>, Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut r = rng(3);
    let n = [0.0_f32, 0.0, 1.0];
    let grazing = [1.0_f32, 0.0, 0.0];
    let near = [0.999_999_9_f32, 0.0, 4.5e-4];
    let mut l = vec![n, grazing, near, grazing, near, [-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], n];
    let mut v =
        vec![n, grazing, near, [-1.0, 0.0, 0.0], [-0.999_999_9, 0.0, 4.5e-4], grazing, n, near];
    for _ in 0..24 {
        let d = direction(&mut r, 0.0);
        l.push(d);
        v.push(d); // l = v
    }
    let rows = l.len();
    let values = [1e30_f32, -1e30, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e3, -1e3, 0.0];
    let spatial = (0..rows * spatial_dim).map(|i| values[(i * 7 + i / spatial_dim) % 8]).collect();
    (spatial, l, v)
}

fn variants() -> Vec<ModelConfig> {
    let mut out = Vec::new();
    for kind in ModelKind::ALL {
        out.push(small(kind));
        if kind.analytic().is_none() {
            for (rec, par) in [
                (Reciprocity::Mapping, AngleParametrization::Rusinkiewicz),
                (Reciprocity::RandomSwap, AngleParametrization::ViewLight),
            ] {
                let mut c = small(kind);
                c.angles.reciprocity = rec;
                c.angles.parametrization = par;
                c.nol = true;
                out.push(c);
            }
        }
        if kind.is_additive() {
            let mut c = small(kind);
            c.albedo_clamp = true;
            c.scalar_specular = true;
            out.push(c);
        }
    }
    out
}

#[test]
fn outputs_are_finite_and_non_negative_for_extreme_inputs() {
    let device = device::cpu();
    for c in variants() {
        let model = BrdfModel::init(&c, &device).unwrap();
        let (spatial, l, v) = extreme(c.spatial_dim);
        let batch = BrdfBatch::new(&c, &Samples { spatial: &spatial, l: &l, v: &v }, None, &device)
            .unwrap();
        let out = model.forward(&batch);
        for (name, t) in [("f", Some(out.f)), ("diffuse", out.diffuse), ("specular", out.specular)]
        {
            if let Some(t) = t {
                let x = values(t);
                assert!(x.iter().all(|y| y.is_finite() && *y >= 0.0), "{c:?} {name}: {x:?}");
            }
        }
        if let Some(xi) = out.xi {
            assert!(values(xi).iter().all(|y| (0.0..=1.0).contains(y)));
        }
        if c.kind.analytic().is_some() {
            // Below the horizon (row 6: l = -n) the BRDF is 0.
            let f = values(model.forward(&batch).f);
            assert_eq!(&f[18..21], &[0.0; 3], "{:?}", c.kind);
        }
    }
}

fn in_range(t: burn::tensor::Tensor<2>, lo: f32, hi: f32) -> bool {
    values(t).iter().all(|x| (lo..=hi).contains(x))
}

#[test]
fn parametric_parameters_stay_in_their_ranges() {
    let device = device::cpu();
    for kind in [ModelKind::Rp, ModelKind::Ts, ModelKind::Disney, ModelKind::Fmbrdf] {
        let c = small(kind);
        let model = BrdfModel::init(&c, &device).unwrap();
        let brdf_neural::BrdfModel::Parametric(p) = &model else { panic!("parametric") };
        let (spatial, l, v) = extreme(c.spatial_dim);
        let batch = BrdfBatch::new(&c, &Samples { spatial: &spatial, l: &l, v: &v }, None, &device)
            .unwrap();
        match p.params(batch.spatial.clone()) {
            BrdfParams::RealisticPhong(q) => {
                assert!(in_range(q.kd.clone(), 0.0, 1.0) && in_range(q.ks.clone(), 0.0, 1.0));
                assert!(in_range(q.kd + q.ks, 0.0, 1.0 + 1e-6));
                assert!(in_range(q.exponent, 1.0, f32::MAX));
            }
            BrdfParams::TorranceSparrow(q) => {
                for t in [q.roughness, q.diffuse, q.f0] {
                    assert!(in_range(t, 0.0, 1.0));
                }
            }
            BrdfParams::Disney(q) => {
                for t in [
                    q.base_color,
                    q.metallic,
                    q.subsurface,
                    q.specular,
                    q.roughness,
                    q.specular_tint,
                    q.sheen,
                    q.sheen_tint,
                    q.clearcoat,
                    q.clearcoat_gloss,
                ] {
                    assert!(in_range(t, 0.0, 1.0));
                }
            }
            BrdfParams::Fmbrdf(q) => {
                assert!(in_range(q.eta, 1.1, 2.5) && in_range(q.rho, 0.0, 1.0));
                assert!(in_range(q.k_s, 0.0, f32::MAX) && in_range(q.kappa, 0.0, 100.0));
                assert!(in_range(q.alpha, 0.001, std::f32::consts::TAU));
                assert!(in_range(q.beta, 0.5, 4.0));
            }
        }
    }
}
