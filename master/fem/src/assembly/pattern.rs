//! Compressed sparse column structure of the free-dof tangent, built once per mesh.

use super::DofMap;
use crate::mesh::Mesh;

/// CSC structure of `K_ff`: column pointers and sorted row indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Pattern {
    /// Number of rows and columns (free dofs).
    pub n: usize,
    /// Start of each column in `row_idx` (length `n + 1`).
    pub col_ptr: Vec<usize>,
    /// Row index of each stored entry, sorted within each column.
    pub row_idx: Vec<usize>,
    /// Where each element's tangent goes: for element `e`, from `scatter_start[e]`, the
    /// position in the value array of its entry `(i, j)` (element dofs, row-major), or
    /// [`NOT_FREE`] where the row or the column is prescribed. Looked up once here, so an
    /// assembly does not search the columns again (the search was more than half of it).
    pub scatter: Vec<u32>,
    /// Start of each element's entries in `scatter` (length `n_elements + 1`).
    pub scatter_start: Vec<usize>,
}

/// A `scatter` entry whose row or column is a prescribed dof.
pub const NOT_FREE: u32 = u32::MAX;

impl Pattern {
    /// Couples every pair of free dofs that share an element.
    pub fn new(mesh: &Mesh, dofs: &DofMap) -> Self {
        let ndf = dofs.field.ndf();
        // node -> neighbour nodes (through elements)
        let mut nbr: Vec<Vec<usize>> = vec![Vec::new(); mesh.n_nodes()];
        for e in 0..mesh.n_elements() {
            let el = mesh.element_nodes(e);
            for &a in el {
                nbr[a].extend_from_slice(el);
            }
        }
        for l in &mut nbr {
            l.sort_unstable();
            l.dedup();
        }
        let n = dofs.n_free;
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::new();
        // Columns in equation order = dof order (equations are numbered in dof order).
        for (dof, &eq) in dofs.equation.iter().enumerate() {
            if eq == usize::MAX {
                continue;
            }
            let node = dof / ndf;
            for &b in &nbr[node] {
                for c in 0..ndf {
                    let r = dofs.equation[b * ndf + c];
                    if r != usize::MAX {
                        row_idx.push(r);
                    }
                }
            }
            col_ptr.push(row_idx.len());
        }
        let mut pattern = Self { n, col_ptr, row_idx, scatter: Vec::new(), scatter_start: vec![0] };
        let mut eqs = Vec::new();
        for e in 0..mesh.n_elements() {
            eqs.clear();
            for &a in mesh.element_nodes(e) {
                eqs.extend((0..ndf).map(|c| dofs.equation[a * ndf + c]));
            }
            for &ri in &eqs {
                for &cj in &eqs {
                    let free = ri != usize::MAX && cj != usize::MAX;
                    let at = if free { pattern.position(ri, cj) } else { usize::MAX };
                    pattern.scatter.push(u32::try_from(at).unwrap_or(NOT_FREE));
                }
            }
            pattern.scatter_start.push(pattern.scatter.len());
        }
        assert!(
            pattern.nnz() < NOT_FREE as usize,
            "a tangent of {} entries does not fit 32-bit positions",
            pattern.nnz()
        );
        pattern
    }

    /// Element `e`'s positions (see [`Pattern::scatter`]).
    #[inline]
    pub fn element_scatter(&self, e: usize) -> &[u32] {
        &self.scatter[self.scatter_start[e]..self.scatter_start[e + 1]]
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Position of entry `(row, col)` in the value array (it must be in the pattern).
    #[inline]
    pub fn position(&self, row: usize, col: usize) -> usize {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        match self.row_idx[a..b].binary_search(&row) {
            Ok(k) => a + k,
            Err(_) => unreachable!("entry ({row}, {col}) outside the sparsity pattern"),
        }
    }
}
