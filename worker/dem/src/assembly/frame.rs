//! The perturbation columns and the shortcut's answer in each [`TangentFrame`] (design note
//! 2026-12-05-updated-lagrangian, section 2.4).
//!
//! Under [`TangentFrame::Current`] the tangent is convected: with `g = grad_x du` the
//! variation of the current configuration and `dw` that of the micro-rotation,
//!
//! ```text
//! ds = g s - tr(g) s + s g^T + C[de]        dm = g m - tr(g) m + C_m[de]
//! ```
//!
//! where `de` is the Cosserat strain increment on the current configuration (Voigt `de_kl =
//! (g - dw Z)_lk`, curvature part `grad_x(dw)`). A column of the perturbation tangent is then
//! the difference of relaxations at `F' = (I +- h E) F` (strain column: `g = h E`, `dw = 0`,
//! `E` the unit matrix with `E[1][0] = 1` for `e_xy = u_y,x - w`) or at `K' = K +- h F^T e_i`
//! (curvature column: `K = grad_X w = F^T grad_x w`, so `grad_x(dw) = h e_i`), minus the
//! transport term. The shortcut's finite version of the same rate is `s = R_d [G s_0 G^T /
//! det G + C de] R_d^T`, `m = R_d [G m_0 / det G + C_m de]`, with `dF = R_d G`: exact for a
//! rigid rotation (`G = I`, `de = 0`), objective (a rotation superposed on the target turns
//! the answer), and its first order is the rate above.

use super::Assembly;
use super::path::{rot, transpose};
use crate::boundary::{mat_inv, mat_mul, rotation_angle};
use crate::spec::{BoundarySpec, TangentFrame};
use cosdem_common::voigt::{KX, KY, N, XX, XY, YX, YY, index};
use cosdem_common::{MacroDeformation, StressVector, Tangent};

/// The unit matrix `E` (`E[a][b] = 1`) of strain column `col`: `e_xx -> (0, 0)`, `e_yy -> (1,
/// 1)`, `e_xy = u_y,x - w -> (1, 0)`, `e_yx = u_x,y + w -> (0, 1)`; `None` for a curvature.
fn unit(col: usize) -> Option<(usize, usize)> {
    match col {
        XX => Some((0, 0)),
        YY => Some((1, 1)),
        XY => Some((1, 0)),
        YX => Some((0, 1)),
        _ => None,
    }
}

/// `base` with Cosserat strain component `col` changed by `h` (micro-rotation fixed), in
/// `frame`: additively in `F` and `K` for [`TangentFrame::Reference`], `F' = (I + h E) F` and
/// `K' = K + h F^T e_i` for [`TangentFrame::Current`].
pub(crate) fn perturbed(
    base: &MacroDeformation,
    col: usize,
    h: f64,
    frame: TangentFrame,
) -> MacroDeformation {
    let mut t = *base;
    match (frame, unit(col)) {
        (TangentFrame::Reference, Some((a, b))) => t.f[a][b] += h,
        (TangentFrame::Reference, None) => t.kappa[col - KX] += h,
        (TangentFrame::Current, Some((a, b))) => {
            // Row a of (I + h E) F is row a of F plus h times row b.
            for j in 0..2 {
                t.f[a][j] = h.mul_add(base.f[b][j], base.f[a][j]);
            }
        }
        (TangentFrame::Current, None) => {
            let i = col - KX;
            for j in 0..2 {
                t.kappa[j] = h.mul_add(base.f[i][j], base.kappa[j]);
            }
        }
    }
    t
}

/// The transport part of column `col` of the convected rate at stress `s`: `E s - tr(E) s + s
/// E^T` in the stress rows (Voigt: `s_ij = s[index(i, j)]`, face normal first) and `E m -
/// tr(E) m` in the couple-stress rows, for the unit matrix `E` of a strain column; zero for a
/// curvature column (`g = 0`).
pub(crate) fn transport(col: usize, s: &StressVector) -> [f64; N] {
    let mut out = [0.0; N];
    let Some((a, b)) = unit(col) else { return out };
    let tr = if a == b { 1.0 } else { 0.0 };
    let m = |i: usize, j: usize| s[index(i, j)];
    for i in 0..2 {
        for j in 0..2 {
            let es = if i == a { m(b, j) } else { 0.0 };
            let se = if j == a { m(i, b) } else { 0.0 };
            out[index(i, j)] = es + se - tr * m(i, j);
        }
        let em = if i == a { s[KX + b] } else { 0.0 };
        out[KX + i] = em - tr * s[KX + i];
    }
    out
}

