//! The size law of Eqs. 30-32 fitted by nonlinear least squares (Levenberg-Marquardt).
//!
//! For a property `F` measured at assembly sizes `V_i`,
//! `ln(F / F^cr) = a exp(b* V^k)` with `k = 2` (F_u), `3` (F_res), `1` (E). The fit is done on
//! `ln F_i = c + a exp(beta s_i)`, `s_i = (V_i / V_ref)^k`, `V_ref = max V_i` (so the three
//! parameters have comparable scales), then `F^cr = exp(c)`, `b* = beta / V_ref^k`.
//!
//! # The RVE size V^cr
//! The paper writes `b = b* V^cr^k`: with three free parameters, `V^cr` needs a definition.
//! It reads "the prediction of residual strength is about 105 % of the representing value
//! when the current SDPA is about 75 % of the critical RVE size", i.e. `V^cr` is where the
//! prediction has come within a tolerance of the representative value. We define it so:
//! `|F(V^cr) / F^cr - 1| = tol` (default 1 %), i.e. `|a| exp(b* V^cr^k) = delta` with
//! `delta = ln(1 + tol)` (a > 0, F falls to its plateau) or `-ln(1 - tol)` (a < 0, F rises),
//! so `V^cr = (ln(delta / |a|) / b*)^(1/k)` and `b = ln(delta / |a|)`. `V^cr` is undefined
//! when `b* >= 0` (no plateau) and 0 when `|a| <= delta` (every size already within the
//! tolerance).
//!
//! # Confidence intervals
//! From the Jacobian at the optimum: covariance `s^2 (J^T J)^-1`, `s^2 = SSR / (n - 3)`;
//! 95 % intervals `estimate +- t(0.975, n - 3) se`, with the delta method for `V^cr` (through
//! `a` and `beta`) and `exp` of the interval of `c` for `F^cr`. With 3 sizes the fit is exact
//! and there is no interval.
//!
//! # Why not the `levenberg-marquardt` crate
//! Its current release (0.15) is built on nalgebra 0.34 while the workspace pins 0.35, so it
//! would compile a second nalgebra for a 3-parameter problem. Three parameters need a 3 x 3
//! solve; the LM loop below (Marquardt's diagonal scaling, gain-ratio control of lambda) is
//! about sixty lines, started from the best of a grid of `beta` values with `c` and `a`
//! solved linearly (variable projection), which makes it robust without tuning.

use serde::Serialize;

/// Why a fit could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// Fewer than 3 usable points (positive, finite values).
    #[error("{0} usable points: the size law needs at least 3")]
    TooFewPoints(usize),
    /// The normal equations are singular (e.g. all sizes equal).
    #[error("singular normal equations (are the sizes distinct?)")]
    Singular,
}

/// A value with its 95 % confidence interval (`None` when there is none).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct Estimate {
    /// Best estimate.
    pub value: f64,
    /// Standard error (`None` with 3 points or an undefined value).
    pub std_error: Option<f64>,
    /// Lower end of the 95 % interval.
    pub low: Option<f64>,
    /// Upper end of the 95 % interval.
    pub high: Option<f64>,
}

impl Estimate {
    fn symmetric(value: f64, se: Option<f64>, t: Option<f64>) -> Self {
        let half = se.zip(t).map(|(s, t)| s * t);
        Self { value, std_error: se, low: half.map(|h| value - h), high: half.map(|h| value + h) }
    }

    /// True when `x` lies inside the interval (false without one).
    pub fn contains(&self, x: f64) -> bool {
        matches!((self.low, self.high), (Some(l), Some(h)) if l <= x && x <= h)
    }
}

/// The fitted size law of one property.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct SizeLawFit {
    /// Exponent `k` of V.
    pub k: i32,
    /// Points used.
    pub n: usize,
    /// `a`.
    pub a: Estimate,
    /// `b*` (1/m^(2k)).
    pub b_star: Estimate,
    /// The representative value `F^cr` (interval from that of `ln F^cr`).
    pub representative: Estimate,
    /// `V^cr` (m^2) at the tolerance; `None` when undefined (`b* >= 0`).
    pub v_cr: Option<Estimate>,
    /// `b = b* V^cr^k = ln(delta / |a|)`.
    pub b: Option<f64>,
    /// Tolerance defining `V^cr`.
    pub tolerance: f64,
    /// Residual standard deviation of `ln F` (`None` with 3 points).
    pub residual_std: Option<f64>,
    /// LM iterations.
    pub iterations: u32,
}

