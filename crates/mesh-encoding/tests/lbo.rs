//! Laplace-Beltrami eigenpairs and encoding: sphere spectrum and its convergence, M-orthonormality,
//! residuals, agreement with the dense solver, connected components, degenerate triangles, the
//! cache and the encoding on shared meshes.

mod common;

use mesh_encoding::lbo::{
    CacheOutcome, EigenSettings, Eigenpairs, LboEncoding, LboEncodingConfig, LboMatrices,
    cached_eigenpairs, dense_eigenpairs, eigenvalue_count_below, smallest_eigenpairs,
};
use mesh_encoding::mesh::icosphere;
use mesh_encoding::{LoadOptions, load_mesh};

fn small_settings() -> EigenSettings {
    EigenSettings { block_size: 8, ..Default::default() }
}

fn solve(v: &[[f64; 3]], f: &[[u32; 3]], k: usize) -> (LboMatrices, Eigenpairs) {
    let m = LboMatrices::assemble(v, f).unwrap();
    let (pairs, report) = smallest_eigenpairs(&m, k, &small_settings()).unwrap();
    assert!(!report.dense, "the test should exercise the sparse solver");
    (m, pairs)
}

/// Largest relative deviation from l(l+1) over the first `lmax + 1` bands.
fn sphere_error(values: &[f64], lmax: usize) -> f64 {
    let mut worst: f64 = 0.0;
    for l in 1..=lmax {
        let exact = (l * (l + 1)) as f64;
        for &x in &values[l * l..(l + 1) * (l + 1)] {
            worst = worst.max((x - exact).abs() / exact);
        }
    }
    worst
}

#[test]
fn sphere_spectrum_converges_to_l_l_plus_1_with_multiplicity() {
    let lmax = 4;
    let k = (lmax + 1) * (lmax + 1);
    let mut errors = Vec::new();
    for level in [3, 4] {
        let (v, f) = icosphere(level);
        let (m, pairs) = solve(&v, &f, k);
        assert!(pairs.values[0].abs() < 1e-9, "{:?}", &pairs.values[..3]);
        // Bands: 2l + 1 values close to l(l+1), separated from the next band.
        for l in 1..=lmax {
            let band = &pairs.values[l * l..(l + 1) * (l + 1)];
            let exact = (l * (l + 1)) as f64;
            assert!(band.iter().all(|x| (x - exact).abs() < 0.05 * exact), "l = {l}: {band:?}");
        }
        assert!(pairs.orthonormality_error(&m.mass) < 1e-8);
        errors.push(sphere_error(&pairs.values, lmax));
    }
    // Second-order convergence: halving the edge length divides the error by about 4.
    assert!(errors[1] < errors[0] / 3.0, "errors under refinement: {errors:?}");
}

#[test]
fn sparse_solver_agrees_with_dense_on_a_perturbed_sphere() {
    let (mut v, f) = icosphere(3);
    // Break the symmetry (distinct eigenvalues) deterministically.
    for (i, p) in v.iter_mut().enumerate() {
        let s = 1.0 + 0.05 * ((i as f64 * 1.618).sin());
        *p = p.map(|c| c * s);
    }
    let k = 40;
    let (m, pairs) = solve(&v, &f, k);
    let dense = dense_eigenpairs(&m, k).unwrap();
    for (i, (a, b)) in pairs.values.iter().zip(&dense.values).enumerate() {
        assert!((a - b).abs() <= 1e-9 * b.abs().max(1.0), "pair {i}: {a} vs {b}");
    }
    // Eigenvectors agree up to sign where the eigenvalue is isolated.
    for j in 1..k {
        let gap = (dense.values[j] - dense.values[j - 1])
            .min(dense.values.get(j + 1).map_or(f64::INFINITY, |x| x - dense.values[j]));
        if gap < 1e-3 * dense.values[j] {
            continue;
        }
        let dot: f64 = (0..m.vertex_count())
            .map(|i| pairs.vectors[(i, j)] * m.mass[i] * dense.vectors[(i, j)])
            .sum();
        assert!((dot.abs() - 1.0).abs() < 1e-7, "pair {j}: |<phi, phi_dense>_M| = {dot}");
    }
    assert!(pairs.orthonormality_error(&m.mass) < 1e-8);
    let res = pairs.relative_residuals(&m);
    assert!(res.iter().all(|r| *r < 1e-6), "residuals {res:?}");
}

