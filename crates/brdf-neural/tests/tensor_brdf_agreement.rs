//! Each tensor BRDF agrees with its scalar `brdf-analytic` twin (f32) to 1e-5 relative on
//! random parameters and directions (some below the horizon, some grazing):
//! |tensor - scalar| <= 1e-5 max(|tensor|, |scalar|) for every sample and channel.

mod common;

use brdf_analytic::{
    Brdf, Disney, DisneyParams, Fmbrdf, FmbrdfParams, RealisticPhong, RealisticPhongParams,
    TorranceSparrow, TorranceSparrowParams,
};
use brdf_neural::device;
use brdf_neural::tensor_brdf::{
    DisneyTensorParams, FmbrdfNets, FmbrdfTensorParams, Geometry, PhongTensorParams,
    TorranceSparrowTensorParams, disney, fmbrdf, fmbrdf_normalization, realistic_phong,
    torrance_sparrow,
};
use burn::tensor::{Device, Tensor, TensorData};
use common::{direction, rng, values};
use rand::Rng;

const N: usize = 400;
const REL: f32 = 1e-5;

/// Directions: mostly upper hemisphere, some grazing, some below the horizon.
fn pairs(r: &mut impl Rng) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let dir = |r: &mut _| {
        let mut d = direction(r, 0.0);
        if rand::Rng::random_bool(r, 0.05) {
            d[2] = -d[2];
        }
        d
    };
    let l = (0..N).map(|_| dir(r)).collect();
    let v = (0..N).map(|_| dir(r)).collect();
    (l, v)
}

fn column(x: &[f32], device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(x.to_vec(), [x.len(), 1]), device)
}

fn rgb(x: &[[f32; 3]], device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(x.concat(), [x.len(), 3]), device)
}

fn assert_agree(name: &str, tensor: Tensor<2>, scalar: &[[f32; 3]]) {
    let t = values(tensor);
    let mut worst = 0.0_f32;
    for (i, (a, b)) in t.iter().zip(scalar.concat()).enumerate() {
        let scale = a.abs().max(b.abs());
        let rel = if scale > 0.0 { (a - b).abs() / scale } else { 0.0 };
        assert!(rel <= REL, "{name}: sample {} channel {}: tensor {a} scalar {b}", i / 3, i % 3);
        worst = worst.max(rel);
    }
    eprintln!("{name}: worst relative difference {worst:.2e}");
}

fn unit3(r: &mut impl Rng) -> [f32; 3] {
    [r.random(), r.random(), r.random()]
}

#[test]
fn realistic_phong_agrees_with_scalar() {
    let device = device::cpu();
    let mut r = rng(21);
    let (l, v) = pairs(&mut r);
    let (mut kd, mut ks, mut n, mut expect) = (vec![], vec![], vec![], vec![]);
    for i in 0..N {
        let p = RealisticPhongParams::from_split(
            unit3(&mut r),
            unit3(&mut r),
            1.0 + 200.0 * r.random::<f32>().powi(2),
        );
        let m = RealisticPhong::new(p);
        let q = *m.params();
        kd.push(q.kd);
        ks.push(q.ks);
        n.push(q.exponent);
        expect.push(m.eval(l[i], v[i]));
    }
    let g = Geometry::new(&l, &v, false, &device);
    let p = PhongTensorParams {
        kd: rgb(&kd, &device),
        ks: rgb(&ks, &device),
        exponent: column(&n, &device),
    };
    assert_agree("RP", realistic_phong(&p, &g), &expect);
}

#[test]
fn torrance_sparrow_agrees_with_scalar() {
    let device = device::cpu();
    let mut r = rng(22);
    let (l, v) = pairs(&mut r);
    let (mut rough, mut diff, mut f0, mut expect) = (vec![], vec![], vec![], vec![]);
    for i in 0..N {
        let p = TorranceSparrowParams {
            roughness: r.random(),
            diffuse: unit3(&mut r),
            f0: unit3(&mut r),
        };
        rough.push(p.roughness);
        diff.push(p.diffuse);
        f0.push(p.f0);
        expect.push(TorranceSparrow::new(p).eval(l[i], v[i]));
    }
    let g = Geometry::new(&l, &v, false, &device);
    let p = TorranceSparrowTensorParams {
        roughness: column(&rough, &device),
        diffuse: rgb(&diff, &device),
        f0: rgb(&f0, &device),
    };
    assert_agree("TS", torrance_sparrow(&p, &g), &expect);
}

