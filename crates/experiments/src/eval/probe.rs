//! The BRDF probes behind the report's BRDF plots (`report::brdf_plots`): any
//! [`brdf_analytic::SurfaceBrdf`] (a fitted model, or the ground-truth material of a semi-synthetic
//! scene) evaluated on fixed direction sets, so that models can be compared with each other and
//! with the truth away from the directions the cameras saw.
//!
//! | probe | directions | value |
//! | --- | --- | --- |
//! | lit sphere | 96^2 orthographic pixels, light [`SPHERE_LIGHT`] (45 deg from the view) | L = f E cos(theta_l), E = pi |
//! | slices | light at [`INCIDENT_DEG`] in the x-z plane, viewer at -89..=89 deg in 1 deg steps | f cos(theta_i) |
//! | albedo | viewer at 0..=88 deg in 2 deg steps, [`CURVE_STRATA`]^2 stratified cosine-weighted lights | directional albedo |
//! | validity | every pixel of the first test view with a record: its view direction, [`MAP_STRATA`]^2 lights; its test light | albedo; relative reciprocity error |
//!
//! A spatially varying model is probed at one surface point: the one seen nearest the centre
//! of the first test view (the validity maps use every pixel's own point). Directional albedo
//! is `pi / N * sum f(l_k, v)` over stratified cosine-weighted `l_k` with fixed jitter, so a
//! probe is deterministic. The result of a run is stored as `<run>/probe.bin` ([`write`](fn@write)).

use crate::data::RecordSet;
use crate::{Error, Result};
use angles::Frame;
use brdf_analytic::SurfaceBrdf;
use metrics::energy::cosine_direction;
use report::brdf_plots::{
    AlbedoPoint, BrdfProbe, LitSphere, PolarSlice, SPHERE_SIZE, ValidityMaps, sphere_normal,
};
use scene::{SampleSet, SceneDataset, Split};
use std::path::Path;

/// Incident angles of the slices, degrees.
pub const INCIDENT_DEG: [f64; 4] = [0.0, 30.0, 60.0, 75.0];

/// The lit sphere's light: up and to the left, 45 degrees from the viewing direction.
pub const SPHERE_LIGHT: [f64; 3] = [-0.5, 0.5, std::f64::consts::FRAC_1_SQRT_2];

/// Strata per axis of the directional-albedo curve (1,024 directions a point).
pub const CURVE_STRATA: usize = 32;

/// Strata per axis of a validity map's albedo (144 directions a pixel).
pub const MAP_STRATA: usize = 12;

/// Irradiance of the sphere's light (as in the scenes: a white Lambertian facing it renders 1).
const E: f32 = std::f32::consts::PI;

/// `n * n` cosine-weighted local directions, one per stratum of the unit square, jittered by a
/// fixed SplitMix64 stream.
pub fn stratified_cosine(n: usize) -> Vec<[f32; 3]> {
    let mut rng = stdx::rng::SplitMix64::new(0x5EED_0FA1_BED0);
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let u1 = (i as f64 + rng.next_f64()) / n as f64;
            let u2 = (j as f64 + rng.next_f64()) / n as f64;
            out.push(cosine_direction(u1, u2));
        }
    }
    out
}

/// `brdf` at `point` for every (l, v) pair, in the batches the BRDF prefers; non-finite
/// values become 0 (the plots show what is finite; the analyses reject NaN elsewhere).
pub fn eval_pairs(
    brdf: &dyn SurfaceBrdf,
    points: &[u32],
    l: &[[f32; 3]],
    v: &[[f32; 3]],
) -> Vec<[f32; 3]> {
    let mut out = vec![[0.0f32; 3]; l.len()];
    let chunk = brdf.preferred_batch().max(1);
    for (k, o) in out.chunks_mut(chunk).enumerate() {
        let r = k * chunk..k * chunk + o.len();
        brdf.eval_points(&points[r.clone()], &l[r.clone()], &v[r], o);
    }
    for c in out.iter_mut().flatten() {
        if !c.is_finite() {
            *c = 0.0;
        }
    }
    out
}

