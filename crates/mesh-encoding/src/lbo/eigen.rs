//! The generalized symmetric eigensolver for the `k` smallest pairs of `L phi = lambda M phi`:
//! shift-invert **block Lanczos with full reorthogonalisation** on one sparse Cholesky factor.
//!
//! # Method
//! `M` is diagonal (lumped), so with `D = M^(-1/2)` the problem is the standard symmetric one
//! `C x = lambda x`, `C = D L D`, `phi = D x`. The solver
//! 1. factors `A = L - sigma M` once (faer's supernodal sparse Cholesky with its AMD ordering);
//!    `sigma < 0` is a small negative shift (default `-0.01 * 4 pi / area`, a hundredth of the
//!    Weyl spacing of the eigenvalues) so `A` is positive definite even though `L` is singular
//!    (one constant null vector per connected component);
//! 2. runs block Lanczos on the operator `Op = M^(1/2) A^-1 M^(1/2) = (C - sigma)^-1`, whose largest
//!    eigenvalues `theta = 1 / (lambda - sigma)` are the wanted smallest `lambda`. Each step
//!    solves one block of `b` right-hand sides (default 32) at once, so the factor is streamed
//!    through the cache once per block rather than once per vector, and orthogonalises the new
//!    block twice (block classical Gram-Schmidt, GEMM) against the whole basis: no loss of
//!    orthogonality, no spurious copies, no restarts;
//! 3. does Rayleigh-Ritz on the projected block-tridiagonal matrix (faer's dense self-adjoint
//!    eigen) from the moment the basis holds `k + 2b` vectors, then every few blocks, until the
//!    Lanczos residual `|R_j y_last|` of each of the `k` wanted Ritz pairs is below
//!    `tolerance * theta` (the eigenvalue error is then of order `tolerance^2`);
//! 4. forms the Ritz vectors with one GEMM, maps them back (`phi = D x`, so `Phi^T M Phi = I`
//!    to rounding) and replaces each eigenvalue by its Rayleigh quotient `phi^T L phi`.
//!
//! # Why this method
//! The cost of the plain shift-invert Lanczos recipe (ARPACK, or faer's Krylov-Schur on a
//! user operator) is dominated by hundreds of single-vector triangular solves, each streaming a
//! factor of tens of MB through memory, plus BLAS-2 orthogonalisation. Here the solves come in
//! blocks (far fewer passes over the factor) and everything else is BLAS-3: the basis
//! orthogonalisation (`4 n m^2` flops for a basis of `m` vectors), the Ritz vectors (`2 n m k`)
//! and the dense projected eigenproblem (`O(m^3)`). Block Krylov needs a somewhat larger basis
//! than single-vector Lanczos for the same accuracy (the polynomial degree is `m / b`), which
//! the GEMM speed more than pays for; keeping the whole basis (no restart) costs `8 n m` bytes,
//! about 0.4 GB for 35k vertices and 513 pairs. LOBPCG was the alternative: it needs a
//! preconditioner of comparable cost and many more iterations for 513 clustered pairs.
//! Measured timings are in the crate's `lbo_bench` example and the project notes.
//!
//! Small problems (when a basis of `k + 3b` vectors would exceed half the vertices) go to the
//! dense reference solver [`dense_eigenpairs`] instead.

use std::time::Instant;

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

use super::assembly::LboMatrices;
use crate::error::{Error, Result};

/// Settings of [`smallest_eigenpairs`]. They are part of the eigenpair cache key.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EigenSettings {
    /// Largest number of vectors per Lanczos block (default 32; the solver uses at most `k / 8`,
    /// at least 8). Larger blocks make the solves and GEMMs more efficient but need a larger
    /// basis.
    pub block_size: usize,
    /// Convergence tolerance on the relative Lanczos residual `|Op x - theta x| / theta`
    /// (default 1e-9).
    pub tolerance: f64,
    /// Largest basis before giving up, as a multiple of `k` (default 6.0, at least `k` plus 40
    /// blocks); the basis never exceeds half the vertex count.
    pub max_basis_factor: f64,
    /// Shift `sigma` as a multiple of the Weyl spacing `4 pi / area` (default -0.01; must be
    /// negative so that `L - sigma M` is positive definite).
    pub shift_factor: f64,
    /// Seed of the random start block (default 0x5eed).
    pub seed: u64,
    /// Target eigenvalues per slice of the spectrum-slicing solver (`super::slicing`, exact
    /// eigenvalue counts by inertia); used when `k > 2 * slice_size`. Default 0: off, one shift
    /// (faster in the measurements so far).
    pub slice_size: usize,
}

