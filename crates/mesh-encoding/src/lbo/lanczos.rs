//! Shift-invert block Lanczos with full reorthogonalisation on one sparse Cholesky factor: the
//! default sparse path of [`super::smallest_eigenpairs`] (method in [`super::eigen`]).
//!
//! Per block step (`b` vectors, basis of `m`):
//! * **solve**: `W = M^(1/2) A^-1 M^(1/2) V_j`, one multi-RHS triangular solve pair;
//! * **orthogonalise**: the three-term block recurrence (projection on the last two blocks,
//!   `O(n b^2)`), then one classical Gram-Schmidt pass against the whole basis (two GEMMs,
//!   `4 n m b` flops), repeated only when a column lost more than half its norm in that pass
//!   (the DGKS criterion), then Householder QR of `W`;
//! * **Rayleigh-Ritz** (dense eigen of the projected `m x m` matrix, `O(m^3)`) only at checkpoints
//!   scheduled from the residual history: the worst wanted residual decays about geometrically
//!   in `m`, so after two checks the basis size where it reaches the tolerance is extrapolated
//!   and the next check placed just beyond it. This replaced a check every `k / 10` vectors
//!   (18 dense eigenproblems of up to 1,760 for the bunny at 513 pairs).

use std::time::Instant;

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

use super::eigen::{EigenSettings, orthonormalize_block};
use crate::error::{Error, Result};
use stdx::rng::SplitMix64;

/// Seconds per phase of one Lanczos run.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct PhaseTimes {
    pub(crate) solve: f64,
    pub(crate) orthogonalize: f64,
    pub(crate) ritz: f64,
}

/// Ritz values (the `count` largest `theta`, descending), their coefficient vectors in the basis
/// and their Lanczos residual norms `|R_j y_last|`.
pub(crate) struct Ritz {
    pub(crate) values: Vec<f64>,
    pub(crate) vectors: Mat<f64>,
    pub(crate) residuals: Vec<f64>,
}

/// The outcome of [`block_lanczos`]: the orthonormal basis (`n x m`), the Ritz pairs of the last
/// check and the bookkeeping.
pub(crate) struct LanczosRun {
    pub(crate) basis: Mat<f64>,
    pub(crate) ritz: Ritz,
    pub(crate) checks: usize,
    pub(crate) times: PhaseTimes,
}

/// `W <- A^-1 W` in place for a factored `A`.
pub(crate) type SolveInPlace<'a> = &'a dyn Fn(MatMut<'_, f64>);

/// Block Lanczos state: the basis `V` (allocated for the largest basis) and the projected matrix
/// `H = V^T Op V`, filled column block by column block.
pub(crate) struct Lanczos<'a> {
    solve: SolveInPlace<'a>,
    sqrt_m: &'a [f64],
    b: usize,
    v: Mat<f64>,
    h: Mat<f64>,
    w: Mat<f64>,
    m: usize,
    rng: SplitMix64,
    par: Par,
    pub(crate) times: PhaseTimes,
}

impl<'a> Lanczos<'a> {
    /// A run on `Op = M^(1/2) A^-1 M^(1/2)` (`solve` applies `A^-1`) with blocks of `b` and
    /// room for `max_basis` vectors, started from a random block.
    pub(crate) fn new(
        solve: SolveInPlace<'a>,
        sqrt_m: &'a [f64],
        b: usize,
        max_basis: usize,
        seed: u64,
        par: Par,
    ) -> Self {
        let n = sqrt_m.len();
        let mut rng = SplitMix64::new(seed);
        let mut w = Mat::<f64>::from_fn(n, b, |_, _| rng.next_signed_f64());
        // Capacity for the largest basis, but only the columns in use are touched (resident).
        let mut v = Mat::<f64>::new();
        v.reserve(n, max_basis + b);
        orthonormalize_block(v.as_ref(), w.as_mut(), &mut rng, par);
        v.resize_with(n, b, |i, j| w[(i, j)]);
        let h = Mat::<f64>::zeros(max_basis + b, max_basis + b);
        Lanczos { solve, sqrt_m, b, v, h, w, m: b, rng, par, times: PhaseTimes::default() }
    }

    /// Current basis size (including the block whose image is computed next).
    pub(crate) fn len(&self) -> usize {
        self.m
    }