/// Directional albedo for the view directions `v` (local), each at its point, by
/// [`stratified_cosine`] with `strata`^2 directions.
pub fn directional_albedo(
    brdf: &dyn SurfaceBrdf,
    points: &[u32],
    v: &[[f32; 3]],
    strata: usize,
) -> Vec<[f32; 3]> {
    let dirs = stratified_cosine(strata);
    let n = dirs.len();
    let (mut pp, mut ll, mut vv) = (Vec::new(), Vec::new(), Vec::new());
    for (&p, &v) in points.iter().zip(v) {
        pp.extend(std::iter::repeat_n(p, n));
        ll.extend_from_slice(&dirs);
        vv.extend(std::iter::repeat_n(v, n));
    }
    let f = eval_pairs(brdf, &pp, &ll, &vv);
    f.chunks(n.max(1))
        .map(|c| {
            let mut a = [0.0f64; 3];
            for x in c {
                for k in 0..3 {
                    a[k] += x[k] as f64;
                }
            }
            a.map(|s| (std::f64::consts::PI * s / n as f64) as f32)
        })
        .collect()
}

fn to_f32(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

/// The BRDF at `point` on a sphere lit by [`SPHERE_LIGHT`].
pub fn lit_sphere(brdf: &dyn SurfaceBrdf, point: u32) -> LitSphere {
    let size = SPHERE_SIZE as usize;
    let (mut idx, mut ll, mut vv, mut cos) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..size * size {
        let Some(n) = sphere_normal((i % size) as u32, (i / size) as u32) else { continue };
        let c = n[0] * SPHERE_LIGHT[0] + n[1] * SPHERE_LIGHT[1] + n[2] * SPHERE_LIGHT[2];
        if c <= 0.0 {
            continue;
        }
        let frame = Frame::from_normal(n);
        idx.push(i);
        ll.push(to_f32(frame.to_local(SPHERE_LIGHT)));
        vv.push(to_f32(frame.to_local([0.0, 0.0, 1.0])));
        cos.push(c as f32);
    }
    let f = eval_pairs(brdf, &vec![point; idx.len()], &ll, &vv);
    let mut radiance = vec![[0.0f32; 3]; size * size];
    for (k, &i) in idx.iter().enumerate() {
        radiance[i] = f[k].map(|x| x * E * cos[k]);
    }
    LitSphere { light: SPHERE_LIGHT, radiance }
}

/// The BRDF at `point` on the slices of [`INCIDENT_DEG`].
pub fn slices(brdf: &dyn SurfaceBrdf, point: u32) -> Vec<PolarSlice> {
    let outgoing: Vec<f64> = (-89..=89).map(f64::from).collect();
    INCIDENT_DEG
        .iter()
        .map(|&ti| {
            let (si, ci) = ti.to_radians().sin_cos();
            let l = [-si as f32, 0.0, ci as f32];
            let v: Vec<[f32; 3]> = outgoing
                .iter()
                .map(|t| {
                    let (s, c) = t.to_radians().sin_cos();
                    [s as f32, 0.0, c as f32]
                })
                .collect();
            let f = eval_pairs(brdf, &vec![point; v.len()], &vec![l; v.len()], &v);
            let points =
                outgoing.iter().zip(f).map(|(&t, f)| (t, f.map(|x| x * ci as f32))).collect();
            PolarSlice { theta_i_deg: ti, points }
        })
        .collect()
}

/// Directional albedo at `point` against the viewing angle, 0..=88 degrees.
pub fn albedo_curve(brdf: &dyn SurfaceBrdf, point: u32) -> Vec<AlbedoPoint> {
    let angles: Vec<f64> = (0..=44).map(|i| 2.0 * i as f64).collect();
    let v: Vec<[f32; 3]> = angles
        .iter()
        .map(|t| {
            let (s, c) = t.to_radians().sin_cos();
            [s as f32, 0.0, c as f32]
        })
        .collect();
    let a = directional_albedo(brdf, &vec![point; v.len()], &v, CURVE_STRATA);
    angles.into_iter().zip(a).collect()
}

/// Every probe of `brdf` at `point` (`at` says where that is), with `validity` maps.
pub fn probe(
    brdf: &dyn SurfaceBrdf,
    point: u32,
    at: String,
    validity: Option<ValidityMaps>,
) -> BrdfProbe {
    BrdfProbe {
        point: at,
        sphere: lit_sphere(brdf, point),
        slices: slices(brdf, point),
        albedo: albedo_curve(brdf, point),
        validity,
    }
}

/// The first test view of `dataset` and, for each of its pixels, the first test record that
/// shows it (records index `data`).
pub fn first_test_view(
    dataset: &SceneDataset,
    samples: &SampleSet,
    data: &RecordSet,
) -> Option<(usize, Vec<Option<u32>>)> {
    let &(vi, _) = dataset.pairs(Split::Test).first()?;
    let s = &dataset.manifest.config.settings;
    let mut pixels = vec![None; s.width as usize * s.height as usize];
    for (r, &src) in data.source.iter().enumerate() {
        if samples.view[src] as usize == vi
            && let Some(slot) = pixels.get_mut(samples.pixel[src] as usize)
            && slot.is_none()
        {
            *slot = Some(r as u32);
        }
    }
    Some((vi, pixels))
}

/// The record seen nearest the image centre among `pixels` (row-major, `width` wide).
pub fn centre_record(pixels: &[Option<u32>], width: usize) -> Option<u32> {
    let height = pixels.len() / width.max(1);
    let (cx, cy) = (width as f64 / 2.0, height as f64 / 2.0);
    pixels
        .iter()
        .enumerate()
        .filter_map(|(p, r)| {
            let (x, y) = ((p % width) as f64 + 0.5, (p / width) as f64 + 0.5);
            r.map(|r| ((x - cx).powi(2) + (y - cy).powi(2), r))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, r)| r)
}

/// The validity maps of `brdf` (points are records of `data`) on test view `view`, whose
/// pixels map to records by `pixels`.
pub fn validity_maps(
    brdf: &dyn SurfaceBrdf,
    data: &RecordSet,
    view: usize,
    pixels: &[Option<u32>],
    width: u32,
) -> ValidityMaps {
    let (idx, records): (Vec<usize>, Vec<u32>) =
        pixels.iter().enumerate().filter_map(|(p, r)| r.map(|r| (p, r))).unzip();
    let v: Vec<[f32; 3]> = records.iter().map(|&r| data.v[r as usize]).collect();
    let l: Vec<[f32; 3]> = records.iter().map(|&r| data.l[r as usize]).collect();
    let albedo = directional_albedo(brdf, &records, &v, MAP_STRATA);
    let forward = eval_pairs(brdf, &records, &l, &v);
    let swapped = eval_pairs(brdf, &records, &v, &l);
    let mut maps = ValidityMaps {
        view: format!("test view {view}"),
        width,
        height: (pixels.len() / width.max(1) as usize) as u32,
        albedo: vec![f32::NAN; pixels.len()],
        reciprocity: vec![f32::NAN; pixels.len()],
    };
    for (k, &p) in idx.iter().enumerate() {
        maps.albedo[p] = albedo[k].iter().fold(f32::MIN, |a, &b| a.max(b));
        let mut e = 0.0f32;
        for c in 0..3 {
            let mean = 0.5 * (forward[k][c] + swapped[k][c]);
            e += (forward[k][c] - swapped[k][c]).abs() / mean.max(1e-4) / 3.0;
        }
        maps.reciprocity[p] = e;
    }
    maps
}

/// The probe of a fitted model on its test records: at the point nearest the centre of the
/// first test view, with that view's validity maps; `None` without test records.
pub fn probe_fitted(
    brdf: &dyn SurfaceBrdf,
    dataset: &SceneDataset,
    samples: &SampleSet,
    data: &RecordSet,
) -> Option<BrdfProbe> {
    let (view, pixels) = first_test_view(dataset, samples, data)?;
    let width = dataset.manifest.config.settings.width;
    let point = centre_record(&pixels, width as usize)?;
    let maps = validity_maps(brdf, data, view, &pixels, width);
    let at = format!("surface point seen nearest the centre of test view {view}");
    Some(probe(brdf, point, at, Some(maps)))
}

const MAGIC: &[u8; 8] = b"BRDFPRB1";
const VERSION: u32 = 1;

/// Writes a probe to `path` (atomically).
pub fn write(path: &Path, probe: &BrdfProbe) -> Result<()> {
    stdx::fs::write_atomic(path, &encode(probe))?;
    Ok(())
}

/// The bytes [`write`](fn@write) writes.
pub fn encode(probe: &BrdfProbe) -> Vec<u8> {
    stdx::cache_file::encode(MAGIC, VERSION, 0, probe)
}

/// Reads a probe written by [`write`](fn@write).
pub fn read(path: &Path) -> Result<BrdfProbe> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    stdx::cache_file::decode(&bytes, MAGIC, VERSION, 0).map_err(|e| Error::format(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use brdf_analytic::FnSurface;

    #[test]
    fn a_white_lambertian_has_albedo_one_everywhere_and_a_cosine_sphere() {
        let white =
            brdf_analytic::Lambert::new(brdf_analytic::LambertParams { albedo: [1.0f32; 3] });
        let curve = albedo_curve(&white, 0);
        assert_eq!(curve.len(), 45);
        for (t, a) in &curve {
            for c in a {
                assert!((c - 1.0).abs() < 1e-5, "{t}: {a:?}");
            }
        }
        let s = lit_sphere(&white, 0);
        let size = SPHERE_SIZE;
        for y in (0..size).step_by(7) {
            for x in (0..size).step_by(7) {
                let i = (y * size + x) as usize;
                let want = sphere_normal(x, y).map_or(0.0, |n| {
                    (n[0] * SPHERE_LIGHT[0] + n[1] * SPHERE_LIGHT[1] + n[2] * SPHERE_LIGHT[2])
                        .max(0.0)
                });
                assert!((s.radiance[i][0] as f64 - want).abs() < 1e-5, "{x} {y}");
            }
        }
        // Slices: f cos(theta_i) = cos(theta_i) / pi at every outgoing angle.
        for sl in slices(&white, 0) {
            let want = (sl.theta_i_deg.to_radians().cos() / std::f64::consts::PI) as f32;
            assert_eq!(sl.points.len(), 179);
            assert!(sl.points.iter().all(|(_, f)| (f[1] - want).abs() < 1e-6));
        }
    }

    #[test]
    fn reciprocity_maps_see_an_asymmetric_brdf_and_nan_is_contained() {
        // f = 1 + l_z (not reciprocal); NaN at one point.
        let brdf = FnSurface(
            |p: u32, l: [f32; 3], _v: [f32; 3]| {
                if p == 2 { [f32::NAN; 3] } else { [1.0 + l[2]; 3] }
            },
        );
        let data = RecordSet {
            l: vec![[0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [0.0, 0.0, 1.0]],
            v: vec![[0.6, 0.0, 0.8], [0.6, 0.0, 0.8], [0.0, 0.0, 1.0]],
            ..RecordSet::default()
        };
        let pixels = [Some(0), None, Some(1), Some(2)];
        let m = validity_maps(&brdf, &data, 4, &pixels, 2);
        assert_eq!((m.width, m.height, m.view.as_str()), (2, 2, "test view 4"));
        assert!(m.reciprocity[1].is_nan() && m.albedo[1].is_nan());
        // |2 - 1.8| / 1.9 at pixel 0, exactly reciprocal at pixel 2, NaN evaluated as 0.
        assert!((m.reciprocity[0] - 0.2 / 1.9).abs() < 1e-5, "{}", m.reciprocity[0]);
        assert_eq!(m.reciprocity[2], 0.0);
        assert_eq!((m.reciprocity[3], m.albedo[3]), (0.0, 0.0));
        // Albedo of 1 + l_z: pi (1 + 2/3) ... over cosine-weighted l: mean of l_z is 2/3.
        assert!(
            (m.albedo[0] - std::f32::consts::PI * (1.0 + 2.0 / 3.0)).abs() < 0.02,
            "{}",
            m.albedo[0]
        );
        assert_eq!(centre_record(&pixels, 2), Some(0));
    }

    #[test]
    fn probes_round_trip_through_their_file() {
        let white =
            brdf_analytic::Lambert::new(brdf_analytic::LambertParams { albedo: [0.5f32; 3] });
        let p = probe(&white, 0, "uniform".into(), None);
        let tmp = test_support::TempDir::new("probe");
        let path = tmp.0.join("probe.bin");
        write(&path, &p).unwrap();
        assert_eq!(read(&path).unwrap(), p);
        std::fs::write(&path, b"garbage").unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("probe.bin"), "{e}");
    }
}
