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
    /// in `(0, linear_range]` (N/m per metre).
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
        for &(d, f) in curve.iter().filter(|p| in_linear_range(p.0, linear_range)) {
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

/// A displacement `d` within the linear range `(0, linear_range]`. The displacements are sums
/// of increments: the point meant to sit on the range's end can be an ulp beyond it (20 steps
/// of 5e-5 m reach 0.0010000000000000002 m), and dropping it made two runs of the same curve
/// fit E over different points, hence the [`RANGE_SLACK`].
fn in_linear_range(d: f64, linear_range: f64) -> bool {
    d > 0.0 && d <= linear_range * (1.0 + RANGE_SLACK)
}

/// Whether a curve has passed its peak, and why a metric of [`CurveMetrics`] is absent.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CurveNotes {
    /// A point after the largest load has a smaller load: the largest load is a peak (F_u).
    /// `false` while the load still rises (or stays level) at the last step: the reported
    /// `peak_load` is then only the largest load so far.
    pub peak_reached: bool,
    /// Why there is no peak (absent when `peak_reached`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_peak: Option<String>,
    /// Why the stiffness E is absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_stiffness: Option<String>,
    /// Why E50 is absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_stiffness_50: Option<String>,
}

impl CurveMetrics {
    /// The metrics of [`CurveMetrics::from_curve`] for a general boundary-value curve, with
    /// what is missing said: a curve whose load has not fallen after its maximum has no peak
    /// (`peak_reached: false` with the reason), and then no E50 either (half of a peak not yet
    /// known); E is absent when no point lies in `(0, linear_range]`.
    pub fn assess(curve: &[(f64, f64)], linear_range: f64) -> (Self, CurveNotes) {
        let mut m = Self::from_curve(curve, linear_range);
        let mut notes = CurveNotes::default();
        if curve.is_empty() {
            let why = "no converged step yet".to_string();
            notes.no_peak = Some(why.clone());
            notes.no_stiffness = Some(why.clone());
            notes.no_stiffness_50 = Some(why);
            return (m, notes);
        }
        notes.peak_reached = m.residual_load.is_some();
        if !notes.peak_reached {
            let (d, f) = curve[curve.len() - 1];
            notes.no_peak = Some(format!(
                "the load has not fallen after its largest value: it is {f:e} at the last \
                 point (control displacement {d:e}); peak_load is the largest load so far"
            ));
            m.stiffness_50 = None;
            notes.no_stiffness_50 = Some("no peak reached: F_u / 2 is not known".into());
        } else if m.stiffness_50.is_none() {
            notes.no_stiffness_50 = Some(format!(
                "the peak load {:e} is not positive or is reached at a displacement <= 0",
                m.peak_load
            ));
        }
        if m.stiffness.is_none() {
            notes.no_stiffness = Some(format!(
                "no point with a control displacement in (0, linear_range = {linear_range:e}]"
            ));
        }
        (m, notes)
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

    /// A straight line F = k d (no peak): E = k exactly over any range, the peak is said not
    /// reached, E50 is absent with its reason, and the largest load is the last point's.
    #[test]
    fn a_straight_line_has_its_slope_and_no_peak() {
        let k = 3.5e6;
        let curve: Vec<_> = (1..=30).map(|i| (1e-4 * i as f64, k * 1e-4 * i as f64)).collect();
        let (m, notes) = CurveMetrics::assess(&curve, 1e-3);
        assert!((m.stiffness.unwrap() / k - 1.0).abs() < 1e-14);
        assert!(!notes.peak_reached);
        assert!(notes.no_peak.as_deref().unwrap().contains("has not fallen"), "{notes:?}");
        assert_eq!(m.stiffness_50, None);
        assert!(notes.no_stiffness_50.is_some() && notes.no_stiffness.is_none());
        assert_eq!((m.peak_displacement, m.peak_load), curve[29]);
        assert_eq!(m.residual_load, None);
    }

    /// A parabola F = a d (2 p - d) sampled past its peak at d = p: F_u = a p^2 at p; E is the
    /// least-squares slope through the origin of the sampled points, closed form
    /// `2 a p - a sum d^3 / sum d^2`; E50 = (F_u / 2) / d50 with `d50 = p (1 - 1/sqrt 2)`,
    /// up to the linear interpolation between points (chord error below `a h^2 / 8` in load
    /// for a step h, relative error below 1e-4 here); the residual is the last point's load.
    #[test]
    fn a_curve_with_a_known_peak() {
        let (a, p, h) = (1e8, 0.02, 1e-4);
        let f = |d: f64| a * d * (2.0 * p - d);
        let curve: Vec<_> = (1..=300).map(|i| (h * i as f64, f(h * i as f64))).collect();
        let range = 2e-3;
        let (m, notes) = CurveMetrics::assess(&curve, range);
        assert!(notes.peak_reached && notes.no_peak.is_none(), "{notes:?}");
        assert!((m.peak_load / (a * p * p) - 1.0).abs() < 1e-12);
        assert!((m.peak_displacement - p).abs() < 1e-12);
        assert_eq!(m.residual_load, Some(curve[299].1));
        let lin: Vec<f64> = curve.iter().map(|c| c.0).filter(|&d| d <= range + 1e-15).collect();
        let (s2, s3): (f64, f64) =
            (lin.iter().map(|d| d * d).sum(), lin.iter().map(|d| d.powi(3)).sum());
        let e = 2.0 * a * p - a * s3 / s2;
        assert!((m.stiffness.unwrap() / e - 1.0).abs() < 1e-12, "{:?} vs {e}", m.stiffness);
        let d50 = p * (1.0 - 1.0 / 2f64.sqrt());
        let e50 = 0.5 * a * p * p / d50;
        assert!(
            (m.stiffness_50.unwrap() / e50 - 1.0).abs() < 1e-4,
            "{:?} vs {e50}",
            m.stiffness_50
        );
    }

    /// A monotonic hardening curve F = F_inf (1 - exp(-d / d0)): no peak at any length (said
    /// so, E50 absent); E is the least-squares slope through the origin of the sampled points,
    /// `F_inf sum d (1 - exp(-d/d0)) / sum d^2`, evaluated independently here.
    #[test]
    fn a_monotonic_hardening_curve_has_no_peak() {
        let (f_inf, d0, h) = (5e4, 0.01, 5e-4);
        let curve: Vec<_> =
            (1..=200).map(|i| (h * i as f64, f_inf * (1.0 - (-h * i as f64 / d0).exp()))).collect();
        let (m, notes) = CurveMetrics::assess(&curve, 0.005);
        assert!(!notes.peak_reached);
        assert_eq!(m.stiffness_50, None);
        assert_eq!(m.residual_load, None);
        let pts = &curve[..10];
        let e = pts.iter().map(|(d, f)| d * f).sum::<f64>()
            / pts.iter().map(|(d, _)| d * d).sum::<f64>();
        assert!((m.stiffness.unwrap() / e - 1.0).abs() < 1e-12);
        // Below the initial slope F_inf / d0 (the curve bends down), above the secant at 5 mm.
        assert!(e < f_inf / d0 && e > f_inf * (1.0 - (-0.5f64).exp()) / 0.005);
        // A settlement left negative (no scale) has no point in (0, linear_range]: E absent.
        let neg: Vec<_> = curve.iter().map(|&(d, f)| (-d, f)).collect();
        let (m, notes) = CurveMetrics::assess(&neg, 0.005);
        assert_eq!(m.stiffness, None);
        assert!(notes.no_stiffness.as_deref().unwrap().contains("linear_range"));
        let (_, notes) = CurveMetrics::assess(&[], 0.005);
        assert!(notes.no_peak.is_some() && !notes.peak_reached);
    }

    /// Before the peak is passed there is no residual capacity.
    #[test]
    fn rising_curve_has_no_residual() {
        let m = CurveMetrics::from_curve(&[(0.01, 1.0), (0.02, 2.0)], 0.01);
        assert_eq!(m.residual_load, None);
        assert_eq!(m.peak_load, 2.0);
    }
}
