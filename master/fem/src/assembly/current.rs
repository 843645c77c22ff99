//! The current configuration at a Gauss point, for the updated-Lagrangian option: the
//! deformation gradient of the iterate, the shape gradients and area on the deformed mesh, the
//! polar angle of the Cauchy field and its derivatives, and the geometric (initial-stress)
//! stiffness (docs/theory.md, "Updated-Lagrangian option").
//!
//! Everything is computed from the reference [`GaussData`](super::GaussData) and the nodal
//! displacements: for an isoparametric element `grad_x N_a = F^-T grad_X N_a` and
//! `da = det(F) dA` exactly, so no shape function is evaluated again.

use cosdem_common::voigt::{XX, XY, YX, YY};

/// Which configuration the balance equations are written on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kinematics {
    /// Integrals over the reference mesh, the material's stress used as the nominal stress,
    /// no geometric stiffness, dead pressures: the paper's small-strain statement.
    #[default]
    Small,
    /// Integrals over the configuration of the iterate (`x = X + u`) with the Cauchy stress,
    /// geometric stiffness, pressures that follow the deformed edges.
    UpdatedLagrangian,
}

/// The deformation gradient `F = I + sum_a u_a grad_X N_a^T` of an element's displacements
/// `u[a] = [u_x, u_y]` at a point with reference gradients `grad`.
pub fn deformation_gradient(grad: &[[f64; 2]], u: impl Fn(usize) -> [f64; 2]) -> [[f64; 2]; 2] {
    let mut f = [[1.0, 0.0], [0.0, 1.0]];
    for (a, g) in grad.iter().enumerate() {
        let d = u(a);
        for i in 0..2 {
            f[i][0] += g[0] * d[i];
            f[i][1] += g[1] * d[i];
        }
    }
    f
}

/// `det F`.
pub fn det(f: &[[f64; 2]; 2]) -> f64 {
    f[0][0] * f[1][1] - f[0][1] * f[1][0]
}

/// The current shape gradients `grad_x N_a = F^-T grad_X N_a` into `out` (needs `det F != 0`).
pub fn current_gradients(f: &[[f64; 2]; 2], grad: &[[f64; 2]], out: &mut [[f64; 2]]) {
    let j = det(f);
    // F^-1 = [[F_yy, -F_xy], [-F_yx, F_xx]] / J; (F^-T g)_i = sum_k Finv_ki g_k
    let inv = [[f[1][1] / j, -f[0][1] / j], [-f[1][0] / j, f[0][0] / j]];
    for (o, g) in out.iter_mut().zip(grad) {
        *o = [inv[0][0] * g[0] + inv[1][0] * g[1], inv[0][1] * g[0] + inv[1][1] * g[1]];
    }
}

/// `z = (F_xx + F_yy) + i (F_yx - F_xy)`, whose argument is the polar angle; `dz` of a
/// change `dF` likewise. Returned as `(re, im)`.
fn z_of(f: &[[f64; 2]; 2]) -> (f64, f64) {
    (f[0][0] + f[1][1], f[1][0] - f[0][1])
}

/// `d theta / d F_ij` (row i, column j) of the polar angle `theta`
/// ([`MacroDeformation::polar_angle`](cosdem_common::MacroDeformation::polar_angle), the
/// Cauchy field's micro-rotation under the updated-Lagrangian option): `theta = Im log z`,
/// so `d theta = Im(dz / z)`.
pub fn polar_angle_derivative(f: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let (c, s) = z_of(f);
    let d = c * c + s * s;
    // Im(dz conj(z)) / |z|^2 = (c dz_im - s dz_re) / d, dz_re = dF_xx + dF_yy,
    // dz_im = dF_yx - dF_xy.
    [[-s / d, -c / d], [c / d, -s / d]]
}

/// The second derivative of the polar angle along two changes of `F`:
/// `d2 theta [A, B] = -Im(dz_A dz_B / z^2)` (symmetric in `A` and `B`).
pub fn polar_angle_hessian(f: &[[f64; 2]; 2], a: &[[f64; 2]; 2], b: &[[f64; 2]; 2]) -> f64 {
    let (c, s) = z_of(f);
    let (ar, ai) = z_of(a);
    let (br, bi) = z_of(b);
    // p = dz_A dz_B, q = conj(z)^2, result = -Im(p q) / |z|^4
    let (pr, pi) = (ar * br - ai * bi, ar * bi + ai * br);
    let (qr, qi) = (c * c - s * s, -2.0 * c * s);
    let d = c * c + s * s;
    -(pr * qi + pi * qr) / (d * d)
}

/// The stress vector `[s_xx, s_yy, s_xy, s_yx, ..]` as the matrix `s_ij` (face normal first).
pub fn stress_matrix(s: &[f64]) -> [[f64; 2]; 2] {
    [[s[XX], s[XY]], [s[YX], s[YY]]]
}

/// What the Cauchy field's geometric stiffness needs of its polar rotation at a Gauss point:
/// `F`, the reference shape gradients and `dtheta[a] = [d theta/du_ax, d theta/du_ay]`.
#[derive(Clone, Copy, Debug)]
pub struct PolarRotation<'a> {
    /// The deformation gradient.
    pub f: &'a [[f64; 2]; 2],
    /// Reference shape gradients `grad_X N_a`.
    pub grad_ref: &'a [[f64; 2]],
    /// The polar angle's derivative by the nodal displacements.
    pub dtheta: &'a [[f64; 2]],
}

