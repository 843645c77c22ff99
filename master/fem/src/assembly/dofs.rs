//! Degrees of freedom: which field, how they are numbered, which are prescribed.

/// The continuum model of the macro mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Field {
    /// `u_x, u_y, w` per node (the paper's model).
    Cosserat,
    /// `u_x, u_y` per node: the classical continuum. The material gets `kappa = 0` and
    /// `w = (u_y,x - u_x,y) / 2`, the continuum rotation (not `w = 0`), so that
    /// `e_xy = e_yx = (u_y,x + u_x,y) / 2` carry no skew part and the answer does not depend
    /// on how the material penalizes relative rotation. With `w = 0` instead, the elastic law
    /// would give the shear energy `G (u_y,x + u_x,y)^2 + Gc (u_y,x - u_x,y)^2` per unit area
    /// (times 1/2): rigid rotations would cost energy whenever `Gc > 0`. The 6x6 tangent
    /// reduces to `B^T C B` with the two shear rows of `B` both `(N,y d/du_x + N,x d/du_y) / 2`
    /// and the couple rows zero: only `C`'s symmetric-shear and normal blocks contribute.
    Cauchy,
}

impl Field {
    /// Dofs per node.
    pub const fn ndf(self) -> usize {
        match self {
            Self::Cosserat => 3,
            Self::Cauchy => 2,
        }
    }
}

/// A nodal dof component.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Component {
    /// Displacement along x.
    Ux,
    /// Displacement along y.
    Uy,
    /// Micro-rotation (Cosserat only).
    W,
}

impl Component {
    /// Offset of the component within a node's dofs.
    pub const fn offset(self) -> usize {
        match self {
            Self::Ux => 0,
            Self::Uy => 1,
            Self::W => 2,
        }
    }
}

/// Global dof numbering: dof `node * ndf + component`; free dofs get equation numbers,
/// prescribed ones are eliminated from the linear system.
///
/// Dirichlet conditions are eliminated rather than imposed by row/column replacement: the
/// system is smaller and keeps the material's symmetry, the prescribed values enter once per
/// step through the predictor right-hand side `-K_fc du_c`.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    /// The field (dofs per node).
    pub field: Field,
    /// Number of nodes.
    pub n_nodes: usize,
    /// Equation number of each dof, `usize::MAX` when prescribed.
    pub equation: Vec<usize>,
    /// Number of free dofs (equations).
    pub n_free: usize,
}

impl DofMap {
    /// Numbers the free dofs in node order, skipping `prescribed[dof] == true`.
    pub fn new(field: Field, n_nodes: usize, prescribed: &[bool]) -> Self {
        debug_assert_eq!(prescribed.len(), n_nodes * field.ndf());
        let mut n_free = 0;
        let equation = prescribed
            .iter()
            .map(|&p| {
                if p {
                    usize::MAX
                } else {
                    n_free += 1;
                    n_free - 1
                }
            })
            .collect();
        Self { field, n_nodes, equation, n_free }
    }

    /// Total number of dofs.
    pub fn n_dofs(&self) -> usize {
        self.equation.len()
    }

    /// Global dof of a node component.
    pub fn dof(&self, node: usize, c: Component) -> usize {
        node * self.field.ndf() + c.offset()
    }
}