impl Default for EigenSettings {
    fn default() -> Self {
        EigenSettings {
            block_size: 32,
            tolerance: 1e-9,
            max_basis_factor: 6.0,
            shift_factor: -0.01,
            seed: 0x5eed,
            slice_size: 0,
        }
    }
}

/// The `k` smallest eigenpairs of `L phi = lambda M phi`.
#[derive(Debug, Clone)]
pub struct Eigenpairs {
    /// Eigenvalues in ascending order (the first is 0 up to rounding, one per connected
    /// component).
    pub values: Vec<f64>,
    /// Eigenvectors as the columns of an `n x k` matrix, M-orthonormal (`Phi^T M Phi = I`); the
    /// sign of each column is arbitrary.
    pub vectors: Mat<f64>,
}

impl Eigenpairs {
    /// Number of pairs `k`.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// True when there are no pairs.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Number of vertices `n`.
    pub fn vertex_count(&self) -> usize {
        self.vectors.nrows()
    }

    /// The relative residuals `|L phi_i - lambda_i M phi_i|_{M^-1} / max(lambda_i, 4 pi / area)`
    /// of every pair (the `M^-1` norm is the Euclidean norm of the standard form `D L D`).
    pub fn relative_residuals(&self, matrices: &LboMatrices) -> Vec<f64> {
        let scale = weyl_spacing(matrices);
        let mut lphi = Mat::<f64>::zeros(self.vertex_count(), self.len());
        faer::sparse::linalg::matmul::sparse_dense_matmul(
            lphi.as_mut(),
            Accum::Replace,
            matrices.stiffness.as_ref(),
            self.vectors.as_ref(),
            1.0,
            Par::Seq,
        );
        (0..self.len())
            .map(|j| {
                let lambda = self.values[j];
                let r2: f64 = (0..self.vertex_count())
                    .map(|i| {
                        let m = matrices.mass[i];
                        let r = lphi[(i, j)] - lambda * m * self.vectors[(i, j)];
                        r * r / m
                    })
                    .sum();
                r2.sqrt() / lambda.abs().max(scale)
            })
            .collect()
    }

    /// `max |Phi^T M Phi - I|` over all entries.
    pub fn orthonormality_error(&self, mass: &[f64]) -> f64 {
        let mut mphi = self.vectors.clone();
        for j in 0..mphi.ncols() {
            for (x, m) in mphi.col_as_slice_mut(j).iter_mut().zip(mass) {
                *x *= m;
            }
        }
        let gram = self.vectors.transpose() * &mphi;
        let k = self.len();
        let mut err = 0.0f64;
        for j in 0..k {
            for i in 0..k {
                let target = if i == j { 1.0 } else { 0.0 };
                err = err.max((gram[(i, j)] - target).abs());
            }
        }
        err
    }
}

/// How a solve went.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveReport {
    /// True when the dense reference solver was used (small problems).
    pub dense: bool,
    /// The shift `sigma`.
    pub shift: f64,
    /// Final Lanczos basis size (0 for the dense path).
    pub basis_size: usize,
    /// Number of Rayleigh-Ritz checks.
    pub ritz_checks: usize,
    /// Seconds spent in the symbolic and numeric factorisation.
    pub factor_seconds: f64,
    /// Seconds of the whole solve.
    pub total_seconds: f64,
}

/// `4 pi / area`: Weyl's law gives `lambda_j ~ j * 4 pi / area` on a closed surface.
pub(crate) fn weyl_spacing(matrices: &LboMatrices) -> f64 {
    4.0 * std::f64::consts::PI / matrices.total_mass()
}