/// The increment from `old` to `new` split as the shortcut of [`TangentFrame::Current`]
/// needs it: `dF = F_new F_old^-1 = R_d G`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Increment {
    /// The rotation the assembly follows: `R(w_new - w_old)` for the penalty boundary (whose
    /// boundary discs turn with `w`), the polar rotation of `dF` for the periodic cell (whose
    /// discs turn with the continuum and which ignores `w`).
    pub rotation: [[f64; 2]; 2],
    /// `G = R_d^T dF`: the stretch of the increment (with the relative rotation of continuum
    /// and micro-rotation for the penalty boundary).
    pub stretch: [[f64; 2]; 2],
    /// The Cosserat strain increment on the committed configuration: `G - I` in Voigt order
    /// (`[G_xx - 1, G_yy - 1, G_yx, G_xy]`), curvature `F_old^-T (K_new - K_old)`.
    pub strain: [f64; N],
}

/// The increment from `old` to `new` ([`Increment`]).
pub(crate) fn increment(
    old: &MacroDeformation,
    new: &MacroDeformation,
    periodic: bool,
) -> Increment {
    let fi = mat_inv(&old.f);
    let df = mat_mul(&new.f, &fi);
    let rotation = rot(if periodic { rotation_angle(&df) } else { new.w - old.w });
    let g = mat_mul(&transpose(&rotation), &df);
    let dk = [new.kappa[0] - old.kappa[0], new.kappa[1] - old.kappa[1]];
    // grad_x(dw) on the committed configuration: F_old^-T dK.
    let k = |i: usize| fi[0][i].mul_add(dk[0], fi[1][i] * dk[1]);
    let strain = [g[0][0] - 1.0, g[1][1] - 1.0, g[1][0], g[0][1], k(0), k(1)];
    Increment { rotation, stretch: g, strain }
}

/// The 6 x 6 tangent `c` (rows and columns in Voigt order) of a state turned by `q`: `C'_ijkl
/// = q_ia q_jb q_kc q_ld C_abcd` on the stress-strain block, `m` and `k` turning as vectors.
pub(crate) fn rotate_tangent(c: &Tangent, q: &[[f64; 2]; 2]) -> Tangent {
    let mut t = [[0.0; N]; N];
    for i in 0..2 {
        for j in 0..2 {
            for a in 0..2 {
                for b in 0..2 {
                    t[index(i, j)][index(a, b)] = q[i][a] * q[j][b];
                }
            }
        }
        for a in 0..2 {
            t[KX + i][KX + a] = q[i][a];
        }
    }
    let mut tc = [[0.0; N]; N];
    for r in 0..N {
        for k in 0..N {
            tc[r][k] = (0..N).map(|l| t[r][l] * c[l][k]).sum();
        }
    }
    let mut out = [[0.0; N]; N];
    for r in 0..N {
        for k in 0..N {
            out[r][k] = (0..N).map(|l| tc[r][l] * t[k][l]).sum();
        }
    }
    out
}

/// The shortcut answer of [`TangentFrame::Current`] from the relaxed stress `s0` and tangent
/// `c` over the increment `inc`: `s = R_d [G s_0 G^T / det G + C de] R_d^T`, `m = R_d [G m_0 /
/// det G + C_m de]`, and the tangent turned by `R_d`. Returns the stress, the tangent and the
/// size `max |C de|` of the extrapolated increment.
pub(crate) fn extrapolate_current(
    s0: &StressVector,
    c: &Tangent,
    inc: &Increment,
) -> (StressVector, Tangent, f64) {
    let g = &inc.stretch;
    let j = g[0][0] * g[1][1] - g[0][1] * g[1][0];
    let ds: [f64; N] =
        std::array::from_fn(|r| (0..N).fold(0.0, |acc, k| c[r][k].mul_add(inc.strain[k], acc)));
    let bound = ds.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let sm = [[s0[XX], s0[XY]], [s0[YX], s0[YY]]];
    let mut inner = mat_mul(&mat_mul(g, &sm), &transpose(g));
    for (i, row) in inner.iter_mut().enumerate() {
        for (k, v) in row.iter_mut().enumerate() {
            *v = *v / j + ds[index(i, k)];
        }
    }
    let m: [f64; 2] =
        std::array::from_fn(|i| g[i][0].mul_add(s0[KX], g[i][1] * s0[KY]) / j + ds[KX + i]);
    let r = &inc.rotation;
    let s = mat_mul(&mat_mul(r, &inner), &transpose(r));
    let mut out = [0.0; N];
    for i in 0..2 {
        for k in 0..2 {
            out[index(i, k)] = s[i][k];
        }
        out[KX + i] = r[i][0].mul_add(m[0], r[i][1] * m[1]);
    }
    (out, rotate_tangent(c, r), bound)
}

