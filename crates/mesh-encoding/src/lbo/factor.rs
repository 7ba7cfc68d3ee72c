//! The sparse Cholesky factor of `L - sigma M` used by block Lanczos, solving many blocks of
//! right-hand sides without allocating.
//!
//! faer's high-level `Llt::solve_in_place` allocates its whole workspace (an `n x b` temporary
//! plus the supernodal scratch, megabytes) on every call and runs with faer's global
//! parallelism. Block Lanczos calls it about a hundred times: the allocations showed up as
//! system time and page faults (block solves took 10.7 s of a 21 s bunny solve on a quiet
//! machine, 1.7 s in another run). This factor keeps one workspace, grown on demand, and
//! solves with the solver's own parallelism setting.

use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky, factorize_symbolic_cholesky};
use faer::{Conj, MatMut, Par, Side};
use std::cell::RefCell;

/// A numeric sparse LL^T factor with a reusable solve workspace.
pub(crate) struct CholeskyFactor {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    par: Par,
    /// Workspace and the number of right-hand-side columns it was sized for.
    scratch: RefCell<(MemBuffer, usize)>,
}

impl CholeskyFactor {
    /// Factors the symmetric positive definite `a` (lower triangle read), fill-reducing
    /// ordering by AMD (faer's default).
    pub(crate) fn new(a: SparseColMatRef<'_, usize, f64>, par: Par) -> Result<Self> {
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .map_err(|e| Error::lbo(format!("symbolic Cholesky failed: {e:?}")))?;
        let mut values = vec![0.0; symbolic.len_val()];
        let mut mem = MemBuffer::try_new(
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
        )
        .map_err(|e| Error::lbo(format!("Cholesky workspace: {e:?}")))?;
        symbolic
            .factorize_numeric_llt::<f64>(
                &mut values,
                a,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| Error::lbo(format!("Cholesky of L - sigma M failed: {e:?}")))?;
        let scratch =
            RefCell::new((MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, par)), 1));
        Ok(Self { symbolic, values, par, scratch })
    }

    /// Overwrites `rhs` with `A^-1 rhs`.
    pub(crate) fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        let mut guard = self.scratch.borrow_mut();
        if guard.1 < rhs.ncols() {
            let cols = rhs.ncols();
            *guard =
                (MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(cols, self.par)), cols);
        }
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            self.par,
            MemStack::new(&mut guard.0),
        );
    }
}
