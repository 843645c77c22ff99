//! The extrapolated predictor (`relaxation.predictor = "extrapolated"`, issue 30 item 1).
//!
//! A relaxation from the committed state starts from the affine jump (`predict`). On a smooth
//! loading path the assembly's non-affine response to the next increment is close to its
//! response to the last one, so the predictor adds the last committed step's non-affine
//! displacement and rotation of every disc when the new increment goes on in the last one's
//! direction:
//!
//! ```text
//! delta_q   = x_q(n) - [X_c + dF_n (x_q(n-1) - X_c)]          (at the commit of step n)
//! dtheta_q  = theta_q(n) - theta_q(n-1) - (affine rotation of step n)_q
//! s         = 1 if <a, b> / <b, b> > 2^-1.5 else 0,   a = the new increment, b = step n's
//! x_q      <- X_c + dF (x_q(n) - X_c) + s delta_q,   theta_q <- ... + s dtheta_q
//! ```
//!
//! The increments `a`, `b` are the vectors `(dF - I, dw, (sqrt(V)/2) dkappa)` of the shortcut's
//! measure, `dF = F_to F_from^-1`. A new direction (a new stage), a reversal or a step cut to
//! a quarter gets the affine jump alone ([`scale`] says why `s` is a step). The contact
//! histories follow the predicted relative motion of each pair, exactly as they follow the
//! affine jump's, so the path dependence of sliding stays that of the relaxation that
//! follows.
//!
//! The increment belongs to the committed state: it is recomputed at every commit (when the
//! spec asks for it), travels with the state's bytes, and so a restored or migrated
//! assembly predicts the same bits as the one it replaces.

use super::{Assembly, State};
use crate::boundary::{mat_inv, mat_mul};
use crate::spec::Predictor;
use cosdem_common::MacroDeformation;
use serde::{Deserialize, Serialize};

/// The projection of the new increment on the last above which the last step's non-affine
/// increment is added: `2^-1.5`, between a step cut in half and one cut to a quarter.
pub const THRESHOLD: f64 = 0.353_553_390_593_273_8;

/// The non-affine part of the last committed step, per disc.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepIncrement {
    /// The macro deformation the step started from.
    pub from: MacroDeformation,
    /// The macro deformation it was committed at (the committed state's target).
    pub to: MacroDeformation,
    /// Non-affine displacement, x (m).
    pub dx: Vec<f64>,
    /// Non-affine displacement, y (m).
    pub dy: Vec<f64>,
    /// Rotation beyond the affine rotation of the step (rad).
    pub dth: Vec<f64>,
}

/// The predicted non-affine displacement and rotation of every disc, added to the affine jump.
#[derive(Clone, Debug)]
pub(super) struct Shift {
    pub dx: Vec<f64>,
    pub dy: Vec<f64>,
    pub dth: Vec<f64>,
}

impl Shift {
    /// This shift times `s` (the first of `n` sub-jumps gets `1/n` of it).
    pub fn scaled(&self, s: f64) -> Shift {
        if s == 1.0 {
            return self.clone();
        }
        let times = |v: &[f64]| v.iter().map(|d| s * d).collect();
        Shift { dx: times(&self.dx), dy: times(&self.dy), dth: times(&self.dth) }
    }
}

impl Assembly {
    /// The increment of the step from the committed state `old` to the relaxed state `new`.
    pub(super) fn step_increment(&self, old: &State, new: &State) -> StepIncrement {
        let df = mat_mul(&new.target.f, &mat_inv(&old.target.f));
        let rot = self.affine_rotations(&old.target, &new.target);
        let xc = self.refc.xc;
        let (o, n) = (&old.dynamics, &new.dynamics);
        let count = self.disc_count();
        let (mut dx, mut dy, mut dth) =
            (Vec::with_capacity(count), Vec::with_capacity(count), Vec::with_capacity(count));
        for q in 0..count {
            // The affine image, computed as `predict` computes it.
            let (px, py) = (o.x[q] - xc[0], o.y[q] - xc[1]);
            dx.push(n.x[q] - (xc[0] + df[0][0].mul_add(px, df[0][1] * py)));
            dy.push(n.y[q] - (xc[1] + df[1][0].mul_add(px, df[1][1] * py)));
            dth.push(n.th[q] - (o.th[q] + rot[q]));
        }
        StepIncrement { from: old.target, to: new.target, dx, dy, dth }
    }

