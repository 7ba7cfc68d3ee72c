//! The sparse Cholesky factor of `L - sigma M` used by block Lanczos, solving many blocks of
//! right-hand sides without allocating.
//!
//! faer's high-level `Llt::solve_in_place` allocates its whole workspace (an `n x b` temporary
//! plus the supernodal scratch, megabytes) on every call and runs with faer's global
//! parallelism. Block Lanczos calls it about a hundred times: the allocations showed up as
//! system time and page faults, half of a bunny solve on one machine (`PERFORMANCE.md`). This
//! factor keeps one workspace, grown on demand, and solves with the solver's own parallelism
//! setting.

use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky, factorize_symbolic_cholesky};
use faer::{Conj, MatMut, Par, Side};
use std::cell::RefCell;

/// The command line's environment variable that sets
/// [`EigenSettings::memory_budget`](super::eigen::EigenSettings::memory_budget), in GiB: named in
/// a refusal's hint (this crate reads no environment).
pub const MEMORY_BUDGET_VAR: &str = "NEURAL_BRDF_LBO_MEMORY_GIB";

/// Bytes the factor may take: `set` (the solver's [`EigenSettings::memory_budget`]), else 3/4
/// of `MemAvailable` (Linux), else 8 GiB; and where that figure came from.
///
/// [`EigenSettings::memory_budget`]: super::eigen::EigenSettings::memory_budget
fn memory_budget(set: Option<u64>) -> (u64, String) {
    const GIB: f64 = (1u64 << 30) as f64;
    if let Some(bytes) = set {
        return (
            bytes,
            format!("the budget of {:.1} GiB set ({MEMORY_BUDGET_VAR})", bytes as f64 / GIB),
        );
    }
    let available = std::fs::read_to_string("/proc/meminfo").ok().and_then(|m| {
        let line = m.lines().find(|l| l.starts_with("MemAvailable:"))?;
        line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kib| kib * 1024)
    });
    match available {
        Some(bytes) => {
            (bytes / 4 * 3, format!("3/4 of the {:.1} GiB available", bytes as f64 / GIB))
        }
        None => (8 << 30, "the default".into()),
    }
}

/// Refuses a solve whose factor (`nnz` stored values for an `n`-vertex mesh) and `extra` bytes
/// beside it would not fit the memory budget, before anything is allocated: a clear error with a
/// decimation hint instead of the kernel's out-of-memory kill. The estimate counts the factor's
/// values and row indices and the numeric factorisation's peak (about as much again).
fn check_memory(n: usize, nnz: usize, extra: u64, set: Option<u64>) -> Result<()> {
    let (budget, source) = memory_budget(set);
    memory_verdict(n, nnz, extra, budget, &source)
}

/// [`check_memory`] against a given budget of `budget` bytes (from `source`).
fn memory_verdict(n: usize, nnz: usize, extra: u64, budget: u64, source: &str) -> Result<()> {
    const GIB: f64 = (1u64 << 30) as f64;
    let need = (nnz as u64).saturating_mul(8 + 8).saturating_mul(2).saturating_add(extra);
    if need <= budget {
        return Ok(());
    }
    // Fill grows a little faster than linearly with n on surface meshes: aim at what fits.
    let fits = (n as f64 * (budget as f64 / need as f64).powf(1.1)).max(1.0) as u64;
    Err(Error::lbo(format!(
        "the eigenfunctions of this {n}-vertex mesh need about {:.1} GiB (a sparse Cholesky \
         factor of {nnz} nonzeros and the Lanczos basis), above the budget of {:.1} GiB ({source}); decimate the mesh \
         to at most about {fits} vertices (the LBO features need no finer mesh; the importer \
         decimates DiLiGenT-MV's meshes to about 1e5 vertices: `cargo xtask import-diligent \
         --target-vertices`) or raise {MEMORY_BUDGET_VAR}",
        need as f64 / GIB,
        budget as f64 / GIB
    )))
}

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
    /// ordering by AMD (faer's default), after checking that the factor and `extra_bytes` the
    /// caller allocates beside it (the Lanczos basis) fit the memory budget (`budget`, or the
    /// default of [`memory_budget`]).
    pub(crate) fn new(
        a: SparseColMatRef<'_, usize, f64>,
        par: Par,
        extra_bytes: u64,
        budget: Option<u64>,
    ) -> Result<Self> {
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .map_err(|e| Error::lbo(format!("symbolic Cholesky failed: {e:?}")))?;
        check_memory(a.nrows(), symbolic.len_val(), extra_bytes, budget)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_factor_over_the_budget_is_a_clear_error_with_a_decimation_hint() {
        assert!(memory_verdict(1000, 50_000, 1 << 20, 1 << 30, "test").is_ok());
        let e = memory_verdict(1_000_000, 400_000_000, 0, 4 << 30, "a 4 GiB test budget")
            .unwrap_err()
            .to_string();
        assert!(e.contains("1000000-vertex mesh need about 11.9 GiB"), "{e}");
        assert!(e.contains("budget of 4.0 GiB (a 4 GiB test budget)"), "{e}");
        assert!(e.contains("decimate the mesh to at most about 30"), "{e}");
        assert!(e.contains(MEMORY_BUDGET_VAR), "{e}");
    }
}
