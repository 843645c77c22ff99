//! Sparse direct solves with faer: the symbolic factorization is computed once per pattern
//! and reused for every Newton iteration and load step.
//!
//! The factorizations and solves run on one thread ([`Par::Seq`]). faer's default spreads them
//! over every core with rayon, which on the 2-core machine made one Newton iteration's
//! factorization and solve slower, not faster: 54.9 ms against 35.5 ms on one thread for the
//! 43 x 43 Q8 panel (16 812 dofs), 671 ms against 583 ms at 100 x 100 (90 399 dofs)
//! (`benches/newton_iteration.rs` in `cosdem-study`, 2026-12-06). One thread also makes the
//! FE solution independent of the thread count by construction.

use crate::assembly::Pattern;
use crate::error::{Error, Result};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, Lu, SymbolicLlt, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{MatMut, Par, Side};

/// A sparse direct solver bound to one sparsity pattern.
#[derive(Debug)]
pub struct LinearSolver {
    symbolic: SymbolicSparseColMat<usize>,
    lu: Option<SymbolicLu<usize>>,
    llt: Option<SymbolicLlt<usize>>,
}

impl LinearSolver {
    /// Takes the structure of `pattern`; the symbolic analyses are done on first use.
    pub fn new(pattern: &Pattern) -> Result<Self> {
        let symbolic = SymbolicSparseColMat::new_checked(
            pattern.n,
            pattern.n,
            pattern.col_ptr.clone(),
            None,
            pattern.row_idx.clone(),
        );
        faer::set_global_parallelism(Par::Seq);
        Ok(Self { symbolic, lu: None, llt: None })
    }

    /// Solves `K x = rhs` in place. `values` are the CSC values of `K` on the pattern.
    ///
    /// `symmetric` selects Cholesky (lower triangle read); if the numeric Cholesky fails
    /// (matrix not positive definite, e.g. on a softening branch) the solve falls back to LU.
    /// The error string of a failed numeric factorization says why (singular pivot, ...).
    pub fn solve(
        &mut self,
        values: &[f64],
        rhs: &mut [f64],
        symmetric: bool,
    ) -> std::result::Result<(), String> {
        let n = rhs.len();
        self.solve_columns(values, rhs, n, symmetric)
    }

    /// Solves `K X = RHS` in place for the columns of `rhs` (column-major, `n` rows each):
    /// one factorization for all of them.
    pub fn solve_columns(
        &mut self,
        values: &[f64],
        rhs: &mut [f64],
        n: usize,
        symmetric: bool,
    ) -> std::result::Result<(), String> {
        if rhs.is_empty() || n == 0 {
            return Ok(());
        }
        let k = SparseColMatRef::new(self.symbolic.as_ref(), values);
        let m = rhs.len() / n;
        if symmetric {
            if self.llt.is_none() {
                let s = SymbolicLlt::try_new(self.symbolic.as_ref(), Side::Lower)
                    .map_err(|e| format!("symbolic Cholesky: {e:?}"))?;
                self.llt = Some(s);
            }
            let s = self.llt.clone().expect("set above");
            if let Ok(f) = Llt::try_new_with_symbolic(s, k, Side::Lower) {
                f.solve_in_place(MatMut::from_column_major_slice_mut(rhs, n, m));
                return finite(rhs);
            }
            tracing::warn!("Cholesky failed (tangent not positive definite); using LU");
        }
        if self.lu.is_none() {
            let s = SymbolicLu::try_new(self.symbolic.as_ref())
                .map_err(|e| format!("symbolic LU: {e:?}"))?;
            self.lu = Some(s);
        }
        let s = self.lu.clone().expect("set above");
        let f = Lu::try_new_with_symbolic(s, k).map_err(|e| format!("LU: {e:?}"))?;
        f.solve_in_place(MatMut::from_column_major_slice_mut(rhs, n, m));
        finite(rhs)
    }

    /// Runs the symbolic analyses now (for timing or to fail early).
    pub fn analyse(&mut self, symmetric: bool) -> Result<()> {
        if symmetric && self.llt.is_none() {
            self.llt = Some(
                SymbolicLlt::try_new(self.symbolic.as_ref(), Side::Lower)
                    .map_err(|e| Error::LinearSolver(format!("symbolic Cholesky: {e:?}")))?,
            );
        }
        if !symmetric && self.lu.is_none() {
            self.lu = Some(
                SymbolicLu::try_new(self.symbolic.as_ref())
                    .map_err(|e| Error::LinearSolver(format!("symbolic LU: {e:?}")))?,
            );
        }
        Ok(())
    }
}

fn finite(x: &[f64]) -> std::result::Result<(), String> {
    match x.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(format!("solution not finite at equation {i} (singular tangent)")),
    }
}