/// Adds the geometric stiffness of one Gauss point to the element matrix `ke` (`nd x nd`,
/// row-major, `ndf` dofs per node), with the current gradients `gc`, shape values `n`,
/// the stress `s` (Voigt) and the current area `da` (docs/theory.md, "Updated-Lagrangian
/// option"):
///
/// - `K(u_a j, u_b l) += delta_jl N_a,i s_ik N_b,k da` (the initial-stress term, with the
///   non-symmetric `s` as it stands);
/// - Cosserat: `K(w_a, u_b l) += N_a (s_yx - s_xy) N_b,l da` (the moment balance's relative
///   rotation term turning with the element);
/// - Cauchy: `K(u_a j, u_b l) += (s_yx - s_xy) (dtheta_aj N_b,l + d2theta_aj,bl) da` with
///   `theta` the polar angle sent as the rotation, `dtheta` its derivative by the nodal
///   displacements (`dtheta[a] = [d/du_ax, d/du_ay]`) and `d2theta` the second one.
pub fn add_geometric_stiffness(
    ke: &mut [f64],
    nd: usize,
    ndf: usize,
    n: &[f64],
    gc: &[[f64; 2]],
    s: &[f64],
    da: f64,
    cauchy: Option<PolarRotation<'_>>,
) {
    let sm = stress_matrix(s);
    let skew = s[YX] - s[XY];
    let nn = n.len();
    for a in 0..nn {
        // N_a,i s_ik
        let ga =
            [gc[a][0] * sm[0][0] + gc[a][1] * sm[1][0], gc[a][0] * sm[0][1] + gc[a][1] * sm[1][1]];
        for b in 0..nn {
            let kab = (ga[0] * gc[b][0] + ga[1] * gc[b][1]) * da;
            for j in 0..2 {
                ke[(a * ndf + j) * nd + b * ndf + j] += kab;
            }
            match cauchy {
                None if ndf == 3 => {
                    for l in 0..2 {
                        ke[(a * ndf + 2) * nd + b * ndf + l] += n[a] * skew * gc[b][l] * da;
                    }
                }
                None => {}
                Some(PolarRotation { f, grad_ref, dtheta }) => {
                    for j in 0..2 {
                        let mut dfa = [[0.0; 2]; 2];
                        dfa[j] = grad_ref[a];
                        for l in 0..2 {
                            let mut dfb = [[0.0; 2]; 2];
                            dfb[l] = grad_ref[b];
                            let h = polar_angle_hessian(f, &dfa, &dfb);
                            ke[(a * ndf + j) * nd + b * ndf + l] +=
                                skew * (dtheta[a][j] * gc[b][l] + h) * da;
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn polar_angle(f: &[[f64; 2]; 2]) -> f64 {
        cosdem_common::MacroDeformation { f: *f, w: 0.0, kappa: [0.0; 2] }.polar_angle()
    }

    fn rot(a: f64) -> [[f64; 2]; 2] {
        [[a.cos(), -a.sin()], [a.sin(), a.cos()]]
    }

    fn mul(a: &[[f64; 2]; 2], b: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
        std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
    }

    /// The polar angle of `R(a) U` (U symmetric positive definite) is `a`, for angles up to
    /// pi in magnitude (atan2 is exact to a few ulps).
    #[test]
    fn polar_angle_of_a_rotated_stretch_is_the_rotation() {
        let u = [[1.3, 0.2], [0.2, 0.8]];
        for a in [-3.0, -1.2, 0.0, 0.4, std::f64::consts::FRAC_PI_2, 3.1] {
            assert!((polar_angle(&mul(&rot(a), &u)) - a).abs() < 1e-14, "{a}");
        }
    }

    /// First and second derivatives of the polar angle against central differences (h =
    /// 1e-5 on entries ~1: truncation h^2 ~ 1e-10, cancellation 1e-16 / h ~ 1e-11).
    #[test]
    fn polar_angle_derivatives_match_central_differences() {
        let f = [[1.2, 0.45], [-0.3, 0.7]];
        let d = polar_angle_derivative(&f);
        let h = 1e-5;
        let unit = |i: usize, j: usize| {
            let mut e = [[0.0; 2]; 2];
            e[i][j] = 1.0;
            e
        };
        let plus = |f: &[[f64; 2]; 2], e: &[[f64; 2]; 2], t: f64| {
            std::array::from_fn(|i| std::array::from_fn(|j| f[i][j] + t * e[i][j]))
        };
        for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            let e = unit(i, j);
            let fd = (polar_angle(&plus(&f, &e, h)) - polar_angle(&plus(&f, &e, -h))) / (2.0 * h);
            assert!((fd - d[i][j]).abs() < 1e-9, "d theta / dF_{i}{j}: {} vs {fd}", d[i][j]);
            for (k, l) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                let g = unit(k, l);
                let dp = polar_angle_derivative(&plus(&f, &g, h));
                let dm = polar_angle_derivative(&plus(&f, &g, -h));
                let fd2 = (dp[i][j] - dm[i][j]) / (2.0 * h);
                let an = polar_angle_hessian(&f, &e, &g);
                assert!((fd2 - an).abs() < 1e-8, "d2 theta [{i}{j}, {k}{l}]: {an} vs {fd2}");
            }
        }
    }

    /// `grad_x N = F^-T grad_X N`: the chain rule, checked on a linear field `v = c . X`
    /// whose current gradient is `F^-T c` (round-off).
    #[test]
    fn current_gradients_are_the_chain_rule() {
        let f = [[1.1, 0.3], [-0.2, 0.9]];
        let c = [0.7, -1.3];
        let mut out = [[0.0; 2]];
        current_gradients(&f, &[c], &mut out);
        // F^T out = c
        let back =
            [f[0][0] * out[0][0] + f[1][0] * out[0][1], f[0][1] * out[0][0] + f[1][1] * out[0][1]];
        assert!((back[0] - c[0]).abs() < 1e-15 && (back[1] - c[1]).abs() < 1e-15);
    }
}