#[test]
fn spectrum_slicing_agrees_with_dense_and_finds_every_pair() {
    let (mut v, f) = icosphere(3);
    for (i, p) in v.iter_mut().enumerate() {
        let s = 1.0 + 0.05 * ((i as f64 * 0.7).cos());
        *p = p.map(|c| c * s);
    }
    let m = LboMatrices::assemble(&v, &f).unwrap();
    let k = 40;
    let settings = EigenSettings { block_size: 8, slice_size: 8, ..Default::default() };
    let (pairs, _) = smallest_eigenpairs(&m, k, &settings).unwrap();
    let dense = dense_eigenpairs(&m, k).unwrap();
    for (i, (a, b)) in pairs.values.iter().zip(&dense.values).enumerate() {
        assert!((a - b).abs() <= 1e-9 * b.abs().max(1.0), "pair {i}: {a} vs {b}");
    }
    assert!(pairs.orthonormality_error(&m.mass) < 1e-8);
    let res = pairs.relative_residuals(&m);
    assert!(res.iter().all(|r| *r < 1e-6), "residuals {res:?}");
}

#[test]
fn inertia_counts_match_the_sphere_bands_and_the_solver_checks_them() {
    let (v, f) = icosphere(3);
    let m = LboMatrices::assemble(&v, &f).unwrap();
    // Bands l = 0..3 near l(l+1) = 0, 2, 6, 12 with multiplicities 1, 3, 5, 7.
    assert_eq!(eigenvalue_count_below(&m, -0.5).unwrap(), 0);
    assert_eq!(eigenvalue_count_below(&m, 1.0).unwrap(), 1);
    assert_eq!(eigenvalue_count_below(&m, 4.0).unwrap(), 4);
    assert_eq!(eigenvalue_count_below(&m, 9.0).unwrap(), 9);
    assert_eq!(eigenvalue_count_below(&m, 16.0).unwrap(), 16);
    // The solver's own check: k = 20 ends inside the l = 4 band (16..25).
    let (pairs, report) = smallest_eigenpairs(&m, 20, &small_settings()).unwrap();
    let (mu, count) = report.inertia.expect("the sparse solver checks completeness");
    assert_eq!(count, pairs.values.iter().filter(|&&x| x < mu).count());
    assert!((12.0..20.0).contains(&mu), "check shift {mu} should sit between bands");
}

#[test]
fn narrow_blocks_still_find_every_member_of_the_sphere_bands() {
    // Blocks of 4 are narrower than the bands (multiplicity up to 9); a missed member would be
    // caught by the inertia check and the solve retried with wider blocks.
    let (v, f) = icosphere(3);
    let m = LboMatrices::assemble(&v, &f).unwrap();
    let k = 30;
    let settings = EigenSettings { block_size: 4, ..Default::default() };
    let (pairs, report) = smallest_eigenpairs(&m, k, &settings).unwrap();
    assert!(!report.dense);
    let dense = dense_eigenpairs(&m, k).unwrap();
    for (i, (a, b)) in pairs.values.iter().zip(&dense.values).enumerate() {
        assert!((a - b).abs() <= 1e-9 * b.abs().max(1.0), "pair {i}: {a} vs {b}");
    }
}

#[test]
fn two_components_give_two_zero_eigenvalues() {
    let (v1, f1) = icosphere(3);
    let n1 = v1.len() as u32;
    let mut v = v1.clone();
    v.extend(v1.iter().map(|p| [p[0] * 0.5 + 3.0, p[1] * 0.5, p[2] * 0.5]));
    let mut f = f1.clone();
    f.extend(f1.iter().map(|t| t.map(|i| i + n1)));
    let (m, pairs) = solve(&v, &f, 6);
    assert!(pairs.values[0].abs() < 1e-9 && pairs.values[1].abs() < 1e-9, "{:?}", pairs.values);
    // Next: l = 1 of the big sphere (radius 1: 2), then the small one has 8 (radius 0.5).
    assert!((pairs.values[2] - 2.0).abs() < 0.05, "{:?}", pairs.values);
    assert!(pairs.orthonormality_error(&m.mass) < 1e-8);
}

