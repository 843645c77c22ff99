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
