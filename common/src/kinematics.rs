//! Macro kinematics at a Gauss point: what the master sends, what an assembly is driven by.

use crate::voigt::{KX, KY, N, XX, XY, YX, YY};
use serde::{Deserialize, Serialize};

/// Why a macro deformation cannot drive an assembly.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    /// A component is NaN or infinite.
    #[error("macro deformation field `{field}` is not finite: {value}")]
    NotFinite {
        /// Name of the field (`F_xx`, `w`, `k_x`, ...).
        field: &'static str,
        /// The offending value.
        value: f64,
    },
    /// det(Fbar) <= 0: the deformation inverts or collapses the assembly.
    #[error("macro deformation gradient is not invertible: det(F) = {det} (must be > 0)")]
    NotInvertible {
        /// The determinant found.
        det: f64,
    },
}

/// Kinematics of a Cosserat material point (THEORY.md sections 1-2).
///
/// `f[a][b] = Fbar_ab = delta_ab + du_a/dx_b` (it includes the continuum rotation);
/// `w` is the independent micro-rotation; `kappa = [w,x, w,y]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MacroDeformation {
    /// Deformation gradient, row a column b: `delta_ab + du_a/dx_b`.
    pub f: [[f64; 2]; 2],
    /// Macro micro-rotation (rad, counter-clockwise).
    pub w: f64,
    /// Macro curvature `[w,x, w,y]` (1/m).
    pub kappa: [f64; 2],
}

impl Default for MacroDeformation {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl MacroDeformation {
    /// The undeformed state.
    pub const IDENTITY: Self = Self { f: [[1.0, 0.0], [0.0, 1.0]], w: 0.0, kappa: [0.0, 0.0] };

    /// From the displacement gradient `g[a][b] = du_a/dx_b`, rotation and curvature.
    pub fn from_gradient(g: [[f64; 2]; 2], w: f64, kappa: [f64; 2]) -> Self {
        Self { f: [[1.0 + g[0][0], g[0][1]], [g[1][0], 1.0 + g[1][1]]], w, kappa }
    }

    /// From the Cosserat strain vector `e` (small strain) and the micro-rotation `w`:
    /// the inverse of [`MacroDeformation::strain`].
    pub fn from_strain(e: &[f64; N], w: f64) -> Self {
        // e_xy = u_y,x - w, e_yx = u_x,y + w
        let g = [[e[XX], e[YX] - w], [e[XY] + w, e[YY]]];
        Self::from_gradient(g, w, [e[KX], e[KY]])
    }

    /// The deformation a fraction `t` of the way from `self` to `to`: `F`, `w` and `kappa`
    /// each linear in `t` (the straight path of a load step in the macro dofs, which are
    /// linear in all three). `t = 0` is `self`, `t = 1` is `to` exactly.
    pub fn interpolate(&self, to: &Self, t: f64) -> Self {
        if t == 1.0 {
            return *to;
        }
        let l = |a: f64, b: f64| (b - a).mul_add(t, a);
        Self {
            f: std::array::from_fn(|a| std::array::from_fn(|b| l(self.f[a][b], to.f[a][b]))),
            w: l(self.w, to.w),
            kappa: std::array::from_fn(|a| l(self.kappa[a], to.kappa[a])),
        }
    }

    /// Displacement gradient `du_a/dx_b = F_ab - delta_ab`.
    pub fn gradient(&self) -> [[f64; 2]; 2] {
        [[self.f[0][0] - 1.0, self.f[0][1]], [self.f[1][0], self.f[1][1] - 1.0]]
    }

    /// The Cosserat strain vector `[e_xx, e_yy, e_xy, e_yx, k_x, k_y]` (Eqs. 4-6).
    pub fn strain(&self) -> [f64; N] {
        let g = self.gradient();
        [g[0][0], g[1][1], g[1][0] - self.w, g[0][1] + self.w, self.kappa[0], self.kappa[1]]
    }

    /// Angle of the polar rotation of `F` (`F = R(theta) U`, `U` symmetric positive definite),
    /// `theta = atan2(F_yx - F_xy, F_xx + F_yy)` in `(-pi, pi]`, counter-clockwise.
    ///
    /// The micro-rotation of a Cauchy (non-Cosserat) point under the updated-Lagrangian
    /// option; its linearisation at `F = I` is `(u_y,x - u_x,y) / 2`. Meaningful for
    /// `det(F) > 0`.
    pub fn polar_angle(&self) -> f64 {
        (self.f[1][0] - self.f[0][1]).atan2(self.f[0][0] + self.f[1][1])
    }

