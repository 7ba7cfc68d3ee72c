//! The generalized symmetric eigensolver for the `k` smallest pairs of `L phi = lambda M phi`:
//! shift-invert **block Lanczos with full reorthogonalisation** on one sparse Cholesky factor,
//! with an exact **inertia check** that no eigenvalue was missed.
//!
//! # Method
//! `M` is diagonal (lumped), so with `D = M^(-1/2)` the problem is the standard symmetric one
//! `C x = lambda x`, `C = D L D`, `phi = D x`. The solver
//! 1. factors `A = L - sigma M` once (faer's supernodal sparse Cholesky with its AMD ordering);
//!    `sigma < 0` is a small negative shift (default `-0.01 * 4 pi / area`, a hundredth of the
//!    Weyl spacing of the eigenvalues) so `A` is positive definite even though `L` is singular
//!    (one constant null vector per connected component);
//! 2. runs block Lanczos (`super::lanczos`) on `Op = M^(1/2) A^-1 M^(1/2) = (C - sigma)^-1`,
//!    whose largest eigenvalues `theta = 1 / (lambda - sigma)` are the wanted smallest `lambda`.
//!    Each step solves one block of `b` right-hand sides (default 16) at once, projects out the
//!    last two blocks (the three-term recurrence), then orthogonalises once against the whole
//!    basis with two GEMMs (a second pass only when the DGKS test asks for it; it never did on
//!    the meshes measured). Rayleigh-Ritz on the projected matrix runs at a few checkpoints
//!    (the first at `2.5 k` vectors, later ones extrapolated from the residual decay) until the
//!    Lanczos residual `|R_j y_last|` of each of the `k` wanted Ritz pairs is below
//!    `tolerance * theta` (the eigenvalue error is then of order `tolerance^2`);
//! 3. forms the Ritz vectors with one GEMM, maps them back (`phi = D x`, so `Phi^T M Phi = I`
//!    to rounding) and replaces each eigenvalue by its Rayleigh quotient `phi^T L phi`;
//! 4. checks completeness: one sparse `LDL^T` of `L - mu M` with `mu` in a gap just below the
//!    largest returned eigenvalue gives, by Sylvester's law of inertia, the exact number of
//!    eigenvalues below `mu`; it must equal the number of returned values below `mu` (reported
//!    in [`SolveReport::inertia`]). On a mismatch (a cluster wider than the block can lose a
//!    member) the solve is retried with doubled blocks and another start block.
//!
//! # Why this method
//! The plain shift-invert Lanczos recipe (ARPACK) is dominated by hundreds of single-vector
//! triangular solves and BLAS-2 orthogonalisation. Here solves come in blocks and everything
//! else is BLAS-3. With 513 pairs the cost is the orthogonalisation (`2 n m^2` flops for a final
//! basis of `m` vectors, about `2.9 k` with blocks of 16): the solves are a sixth of the time and
//! the factorisation under 1 %. Keeping the whole basis (no restart) costs `8 n m` bytes. Blocks
//! of 16 gave the smallest time on the bunny (8: smaller basis but slower narrow GEMMs; 24-64:
//! larger basis). Spectrum slicing (`super::slicing`, `slice_size > 0`) is an alternative
//! with a smaller orthogonalisation cost but more factorisations and a global Rayleigh-Ritz;
//! it was not faster at 513 pairs. Figures and how they were measured: `PERFORMANCE.md`.
//!
//! Small problems go to the dense reference solver [`dense_eigenpairs`] instead: when a basis of
//! `3 k` vectors (what Lanczos needs for k pairs) would exceed half the vertices, and when Lanczos
//! does not converge on a mesh of at most [`DENSE_FALLBACK_VERTICES`] vertices.

use std::time::Instant;

use faer::linalg::matmul::matmul;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

use super::assembly::LboMatrices;
use super::lanczos::{Ritz, block_lanczos};
use crate::error::{Error, Result};
use stdx::rng::SplitMix64;

/// Settings of [`smallest_eigenpairs`]. They are part of the eigenpair cache key.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EigenSettings {
    /// Largest number of vectors per Lanczos block (default 16; the solver uses at most `k / 8`,
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
    /// Threads for faer's dense kernels inside the solver: 1 (default) sequential, 0 faer's
    /// global setting, `t > 1` a rayon pool of `t`. Not part of the cache key (results differ
    /// only by rounding). Sequential is the default because faer's rayon kernels were slower
    /// than sequential ones on a 2-core machine shared with other jobs (see `PERFORMANCE.md`).
    pub threads: usize,
    /// The bytes the Cholesky factor (and the Lanczos basis beside it) may take; a solve that
    /// would need more is refused before it allocates, with a decimation hint. `None` (the
    /// default): three quarters of the memory available when the solve starts (Linux's
    /// `MemAvailable`), else 8 GiB. Not part of the cache key (it decides only whether a solve
    /// may start).
    pub memory_budget: Option<u64>,
}