/// The `k` smallest eigenpairs of `L phi = lambda M phi` by shift-invert block Lanczos (see
/// the module documentation), or by the dense solver for small problems.
///
/// # Errors
/// [`Error::Lbo`] when `k` is 0 or exceeds the vertex count, the settings are invalid, the
/// factorisation fails, or the basis limit is reached before convergence.
pub fn smallest_eigenpairs(
    matrices: &LboMatrices,
    k: usize,
    settings: &EigenSettings,
) -> Result<(Eigenpairs, SolveReport)> {
    let start = Instant::now();
    let n = matrices.vertex_count();
    if k == 0 || k > n {
        return Err(Error::lbo(format!("cannot compute {k} eigenpairs of a {n}-vertex mesh")));
    }
    let positive = |x: f64| x > 0.0;
    if settings.block_size == 0
        || !positive(settings.tolerance)
        || !positive(-settings.shift_factor)
    {
        return Err(Error::lbo(format!("invalid eigen-solver settings {settings:?}")));
    }
    // A block much wider than k / 8 would leave too few Krylov steps (the polynomial degree).
    let b = settings.block_size.min((k / 8).max(8));
    let shift = settings.shift_factor * weyl_spacing(matrices);
    let max_basis =
        ((settings.max_basis_factor * k as f64) as usize).max(k + 40 * b).min(n / 2) / b * b;
    if k + 3 * b > n / 2 || max_basis < k + 2 * b {
        let pairs = dense_eigenpairs(matrices, k)?;
        let report = SolveReport {
            dense: true,
            shift: 0.0,
            basis_size: 0,
            ritz_checks: 0,
            factor_seconds: 0.0,
            total_seconds: start.elapsed().as_secs_f64(),
        };
        return Ok((pairs, report));
    }
    if settings.slice_size > 0 && k > 2 * settings.slice_size {
        return super::slicing::sliced_eigenpairs(matrices, k, settings);
    }

    // 1. Factor A = L - sigma M.
    let par = faer::get_global_parallelism();
    let factor_start = Instant::now();
    let a = shifted_stiffness(matrices, shift)?;
    let symbolic = SymbolicLlt::try_new(a.symbolic(), Side::Lower)
        .map_err(|e| Error::lbo(format!("symbolic Cholesky failed: {e:?}")))?;
    let llt = Llt::try_new_with_symbolic(symbolic, a.as_ref(), Side::Lower)
        .map_err(|e| Error::lbo(format!("Cholesky of L - sigma M failed: {e:?}")))?;
    drop(a);
    let factor_seconds = factor_start.elapsed().as_secs_f64();
    let sqrt_m: Vec<f64> = matrices.mass.iter().map(|m| m.sqrt()).collect();
    let d: Vec<f64> = sqrt_m.iter().map(|s| 1.0 / s).collect();

    // 2. Block Lanczos with full reorthogonalisation.
    let mut v = Mat::<f64>::zeros(n, max_basis + b);
    let mut h = Mat::<f64>::zeros(max_basis + b, max_basis + b);
    let mut rng = SplitMix64(settings.seed);
    let mut w = Mat::<f64>::from_fn(n, b, |_, _| rng.uniform());
    let r0 = orthonormalize_block(v.as_ref().subcols(0, 0), w.as_mut(), &mut rng, par);
    drop(r0);
    v.as_mut().subcols_mut(0, b).copy_from(&w);

    let first_check = k + 2 * b;
    let mut next_check = first_check;
    let mut ritz_checks = 0;
    let mut m = b; // basis size after the current block
    loop {
        let cur = m - b;
        // W = Op V_j = M^(1/2) A^-1 M^(1/2) V_j
        for j in 0..b {
            let src = v.col_as_slice(cur + j);
            for ((dst, s), si) in w.col_as_slice_mut(j).iter_mut().zip(src).zip(&sqrt_m) {
                *dst = s * si;
            }
        }
        llt.solve_in_place(w.as_mut());
        for j in 0..b {
            for (x, si) in w.col_as_slice_mut(j).iter_mut().zip(&sqrt_m) {
                *x *= si;
            }
        }
        // Two passes of block Gram-Schmidt against the whole basis, then QR of the rest.
        let basis = v.as_ref().subcols(0, m);
        for _ in 0..2 {
            let coeff = basis.transpose() * &w;
            matmul(w.as_mut(), Accum::Add, basis, &coeff, -1.0, par);
            let mut hcol = h.as_mut().submatrix_mut(0, cur, m, b);
            hcol += &coeff;
        }
        let r = orthonormalize_block(basis, w.as_mut(), &mut rng, par);
        h.as_mut().submatrix_mut(m, cur, b, b).copy_from(&r);

        if m >= next_check || m + b > max_basis {
            ritz_checks += 1;
            let ritz = rayleigh_ritz(h.as_ref(), m, b, k)?;
            let converged = ritz
                .values
                .iter()
                .zip(&ritz.residuals)
                .all(|(theta, res)| *res <= settings.tolerance * theta.abs());
            if converged {
                let pairs = finish(matrices, v.as_ref().subcols(0, m), &ritz, &d, shift, par);
                let report = SolveReport {
                    dense: false,
                    shift,
                    basis_size: m,
                    ritz_checks,
                    factor_seconds,
                    total_seconds: start.elapsed().as_secs_f64(),
                };
                return Ok((pairs, report));
            }
            if m + b > max_basis {
                let worst = ritz
                    .values
                    .iter()
                    .zip(&ritz.residuals)
                    .map(|(t, r)| r / t.abs())
                    .fold(0.0, f64::max);
                return Err(Error::lbo(format!(
                    "block Lanczos did not converge for {k} pairs within a basis of {m} \
                     vectors (worst relative residual {worst:.2e}); raise max_basis_factor"
                )));
            }
            // Unconverged pairs sit at the end of the wanted range; grow by a tenth of k.
            next_check = m + (k / 10).max(b).div_ceil(b) * b;
        }
        v.as_mut().subcols_mut(m, b).copy_from(&w);
        m += b;
    }
}

