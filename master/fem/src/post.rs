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

/// Relative slack of a range's end on a curve of summed increments (the linear range; a
/// stopped reference's last displacement): a point within it counts as on the end.
pub const RANGE_SLACK: f64 = 1e-9;

/// What the paper reads off a load-displacement curve (THEORY.md section 4, scene A).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CurveMetrics {
    /// Bearing capacity F_u: the peak load (N per metre of thickness).
    pub peak_load: f64,
    /// Displacement at the peak (m).
    pub peak_displacement: f64,
    /// Residual capacity F_res: the minimum load after the peak (the plateau minimum);
    /// `None` while the curve has not passed its peak (the last point is the peak).
    pub residual_load: Option<f64>,
    /// Stiffness E: least-squares slope through the origin of the points with displacement
    /// `<= linear_range` (N/m per metre).
    pub stiffness: Option<f64>,
    /// The paper's Fig. 5 stiffness E50 = (F_u / 2) / d50, with d50 the displacement at which
    /// the load first reaches F_u / 2 (linear interpolation between points).
    pub stiffness_50: Option<f64>,
}

impl CurveMetrics {
    /// Metrics of a curve of `(displacement, load)` points in loading order, starting after
    /// the origin (the origin `(0, 0)` is implied). `linear_range` is the displacement that
    /// bounds the linear range (the paper: 0.01 m).
    pub fn from_curve(curve: &[(f64, f64)], linear_range: f64) -> Self {
        let Some((ipk, &(dpk, fpk))) =
            curve.iter().enumerate().max_by(|a, b| a.1.1.total_cmp(&b.1.1))
        else {
            return Self::default();
        };
        let residual_load = (ipk + 1 < curve.len())
            .then(|| curve[ipk + 1..].iter().map(|p| p.1).fold(f64::INFINITY, f64::min));
        let (mut sxy, mut sxx) = (0.0, 0.0);
        // The displacements are sums of increments: the point meant to sit on the range's end
        // can be an ulp beyond it (20 steps of 5e-5 m reach 0.0010000000000000002 m), and
        // dropping it made two runs of the same curve fit E over different points.
        let end = linear_range * (1.0 + RANGE_SLACK);
        for &(d, f) in curve.iter().filter(|p| p.0 <= end) {
            sxy += d * f;
            sxx += d * d;
        }
        let stiffness = (sxx > 0.0).then(|| sxy / sxx);
        let half = 0.5 * fpk;
        let mut prev = (0.0, 0.0);
        let mut d50 = None;
        for &(d, f) in curve {
            if f >= half {
                let t = if f > prev.1 { (half - prev.1) / (f - prev.1) } else { 1.0 };
                d50 = Some(prev.0 + t * (d - prev.0));
                break;
            }
            prev = (d, f);
        }
        let stiffness_50 = d50.filter(|d| *d > 0.0).map(|d| half / d);
        Self { peak_load: fpk, peak_displacement: dpk, residual_load, stiffness, stiffness_50 }
    }
}

#[cfg(test)]
mod curve_tests {
    use super::CurveMetrics;

    /// A bilinear softening curve with known peak, plateau and slopes; every metric is exact
    /// up to round-off of a few operations.
    #[test]
    fn metrics_of_a_piecewise_linear_curve() {
        // Rises at 1e6 N/m to 2e4 N at 0.02 m, softens to 1.2e4 N at 0.04 m, then plateau
        // with a minimum of 1.1e4 N.
        let mut curve = Vec::new();
        for i in 1..=20 {
            let d = 0.001 * i as f64;
            curve.push((d, 1e6 * d));
        }
        for i in 1..=20 {
            let d = 0.02 + 0.001 * i as f64;
            curve.push((d, 2e4 - 8e3 * (i as f64 / 20.0)));
        }
        curve.push((0.045, 1.1e4));
        curve.push((0.05, 1.15e4));
        let m = CurveMetrics::from_curve(&curve, 0.01);
        assert_eq!(m.peak_load, 2e4);
        assert!((m.peak_displacement - 0.02).abs() < 1e-15);
        assert_eq!(m.residual_load, Some(1.1e4));
        assert!((m.stiffness.unwrap() - 1e6).abs() < 1e-6);
        // Half the peak (1e4 N) is reached at 0.01 m: E50 = 1e4 / 0.01 = 1e6.
        assert!((m.stiffness_50.unwrap() - 1e6).abs() < 1e-6);
    }

    /// The point on the linear range's end counts whatever the round-off of the summed
    /// increments that reached it: 20 steps of 5e-5 m end at 0.0010000000000000002 m, 10 of
    /// 1e-4 m at 0.001 m, and both fit E over the same points. A point clearly beyond the end
    /// (1e-6 relative) does not count.
    #[test]
    fn the_linear_range_end_survives_summed_increments() {
        let walk = |n: usize, h: f64| {
            let mut d = 0.0;
            (0..n)
                .map(|_| {
                    d += h;
                    (d, 1e6 * d + if d > 0.00095 + 1e-12 { 1e3 } else { 0.0 })
                })
                .collect::<Vec<_>>()
        };
        let fine = walk(20, 5e-5);
        assert!(fine.last().unwrap().0 > 1e-3, "the fine walk overshoots by an ulp");
        let fine = CurveMetrics::from_curve(&fine, 1e-3).stiffness.unwrap();
        let mut exact: Vec<_> = walk(20, 5e-5);
        exact.last_mut().unwrap().0 = 1e-3;
        let exact = CurveMetrics::from_curve(&exact, 1e-3).stiffness.unwrap();
        assert!((fine / exact - 1.0).abs() < 1e-12, "{fine} vs {exact}");
        // The last point carries a 1e3 N bump: dropping it would give exactly 1e6.
        assert!(fine > 1e6 * (1.0 + 1e-3), "{fine}");
        let beyond = [(5e-4, 500.0), (1e-3 * (1.0 + 1e-6), 5e3)];
        let e = CurveMetrics::from_curve(&beyond, 1e-3).stiffness.unwrap();
        assert!((e / 1e6 - 1.0).abs() < 1e-12, "{e}");
    }

    /// Before the peak is passed there is no residual capacity.
    #[test]
    fn rising_curve_has_no_residual() {
        let m = CurveMetrics::from_curve(&[(0.01, 1.0), (0.02, 2.0)], 0.01);
        assert_eq!(m.residual_load, None);
        assert_eq!(m.peak_load, 2.0);
    }
}