#[test]
fn open_mesh_with_degenerate_triangles_gives_finite_neumann_spectrum() {
    // A flat 2 x 1 rectangle, grid 24 x 12, plus degenerate triangles on existing vertices.
    let (nx, ny) = (24usize, 12usize);
    let mut v = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            v.push([2.0 * i as f64 / nx as f64, j as f64 / ny as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut f = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    f.push([id(0, 0), id(1, 0), id(2, 0)]); // collinear
    f.push([id(3, 3), id(3, 3), id(4, 4)]); // repeated index
    let m = LboMatrices::assemble(&v, &f).unwrap();
    assert_eq!(m.skipped_triangles, 2);
    let (pairs, _) = smallest_eigenpairs(&m, 6, &small_settings()).unwrap();
    // Neumann eigenvalues of [0,2]x[0,1]: (pi a / 2)^2 + (pi b)^2 = 0, pi^2/4, pi^2, pi^2 (a=2),
    // 5 pi^2 / 4, 2 pi^2 (a=4) ...
    let pi2 = std::f64::consts::PI.powi(2);
    let exact = [0.0, pi2 / 4.0, pi2, pi2, 1.25 * pi2, 2.0 * pi2];
    for (x, e) in pairs.values.iter().zip(exact) {
        assert!(x.is_finite() && (x - e).abs() < 0.02 * e.max(1.0), "{:?}", pairs.values);
    }
}

#[test]
fn cache_computes_loads_and_detects_corruption() {
    let (v, f) = icosphere(3);
    let tmp = common::TempDir::new("lbo-cache");
    let dir = tmp.0.clone();
    let s = small_settings();
    let (a, o) = cached_eigenpairs(&v, &f, 10, &s, &dir).unwrap();
    assert_eq!(o, CacheOutcome::Computed);
    let (b, o) = cached_eigenpairs(&v, &f, 10, &s, &dir).unwrap();
    assert_eq!(o, CacheOutcome::Loaded);
    assert_eq!(a.values, b.values);
    assert_eq!(a.vectors, b.vectors);
    let files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let mut bytes = std::fs::read(&files[0]).unwrap();
    bytes[1000] ^= 0x01;
    std::fs::write(&files[0], &bytes).unwrap();
    let (c, o) = cached_eigenpairs(&v, &f, 10, &s, &dir).unwrap();
    assert!(matches!(&o, CacheOutcome::Recomputed(r) if r.contains("checksum")), "{o:?}");
    assert_eq!(c.values, a.values);
    std::fs::write(&files[0], &bytes[..bytes.len() / 2]).unwrap();
    let (_, o) = cached_eigenpairs(&v, &f, 10, &s, &dir).unwrap();
    assert!(matches!(&o, CacheOutcome::Recomputed(r) if r.contains("truncated")), "{o:?}");
    let (_, o) = cached_eigenpairs(&v, &f, 10, &s, &dir).unwrap();
    assert_eq!(o, CacheOutcome::Loaded);
}

#[test]
fn spot_eigenpairs_and_encoding() {
    let Some(data) = common::data_dir() else { return };
    let loaded = load_mesh(data.join("meshes/spot.obj"), &LoadOptions::default()).unwrap();
    let m = LboMatrices::from_mesh(&loaded.mesh).unwrap();
    let k = 65;
    let (pairs, report) = smallest_eigenpairs(&m, k, &EigenSettings::default()).unwrap();
    assert!(!report.dense);
    assert!(pairs.orthonormality_error(&m.mass) < 1e-8);
    let res = pairs.relative_residuals(&m);
    assert!(
        res.iter().all(|r| *r < 1e-5),
        "max residual {:?}",
        res.iter().cloned().fold(0.0, f64::max)
    );
    assert!(pairs.values[0].abs() < 1e-8 && pairs.values[1] > 1e-3);
    assert!(pairs.values.windows(2).all(|w| w[0] <= w[1]));

    let config = LboEncodingConfig { selection: (0..64).collect(), ..Default::default() };
    let enc = LboEncoding::new(&pairs, &config).unwrap();
    assert_eq!((enc.vertex_count(), enc.dim()), (m.vertex_count(), 64));
    for c in 0..64 {
        let col = (0..enc.vertex_count()).map(|v| enc.vertex(v)[c]);
        let (lo, hi) = col.fold((f32::MAX, f32::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
        assert!((hi - lo - 1.0).abs() < 1e-5, "column {c}: range {}", hi - lo);
    }
    let tri = loaded.mesh.triangles[100];
    let at_corner = enc.interpolate(&loaded.mesh.triangles, &[(100, [0.0, 1.0, 0.0])]);
    assert_eq!(at_corner, enc.vertex(tri[1] as usize));
    // The default configuration needs 513 pairs.
    assert!(LboEncoding::new(&pairs, &LboEncodingConfig::default()).is_err());
}

#[test]
fn many_pairs_on_a_small_mesh_use_the_dense_solver() {
    // 150 pairs of a 642-vertex mesh: half the vertex count cannot hold the ~3 k vectors block
    // Lanczos needs, so the solver answers with the dense one (it used to fail to converge,
    // as 513 pairs did on spot's 2,930 vertices).
    let (v, f) = icosphere(3);
    let m = LboMatrices::assemble(&v, &f).unwrap();
    let (pairs, report) = smallest_eigenpairs(&m, 150, &EigenSettings::default()).unwrap();
    assert!(report.dense);
    let dense = dense_eigenpairs(&m, 150).unwrap();
    assert_eq!(pairs.values, dense.values);
    assert!(pairs.orthonormality_error(&m.mass) < 1e-8);
}