    /// One block step: applies `Op` to the newest block, orthogonalises the result against the
    /// basis and appends it (`m += b`). The projected matrix then holds `H[0..m+b, 0..m]`.
    pub(crate) fn step(&mut self) {
        let (b, m, par) = (self.b, self.m, self.par);
        let cur = m - b;
        let t = Instant::now();
        for j in 0..b {
            let src = self.v.col_as_slice(cur + j);
            let dst = self.w.col_as_slice_mut(j);
            for ((d, s), si) in dst.iter_mut().zip(src).zip(self.sqrt_m) {
                *d = s * si;
            }
        }
        (self.solve)(self.w.as_mut());
        for j in 0..b {
            for (x, si) in self.w.col_as_slice_mut(j).iter_mut().zip(self.sqrt_m) {
                *x *= si;
            }
        }
        self.times.solve += t.elapsed().as_secs_f64();

        let t = Instant::now();
        // Three-term recurrence: project out the last two blocks (the bulk of W).
        let local = cur.saturating_sub(b);
        self.project(local, m);
        // Full reorthogonalisation against the whole basis, repeated when cancellation was
        // severe (DGKS: some column kept less than half of its norm).
        for pass in 0..3 {
            let before: Vec<f64> = (0..b).map(|j| self.w.col(j).norm_l2()).collect();
            self.project(0, m);
            let lost = (0..b).any(|j| self.w.col(j).norm_l2() < 0.5 * before[j]);
            if !lost || pass == 2 {
                break;
            }
        }
        let basis = self.v.as_ref().subcols(0, m);
        let r = orthonormalize_block(basis, self.w.as_mut(), &mut self.rng, par);
        self.h.as_mut().submatrix_mut(m, cur, b, b).copy_from(&r);
        let w = &self.w;
        self.v.resize_with(w.nrows(), m + b, |i, j| w[(i, j - m)]);
        self.m += b;
        self.times.orthogonalize += t.elapsed().as_secs_f64();
    }

    /// `W -= V[:, from..to] C`, `C = V[:, from..to]^T W`, accumulating `C` into `H`.
    fn project(&mut self, from: usize, to: usize) {
        let cur = self.m - self.b;
        let basis = self.v.as_ref().subcols(from, to - from);
        let mut coeff = Mat::<f64>::zeros(to - from, self.b);
        matmul(coeff.as_mut(), Accum::Replace, basis.transpose(), self.w.as_ref(), 1.0, self.par);
        matmul(self.w.as_mut(), Accum::Add, basis, coeff.as_ref(), -1.0, self.par);
        let mut hcol = self.h.as_mut().submatrix_mut(from, cur, to - from, self.b);
        hcol += &coeff;
    }

    /// Rayleigh-Ritz on the basis before the newest block (`m - b` vectors, whose residual
    /// couplings are known): the `count` largest Ritz pairs (largest `|theta|` when
    /// `by_magnitude`).
    pub(crate) fn ritz(&mut self, count: usize, by_magnitude: bool) -> Result<Ritz> {
        let t = Instant::now();
        let r = rayleigh_ritz(self.h.as_ref(), self.m - self.b, self.b, count, by_magnitude);
        self.times.ritz += t.elapsed().as_secs_f64();
        r
    }

    /// A view of the basis of the last Ritz check (`n x (m - b)`).
    pub(crate) fn basis(&self) -> MatRef<'_, f64> {
        self.v.as_ref().subcols(0, self.m - self.b)
    }

    /// The basis of the last Ritz check (`n x (m - b)`), consuming the run (no copy).
    pub(crate) fn into_basis(mut self) -> Mat<f64> {
        let (n, used) = (self.v.nrows(), self.m - self.b);
        self.v.truncate(n, used);
        self.v
    }
}

/// Rayleigh-Ritz on the projected matrix `H[0..m, 0..m]` (symmetrised): the `count` largest
/// Ritz pairs (by `theta` or `|theta|`, descending) and their residuals
/// `|H[m..m+b, m-b..m] y[m-b..m]|`.
fn rayleigh_ritz(
    h: MatRef<'_, f64>,
    m: usize,
    b: usize,
    count: usize,
    by_magnitude: bool,
) -> Result<Ritz> {
    let t = Mat::<f64>::from_fn(m, m, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
    let eig = t
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::lbo(format!("dense eigen of the projected matrix failed: {e:?}")))?;
    let s = eig.S().column_vector();
    let u = eig.U();
    let count = count.min(m);
    let mut cols: Vec<usize> = (0..m).rev().collect(); // descending theta
    if by_magnitude {
        cols.sort_by(|&i, &j| s[j].abs().total_cmp(&s[i].abs()));
    }
    cols.truncate(count);
    let values: Vec<f64> = cols.iter().map(|&c| s[c]).collect();
    let vectors = Mat::<f64>::from_fn(m, count, |i, j| u[(i, cols[j])]);
    let coupling = h.submatrix(m, m - b, b, b);
    let res = coupling * vectors.as_ref().subrows(m - b, b);
    let residuals = (0..count).map(|j| res.col(j).norm_l2()).collect();
    Ok(Ritz { values, vectors, residuals })
}