#[test]
fn disney_agrees_with_scalar() {
    let device = device::cpu();
    for gamma in [false, true] {
        let mut r = rng(23);
        let (l, v) = pairs(&mut r);
        let mut s: Vec<Vec<f32>> = vec![vec![]; 9];
        let (mut base, mut expect) = (vec![], vec![]);
        for i in 0..N {
            let x: Vec<f32> = (0..9).map(|_| r.random()).collect();
            let p = DisneyParams {
                base_color: unit3(&mut r),
                metallic: x[0],
                subsurface: x[1],
                specular: x[2],
                roughness: x[3],
                specular_tint: x[4],
                sheen: x[5],
                sheen_tint: x[6],
                clearcoat: x[7],
                clearcoat_gloss: x[8],
                gamma_base_color: gamma,
            };
            base.push(p.base_color);
            for (k, xk) in x.iter().enumerate() {
                s[k].push(*xk);
            }
            expect.push(Disney::new(p).eval(l[i], v[i]));
        }
        let g = Geometry::new(&l, &v, false, &device);
        let c = |k: usize| column(&s[k], &device);
        let p = DisneyTensorParams {
            base_color: rgb(&base, &device),
            metallic: c(0),
            subsurface: c(1),
            specular: c(2),
            roughness: c(3),
            specular_tint: c(4),
            sheen: c(5),
            sheen_tint: c(6),
            clearcoat: c(7),
            clearcoat_gloss: c(8),
            gamma_base_color: gamma,
        };
        assert_agree(if gamma { "Disney (gamma)" } else { "Disney" }, disney(&p, &g), &expect);
    }
}

#[test]
fn fmbrdf_agrees_with_scalar() {
    let device = device::cpu();
    let nets = FmbrdfNets::new(&device);
    let mut r = rng(24);
    for (alpha, beta) in [(0.05_f32, 0.7_f32), (0.3, 2.0), (1.0, 3.5), (0.01, 1.2)] {
        let (l, v) = pairs(&mut r);
        let base = Fmbrdf::new(FmbrdfParams { alpha, beta, ..Default::default() });
        let (mut eta, mut rho, mut ks, mut kappa, mut expect) =
            (vec![], vec![], vec![], vec![], vec![]);
        for i in 0..N {
            let p = FmbrdfParams {
                eta: r.random_range(1.1..2.5),
                rho: unit3(&mut r),
                k_s: r.random_range(0.0..5.0),
                kappa: r.random_range(0.0..100.0),
                alpha,
                beta,
            };
            eta.push(p.eta);
            rho.push(p.rho);
            ks.push(p.k_s);
            kappa.push(p.kappa);
            expect.push(base.with_params(p).eval(l[i], v[i]));
        }
        let g = Geometry::new(&l, &v, true, &device);
        let p = FmbrdfTensorParams {
            eta: column(&eta, &device),
            rho: rgb(&rho, &device),
            k_s: column(&ks, &device),
            kappa: column(&kappa, &device),
            alpha: column(&[alpha], &device),
            beta: column(&[beta], &device),
        };
        let c = values(fmbrdf_normalization(p.alpha.clone(), p.beta.clone(), &device))[0];
        let c_ref = base.normalization();
        assert!((c - c_ref).abs() <= 1e-5 * c_ref, "c({alpha}, {beta}): {c} vs {c_ref}");
        let f = fmbrdf(&p, &nets, &g, brdf_neural::products::Products::F32);
        assert_agree(&format!("FMBRDF alpha {alpha} beta {beta}"), f, &expect);
    }
}
