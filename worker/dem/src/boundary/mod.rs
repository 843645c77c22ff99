//! Boundary conditions that impose the macro deformation on an assembly.

/// Miehe's penalty constraints on the boundary layer (Eq. 24).
pub mod penalty;
/// Periodic cell that follows Fbar.
pub mod periodic;

/// `a b` for 2x2 matrices.
pub fn mat_mul(a: &[[f64; 2]; 2], b: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            c[i][j] = a[i][0].mul_add(b[0][j], a[i][1] * b[1][j]);
        }
    }
    c
}

/// Inverse of a 2x2 matrix (the caller guarantees det > 0).
pub fn mat_inv(a: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    [[a[1][1] / det, -a[0][1] / det], [-a[1][0] / det, a[0][0] / det]]
}

/// Rotation angle of the polar decomposition `F = R U` (exact in 2D).
pub fn rotation_angle(f: &[[f64; 2]; 2]) -> f64 {
    (f[1][0] - f[0][1]).atan2(f[0][0] + f[1][1])
}
