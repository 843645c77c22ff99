//! Voigt order of the 2D Cosserat strain and stress vectors (THEORY.md section 1).
//!
//! `e = [e_xx, e_yy, e_xy, e_yx, k_x, k_y]`, `s = [s_xx, s_yy, s_xy, s_yx, m_x, m_y]`;
//! `s . e` is the internal work density.

/// Number of components of the Cosserat strain / stress vectors.
pub const N: usize = 6;
/// Index of `e_xx` / `s_xx`.
pub const XX: usize = 0;
/// Index of `e_yy` / `s_yy`.
pub const YY: usize = 1;
/// Index of `e_xy = u_y,x - w` / `s_xy`.
pub const XY: usize = 2;
/// Index of `e_yx = u_x,y + w` / `s_yx`.
pub const YX: usize = 3;
/// Index of `k_x = w,x` / `m_x = m_zx`.
pub const KX: usize = 4;
/// Index of `k_y = w,y` / `m_y = m_zy`.
pub const KY: usize = 5;

/// Voigt index of the second-order component `(i, j)` with `i, j` in `{0 = x, 1 = y}`.
pub const fn index(i: usize, j: usize) -> usize {
    match (i, j) {
        (0, 0) => XX,
        (1, 1) => YY,
        (0, 1) => XY,
        _ => YX,
    }
}

/// Short names of the components, for output headers.
pub const NAMES: [&str; N] = ["xx", "yy", "xy", "yx", "kx", "ky"];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_is_a_bijection_on_the_four_force_components() {
        let mut seen = [false; 4];
        for i in 0..2 {
            for j in 0..2 {
                let k = index(i, j);
                assert!(!seen[k]);
                seen[k] = true;
            }
        }
        assert_eq!(index(0, 1), XY);
        assert_eq!(index(1, 0), YX);
    }
}
