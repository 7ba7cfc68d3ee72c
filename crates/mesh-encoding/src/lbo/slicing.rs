//! Spectrum slicing for many eigenpairs: several shifts, one sparse `LDL^T` factor each, a short
//! block Lanczos run per shift, exact eigenvalue counts from Sylvester's law of inertia, and one
//! global Rayleigh-Ritz over everything found.
//!
//! With a single shift below the spectrum, the `k`-th eigenvalue is poorly separated in the
//! shift-inverted operator (`theta = 1 / lambda`: the relative gap at the end of the wanted range
//! is about `b / k`), so the basis must grow to several times `k` and the `O(n m^2)`
//! orthogonalisation dominates. Slicing replaces one large basis by `S` small ones:
//! 1. shifts `mu_1 < mu_2 < ...` spaced by about `slice_size` Weyl spacings (`4 pi / area`);
//!    each `L - mu_s M` is factored as `LDL^T` (faer's supernodal factorisation without
//!    pivoting, same symbolic analysis and AMD ordering for all shifts) and the number of
//!    negative pivots `c_s` is the exact number of eigenvalues below `mu_s`. Shifts are added
//!    until `c_S >= k`;
//! 2. shift `s` owns the interval `[mu_{s-1}, mu_s)` (with `mu_0 = sigma < 0`, `c_0 = 0`) whose
//!    eigenvalue count `c_s - c_{s-1}` is known exactly. Block Lanczos on
//!    `M^(1/2) (L - mu_s M)^-1 M^(1/2)` runs until that many Ritz pairs in the interval have
//!    converged: the stopping test is exact, so no eigenvalue is missed and none is counted
//!    twice. Eigenvalues nearest `mu_s` converge first; the interval's far end lies one slice
//!    away, so the basis stays a small multiple of the slice size;
//! 3. the vectors of all slices (`K >= k` of them) are M-orthonormalised together and a final
//!    Rayleigh-Ritz on `L` gives `Phi^T M Phi = I` to rounding and eigenvalues from
//!    `Phi^T L Phi`; the `k` smallest are returned.
//!
//! Status: correct and complete by construction (exact counts); each slice runs the shared
//! block Lanczos ([`super::lanczos`], same checkpoint scheduling, wanted pairs = largest
//! `|theta|`). On the bunny the orthogonalisation shrinks, but the extra factorisations and the
//! global Rayleigh-Ritz over all slice vectors eat most of the gain, and the residuals are
//! larger (the eigenvalues agree to rounding; figures in the crate's `PERFORMANCE.md`). Off by
//! default (`EigenSettings::slice_size = 0`).

use std::time::Instant;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::matmul::matmul;
use faer::sparse::SparseColMat;
use faer::sparse::linalg::cholesky::{
    SymbolicCholesky, SymbolicCholeskyRaw, factorize_symbolic_cholesky, simplicial, supernodal,
};
use faer::{Accum, Conj, Mat, MatMut, Par, Side};

use super::assembly::LboMatrices;
use super::eigen::{EigenSettings, Eigenpairs, SolveReport, sort_pairs, weyl_spacing};
use super::lanczos::{Lanczos, PhaseTimes, next_checkpoint, worst_ratio};
use crate::error::{Error, Result};

/// One numeric `LDL^T` factor of `L - mu M` with its inertia.
struct ShiftFactor {
    values: Vec<f64>,
    /// Number of negative pivots: eigenvalues below the shift.
    below: usize,
}