    /// The shift the extrapolated predictor adds to the jump from the committed state to
    /// `target`; None with the affine predictor, before the first committed step, when the
    /// stored increment does not end at the committed state, or when [`scale`] is 0.
    pub(super) fn extrapolation(&self, target: &MacroDeformation) -> Option<Shift> {
        if self.spec.relaxation.predictor != Predictor::Extrapolated {
            return None;
        }
        let inc = self.last_step.as_ref()?;
        let at = &self.committed.target;
        if inc.to != *at {
            return None;
        }
        let half = 0.5 * self.refc.area.sqrt();
        if scale(&increment(half, at, target), &increment(half, &inc.from, &inc.to)) == 0.0 {
            return None;
        }
        Some(Shift { dx: inc.dx.clone(), dy: inc.dy.clone(), dth: inc.dth.clone() })
    }
}

/// The increment from `from` to `to` as a vector: `dF - I` (`dF = F_to F_from^-1`), `dw` and
/// `half * dkappa` (`half` = sqrt(V)/2, the shortcut's measure).
pub fn increment(half: f64, from: &MacroDeformation, to: &MacroDeformation) -> [f64; 7] {
    let df = mat_mul(&to.f, &mat_inv(&from.f));
    [
        df[0][0] - 1.0,
        df[0][1],
        df[1][0],
        df[1][1] - 1.0,
        to.w - from.w,
        half * (to.kappa[0] - from.kappa[0]),
        half * (to.kappa[1] - from.kappa[1]),
    ]
}

/// The scale of the shift: 1 when the projection `p = <a, b> / <b, b>` of the new increment
/// `a` on the last one `b` exceeds [`THRESHOLD`], else 0 (a reversal, a new direction, a
/// step cut to a quarter or less); 0 too when `b` is zero or anything is not finite.
///
/// A step, not the projection itself: the Newton iterates of one load step then share one
/// shift, and each solve's start moves with its target only through the affine jump. With the
/// projection as the scale the start also moved by `dp * delta` between iterates, and on the
/// biaxial example Newton stalled at a relative residual of 6.6e-3 (tolerance 5e-3) from 0.8 %
/// strain on: 21 iterations a step, four times the default's DEM steps. The projection
/// rounded to powers of two (1/4 .. 2) stalled at 1 % strain: an iterate crossed a rounding
/// edge. Where the shift is `delta` and the step's own non-affine increment about `p delta`,
/// the start is off by `|1 - p| delta` against the affine jump's `p delta`: better for
/// `p > 1/2`, as good at `p = 1/2` (a step cut in half); the threshold lies halfway (in
/// ratio) between the cuts to a half and to a quarter, so that no iterate of a whole or a
/// halved step sits near it (docs/notes/2026-12-08-extrapolated-predictor.md).
pub fn scale(a: &[f64; 7], b: &[f64; 7]) -> f64 {
    let dot = |u: &[f64; 7], v: &[f64; 7]| u.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
    let (ab, bb) = (dot(a, b), dot(b, b));
    let p = ab / bb;
    if bb > 0.0 && p.is_finite() && p > THRESHOLD { 1.0 } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strain(exx: f64, eyy: f64) -> MacroDeformation {
        MacroDeformation::from_gradient([[exx, 0.0], [0.0, eyy]], 0.0, [0.0; 2])
    }

    /// The same increment again scales by 1, also 20 % off (a Newton iterate), twice as long
    /// or cut in half; cut to a quarter, orthogonal (shear after compression) or reversed, by
    /// 0 (exact values, so compared exactly).
    #[test]
    fn the_scale_is_one_along_the_last_step() {
        assert_eq!(THRESHOLD, 2f64.powf(-1.5));
        let z = strain(0.0, 0.0);
        let b = increment(0.05, &z, &strain(0.0, -1e-3));
        let along = |eyy| scale(&increment(0.05, &z, &strain(0.0, eyy)), &b);
        for (eyy, s) in [
            (-1e-3, 1.0),
            (-1.2e-3, 1.0),
            (-0.8e-3, 1.0),
            (-2e-3, 1.0),
            (-5e-4, 1.0),
            (-2.5e-4, 0.0),
            (1e-3, 0.0),
        ] {
            assert_eq!(along(eyy), s, "e_yy = {eyy}");
        }
        let shear = MacroDeformation::from_gradient([[0.0, 1e-3], [1e-3, 0.0]], 0.0, [0.0; 2]);
        assert_eq!(scale(&increment(0.05, &z, &shear), &b), 0.0);
        assert_eq!(scale(&b, &[0.0; 7]), 0.0);
    }
}
