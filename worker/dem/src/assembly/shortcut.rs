//! Answers without a relaxation (issue 6, item 3a and 3c).
//!
//! Both shortcuts answer from the *last relaxed* state, which is the committed state (a
//! shortcut never creates a trial state, so committing after it keeps the last relaxed state
//! and the next solve measures its increment from there: un-relaxed increments accumulate and
//! the next relaxation sees the whole deformation). Everything depends only on the assembly's
//! own committed history and the requested deformation, never on the worker or thread count
//! or on the Newton history (a failover restores the committed state, the stored answer
//! included, bit for bit).
//!
//! The answer is the first-order extrapolation `s = s_0 + C (e - e_0)` with the last relaxed
//! stress `s_0`, strain `e_0` and tangent `C`, and the tangent is `C`. Not the last stress
//! alone: a point answering `s_0` whatever the strain would contradict the tangent it hands the
//! Newton solver (the residual would not follow the linearization, and a skipped region would
//! carry no stress increment at all); with the extrapolation the macro problem sees a
//! consistent linear material around the last relaxed state.
//!
//! In [`TangentFrame::Current`] (the FE's updated-Lagrangian kinematics) `s_0 + C (e - e_0)`
//! is not objective: a rigid rotation by `a` has `e_xx = e_yy = cos(a) - 1`, which it answers
//! with a stress change of `C (cos(a) - 1)` (30 times the stress of a 100 kPa packing at 0.3
//! rad). The answer is instead `s = R_d [G s_0 G^T / det G + C de] R_d^T` with `dF = R_d G`
//! and the tangent turned by `R_d` (`frame.rs`): its first order is the convected rate the
//! tangent is defined by, and a rigid rotation gets the rotated stress and tangent.
//! `R_d` is the rotation the assembly follows: `R(w_new - w_old)` for the penalty boundary,
//! whose boundary discs turn with `w` (then `G - I` holds the relative rotation of continuum
//! and micro-rotation, which `C`'s columns `e_xy`, `e_yx` answer), the polar rotation of `dF`
//! for the periodic cell, whose discs turn with the continuum and which ignores `w`. Both are
//! the exact rotation of a rigid motion (`F -> Q F`, `w -> w + q`).

use super::{Assembly, State};
use crate::boundary::{mat_inv, mat_mul, rotation_angle};
use crate::contact::rolling;
use crate::spec::{BoundarySpec, TangentFrame};
use cosdem_common::voigt::N;
use cosdem_common::{
    Answer, MacroDeformation, MicroDiagnostics, MicroResponse, StressVector, Tangent,
};
use serde::{Deserialize, Serialize};

/// Margin of the elastic-shortcut check: a contact must stay 10 % inside its Coulomb and
/// rolling caps, and keep at least 10 % of its overlap, on the affine jump. The relaxation that
/// the shortcut replaces moves the discs by the (unknown) change of the fluctuation field;
/// the margin absorbs it.
pub const MARGIN: f64 = 0.1;

/// What the last relaxation answered: kept with the state it was relaxed to.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Relaxed {
    /// Homogenized stress of the relaxed state.
    pub stress: StressVector,
    /// The tangent that was returned with it.
    pub tangent: Tangent,
    /// Active contacts.
    pub contacts: u32,
    /// Fraction of sliding contacts.
    pub sliding_fraction: f64,
    /// Fraction of saturated rolling contacts.
    pub rolling_fraction: f64,
}

impl Assembly {
    /// Size of the deformation from `from` to `to`: `max(|dF_ij|, |dw|, (sqrt(V)/2) |dk_i|)`
    /// (a curvature increment rotates the boundary of the assembly by up to `dk sqrt(V)/2`).
    pub fn increment_size(&self, from: &MacroDeformation, to: &MacroDeformation) -> f64 {
        let half = 0.5 * self.refc.area.sqrt();
        let mut m = (to.w - from.w).abs();
        for a in 0..2 {
            for b in 0..2 {
                m = m.max((to.f[a][b] - from.f[a][b]).abs());
            }
            m = m.max(half * (to.kappa[a] - from.kappa[a]).abs());
        }
        m
    }

    /// The shortcut answer for `target` when the spec allows one and it applies; `None`
    /// means: relax.
    pub(super) fn shortcut(&self, target: &MacroDeformation) -> Option<MicroResponse> {
        let r = &self.spec.relaxation;
        if r.skip_below <= 0.0 && !r.elastic_shortcut {
            return None;
        }
        let st = &self.committed;
        st.relaxed.as_ref()?;
        let size = self.increment_size(&st.target, target);
        let answer = if size < r.skip_below {
            Answer::Skipped
        } else if r.elastic_shortcut && self.stays_elastic(st, target) {
            Answer::Linear
        } else {
            return None;
        };
        let mut response = match self.spec.frame {
            TangentFrame::Reference => extrapolate(st, target, answer, size),
            TangentFrame::Current => {
                let periodic = matches!(self.spec.boundary, BoundarySpec::Periodic);
                let inc = super::frame::increment(&st.target, target, periodic);
                let rel = st.relaxed.as_ref().expect("checked above");
                let (stress, tangent, bound) =
                    super::frame::extrapolate_current(&rel.stress, &rel.tangent, &inc);
                let mut r = extrapolate(st, target, answer, size);
                (r.stress, r.tangent, r.diagnostics.error_bound) = (stress, tangent, bound);
                r
            }
        };
        // The micro-structure answering is the last relaxed one.
        response.diagnostics.descriptors = Some(self.descriptors(st));
        Some(response)
    }