impl EigenSettings {
    /// The faer parallelism of [`EigenSettings::threads`].
    pub fn parallelism(&self) -> Par {
        match self.threads {
            0 => faer::get_global_parallelism(),
            1 => Par::Seq,
            t => Par::rayon(t),
        }
    }
}

impl Default for EigenSettings {
    fn default() -> Self {
        EigenSettings {
            block_size: 16,
            tolerance: 1e-9,
            max_basis_factor: 6.0,
            shift_factor: -0.01,
            seed: 0x5eed,
            slice_size: 0,
            threads: 1,
            memory_budget: None,
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
        let lphi = matrices.stiffness_times(self.vectors.as_ref(), Par::Seq);
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
#[derive(Debug, Clone, Default, PartialEq)]
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
    /// Seconds in the block triangular solves (Lanczos operator applications).
    pub solve_seconds: f64,
    /// Seconds in the orthogonalisation of the Lanczos blocks.
    pub orthogonalize_seconds: f64,
    /// Seconds in the Rayleigh-Ritz checks (dense eigen of the projected matrix).
    pub ritz_seconds: f64,
    /// Seconds in the completeness check (one sparse `LDL^T` factorisation).
    pub check_seconds: f64,
    /// The completeness check: a shift `mu` and the exact number of eigenvalues below it, which
    /// equals the number of returned values below `mu` (`None` when not checked).
    pub inertia: Option<(f64, usize)>,
    /// Seconds of the whole solve.
    pub total_seconds: f64,
}

/// `4 pi / area`: Weyl's law gives `lambda_j ~ j * 4 pi / area` on a closed surface.
pub(crate) fn weyl_spacing(matrices: &LboMatrices) -> f64 {
    4.0 * std::f64::consts::PI / matrices.total_mass()
}

/// Largest vertex count for which a Lanczos failure falls back to the dense solver (a dense
/// generalized eigenproblem of this size takes seconds).
pub const DENSE_FALLBACK_VERTICES: usize = 8_000;

/// Checks that `k` pairs of an `n`-vertex mesh can be computed with these settings.
fn check_request(k: usize, n: usize, settings: &EigenSettings) -> Result<()> {
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
    Ok(())
}

/// The dense solver's pairs with their report (the solve began at `start`).
fn dense_solve(
    matrices: &LboMatrices,
    k: usize,
    start: Instant,
) -> Result<(Eigenpairs, SolveReport)> {
    let pairs = dense_eigenpairs(matrices, k)?;
    let report = SolveReport {
        dense: true,
        total_seconds: start.elapsed().as_secs_f64(),
        ..Default::default()
    };
    Ok((pairs, report))
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
    check_request(k, n, settings)?;
    // A block much wider than k / 8 would leave too few Krylov steps (the polynomial degree).
    let b = settings.block_size.min((k / 8).max(8));
    let shift = settings.shift_factor * weyl_spacing(matrices);
    let max_basis =
        ((settings.max_basis_factor * k as f64) as usize).max(k + 40 * b).min(n / 2) / b * b;
    // Lanczos needs a basis of about 3 k vectors for k pairs (1,472 for 513 on the bunny); when
    // half the vertex count cannot hold that, the mesh is small and the dense solver is cheap.
    if k + 3 * b > n / 2 || max_basis < k + 2 * b || max_basis < 3 * k {
        return dense_solve(matrices, k, start);
    }
    if settings.slice_size > 0 && k > 2 * settings.slice_size {
        return super::slicing::sliced_eigenpairs(matrices, k, settings);
    }

    // 1. Factor A = L - sigma M.
    let par = settings.parallelism();
    let factor_start = Instant::now();
    let a = shifted_stiffness(matrices, shift)?;
    // The Lanczos basis the solve reserves beside the factor (n x (max_basis + b) values).
    let basis_bytes = (n as u64).saturating_mul((max_basis + b) as u64 * 8);
    let budget = settings.memory_budget;
    let llt = super::factor::CholeskyFactor::new(a.as_ref(), par, basis_bytes, budget)?;
    drop(a);
    let factor_seconds = factor_start.elapsed().as_secs_f64();
    let sqrt_m: Vec<f64> = matrices.mass.iter().map(|m| m.sqrt()).collect();
    let d: Vec<f64> = sqrt_m.iter().map(|s| 1.0 / s).collect();

    // 2. Block Lanczos; a failed completeness check (an eigenvalue missed, possible for
    //    clusters wider than the block) retries with a doubled block and another start.
    let mut b = b;
    let mut seed = settings.seed;
    loop {
        let run = match block_lanczos(&llt, &sqrt_m, k, b, max_basis, settings, seed, par) {
            Ok(run) => run,
            // A small mesh whose basis cap was too tight: the dense solver still answers.
            Err(_) if n <= DENSE_FALLBACK_VERTICES => return dense_solve(matrices, k, start),
            Err(e) => return Err(e),
        };
        let pairs = finish(matrices, run.basis.as_ref(), &run.ritz, k, &d, shift, par);
        // 3. Completeness: Sylvester inertia of L - mu M just below the largest value.
        let check_start = Instant::now();
        let inertia = completeness_check(matrices, &pairs.values, par)?;
        let check_seconds = check_start.elapsed().as_secs_f64();
        let complete = inertia
            .is_none_or(|(mu, count)| count == pairs.values.iter().filter(|&&x| x < mu).count());
        if complete || 2 * b > max_basis / 8 {
            if !complete {
                return Err(Error::lbo(format!(
                    "eigenvalue count check failed ({inertia:?}) even with blocks of {b}"
                )));
            }
            let report = SolveReport {
                dense: false,
                shift,
                basis_size: run.basis.ncols(),
                ritz_checks: run.checks,
                factor_seconds,
                solve_seconds: run.times.solve,
                orthogonalize_seconds: run.times.orthogonalize,
                ritz_seconds: run.times.ritz,
                check_seconds,
                inertia,
                total_seconds: start.elapsed().as_secs_f64(),
            };
            return Ok((pairs, report));
        }
        b *= 2;
        seed = seed.wrapping_add(1);
    }
}

/// The exact number of eigenvalues of `L phi = lambda M phi` below `mu` (Sylvester's law of
/// inertia: the negative pivots of a sparse `LDL^T` factorisation of `L - mu M`). Costs about
/// one Cholesky factorisation.
///
/// # Errors
/// [`Error::Lbo`] when the factorisation fails (for example `mu` numerically an eigenvalue).
pub fn eigenvalue_count_below(matrices: &LboMatrices, mu: f64) -> Result<usize> {
    super::slicing::count_below(matrices, mu, Par::Seq)
}

/// The inertia check of the solver: `(mu, number of eigenvalues below mu)` for `mu` in the
/// gap (relative width at least `1e-4`) nearest below the largest of the sorted `values`, or
/// in the widest gap among the last 32 when none is that wide; `None` for fewer than two
/// values. The count is exact (Sylvester's law of inertia on an `LDL^T` factorisation).
///
/// # Errors
/// [`Error::Lbo`] when the factorisation fails.
pub(crate) fn completeness_check(
    matrices: &LboMatrices,
    values: &[f64],
    par: Par,
) -> Result<Option<(f64, usize)>> {
    let k = values.len();
    if k < 2 {
        return Ok(None);
    }
    let rel_gap =
        |i: usize| (values[i + 1] - values[i]) / values[i + 1].abs().max(f64::MIN_POSITIVE);
    let lowest = k.saturating_sub(33);
    let gap = (lowest..k - 1)
        .rev()
        .find(|&i| rel_gap(i) >= 1e-4)
        .or_else(|| (lowest..k - 1).max_by(|&i, &j| rel_gap(i).total_cmp(&rel_gap(j))))
        .expect("at least one gap");
    let mu = 0.5 * (values[gap] + values[gap + 1]);
    let count = super::slicing::count_below(matrices, mu, par)?;
    Ok(Some((mu, count)))
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
        let mut x = Mat::<f64>::from_fn(n, 1, |_, _| rng.next_signed_f64());
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

/// Ritz vectors, back-transformation and Rayleigh-quotient eigenvalues, sorted ascending.
fn finish(
    matrices: &LboMatrices,
    basis: MatRef<'_, f64>,
    ritz: &Ritz,
    k: usize,
    d: &[f64],
    shift: f64,
    par: Par,
) -> Eigenpairs {
    let n = basis.nrows();
    let mut phi = Mat::<f64>::zeros(n, k);
    let coeff = ritz.vectors.as_ref().subcols(0, k);
    matmul(phi.as_mut(), Accum::Replace, basis, coeff, 1.0, par);
    for j in 0..k {
        for (x, di) in phi.col_as_slice_mut(j).iter_mut().zip(d) {
            *x *= di;
        }
    }
    let lphi = matrices.stiffness_times(phi.as_ref(), par);
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