    /// The objective Cosserat stretch strain `E = R(w)^T F - I`, with
    /// `R(a) = [[cos a, -sin a], [sin a, cos a]]`, in the Voigt order of
    /// [`MacroDeformation::strain`]: `[E_xx, E_yy, E_yx, E_xy, kappa_x, kappa_y]`.
    ///
    /// Entry `XY` is the `(y, x)` entry of `E` (first order: `u_y,x - w`), entry `YX` the
    /// `(x, y)` entry (`u_x,y + w`); the curvature entries are `kappa` as sent (the reference
    /// curvature `grad_X w`, itself objective). Equal to [`MacroDeformation::strain`] up to
    /// terms of second order in `(F - I, w)`, and zero for any rigid motion
    /// `F = R(a)`, `w = a`, `kappa = 0`.
    pub fn stretch_strain(&self) -> [f64; N] {
        let (s, c) = self.w.sin_cos();
        let f = &self.f;
        // R^T = [[c, s], [-s, c]].
        let u = [
            [c * f[0][0] + s * f[1][0], c * f[0][1] + s * f[1][1]],
            [c * f[1][0] - s * f[0][0], c * f[1][1] - s * f[0][1]],
        ];
        [u[0][0] - 1.0, u[1][1] - 1.0, u[1][0], u[0][1], self.kappa[0], self.kappa[1]]
    }

    /// `det(Fbar)`: the ratio of current to reference area.
    pub fn det(&self) -> f64 {
        self.f[0][0] * self.f[1][1] - self.f[0][1] * self.f[1][0]
    }

    /// Checks that every component is finite and that `det(Fbar) > 0`.
    pub fn validate(&self) -> Result<(), KinematicsError> {
        let fields = [
            ("F_xx", self.f[0][0]),
            ("F_xy", self.f[0][1]),
            ("F_yx", self.f[1][0]),
            ("F_yy", self.f[1][1]),
            ("w", self.w),
            ("k_x", self.kappa[0]),
            ("k_y", self.kappa[1]),
        ];
        for (field, value) in fields {
            if !value.is_finite() {
                return Err(KinematicsError::NotFinite { field, value });
            }
        }
        let det = self.det();
        if det.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(KinematicsError::NotInvertible { det });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn strain_follows_theory_sign_conventions() {
        // u_x = a y, u_y = b x, w = c: e_xy = b - c, e_yx = a + c.
        let m = MacroDeformation::from_gradient([[0.0, 0.3], [0.2, 0.0]], 0.05, [0.1, -0.2]);
        let e = m.strain();
        assert_eq!(e, [0.0, 0.0, 0.2 - 0.05, 0.3 + 0.05, 0.1, -0.2]);
    }

    #[test]
    fn rejects_nan_and_inversion_naming_the_field() {
        let mut m = MacroDeformation::IDENTITY;
        m.kappa[1] = f64::NAN;
        let err = m.validate().unwrap_err().to_string();
        assert!(err.contains("k_y"), "{err}");
        let m = MacroDeformation::from_gradient([[-1.0, 0.0], [0.0, 0.0]], 0.0, [0.0; 2]);
        assert!(matches!(m.validate(), Err(KinematicsError::NotInvertible { .. })));
    }

    #[test]
    fn interpolate_ends_exactly_and_is_linear_in_the_strain() {
        let a = MacroDeformation::from_gradient([[1e-3, 2e-4], [-3e-4, -2e-3]], 1e-4, [0.5, -0.2]);
        let b = MacroDeformation::from_gradient([[3e-3, -1e-4], [5e-4, -6e-3]], -2e-4, [0.1, 0.3]);
        assert_eq!(a.interpolate(&b, 0.0), a);
        assert_eq!(a.interpolate(&b, 1.0), b);
        // The strain is linear in F and w, so the midpoint's strain is the mean strain, to a
        // few roundings of the largest number involved: F_xx, F_yy near 1 (ulp 2.2e-16).
        let (ea, eb, em) = (a.strain(), b.strain(), a.interpolate(&b, 0.5).strain());
        for k in 0..N {
            assert!((em[k] - 0.5 * (ea[k] + eb[k])).abs() <= 4.0 * f64::EPSILON, "component {k}");
        }
    }

    /// `R(a) F` and `w + a`: the same deformation seen after a superposed rotation by `a`.
    fn rotated(m: &MacroDeformation, a: f64) -> MacroDeformation {
        let (s, c) = a.sin_cos();
        let f = m.f;
        MacroDeformation {
            f: [
                [c * f[0][0] - s * f[1][0], c * f[0][1] - s * f[1][1]],
                [s * f[0][0] + c * f[1][0], s * f[0][1] + c * f[1][1]],
            ],
            w: m.w + a,
            kappa: m.kappa,
        }
    }

    #[test]
    fn polar_angle_of_a_rotation_and_of_a_stretch() {
        // F = R(a) diag(2, 0.5): the polar angle is a for every a in (-pi, pi). Round-off: the
        // atan2 of entries of size 2 computed with a few roundings, ~1e-15 rad.
        for k in -19..=19 {
            let a = k as f64 * std::f64::consts::PI / 20.0;
            let m = MacroDeformation { f: [[2.0, 0.0], [0.0, 0.5]], w: 0.0, kappa: [0.0; 2] };
            let theta = rotated(&m, a).polar_angle();
            assert!((theta - a).abs() <= 1e-14, "a = {a}: theta = {theta}");
        }
        // Linearisation at F = I: (u_y,x - u_x,y) / 2, error second order: |H|^2 = 1e-8 bounds
        // it (here it is theta tr(H) / 2 = 2e-9).
        let m = MacroDeformation::from_gradient([[1e-4, -3e-5], [7e-5, -2e-5]], 0.0, [0.0; 2]);
        let err = (m.polar_angle() - 0.5 * (7e-5 + 3e-5)).abs();
        assert!(err > 0.0 && err <= 1e-8, "linearisation error {err}");
    }

    #[test]
    fn stretch_strain_is_zero_for_a_rigid_motion() {
        // F = R(a), w = a, kappa = 0 for a in [-pi, pi]: R(a)^T R(a) - I is round-off
        // (products and sums of sin, cos of magnitude <= 1: a few 1e-16).
        for k in -20..=20 {
            let a = k as f64 * std::f64::consts::PI / 20.0;
            let e = rotated(&MacroDeformation::IDENTITY, a).stretch_strain();
            assert!(e.iter().all(|v| v.abs() <= 1e-15), "a = {a}: {e:?}");
        }
    }

    #[test]
    fn stretch_strain_is_the_small_strain_to_first_order() {
        // The difference is second order: halving (H, w) must divide it by 4 (within 10 %),
        // and it stays below |(H, w)|^2.
        let h = [[0.03, -0.02], [0.05, -0.04]];
        let (w, kappa) = (0.025, [0.7, -0.3]);
        let diff = |t: f64| {
            let g = [[t * h[0][0], t * h[0][1]], [t * h[1][0], t * h[1][1]]];
            let m = MacroDeformation::from_gradient(g, t * w, kappa);
            let (a, b) = (m.stretch_strain(), m.strain());
            assert_eq!((a[KX], a[KY]), (b[KX], b[KY]));
            (0..N).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max)
        };
        let norm2: f64 = h.iter().flatten().map(|v| v * v).sum::<f64>() + w * w;
        let (d1, d2) = (diff(1.0), diff(0.5));
        assert!(d1 > 0.0 && d1 <= norm2, "difference {d1} against |(H, w)|^2 = {norm2}");
        assert!((d1 / d2 - 4.0).abs() <= 0.4, "ratio {}", d1 / d2);
    }

