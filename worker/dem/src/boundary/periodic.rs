//! Periodic boundary: the cell follows Fbar (`H = Fbar H_0`), particles relax inside it,
//! pairs see each other through the minimum image of the deformed cell (Lees-Edwards-like).
//!
//! What happens to `wbar` and `kbar`. A periodic cell has no boundary layer on which to pin
//! rotations, and a particle rotation field `wbar + kbar . X` is not periodic, so imposing it
//! through every particle would either fight the periodicity (curvature) or pin the interior
//! rotations (which a penalty boundary does not do either: Eq. 24 pins only the boundary
//! layer). We therefore let particle rotations relax freely: at the start of a solve every
//! particle is rotated by the increment of the continuum rotation (the rotation of the polar
//! decomposition of Fbar), which keeps rigid rotations exactly stress-free, and the relaxation
//! does the rest. `wbar` and `kbar` do not enter; the couple stress comes from the contacts
//! only (`m_i = (1/A) sum l_i M`), and the stress is then symmetric at equilibrium for equal
//! discs without rolling resistance (torque balance of every disc). The tangent operators
//! still report the contact-stiffness `D` block.

/// Cell matrix `H = F diag(lx, ly)`: its columns are the deformed cell vectors.
pub fn cell(f: &[[f64; 2]; 2], lx: f64, ly: f64) -> [[f64; 2]; 2] {
    [[f[0][0] * lx, f[0][1] * ly], [f[1][0] * lx, f[1][1] * ly]]
}