/// `L - sigma M` as a sparse matrix (both triangles).
fn shifted_stiffness(matrices: &LboMatrices, shift: f64) -> Result<SparseColMat<usize, f64>> {
    let l = matrices.stiffness.as_ref();
    let n = matrices.vertex_count();
    let mut triplets = Vec::with_capacity(l.compute_nnz() + n);
    for j in 0..n {
        for (i, &x) in l.row_idx_of_col(j).zip(l.val_of_col(j)) {
            triplets.push(Triplet::new(i, j, x));
        }
        triplets.push(Triplet::new(j, j, -shift * matrices.mass[j]));
    }
    SparseColMat::try_new_from_triplets(n, n, &triplets)
        .map_err(|e| Error::lbo(format!("cannot build L - sigma M: {e:?}")))
}

/// Householder QR of `w` in place (`w` becomes `Q`), returning `R`. Columns that are (near)
/// linearly dependent are replaced by random vectors orthogonal to `basis` and to the other
/// columns, with a zero row in `R`: the Krylov space has become invariant there.
pub(crate) fn orthonormalize_block(
    basis: MatRef<'_, f64>,
    mut w: MatMut<'_, f64>,
    rng: &mut SplitMix64,
    par: Par,
) -> Mat<f64> {
    let b = w.ncols();
    let qr = w.as_ref().qr();
    let mut r = qr.thin_R().to_owned();
    let q = qr.compute_thin_Q();
    w.copy_from(&q);
    let scale = (0..b).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    for i in 0..b {
        if r[(i, i)].abs() > 1e-10 * scale && scale > 0.0 {
            continue;
        }
        for j in 0..b {
            r[(i, j)] = 0.0;
        }
        let n = w.nrows();
        let mut x = Mat::<f64>::from_fn(n, 1, |_, _| rng.uniform());
        for _ in 0..2 {
            if basis.ncols() > 0 {
                let c = basis.transpose() * &x;
                matmul(x.as_mut(), Accum::Add, basis, &c, -1.0, par);
            }
            let others = w.as_ref();
            let c = others.transpose() * &x;
            // Exclude column i itself from the projection.
            let mut c = c;
            c[(i, 0)] = 0.0;
            matmul(x.as_mut(), Accum::Add, others, &c, -1.0, par);
        }
        let norm = x.col(0).norm_l2();
        w.as_mut().col_mut(i).copy_from(x.col(0) / norm);
    }
    r
}

/// Ritz values (the `k` largest `theta`, descending), their coefficient vectors in the basis and
/// their Lanczos residual norms.
struct Ritz {
    values: Vec<f64>,
    vectors: Mat<f64>,
    residuals: Vec<f64>,
}