    proptest! {
        #[test]
        fn stretch_strain_is_invariant_under_a_superposed_rotation(
            g in prop::array::uniform4(-0.5f64..0.5),
            w in -0.7f64..0.7,
            b in -std::f64::consts::PI..std::f64::consts::PI,
        ) {
            let m = MacroDeformation::from_gradient([[g[0], g[1]], [g[2], g[3]]], w, [0.4, -0.1]);
            let (e0, e1) = (m.stretch_strain(), rotated(&m, b).stretch_strain());
            // R(w + b)^T R(b) F = R(w)^T F up to round-off of entries of size <= 2.
            for k in 0..N {
                prop_assert!((e0[k] - e1[k]).abs() <= 1e-14, "component {k}: {e0:?} {e1:?}");
            }
            // The polar angle turns by b (mod 2 pi) when F is invertible.
            if m.det() > 0.0 {
                let d = rotated(&m, b).polar_angle() - m.polar_angle() - b;
                let d = (d + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                    - std::f64::consts::PI;
                prop_assert!(d.abs() <= 1e-13, "polar angle off by {d}");
            }
        }
    }

    proptest! {
        #[test]
        fn from_strain_inverts_strain(e in prop::array::uniform6(-0.1f64..0.1), w in -0.1f64..0.1) {
            let m = MacroDeformation::from_strain(&e, w);
            let back = m.strain();
            for k in 0..N {
                // One rounding in each direction: 1 ulp of the largest term involved.
                prop_assert!((back[k] - e[k]).abs() <= 4.0 * f64::EPSILON);
            }
        }
    }
}