/// The size (in the measure of [`Assembly::increment_size`]) under which a current-frame
/// strain increment is nil for the secant tangent: 1e4 times the rounding of `dF - I` of a
/// rotation, far below any increment a load step makes.
const NIL_STRAIN: f64 = 1e-12;

/// `Q s Q^T` and `Q m` of a stress (or strain) vector in Voigt order.
pub(crate) fn turn(v: &[f64; N], q: &[[f64; 2]; 2]) -> [f64; N] {
    let m = [[v[XX], v[XY]], [v[YX], v[YY]]];
    let t = mat_mul(&mat_mul(q, &m), &transpose(q));
    let k: [f64; 2] = std::array::from_fn(|i| q[i][0].mul_add(v[KX], q[i][1] * v[KY]));
    [t[0][0], t[1][1], t[0][1], t[1][0], k[0], k[1]]
}

impl Assembly {
    /// The paper tangent `paper` scaled by the secant ratio from the committed relaxed state
    /// to the trial answer `stress` at `target` ([`crate::spec::TangentKind::Secant`]). The
    /// increments are `e - e_0` and `s - s_0` in [`TangentFrame::Reference`]; in
    /// [`TangentFrame::Current`] the strain increment of [`increment`] and the stress minus the
    /// committed stress carried by the increment (`R_d G s_0 G^T R_d^T / det G`), both on the
    /// trial configuration, so that a rigid rotation is no increment at all (the paper tangent).
    pub(super) fn secant_tangent(
        &self,
        paper: &Tangent,
        stress: &StressVector,
        target: &MacroDeformation,
    ) -> Tangent {
        let Some(c) = &self.committed.relaxed else { return *paper };
        let old = &self.committed.target;
        let (de, ds): ([f64; N], [f64; N]) = match self.spec.frame {
            TangentFrame::Reference => {
                let (e1, e0) = (target.strain(), old.strain());
                (
                    std::array::from_fn(|i| e1[i] - e0[i]),
                    std::array::from_fn(|i| stress[i] - c.stress[i]),
                )
            }
            TangentFrame::Current => {
                let periodic = matches!(self.spec.boundary, BoundarySpec::Periodic);
                let inc = increment(old, target, periodic);
                let carried = extrapolate_current(&c.stress, &[[0.0; N]; N], &inc).0;
                (turn(&inc.strain, &inc.rotation), std::array::from_fn(|i| stress[i] - carried[i]))
            }
        };
        // A rigid rotation leaves a current-frame strain increment of rounding size (1e-16):
        // no increment, like the nil increment of the reference frame.
        let half = 0.5 * self.refc.area.sqrt();
        let size =
            (0..N).map(|i| de[i].abs() * if i < KX { 1.0 } else { half }).fold(0.0, f64::max);
        if self.spec.frame == TangentFrame::Current && size <= NIL_STRAIN {
            return *paper;
        }
        let work: f64 = (0..N).map(|i| ds[i] * de[i]).sum();
        let elastic: f64 =
            (0..N).map(|i| de[i] * (0..N).map(|j| paper[i][j] * de[j]).sum::<f64>()).sum();
        if !(work > 0.0 && elastic > 0.0) {
            return *paper;
        }
        let (lo, hi) = crate::spec::SECANT_RANGE;
        let s = (work / elastic).clamp(lo, hi);
        paper.map(|row| row.map(|v| s * v))
    }
}

#[cfg(test)]
mod tests;