/// Largest `residual / (tolerance * |theta|)` over the first `k` Ritz pairs (converged when
/// at most 1).
pub(crate) fn worst_ratio(ritz: &Ritz, k: usize, tolerance: f64) -> f64 {
    ritz.values
        .iter()
        .zip(&ritz.residuals)
        .take(k)
        .map(|(t, r)| r / (tolerance * t.abs()))
        .fold(0.0, f64::max)
}

/// Runs block Lanczos from a random block (`seed`) until the `k` largest Ritz pairs of `Op` have
/// relative residuals below `settings.tolerance`.
///
/// # Errors
/// [`Error::Lbo`] when the basis limit is reached before convergence or a dense eigen fails.
#[allow(clippy::too_many_arguments)]
pub(crate) fn block_lanczos(
    llt: &super::factor::CholeskyFactor,
    sqrt_m: &[f64],
    k: usize,
    b: usize,
    max_basis: usize,
    settings: &EigenSettings,
    seed: u64,
    par: Par,
) -> Result<LanczosRun> {
    let solve = |w: MatMut<'_, f64>| llt.solve_in_place(w);
    let mut lz = Lanczos::new(&solve, sqrt_m, b, max_basis, seed, par);
    // Block Lanczos needs a basis of several times k for the last wanted pairs (about 3.4 k
    // for b = 32 on the bunny); the first check at 2.5 k wastes little when it is too early.
    let first = (k + 2 * b).max(k * 5 / 2).min(max_basis);
    let mut next_check = first;
    let mut history: Option<(usize, f64)> = None;
    let mut checks = 0;
    loop {
        lz.step();
        let m = lz.len() - b;
        if m < next_check && lz.len() <= max_basis {
            continue;
        }
        checks += 1;
        let ritz = lz.ritz(k, false)?;
        let worst = worst_ratio(&ritz, k, settings.tolerance);
        if worst <= 1.0 {
            let times = lz.times;
            return Ok(LanczosRun { basis: lz.into_basis(), ritz, checks, times });
        }
        if lz.len() > max_basis {
            return Err(Error::lbo(format!(
                "block Lanczos did not converge for {k} pairs within a basis of {m} vectors \
                 (worst residual {worst:.2e} times the tolerance); raise max_basis_factor"
            )));
        }
        next_check = next_checkpoint(m, worst, history, b, max_basis);
        history = Some((m, worst));
    }
}

/// Where to check next: extrapolates the geometric decay of the worst residual ratio from the
/// last two checks (10 % margin), or grows by an eighth without history; at least one block,
/// at most a quarter of the basis more, rounded up to whole blocks.
pub(crate) fn next_checkpoint(
    m: usize,
    worst: f64,
    history: Option<(usize, f64)>,
    b: usize,
    max_basis: usize,
) -> usize {
    let default = (m / 8).max(b);
    let grow = match history {
        Some((m0, w0)) if w0 > worst && m > m0 => {
            let rate = (worst / w0).ln() / (m - m0) as f64; // < 0: log decay per vector
            let needed = worst.ln() / -rate;
            (1.1 * needed).ceil() as usize
        }
        _ => default,
    };
    let grow = grow.clamp(b, (m / 4).max(b)).div_ceil(b) * b;
    (m + grow).min(max_basis)
}

#[cfg(test)]
mod tests {
    use super::next_checkpoint;

    #[test]
    fn checkpoints_extrapolate_the_residual_decay() {
        // Without history: an eighth more (200, rounded up to 7 blocks of 32).
        assert_eq!(next_checkpoint(1600, 1e3, None, 32, 4000), 1824);
        // Residual ratio fell by 1e3 over 200 vectors and is at 1e3: 200 more, +10 %, blocks.
        assert_eq!(next_checkpoint(1600, 1e3, Some((1400, 1e6)), 32, 4000), 1824);
        assert_eq!(next_checkpoint(1600, 1e3, Some((1400, 1e6)), 64, 4000), 1856);
        // Clamped to a quarter of the basis (400 -> 416) and to the limit.
        assert_eq!(next_checkpoint(1600, 1e9, Some((1500, 1e10)), 32, 4000), 2016);
        assert_eq!(next_checkpoint(1600, 1e9, Some((1500, 1e10)), 32, 1700), 1700);
        // At least one block.
        assert_eq!(next_checkpoint(1600, 1.01, Some((1400, 1e6)), 32, 4000), 1632);
    }
}