/// Rayleigh-Ritz on the projected matrix `H[0..m, 0..m]` (symmetrised).
fn rayleigh_ritz(h: MatRef<'_, f64>, m: usize, b: usize, k: usize) -> Result<Ritz> {
    let t = Mat::<f64>::from_fn(m, m, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
    let eig = t
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::lbo(format!("dense eigen of the projected matrix failed: {e:?}")))?;
    let s = eig.S().column_vector();
    let u = eig.U();
    // Ascending order: the k largest are the last k; take them largest first.
    let cols: Vec<usize> = (m - k..m).rev().collect();
    let values: Vec<f64> = cols.iter().map(|&c| s[c]).collect();
    let vectors = Mat::<f64>::from_fn(m, k, |i, j| u[(i, cols[j])]);
    let coupling = h.submatrix(m, m - b, b, b);
    let last = vectors.as_ref().subrows(m - b, b);
    let res = coupling * last;
    let residuals = (0..k).map(|j| res.col(j).norm_l2()).collect();
    Ok(Ritz { values, vectors, residuals })
}

/// Ritz vectors, back-transformation and Rayleigh-quotient eigenvalues, sorted ascending.
fn finish(
    matrices: &LboMatrices,
    basis: MatRef<'_, f64>,
    ritz: &Ritz,
    d: &[f64],
    shift: f64,
    par: Par,
) -> Eigenpairs {
    let n = basis.nrows();
    let k = ritz.values.len();
    let mut phi = Mat::<f64>::zeros(n, k);
    matmul(phi.as_mut(), Accum::Replace, basis, &ritz.vectors, 1.0, par);
    for j in 0..k {
        for (x, di) in phi.col_as_slice_mut(j).iter_mut().zip(d) {
            *x *= di;
        }
    }
    let mut lphi = Mat::<f64>::zeros(n, k);
    faer::sparse::linalg::matmul::sparse_dense_matmul(
        lphi.as_mut(),
        Accum::Replace,
        matrices.stiffness.as_ref(),
        phi.as_ref(),
        1.0,
        par,
    );
    let values: Vec<f64> = (0..k)
        .map(|j| {
            let num: f64 =
                phi.col_as_slice(j).iter().zip(lphi.col_as_slice(j)).map(|(a, b)| a * b).sum();
            let den: f64 =
                phi.col_as_slice(j).iter().zip(&matrices.mass).map(|(a, m)| a * a * m).sum();
            let rq = num / den;
            // The Rayleigh quotient is second-order accurate; fall back to the Ritz value if
            // rounding made it meaningless.
            if rq.is_finite() { rq } else { shift + 1.0 / ritz.values[j] }
        })
        .collect();
    sort_pairs(values, phi)
}

/// Sorts eigenpairs by ascending eigenvalue.
pub(crate) fn sort_pairs(values: Vec<f64>, vectors: Mat<f64>) -> Eigenpairs {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let sorted = Mat::<f64>::from_fn(vectors.nrows(), order.len(), |i, j| vectors[(i, order[j])]);
    Eigenpairs { values: order.iter().map(|&j| values[j]).collect(), vectors: sorted }
}

/// Dense reference solver: all eigenpairs of `D L D` by faer's dense self-adjoint eigen, the
/// `k` smallest returned. `O(n^3)` time and `O(n^2)` memory: for small meshes and tests.
///
/// # Errors
/// [`Error::Lbo`] when `k` is 0 or exceeds the vertex count, or the dense eigen fails.
pub fn dense_eigenpairs(matrices: &LboMatrices, k: usize) -> Result<Eigenpairs> {
    let n = matrices.vertex_count();
    if k == 0 || k > n {
        return Err(Error::lbo(format!("cannot compute {k} eigenpairs of a {n}-vertex mesh")));
    }
    let d: Vec<f64> = matrices.mass.iter().map(|m| 1.0 / m.sqrt()).collect();
    let mut c = Mat::<f64>::zeros(n, n);
    let l = matrices.stiffness.as_ref();
    for j in 0..n {
        for (i, &x) in l.row_idx_of_col(j).zip(l.val_of_col(j)) {
            c[(i, j)] += d[i] * x * d[j];
        }
    }
    let eig = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::lbo(format!("dense eigen failed: {e:?}")))?;
    let s = eig.S().column_vector();
    let u = eig.U();
    let vectors = Mat::<f64>::from_fn(n, k, |i, j| d[i] * u[(i, j)]);
    let values = (0..k).map(|j| s[j]).collect();
    Ok(sort_pairs(values, vectors))
}

/// Small deterministic generator for the start block (SplitMix64).
pub(crate) struct SplitMix64(pub(crate) u64);

impl SplitMix64 {
    /// Uniform in [-1, 1).
    pub(crate) fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}