/// Factors `a` (with the given diagonal) and counts negative pivots.
fn factor_ldlt(
    symbolic: &SymbolicCholesky<usize>,
    a: &SparseColMat<usize, f64>,
    par: Par,
) -> Result<ShiftFactor> {
    let mut values = vec![0.0; symbolic.len_val()];
    let mut mem =
        MemBuffer::new(symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()));
    symbolic
        .factorize_numeric_ldlt(
            &mut values,
            a.as_ref(),
            Side::Lower,
            LdltRegularization::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .map_err(|e| Error::lbo(format!("LDL^T of L - mu M failed: {e:?}")))?;
    let mut below = 0;
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let ld = simplicial::SimplicialLdltRef::new(s, &values);
            let factor = faer::sparse::SparseColMatRef::new(s.factor(), ld.values());
            for j in 0..s.ncols() {
                for (i, &x) in factor.row_idx_of_col(j).zip(factor.val_of_col(j)) {
                    if i == j && x < 0.0 {
                        below += 1;
                    }
                }
            }
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let ld = supernodal::SupernodalLdltRef::new(s, &values);
            for sn in 0..s.n_supernodes() {
                let block = ld.supernode(sn).val();
                for i in 0..block.ncols() {
                    if block[(i, i)] < 0.0 {
                        below += 1;
                    }
                }
            }
        }
    }
    Ok(ShiftFactor { values, below })
}

/// The exact number of eigenvalues of `L phi = lambda M phi` below `mu`: the negative pivots of
/// an `LDL^T` factorisation of `L - mu M` (Sylvester's law of inertia; `M` is positive).
///
/// # Errors
/// [`Error::Lbo`] when the factorisation fails (`mu` numerically an eigenvalue).
pub(crate) fn count_below(matrices: &LboMatrices, mu: f64, par: Par) -> Result<usize> {
    Ok(ShiftedPencil::new(matrices, par)?.factor(mu)?.below)
}

/// `L - mu M` for any shift `mu`, sharing one symbolic analysis: `a` keeps L's pattern (the
/// diagonal is always present) and gets its values refilled per shift.
struct ShiftedPencil<'a> {
    a: SparseColMat<usize, f64>,
    /// Where each column's diagonal entry sits in `a`'s values.
    diag_pos: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// L's values.
    l_values: Vec<f64>,
    mass: &'a [f64],
    par: Par,
}

impl<'a> ShiftedPencil<'a> {
    fn new(matrices: &'a LboMatrices, par: Par) -> Result<Self> {
        let l = matrices.stiffness.as_ref();
        let col_ptr = l.col_ptr();
        let diag_pos = (0..matrices.vertex_count())
            .map(|j| {
                let rows = l.row_idx_of_col_raw(j);
                let p =
                    rows.iter().position(|&i| i == j).ok_or_else(|| Error::lbo("no diagonal"))?;
                Ok(col_ptr[j] + p)
            })
            .collect::<Result<Vec<_>>>()?;
        let a = matrices.stiffness.clone();
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            faer::sparse::linalg::cholesky::SymmetricOrdering::Amd,
            Default::default(),
        )
        .map_err(|e| Error::lbo(format!("symbolic factorisation failed: {e:?}")))?;
        let l_values = matrices.stiffness.val().to_vec();
        Ok(Self { a, diag_pos, symbolic, l_values, mass: &matrices.mass, par })
    }

    /// The `LDL^T` factor of `L - mu M`.
    fn factor(&mut self, mu: f64) -> Result<ShiftFactor> {
        let vals = self.a.val_mut();
        vals.copy_from_slice(&self.l_values);
        for (j, &p) in self.diag_pos.iter().enumerate() {
            vals[p] -= mu * self.mass[j];
        }
        factor_ldlt(&self.symbolic, &self.a, self.par)
    }
}

/// The columns of every slice's vectors side by side.
fn concat_columns(n: usize, blocks: &[Mat<f64>]) -> Mat<f64> {
    let total = blocks.iter().map(Mat::ncols).sum();
    let mut x = Mat::<f64>::zeros(n, total);
    let mut col = 0;
    for v in blocks {
        x.as_mut().subcols_mut(col, v.ncols()).copy_from(v);
        col += v.ncols();
    }
    x
}