    /// True when the affine jump of the relaxed state `st` to `target` (each disc's last
    /// fluctuation carried along, contact histories advanced by the jump's slip and relative
    /// rotation, exactly as the relaxation's predictor does) keeps every active contact
    /// active (at least `MARGIN` of its overlap left) and sticking (`|F_s| <= (1 - MARGIN)
    /// mu_s F_n`, `|M_r| <= (1 - MARGIN) mu_r r* F_n`), closes no contact, and moves no disc
    /// beyond half the Verlet skin from where the pair list was built (so no pair outside the
    /// list can close).
    pub fn stays_elastic(&self, st: &State, target: &MacroDeformation) -> bool {
        let old = st.target;
        let df = mat_mul(&target.f, &mat_inv(&old.f));
        let xc = self.refc.xc;
        let n = self.disc_count();
        let periodic = matches!(self.spec.boundary, BoundarySpec::Periodic);
        let (dw, dk) =
            (target.w - old.w, [target.kappa[0] - old.kappa[0], target.kappa[1] - old.kappa[1]]);
        let drot = rotation_angle(&target.f) - rotation_angle(&old.f);
        let dth = |q: usize| -> f64 {
            if periodic {
                drot
            } else {
                dw + dk[0].mul_add(self.refc.x0[q] - xc[0], dk[1] * (self.refc.y0[q] - xc[1]))
            }
        };
        let d = &st.dynamics;
        let pl = &st.pairs;
        let half_skin2 = 0.25 * (self.spec.relaxation.skin * self.refc.r_min).powi(2);
        for q in 0..n {
            let (px, py) = (d.x[q] - xc[0], d.y[q] - xc[1]);
            let x = xc[0] + df[0][0].mul_add(px, df[0][1] * py);
            let y = xc[1] + df[1][0].mul_add(px, df[1][1] * py);
            let (ex, ey) = (x - pl.xb[q], y - pl.yb[q]);
            if ex.mul_add(ex, ey * ey) >= half_skin2 {
                return false;
            }
        }
        let law = &self.law;
        let r = &self.refc.r;
        let per = !pl.ox.is_empty();
        for k in 0..pl.len() {
            let (i, j) = (pl.i[k] as usize, pl.j[k] as usize);
            let mut lx = d.x[j] - d.x[i];
            let mut ly = d.y[j] - d.y[i];
            if per {
                lx += pl.ox[k];
                ly += pl.oy[k];
            }
            let rs = r[i] + r[j];
            let ov0 = rs - lx.hypot(ly);
            let nx = df[0][0].mul_add(lx, df[0][1] * ly);
            let ny = df[1][0].mul_add(lx, df[1][1] * ly);
            let ov = rs - nx.hypot(ny);
            if ov0 <= 0.0 {
                if ov > 0.0 {
                    return false; // a contact would close
                }
                continue;
            }
            if ov < MARGIN * ov0 {
                return false; // a contact would open (or nearly)
            }
            let dphi = (lx * ny - ly * nx).atan2(lx * nx + ly * ny);
            let (ai, aj) = (r[i] - 0.5 * ov, r[j] - 0.5 * ov);
            let (ti, tj) = (dth(i), dth(j));
            let ds = (ai + aj) * dphi - (ai * ti + aj * tj);
            let fnorm = law.kn * ov;
            let fs = (-law.ks).mul_add(ds, pl.fs[k]);
            if fs.abs() > (1.0 - MARGIN) * law.mu_s * fnorm && law.ks > 0.0 {
                return false; // it would slide
            }
            if law.has_rolling() {
                let cap = law.mu_r * rolling::rstar(r[i], r[j]) * fnorm;
                let hr = (-law.kr).mul_add(tj - ti, pl.hr[k]);
                if hr.abs() > (1.0 - MARGIN) * cap {
                    return false; // its rolling moment would saturate
                }
            }
        }
        true
    }
}

/// `s_0 + C (e - e_0)` with tangent `C` from the relaxed state `st` (which has an answer).
fn extrapolate(st: &State, target: &MacroDeformation, answer: Answer, size: f64) -> MicroResponse {
    let rel = st.relaxed.as_ref().expect("checked by the caller");
    let (e0, e1) = (st.target.strain(), target.strain());
    let mut stress = rel.stress;
    let mut bound = 0.0f64;
    for (row, s) in stress.iter_mut().enumerate() {
        let mut ds = 0.0;
        for col in 0..N {
            ds = rel.tangent[row][col].mul_add(e1[col] - e0[col], ds);
        }
        *s += ds;
        bound = bound.max(ds.abs());
    }
    MicroResponse {
        stress,
        tangent: rel.tangent,
        diagnostics: MicroDiagnostics {
            steps: 0,
            residual_ratio: 0.0,
            converged: true,
            contacts: rel.contacts,
            sliding_fraction: rel.sliding_fraction,
            rolling_fraction: rel.rolling_fraction,
            wall_seconds: 0.0,
            answer,
            unrelaxed_increment: size,
            error_bound: bound,
            descriptors: None,
        },
    }
}
