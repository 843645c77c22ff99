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
}

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
        Self { n, col_ptr, row_idx }
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