/// The sliced solve (see the module documentation). Called by
/// [`super::smallest_eigenpairs`] for large `k`.
pub(crate) fn sliced_eigenpairs(
    matrices: &LboMatrices,
    k: usize,
    settings: &EigenSettings,
) -> Result<(Eigenpairs, SolveReport)> {
    let start = Instant::now();
    let n = matrices.vertex_count();
    let par = settings.parallelism();
    let weyl = weyl_spacing(matrices);
    let sigma = settings.shift_factor * weyl;
    let q = settings.slice_size.max(8);
    let b = settings.block_size.min(q / 2).max(8);

    let mut pencil = ShiftedPencil::new(matrices, par)?;
    let sqrt_m: Vec<f64> = matrices.mass.iter().map(|m| m.sqrt()).collect();
    let mut times = PhaseTimes::default();
    // Slightly irrational step so shifts do not land on the integer spectrum of a unit sphere.
    let mut step = q as f64 * weyl * 1.0137;
    let mut lower = (sigma, 0usize);
    let mut found: Vec<Mat<f64>> = Vec::new();
    let mut factor_seconds = 0.0;
    let mut ritz_checks = 0;
    let mut max_basis_used = 0;
    while lower.1 < k {
        let t = Instant::now();
        let mut upper = lower.0 + step;
        let mut below = pencil.factor(upper)?.below;
        // Too many eigenvalues in the slice: shrink the step until the count is reasonable.
        while below - lower.1 > 2 * q {
            step *= 0.5;
            upper = lower.0 + step;
            below = pencil.factor(upper)?.below;
        }
        let count = below - lower.1;
        if count > 0 {
            // Solve at the slice's midpoint: its far ends are half a slice away.
            let mu = 0.5 * (lower.0 + upper);
            let f = pencil.factor(mu)?;
            factor_seconds += t.elapsed().as_secs_f64();
            let (vectors, basis, checks) = slice_lanczos(
                &pencil.symbolic,
                &f,
                &sqrt_m,
                mu,
                (lower.0, upper),
                count,
                b,
                settings,
                settings.seed.wrapping_add(found.len() as u64),
                par,
                &mut times,
            )?;
            ritz_checks += checks;
            max_basis_used = max_basis_used.max(basis);
            found.push(vectors);
            step *= (q as f64 / count as f64).clamp(0.5, 2.0);
        } else {
            factor_seconds += t.elapsed().as_secs_f64();
            step *= 2.0;
        }
        lower = (upper, below);
    }

    // Global Rayleigh-Ritz over all slices.
    let x = concat_columns(n, &found);
    drop(found);
    let pairs = global_rayleigh_ritz(matrices, &x, k, par)?;
    let report = SolveReport {
        dense: false,
        shift: sigma,
        basis_size: max_basis_used,
        ritz_checks,
        factor_seconds,
        solve_seconds: times.solve,
        orthogonalize_seconds: times.orthogonalize,
        ritz_seconds: times.ritz,
        total_seconds: start.elapsed().as_secs_f64(),
        ..Default::default()
    };
    Ok((pairs, report))
}

/// Block Lanczos for one shift `mu`: returns the `count` converged eigenvectors (as `phi`,
/// M-normed) with eigenvalues in `[lo, hi)`, the basis size used and the number of Ritz checks;
/// adds its phase times to `times`.
#[allow(clippy::too_many_arguments)]
fn slice_lanczos(
    symbolic: &SymbolicCholesky<usize>,
    f: &ShiftFactor,
    sqrt_m: &[f64],
    mu: f64,
    (lo, hi): (f64, f64),
    count: usize,
    b: usize,
    settings: &EigenSettings,
    seed: u64,
    par: Par,
    times: &mut PhaseTimes,
) -> Result<(Mat<f64>, usize, usize)> {
    let n = sqrt_m.len();
    let ldlt = faer::sparse::linalg::cholesky::LdltRef::new(symbolic, &f.values);
    let solve = |w: MatMut<'_, f64>| {
        let mut mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(w.ncols(), par));
        ldlt.solve_in_place_with_conj(Conj::No, w, par, MemStack::new(&mut mem));
    };
    let max_basis = ((settings.max_basis_factor * (2 * count) as f64) as usize)
        .max(2 * count + 40 * b)
        .min(n / 2)
        / b
        * b;
    let mut lz = Lanczos::new(&solve, sqrt_m, b, max_basis, seed, par);
    // The wanted pairs are those with the largest |theta| (eigenvalues nearest mu); the
    // interval's ends need a basis of a few times `count`.
    let mut next_check = (2 * count).max(count + 2 * b).min(max_basis);
    let mut history = None;
    let mut checks = 0;
    loop {
        lz.step();
        let m = lz.len() - b;
        if m < next_check && lz.len() <= max_basis {
            continue;
        }
        checks += 1;
        let ritz = lz.ritz(m, true)?;
        // Converged Ritz pairs whose eigenvalue mu + 1/theta lies in [lo, hi).
        let chosen: Vec<usize> = (0..m)
            .filter(|&i| {
                let theta = ritz.values[i];
                (lo..hi).contains(&(mu + 1.0 / theta))
                    && ritz.residuals[i] <= settings.tolerance * theta.abs()
            })
            .collect();
        if chosen.len() >= count {
            let y = Mat::<f64>::from_fn(m, chosen.len(), |i, j| ritz.vectors[(i, chosen[j])]);
            let mut phi = Mat::<f64>::zeros(n, chosen.len());
            matmul(phi.as_mut(), Accum::Replace, lz.basis(), &y, 1.0, par);
            for j in 0..phi.ncols() {
                for (x, si) in phi.col_as_slice_mut(j).iter_mut().zip(sqrt_m) {
                    *x /= si;
                }
            }
            add_times(times, &lz.times);
            return Ok((phi, m, checks));
        }
        if lz.len() > max_basis {
            return Err(Error::lbo(format!(
                "slice [{lo:.4e}, {hi:.4e}): only {} of {count} eigenpairs converged within \
                 a basis of {m} vectors; raise max_basis_factor",
                chosen.len()
            )));
        }
        let worst = worst_ratio(&ritz, count, settings.tolerance);
        next_check = next_checkpoint(m, worst, history, b, max_basis);
        history = Some((m, worst));
    }
}