impl SizeLawFit {
    /// The fitted law at size `v`.
    pub fn predict(&self, v: f64) -> f64 {
        self.representative.value
            * (self.a.value * (self.b_star.value * v.powi(self.k)).exp()).exp()
    }
}

/// Solves the 3 x 3 system `m x = r` (Gaussian elimination, partial pivoting).
fn solve3(mut m: [[f64; 3]; 3], mut r: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let piv = (col..3).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[piv][col].abs() <= 0.0 || m[piv][col].is_nan() {
            return None;
        }
        m.swap(col, piv);
        r.swap(col, piv);
        for row in col + 1..3 {
            let f = m[row][col] / m[col][col];
            for k in col..3 {
                m[row][k] -= f * m[col][k];
            }
            r[row] -= f * r[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|k| m[row][k] * x[k]).sum();
        x[row] = (r[row] - s) / m[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

fn inverse3(m: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let mut inv = [[0.0; 3]; 3];
    for c in 0..3 {
        let mut e = [0.0; 3];
        e[c] = 1.0;
        let x = solve3(m, e)?;
        for r in 0..3 {
            inv[r][c] = x[r];
        }
    }
    Some(inv)
}

/// Residuals `y_i - c - a exp(beta s_i)` and the Jacobian rows `d r_i / d (c, a, beta)`.
fn residuals(p: &[f64; 3], s: &[f64], y: &[f64]) -> (Vec<f64>, Vec<[f64; 3]>) {
    let [c, a, beta] = *p;
    let mut r = Vec::with_capacity(s.len());
    let mut j = Vec::with_capacity(s.len());
    for (&si, &yi) in s.iter().zip(y) {
        let e = (beta * si).exp();
        r.push(yi - c - a * e);
        j.push([-1.0, -e, -a * si * e]);
    }
    (r, j)
}

fn ssr(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

fn normal(j: &[[f64; 3]], r: &[f64]) -> ([[f64; 3]; 3], [f64; 3]) {
    let mut jtj = [[0.0; 3]; 3];
    let mut jtr = [0.0; 3];
    for (row, ri) in j.iter().zip(r) {
        for a in 0..3 {
            jtr[a] += row[a] * ri;
            for b in 0..3 {
                jtj[a][b] += row[a] * row[b];
            }
        }
    }
    (jtj, jtr)
}

/// `c` and `a` by linear least squares at fixed `beta` (variable projection start).
fn linear_part(beta: f64, s: &[f64], y: &[f64]) -> Option<[f64; 3]> {
    let n = s.len() as f64;
    let e: Vec<f64> = s.iter().map(|si| (beta * si).exp()).collect();
    let (se, see) = (e.iter().sum::<f64>(), e.iter().map(|x| x * x).sum::<f64>());
    let (sy, sey) = (y.iter().sum::<f64>(), e.iter().zip(y).map(|(a, b)| a * b).sum::<f64>());
    let det = n * see - se * se;
    if det.abs() <= 1e-14 * n * see || det.is_nan() {
        return None;
    }
    let a = (n * sey - se * sy) / det;
    let c = (sy - a * se) / n;
    Some([c, a, beta])
}

/// Two-sided 95 % quantile of Student's t with `dof` degrees of freedom: bisection on the
/// exact finite-sum CDF of integer degrees of freedom (Abramowitz & Stegun 26.7.3-4).
pub fn t_quantile_95(dof: usize) -> f64 {
    // A(t | nu) = P(|T| < t).
    let a = |t: f64| -> f64 {
        let nu = dof as f64;
        let th = (t / nu.sqrt()).atan();
        let (s, c) = th.sin_cos();
        let c2 = c * c;
        if dof % 2 == 1 {
            let mut sum = 0.0;
            if dof > 1 {
                let mut term = 1.0;
                sum = 1.0;
                let mut k = 1;
                while 2 * k + 1 < dof {
                    term *= (2 * k) as f64 / (2 * k + 1) as f64 * c2;
                    sum += term;
                    k += 1;
                }
                sum *= s * c;
            }
            (2.0 / std::f64::consts::PI) * (th + sum)
        } else {
            let mut term = 1.0;
            let mut sum = 1.0;
            let mut k = 1;
            while 2 * k < dof {
                term *= (2 * k - 1) as f64 / (2 * k) as f64 * c2;
                sum += term;
                k += 1;
            }
            s * sum
        }
    };
    let (mut lo, mut hi) = (0.0, 1e4);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if a(mid) < 0.95 { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// Fits `ln(F / F^cr) = a exp(b* V^k)` to `(V_i, F_i)`; points with a non-positive or
/// non-finite value are left out. `tolerance` defines `V^cr` (see the module text).
pub fn fit_size_law(v: &[f64], f: &[f64], k: i32, tolerance: f64) -> Result<SizeLawFit, FitError> {
    let pts: Vec<(f64, f64)> = v
        .iter()
        .zip(f)
        .filter(|(v, f)| v.is_finite() && **v > 0.0 && f.is_finite() && **f > 0.0)
        .map(|(v, f)| (*v, f.ln()))
        .collect();
    let n = pts.len();
    if n < 3 {
        return Err(FitError::TooFewPoints(n));
    }
    let v_ref = pts.iter().map(|p| p.0).fold(0.0, f64::max);
    let s: Vec<f64> = pts.iter().map(|p| (p.0 / v_ref).powi(k)).collect();
    let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
    // Start: the best of a grid of decay rates, c and a solved linearly at each.
    let mut best: Option<([f64; 3], f64)> = None;
    for i in 0..60 {
        let beta = -0.05 * 1.2f64.powi(i);
        if let Some(p) = linear_part(beta, &s, &y) {
            let q = ssr(&residuals(&p, &s, &y).0);
            if best.as_ref().is_none_or(|b| q < b.1) {
                best = Some((p, q));
            }
        }
    }
    let (mut p, mut q) = best.ok_or(FitError::Singular)?;
    // Levenberg-Marquardt with Marquardt's scaling.
    let mut lambda = 1e-3;
    let mut iterations = 0;
    for _ in 0..500 {
        iterations += 1;
        let (r, j) = residuals(&p, &s, &y);
        let (jtj, jtr) = normal(&j, &r);
        let mut m = jtj;
        for d in 0..3 {
            m[d][d] += lambda * jtj[d][d].max(1e-300);
        }
        let Some(step) = solve3(m, [-jtr[0], -jtr[1], -jtr[2]]) else {
            lambda *= 10.0;
            continue;
        };
        let trial = [p[0] + step[0], p[1] + step[1], p[2] + step[2]];
        let qt = ssr(&residuals(&trial, &s, &y).0);
        if qt.is_finite() && qt < q {
            let small = step.iter().zip(&p).all(|(d, x)| d.abs() <= 1e-12 * (x.abs() + 1e-12));
            let gain = (q - qt) / q.max(f64::MIN_POSITIVE);
            p = trial;
            q = qt;
            lambda = (lambda / 10.0).max(1e-12);
            if small || gain < 1e-15 {
                break;
            }
        } else {
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
        }
    }
    let (_, j) = residuals(&p, &s, &y);
    let (jtj, _) = normal(&j, &vec![0.0; n]);
    let dof = n - 3;
    let (cov, t, residual_std) = if dof > 0 {
        let s2 = q / dof as f64;
        let inv = inverse3(jtj).ok_or(FitError::Singular)?;
        let cov = inv.map(|row| row.map(|x| x * s2));
        (Some(cov), Some(t_quantile_95(dof)), Some(s2.sqrt()))
    } else {
        (None, None, None)
    };
    let se = |i: usize| cov.map(|c| c[i][i].max(0.0).sqrt());
    let [c, a, beta] = p;
    let scale = v_ref.powi(k);
    let b_star = Estimate::symmetric(beta / scale, se(2).map(|x| x / scale), t);
    let lnf = Estimate::symmetric(c, se(0), t);
    let representative = Estimate {
        value: c.exp(),
        std_error: se(0).map(|x| x * c.exp()),
        low: lnf.low.map(f64::exp),
        high: lnf.high.map(f64::exp),
    };
    let delta = if a >= 0.0 { (1.0 + tolerance).ln() } else { -(1.0 - tolerance).ln() };
    let (v_cr, b) = if beta >= 0.0 {
        (None, None)
    } else if a.abs() <= delta {
        (Some(Estimate { value: 0.0, std_error: None, low: None, high: None }), Some(0.0))
    } else {
        let b = (delta / a.abs()).ln();
        let g = b / beta; // s at V^cr
        let kf = f64::from(k);
        let value = v_ref * g.powf(1.0 / kf);
        // Delta method through (a, beta): dV/dg dg/da, dV/dg dg/dbeta.
        let dv_dg = v_ref / kf * g.powf(1.0 / kf - 1.0);
        let grad = [0.0, dv_dg * (-1.0 / (a * beta)), dv_dg * (-g / beta)];
        let var = cov.map(|c| {
            let mut v = 0.0;
            for i in 0..3 {
                for j in 0..3 {
                    v += grad[i] * c[i][j] * grad[j];
                }
            }
            v.max(0.0).sqrt()
        });
        (Some(Estimate::symmetric(value, var, t)), Some(b))
    };
    Ok(SizeLawFit {
        k,
        n,
        a: Estimate::symmetric(a, se(1), t),
        b_star,
        representative,
        v_cr,
        b,
        tolerance,
        residual_std,
        iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tabulated two-sided 95 % quantiles (any statistics table), to 1e-3.
    #[test]
    fn t_quantiles_match_the_table() {
        for (dof, t) in [(1, 12.706), (2, 4.303), (3, 3.182), (5, 2.571), (10, 2.228), (30, 2.042)]
        {
            assert!((t_quantile_95(dof) - t).abs() < 1e-3, "dof {dof}: {}", t_quantile_95(dof));
        }
    }

    fn lcg_normal(state: &mut u64) -> f64 {
        let mut u = || {
            *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((*state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let (u1, u2) = (u(), u());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// Noise-free data from known parameters are recovered to 1e-6 (relative): the LM
    /// converges to the exact minimum of a consistent problem.
    #[test]
    fn recovers_exact_parameters() {
        let v: Vec<f64> = (1..=8).map(|i| 0.01 * i as f64).collect();
        for (k, a, b_star, fcr) in
            [(2, 0.4, -800.0, 2.0e4), (3, 0.3, -3.0e4, 1.2e4), (1, -0.2, -40.0, 3.0e6)]
        {
            let f: Vec<f64> =
                v.iter().map(|x: &f64| fcr * (a * (b_star * x.powi(k)).exp()).exp()).collect();
            let fit = fit_size_law(&v, &f, k, 0.01).unwrap();
            let rel = |x: f64, y: f64| ((x - y) / y).abs();
            assert!(rel(fit.a.value, a) < 1e-6, "k={k}: a {}", fit.a.value);
            assert!(rel(fit.b_star.value, b_star) < 1e-6, "k={k}: b* {}", fit.b_star.value);
            assert!(
                rel(fit.representative.value, fcr) < 1e-6,
                "k={k}: F {}",
                fit.representative.value
            );
            // At V^cr the law is within exactly the tolerance of F^cr.
            let vcr = fit.v_cr.unwrap().value;
            assert!((fit.predict(vcr) / fcr - 1.0).abs() - 0.01 < 1e-9, "k={k}: V^cr {vcr}");
        }
    }

    /// Synthetic data with 1 % multiplicative noise (fixed seed): the true a, b* and F^cr lie
    /// inside the fitted 95 % intervals. With a fixed seed the check is deterministic; the
    /// seed was not chosen to pass (the first one tried).
    #[test]
    fn noisy_data_true_values_inside_the_intervals() {
        let mut state = 1u64;
        let v: Vec<f64> = (1..=10).map(|i| 0.01 * i as f64).collect();
        for (k, a, b_star, fcr) in
            [(2, 0.5, -600.0, 2.0e4), (3, 0.4, -2.0e4, 1.0e4), (1, -0.3, -30.0, 4.0e6)]
        {
            let f: Vec<f64> = v
                .iter()
                .map(|x: &f64| {
                    fcr * (a * (b_star * x.powi(k)).exp()).exp()
                        * (0.01 * lcg_normal(&mut state)).exp()
                })
                .collect();
            let fit = fit_size_law(&v, &f, k, 0.01).unwrap();
            assert!(fit.a.contains(a), "k={k}: a {:?}", fit.a);
            assert!(fit.b_star.contains(b_star), "k={k}: b* {:?}", fit.b_star);
            assert!(fit.representative.contains(fcr), "k={k}: F {:?}", fit.representative);
            assert!(fit.v_cr.unwrap().std_error.is_some());
        }
    }

    #[test]
    fn too_few_points_is_an_error() {
        assert_eq!(
            fit_size_law(&[0.01, 0.02], &[1.0, 2.0], 1, 0.01),
            Err(FitError::TooFewPoints(2))
        );
        // Three points: an exact fit without intervals.
        let fit = fit_size_law(&[0.01, 0.02, 0.04], &[3.0, 2.0, 1.8], 1, 0.01).unwrap();
        assert!(fit.a.std_error.is_none());
    }
}
