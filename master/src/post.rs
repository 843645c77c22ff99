//! Derived quantities for plots.

/// Equivalent strain, THEORY.md Eq. 34: `q = sqrt(1/2 e7^T M e7)`,
/// `e7 = [dev e_xx, dev e_yy, dev e_zz, e_xy, e_yx, k_x lc, k_y lc]` with
/// `dev e_ii = e_ii - (e_xx + e_yy) / 3` (`e_zz = 0`, plane strain) and
/// `M = I3 (+) [[1/2, 1/2], [1/2, 1/2]] (+) I2`.
///
/// `e` is the strain vector `[e_xx, e_yy, e_xy, e_yx, k_x, k_y]`, `lc` the internal length.
pub fn equivalent_strain(e: &[f64; 6], lc: f64) -> f64 {
    let tr = e[0] + e[1];
    let d = [e[0] - tr / 3.0, e[1] - tr / 3.0, -tr / 3.0];
    let shear = 0.5 * (e[2] + e[3]) * (e[2] + e[3]);
    let q2 =
        d.iter().map(|v| v * v).sum::<f64>() + shear + (e[4] * lc).powi(2) + (e[5] * lc).powi(2);
    (0.5 * q2).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: an in-plane dilation e_xx = e_yy = a does NOT give 0 (dev e_zz = -2a/3,
    /// see the report on THEORY.md); simple shear e_xy = e_yx = g/2 gives
    /// q = sqrt(1/2 * 1/2 g^2) = g/2; a relative rotation e_xy = -e_yx gives 0; curvature k_x
    /// alone gives k_x lc / sqrt(2); uniaxial e_xx = a gives dev = (2a/3, -a/3, -a/3), so
    /// q = sqrt(1/2 * 6a^2/9) = a / sqrt(3).
    #[test]
    fn equivalent_strain_closed_forms() {
        let tol = 1e-15;
        // plane-strain "volume change" e_xx = e_yy still has dev e_zz = -2a/3 != 0:
        let a: f64 = 0.01;
        let q = equivalent_strain(&[a, a, 0.0, 0.0, 0.0, 0.0], 1.0);
        let expect = (0.5 * (2.0 * (a / 3.0).powi(2) + (2.0 * a / 3.0).powi(2))).sqrt();
        assert!((q - expect).abs() < tol);
        assert!((equivalent_strain(&[0.0, 0.0, 0.01, 0.01, 0.0, 0.0], 1.0) - 0.01).abs() < tol);
        assert!(equivalent_strain(&[0.0, 0.0, 0.01, -0.01, 0.0, 0.0], 1.0).abs() < tol);
        let q = equivalent_strain(&[0.0, 0.0, 0.0, 0.0, 0.2, 0.0], 0.05);
        assert!((q - 0.01 / 2f64.sqrt()).abs() < tol);
        let q = equivalent_strain(&[a, 0.0, 0.0, 0.0, 0.0, 0.0], 1.0);
        assert!((q - a / 3f64.sqrt()).abs() < tol);
    }
}