fn add_times(total: &mut PhaseTimes, run: &PhaseTimes) {
    total.solve += run.solve;
    total.orthogonalize += run.orthogonalize;
    total.ritz += run.ritz;
}

/// M-orthonormalises the columns of `x` together (dropping numerically dependent directions)
/// and returns the `k` smallest Ritz pairs of `L` in that space.
fn global_rayleigh_ritz(
    matrices: &LboMatrices,
    x: &Mat<f64>,
    k: usize,
    par: Par,
) -> Result<Eigenpairs> {
    let n = x.nrows();
    let kk = x.ncols();
    let mut mx = x.clone();
    for j in 0..kk {
        for (v, m) in mx.col_as_slice_mut(j).iter_mut().zip(&matrices.mass) {
            *v *= m;
        }
    }
    let mut g = Mat::<f64>::zeros(kk, kk);
    matmul(g.as_mut(), Accum::Replace, x.transpose(), &mx, 1.0, par);
    drop(mx);
    let ge = g
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::lbo(format!("eigen of the Gram matrix: {e:?}")))?;
    let gs = ge.S().column_vector();
    let gmax = (0..kk).map(|i| gs[i]).fold(0.0, f64::max);
    let keep: Vec<usize> = (0..kk).filter(|&i| gs[i] > 1e-10 * gmax).collect();
    if keep.len() < k {
        return Err(Error::lbo(format!(
            "spectrum slicing found only {} independent eigenvectors of {k}",
            keep.len()
        )));
    }
    // Z = X W, W = U_keep diag(g^-1/2): M-orthonormal.
    let wmat =
        Mat::<f64>::from_fn(kk, keep.len(), |i, j| ge.U()[(i, keep[j])] / gs[keep[j]].sqrt());
    let lx = matrices.stiffness_times(x.as_ref(), par);
    let mut xlx = Mat::<f64>::zeros(kk, kk);
    matmul(xlx.as_mut(), Accum::Replace, x.transpose(), &lx, 1.0, par);
    drop(lx);
    let proj = wmat.transpose() * &xlx * &wmat;
    let pe = proj
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::lbo(format!("eigen of the projected stiffness: {e:?}")))?;
    let ps = pe.S().column_vector();
    let coeff = &wmat * pe.U().subcols(0, k);
    let mut phi = Mat::<f64>::zeros(n, k);
    matmul(phi.as_mut(), Accum::Replace, x.as_ref(), &coeff, 1.0, par);
    let values = (0..k).map(|i| ps[i]).collect();
    Ok(sort_pairs(values, phi))
}
