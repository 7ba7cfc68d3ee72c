//! Shared helpers of the brdf-analytic integration tests: parameter strategies, direction
//! generators, the float comparison, a scoped-thread parallel map, and (in [`chi2`]) the chi^2
//! test of a sampler against its density.
#![allow(dead_code)]

pub mod chi2;

use brdf_analytic::*;
use proptest::prelude::*;
use std::f64::consts::TAU;

/// |a - b| / max(|a|, |b|, floor): relative difference with an absolute floor for values near 0.
pub fn rel_diff(a: f64, b: f64, floor: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(floor)
}

/// Largest [`rel_diff`] over the three channels.
pub fn rel_diff_rgb(a: [f64; 3], b: [f64; 3], floor: f64) -> f64 {
    (0..3).map(|c| rel_diff(a[c], b[c], floor)).fold(0.0, f64::max)
}

/// Maps `f` over `items` on all available cores (scoped threads), keeping the order.
pub fn par_map<I: Sync, O: Send>(items: &[I], f: impl Fn(&I) -> O + Sync) -> Vec<O> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = items.len().div_ceil(threads).max(1);
    std::thread::scope(|s| {
        let handles: Vec<_> =
            items.chunks(chunk).map(|c| s.spawn(|| c.iter().map(&f).collect::<Vec<_>>())).collect();
        handles.into_iter().flat_map(|h| h.join().expect("worker panicked")).collect()
    })
}

/// The unit direction at polar angle `theta_deg` from the normal, in the x-z plane (phi = 0).
pub fn dir_deg(theta_deg: f64) -> [f64; 3] {
    let t = theta_deg.to_radians();
    [t.sin(), 0.0, t.cos()]
}

/// A uniformly random direction in the open upper hemisphere.
pub fn upper() -> impl Strategy<Value = [f64; 3]> {
    (1e-6..=1.0_f64, 0.0..TAU).prop_map(|(c, phi)| {
        let s = (1.0 - c * c).max(0.0).sqrt();
        [s * phi.cos(), s * phi.sin(), c]
    })
}

fn unit() -> impl Strategy<Value = f64> {
    0.0..=1.0_f64
}

fn rgb() -> impl Strategy<Value = [f64; 3]> {
    [unit(), unit(), unit()]
}

/// Random Realistic Phong parameters over the whole range (log-uniform exponent).
pub fn phong_params() -> impl Strategy<Value = RealisticPhongParams<f64>> {
    (rgb(), rgb(), 0.0..6.0_f64)
        .prop_map(|(k, zeta, e)| RealisticPhongParams::from_split(k, zeta, 10f64.powf(e)))
}

/// Random Torrance-Sparrow parameters over the whole range.
pub fn ts_params() -> impl Strategy<Value = TorranceSparrowParams<f64>> {
    (unit(), rgb(), rgb()).prop_map(|(roughness, diffuse, f0)| TorranceSparrowParams {
        roughness,
        diffuse,
        f0,
    })
}

/// Random Disney parameters over the whole range, both base-colour conventions.
pub fn disney_params() -> impl Strategy<Value = DisneyParams<f64>> {
    (rgb(), proptest::array::uniform9(unit()), any::<bool>()).prop_map(|(base_color, s, g)| {
        DisneyParams {
            base_color,
            metallic: s[0],
            subsurface: s[1],
            specular: s[2],
            roughness: s[3],
            specular_tint: s[4],
            sheen: s[5],
            sheen_tint: s[6],
            clearcoat: s[7],
            clearcoat_gloss: s[8],
            gamma_base_color: g,
        }
    })
}

/// Disney parameters with every lobe switched on.
pub fn disney_all_lobes<T: Real>() -> DisneyParams<T> {
    DisneyParams {
        base_color: [T::lit(0.6), T::lit(0.3), T::lit(0.2)],
        metallic: T::lit(0.3),
        subsurface: T::lit(0.5),
        specular: T::lit(0.7),
        roughness: T::lit(0.35),
        specular_tint: T::lit(0.4),
        sheen: T::lit(0.6),
        sheen_tint: T::lit(0.5),
        clearcoat: T::lit(0.8),
        clearcoat_gloss: T::lit(0.7),
        gamma_base_color: true,
    }
}
