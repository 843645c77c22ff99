//! The sub-step path of [`crate::spec::TangentFrame::Current`] (design note
//! 2026-12-05-updated-lagrangian, section 4 step 1): between the committed deformation and the
//! target, the increment `dF = F_1 F_0^-1 = R_d U_d` is followed by turning `R_d` by its angle
//! and stretching `U_d` linearly, instead of the straight line in `F`. The straight line
//! shrinks a rotation on the way (a 9-degree increment by `1 - cos(4.5 deg)` = 3e-3 at its
//! midpoint), which a frictional assembly remembers; the polar path keeps a rigid rotation
//! rigid at every sub-step.

use crate::boundary::{mat_inv, mat_mul, rotation_angle};
use cosdem_common::MacroDeformation;

/// The plane rotation `R(a) = [[cos a, -sin a], [sin a, cos a]]`.
pub(crate) fn rot(a: f64) -> [[f64; 2]; 2] {
    let (s, c) = a.sin_cos();
    [[c, -s], [s, c]]
}

/// `R^T` of a 2x2 matrix.
pub(crate) fn transpose(m: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    [[m[0][0], m[1][0]], [m[0][1], m[1][1]]]
}

/// The deformation a fraction `t` of the way from `from` to `to` along the polar path:
/// `F(t) = R(t a) (I + t (U_d - I)) F_0` with `dF = F_1 F_0^-1 = R(a) U_d` (the polar
/// decomposition, `a` in (-pi, pi]), `w` and `kappa` linear in `t` as on the straight path.
/// `t = 0` is `from` and `t = 1` is `to`, exactly. A pure rotation increment (`U_d = I`) stays
/// a rotation of `F_0` all the way: `det F(t) = det F_0` and the stretch of `F(t)` is that of
/// `F_0`. Both ends must be valid deformations (`det F > 0`).
pub fn interpolate_polar(
    from: &MacroDeformation,
    to: &MacroDeformation,
    t: f64,
) -> MacroDeformation {
    if t == 0.0 {
        return *from;
    }
    if t == 1.0 {
        return *to;
    }
    let df = mat_mul(&to.f, &mat_inv(&from.f));
    let a = rotation_angle(&df);
    let u = mat_mul(&transpose(&rot(a)), &df);
    let stretch: [[f64; 2]; 2] = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let delta = if i == j { 1.0 } else { 0.0 };
            (u[i][j] - delta).mul_add(t, delta)
        })
    });
    let f = mat_mul(&rot(t * a), &mat_mul(&stretch, &from.f));
    let l = |a: f64, b: f64| (b - a).mul_add(t, a);
    MacroDeformation {
        f,
        w: l(from.w, to.w),
        kappa: std::array::from_fn(|i| l(from.kappa[i], to.kappa[i])),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn det(f: &[[f64; 2]; 2]) -> f64 {
        f[0][0] * f[1][1] - f[0][1] * f[1][0]
    }

    /// The symmetric stretch `U = R^T F` of a deformation gradient.
    fn stretch(f: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
        mat_mul(&transpose(&rot(rotation_angle(f))), f)
    }

    fn sheared() -> MacroDeformation {
        MacroDeformation { f: [[1.02, 0.13], [-0.04, 0.95]], w: 0.05, kappa: [0.3, -0.1] }
    }

    /// The ends are the ends, bit for bit (the sub-steps end on the target itself).
    #[test]
    fn the_path_ends_exactly_on_both_ends() {
        let a = sheared();
        let b = MacroDeformation { f: [[0.9, -0.2], [0.35, 1.1]], w: 0.4, kappa: [-0.2, 0.5] };
        assert_eq!(interpolate_polar(&a, &b, 0.0), a);
        assert_eq!(interpolate_polar(&a, &b, 1.0), b);
        // Just inside the ends the path is continuous with them: within t |dF| of the start.
        let near = interpolate_polar(&a, &b, 1e-9);
        for i in 0..2 {
            for j in 0..2 {
                assert!((near.f[i][j] - a.f[i][j]).abs() < 1e-8, "F_{i}{j}");
            }
        }
    }

    /// A rigid rotation of a sheared `F_0` by 90 degrees stays a rotation of `F_0` at every
    /// point of the path: `F(t) = R(t pi/2) F_0`, so `det F` and the stretch `U` of `F(t)` are
    /// those of `F_0`. The tolerance is a few roundings of entries of order 1 (1e-15); the
    /// control, the straight path, halves `det F` at its midpoint (`det((I + R(pi/2)) / 2) =
    /// 1/2`).
    #[test]
    fn a_rotation_increment_stays_a_rotation_along_the_path() {
        let from = sheared();
        let q = rot(std::f64::consts::FRAC_PI_2);
        let to = MacroDeformation { f: mat_mul(&q, &from.f), w: from.w + 1.5, ..from };
        let (d0, u0) = (det(&from.f), stretch(&from.f));
        for k in 1..10 {
            let t = f64::from(k) / 10.0;
            let p = interpolate_polar(&from, &to, t);
            assert!((det(&p.f) - d0).abs() <= 1e-15, "t = {t}: det {} vs {d0}", det(&p.f));
            let want = mat_mul(&rot(t * std::f64::consts::FRAC_PI_2), &from.f);
            let u = stretch(&p.f);
            for i in 0..2 {
                for j in 0..2 {
                    assert!((u[i][j] - u0[i][j]).abs() <= 1e-15, "t = {t}: U_{i}{j}");
                    assert!((p.f[i][j] - want[i][j]).abs() <= 1e-15, "t = {t}: F_{i}{j}");
                }
            }
            assert!((p.w - (from.w + 1.5 * t)).abs() <= 1e-15);
        }
        let straight = from.interpolate(&to, 0.5);
        assert!((det(&straight.f) / d0 - 0.5).abs() < 1e-12, "the control's det halves");
    }

    /// A pure stretch increment (no rotation) is the straight path: `F(t) = (I + t (U - I))
    /// F_0` is linear in `t`, so the polar and straight paths agree to rounding.
    #[test]
    fn a_stretch_increment_follows_the_straight_path() {
        let from = MacroDeformation { f: [[1.01, 0.0], [0.0, 0.99]], w: 0.0, kappa: [0.0; 2] };
        let to = MacroDeformation { f: [[0.97, 0.0], [0.0, 1.03]], w: 0.01, kappa: [0.1, 0.0] };
        for t in [0.25, 0.5, 0.75] {
            let (p, s) = (interpolate_polar(&from, &to, t), from.interpolate(&to, t));
            for i in 0..2 {
                for j in 0..2 {
                    assert!((p.f[i][j] - s.f[i][j]).abs() <= 4.0 * f64::EPSILON, "t = {t}");
                }
            }
            assert_eq!((p.w, p.kappa), (s.w, s.kappa));
        }
    }
}
