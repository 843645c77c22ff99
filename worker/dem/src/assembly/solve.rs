use super::extrapolate::Shift;
use super::{Assembly, State};
use crate::boundary::{mat_inv, mat_mul, rotation_angle};
use crate::broadphase;
use crate::contact::rolling;
use crate::error::{Error, Result};
use crate::homogenize::{Homogenized, homogenize};
use crate::integrate::{self, RelaxReport};
use crate::spec::{BoundarySpec, MAX_SUBSTEPS, RelaxationSpec, TangentFrame, TangentKind};
use cosdem_common::voigt::N;
use cosdem_common::{MacroDeformation, MicroDiagnostics, MicroResponse};
use std::time::Instant;

/// How many times a relaxation that blows up (non-finite state) is redone from the same
/// start at half the previous time step before the error is returned. The critical step is
/// `2 / omega_max` for undamped leapfrog, but Cundall's local damping multiplies the force by
/// `1 + alpha` while a dof decelerates, which lowers the stable step to `2 / (omega_max
/// sqrt(1 + alpha))`: 0.77 of it at the default `alpha = 0.7`. The `omega_max` bound counts
/// six contacts per disc and is loose for contact-dominated assemblies (safety 0.8 was
/// stable on every committed table), but tight where a penalty spring dominates: there the
/// boundary disc gets a stable relaxation mass instead
/// ([`crate::integrate::timestep::stable_penalty_masses`]; `eps_f = 1e10` diverged at safety
/// 0.8 before, `tests/extremes.rs`), and the retry catches what is left (a dof just inside
/// that certain-divergence test pushed over by its contacts). The retry is deterministic
/// (same start, same halving), so the answer still depends only on the committed state and
/// the target.
pub const DIVERGENCE_HALVINGS: u32 = 3;

impl Assembly {
    /// Trial solve: the shortcut answer when `relaxation.skip_below` or
    /// `relaxation.elastic_shortcut` allows one (no trial state then), else
    /// [`Assembly::solve_relaxed`].
    pub fn solve(&mut self, target: &MacroDeformation) -> Result<MicroResponse> {
        target.validate()?;
        if let Some(answer) = self.shortcut(target) {
            // Answered from the committed (last relaxed) state: no trial, so a commit keeps
            // the last relaxed state and the increment keeps accumulating.
            self.trial = None;
            return Ok(answer);
        }
        self.solve_relaxed(target)
    }

    /// Trial solve by relaxation, whatever the shortcut settings: from the committed state (or
    /// the last trial with `warm_start`), jump affinely to `target`, relax, homogenize. The
    /// trial state is kept for `commit`.
    pub fn solve_relaxed(&mut self, target: &MacroDeformation) -> Result<MicroResponse> {
        target.validate()?;
        let t0 = Instant::now();
        let (start, shift) = match (&self.trial, self.spec.warm_start) {
            // A warm trial already holds this step's own non-affine part: no extrapolation.
            (Some(t), true) => (t.clone(), None),
            _ => (self.committed.clone(), self.extrapolation(target)),
        };
        let tol = self.spec.relaxation.tolerance;
        let (st, rep) = self.relax_to_from(start, target, tol, shift.as_ref())?;
        let h = self.homogenized(&st);
        let (tangent, tangent_steps) = match self.spec.tangent {
            TangentKind::Paper => (h.paper, 0),
            TangentKind::SlidingAware => (h.sliding_aware, 0),
            TangentKind::Secant => (self.secant_tangent(&h.paper, &h.stress, target), 0),
            TangentKind::Perturbation { strain } => {
                self.perturbation_tangent(&st, &h.stress, strain, rep.steps)?
            }
            TangentKind::Adaptive { sliding, strain } => {
                if h.fabric.contacts > 0 && h.fabric.sliding_fraction >= sliding {
                    self.perturbation_tangent(&st, &h.stress, strain, rep.steps)?
                } else {
                    (h.paper, 0)
                }
            }
        };
        let diagnostics = MicroDiagnostics {
            // DEM steps of this answer: the relaxation and, with the perturbation tangent,
            // its twelve perturbed relaxations (the cost the speed/accuracy sweep counts).
            steps: rep.steps + tangent_steps,
            residual_ratio: rep.ratio,
            converged: rep.converged,
            contacts: h.fabric.contacts,
            sliding_fraction: h.fabric.sliding_fraction,
            rolling_fraction: h.fabric.rolling_fraction,
            wall_seconds: t0.elapsed().as_secs_f64(),
            descriptors: Some(self.descriptors(&st)),
            ..Default::default()
        };
        // Never NaN on the wire: a non-finite answer is an error of this Gauss point.
        let det = st.target.det();
        if !h.stress.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFinite { what: "stress", det });
        }
        if !tangent.iter().flatten().all(|v| v.is_finite()) {
            return Err(Error::NonFinite { what: "tangent", det });
        }
        let mut st = st;
        st.relaxed = Some(super::Relaxed {
            stress: h.stress,
            tangent,
            contacts: h.fabric.contacts,
            sliding_fraction: h.fabric.sliding_fraction,
            rolling_fraction: h.fabric.rolling_fraction,
        });
        self.trial = Some(st);
        Ok(MicroResponse { stress: h.stress, tangent, diagnostics })
    }

    /// Homogenized stress, tangents and fabric of a state.
    pub fn homogenized(&self, st: &State) -> Homogenized {
        let d = &st.dynamics;
        homogenize(&self.law, &d.x, &d.y, &self.refc.r, &st.pairs, st.target.det() * self.refc.area)
    }

    /// Micro descriptors of a state (read only: porosity of the current cell `det(Fbar) V`,
    /// coordination, fabric, sliding, mean rotation; see [`crate::descriptors`]).
    pub fn descriptors(&self, st: &State) -> cosdem_common::MicroDescriptors {
        let d = &st.dynamics;
        let area = st.target.det() * self.refc.area;
        crate::descriptors::of_state(&self.law, &d.x, &d.y, &self.refc.r, &d.th, &st.pairs, area)
    }

    /// Jumps `st` affinely to `target` and relaxes it with tolerance `tol`; with
    /// `relaxation.substep` set, in [`Assembly::substeps`] equal jumps along the straight path
    /// (the polar path [`super::path::interpolate_polar`] in [`TangentFrame::Current`]),
    /// each relaxed in turn (the steps of all of them are counted; the answer counts as
    /// converged only if every one converged).
    pub fn relax_to(
        &mut self,
        st: State,
        target: &MacroDeformation,
        tol: f64,
    ) -> Result<(State, RelaxReport)> {
        self.relax_to_from(st, target, tol, None)
    }

    /// [`Assembly::relax_to`] with the first jump shifted by the extrapolated predictor's
    /// `shift` (the shift of the whole increment, scaled to the first sub-increment's share).
    fn relax_to_from(
        &mut self,
        st: State,
        target: &MacroDeformation,
        tol: f64,
        shift: Option<&Shift>,
    ) -> Result<(State, RelaxReport)> {
        let n = self.substeps(&st.target, target);
        let first = shift.map(|s| s.scaled(1.0 / n as f64));
        let mut first = first.as_ref();
        let from = st.target;
        let (mut st, mut steps, mut all_converged) = (st, 0u64, true);
        for i in 1..n {
            let t = match self.spec.frame {
                TangentFrame::Reference => from.interpolate(target, i as f64 / n as f64),
                TangentFrame::Current => {
                    super::path::interpolate_polar(&from, target, i as f64 / n as f64)
                }
            };
            let (s, rep) = self.relax_capped(st, &t, tol, u64::MAX, first.take())?;
            steps = steps.saturating_add(rep.steps);
            all_converged &= rep.converged;
            st = s;
        }
        let (st, rep) = self.relax_capped(st, target, tol, u64::MAX, first)?;
        let converged = rep.converged && all_converged;
        Ok((st, RelaxReport { steps: steps.saturating_add(rep.steps), converged, ..rep }))
    }

    /// Number of affine jumps from `from` to `to`: `ceil(size / substep)` in the measure of
    /// [`Assembly::increment_size`], between 1 and [`MAX_SUBSTEPS`]; 1 when
    /// `relaxation.substep` is 0 (off).
    pub fn substeps(&self, from: &MacroDeformation, to: &MacroDeformation) -> u64 {
        let h = self.spec.relaxation.substep;
        if h <= 0.0 {
            return 1;
        }
        // The ratio is finite and >= 0 (validated h > 0, finite deformations); a tiny margin
        // keeps an increment of exactly k substeps at k jumps despite rounding.
        let n = (self.increment_size(from, to) / h * (1.0 - 1e-12)).ceil();
        if n.is_nan() { 1 } else { (n as u64).clamp(1, MAX_SUBSTEPS) }
    }

    /// [`Assembly::relax_to`] with at most `max_steps` steps (and never more than the spec's)
    /// per attempt; a relaxation that diverges is redone at half the step (see
    /// [`DIVERGENCE_HALVINGS`]).
    fn relax_capped(
        &mut self,
        mut st: State,
        target: &MacroDeformation,
        tol: f64,
        max_steps: u64,
        shift: Option<&Shift>,
    ) -> Result<(State, RelaxReport)> {
        target.validate()?;
        self.predict(&mut st, target, shift);
        let mut work = std::mem::take(&mut self.work);
        let law = self.law;
        let pen = self.penalty(target);
        let sys = self.system(&law, pen.as_ref(), target);
        let capped;
        let spec = if max_steps < self.spec.relaxation.max_steps {
            capped = RelaxationSpec { max_steps, ..self.spec.relaxation.clone() };
            &capped
        } else {
            &self.spec.relaxation
        };
        // A blow-up is redone from the same start at half the step, at most
        // `DIVERGENCE_HALVINGS` times; the steps of every attempt count in the report.
        let start = (st.dynamics.clone(), st.pairs.clone());
        let (mut dt, mut spent) = (self.dt, 0u64);
        let mut halvings = 0;
        let rep = loop {
            match integrate::relax(&sys, &mut st.dynamics, &mut st.pairs, &mut work, spec, dt, tol)
            {
                Err(Error::Diverged { steps }) if halvings < DIVERGENCE_HALVINGS => {
                    tracing::warn!(
                        steps,
                        dt,
                        "relaxation diverged: redone at half the time step (relaxation.safety \
                         {} is above the damped stability limit of this assembly)",
                        spec.safety
                    );
                    spent += steps;
                    dt *= 0.5;
                    halvings += 1;
                    (st.dynamics, st.pairs) = (start.0.clone(), start.1.clone());
                }
                other => break other,
            }
        };
        self.work = work;
        let rep = rep.map_err(|e| match e {
            Error::Diverged { steps } => Error::Diverged { steps: spent + steps },
            e => e,
        })?;
        Ok((st, RelaxReport { steps: spent + rep.steps, ..rep }))
    }

    /// Runs exactly `steps` leapfrog steps towards `target` (no convergence test): the
    /// benchmark's workload. Returns the steps taken.
    pub fn run_steps(&mut self, target: &MacroDeformation, steps: u64) -> Result<u64> {
        self.run_steps_timed(target, steps, None)
    }

    /// [`Assembly::run_steps`] with the equilibrium ratio computed at the spec's
    /// `check_every` as in a solve (with a tolerance of 0, so never met), and the time of each
    /// stage added to `clock`: where a relaxation's time goes. Without a clock the ratio is
    /// not computed (the rate benchmark's workload).
    pub fn run_steps_timed(
        &mut self,
        target: &MacroDeformation,
        steps: u64,
        clock: Option<&mut integrate::StageTimes>,
    ) -> Result<u64> {
        target.validate()?;
        let mut st = self.committed.clone();
        self.predict(&mut st, target, None);
        let mut work = std::mem::take(&mut self.work);
        let law = self.law;
        let pen = self.penalty(target);
        let sys = self.system(&law, pen.as_ref(), target);
        let mut spec = self.spec.relaxation.clone();
        spec.max_steps = steps;
        let (d, pairs, dt) = (&mut st.dynamics, &mut st.pairs, self.dt);
        let rep = match clock {
            None => {
                spec.check_every = u32::MAX;
                integrate::relax(&sys, d, pairs, &mut work, &spec, dt, 0.0)
            }
            Some(clock) => integrate::relax_timed(&sys, d, pairs, &mut work, &spec, dt, 0.0, clock),
        };
        self.work = work;
        let rep = rep?;
        self.trial = Some(st);
        Ok(rep.steps.max(steps))
    }

    /// The rotation increment of every disc in the affine jump from `old` to `target`
    /// (penalty: `dw + dk . (X_q - X_c)`; periodic: the continuum rotation's increment).
    pub(super) fn affine_rotations(
        &self,
        old: &MacroDeformation,
        target: &MacroDeformation,
    ) -> Vec<f64> {
        let xc = self.refc.xc;
        let n = self.disc_count();
        if matches!(self.spec.boundary, BoundarySpec::Periodic) {
            vec![rotation_angle(&target.f) - rotation_angle(&old.f); n]
        } else {
            let (dw, dk) = (
                target.w - old.w,
                [target.kappa[0] - old.kappa[0], target.kappa[1] - old.kappa[1]],
            );
            (0..n)
                .map(|q| {
                    dw + dk[0].mul_add(self.refc.x0[q] - xc[0], dk[1] * (self.refc.y0[q] - xc[1]))
                })
                .collect()
        }
    }

    /// The affine predictor: every centre is mapped by `dF = F_new F_old^-1` about `X_c`,
    /// every rotation advanced by the increment of its target rotation (penalty: `wbar +
    /// kbar . (X_q - X_c)`; periodic: the continuum rotation), and the contact histories by the
    /// slip and relative rotation of this jump (slip from the exact rotation of the branch
    /// vector, so a rigid rotation leaves the histories untouched). Velocities are zeroed and
    /// the pair list rebuilt. With a `shift` (the extrapolated predictor), every disc moves and
    /// turns by its share of it on top of the affine jump, and the histories follow that
    /// relative motion too.
    fn predict(&self, st: &mut State, target: &MacroDeformation, shift: Option<&Shift>) {
        let old = st.target;
        let df = mat_mul(&target.f, &mat_inv(&old.f));
        let xc = self.refc.xc;
        let n = self.disc_count();
        let mut dth = self.affine_rotations(&old, target);
        if let Some(s) = shift {
            for (d, e) in dth.iter_mut().zip(&s.dth) {
                *d += e;
            }
        }
        let law = &self.law;
        let r = &self.refc.r;
        let d = &mut st.dynamics;
        let pl = &mut st.pairs;
        let per = !pl.ox.is_empty();
        for k in 0..pl.len() {
            let (i, j) = (pl.i[k] as usize, pl.j[k] as usize);
            let mut lx = d.x[j] - d.x[i];
            let mut ly = d.y[j] - d.y[i];
            if per {
                lx += pl.ox[k];
                ly += pl.oy[k];
            }
            let mut nx = df[0][0].mul_add(lx, df[0][1] * ly);
            let mut ny = df[1][0].mul_add(lx, df[1][1] * ly);
            if let Some(s) = shift {
                nx += s.dx[j] - s.dx[i];
                ny += s.dy[j] - s.dy[i];
            }
            let len = nx.hypot(ny);
            let ov = r[i] + r[j] - len;
            if ov <= 0.0 {
                pl.fs[k] = 0.0;
                pl.hr[k] = 0.0;
                continue;
            }
            let dphi = (lx * ny - ly * nx).atan2(lx * nx + ly * ny);
            let (ai, aj) = (r[i] - 0.5 * ov, r[j] - 0.5 * ov);
            let ds = (ai + aj) * dphi - (ai * dth[i] + aj * dth[j]);
            let fnorm = law.kn * ov;
            let cap = law.mu_s * fnorm;
            pl.fs[k] = (-law.ks).mul_add(ds, pl.fs[k]).max(-cap).min(cap);
            if law.has_rolling() {
                let cap = law.mu_r * rolling::rstar(r[i], r[j]) * fnorm;
                pl.hr[k] = (-law.kr).mul_add(dth[j] - dth[i], pl.hr[k]).max(-cap).min(cap);
            }
        }
        for q in 0..n {
            let (px, py) = (d.x[q] - xc[0], d.y[q] - xc[1]);
            d.x[q] = xc[0] + df[0][0].mul_add(px, df[0][1] * py);
            d.y[q] = xc[1] + df[1][0].mul_add(px, df[1][1] * py);
            d.th[q] += dth[q];
        }
        if let Some(s) = shift {
            for q in 0..n {
                d.x[q] += s.dx[q];
                d.y[q] += s.dy[q];
            }
        }
        d.stop();
        st.target = *target;
        st.relaxed = None;
        let skin = self.spec.relaxation.skin * self.refc.r_min;
        *pl = broadphase::build(&d.x, &d.y, r, skin, self.domain(target), pl);
    }

    /// Central-difference tangent: twelve extra relaxations from the equilibrated trial state
    /// `st` (left untouched, its stress `stress`), strain perturbation `h`, tolerance 1e-1 of
    /// the solve's; perturbed and, in [`TangentFrame::Current`], convected as
    /// [`super::frame`] says. Returns the tangent and the relaxation steps it took.
    ///
    /// Each perturbed relaxation is capped at [`perturbation_cap`] steps: past a peak an
    /// assembly near a slip event can creep for the whole `max_steps` budget (measured: 880
    /// discs, 400 000 steps, 35 s per column, 13 columns), while the column it would give is
    /// already as good as the unrelaxed part of the base state allows. A capped column is the
    /// difference of two equally capped relaxations from the same state, so their common
    /// unrelaxed part cancels to first order.
    fn perturbation_tangent(
        &mut self,
        st: &State,
        stress: &cosdem_common::StressVector,
        h: f64,
        main_steps: u64,
    ) -> Result<([[f64; N]; N], u64)> {
        let tol = 1e-1 * self.spec.relaxation.tolerance;
        let cap = perturbation_cap(main_steps, self.spec.relaxation.max_steps);
        let base = st.target;
        let mut c = [[0.0; N]; N];
        let mut steps = 0;
        for col in 0..N {
            let mut s = [[0.0; N]; 2];
            for (side, sign) in [(0usize, 1.0f64), (1, -1.0)] {
                let t = super::frame::perturbed(&base, col, sign * h, self.spec.frame);
                let (pst, rep) = self.relax_capped(st.clone(), &t, tol, cap, None)?;
                steps += rep.steps;
                s[side] = self.homogenized(&pst).stress;
            }
            for row in 0..N {
                c[row][col] = (s[0][row] - s[1][row]) / (2.0 * h);
            }
            if self.spec.frame == TangentFrame::Current {
                let t = super::frame::transport(col, stress);
                for row in 0..N {
                    c[row][col] -= t[row];
                }
            }
        }
        Ok((c, steps))
    }
}

/// Step cap of one perturbed relaxation of the perturbation tangent: four times the steps of
/// the relaxation it perturbs, at least 2 000, at most the job's `max_steps`.
pub(crate) fn perturbation_cap(main_steps: u64, max_steps: u64) -> u64 {
    main_steps.saturating_mul(4).max(2_000).min(max_steps)
}

impl Assembly {
    /// Plain leapfrog (no damping, no prediction) of `st` for `steps` steps at the base step,
    /// sampling every `every` steps the leapfrog energy `U(x_n) + sum 1/2 m v_{n-1/2} .
    /// v_{n+1/2}` (kinetic part with the relaxation masses), which leapfrog conserves exactly
    /// for quadratic potentials. Returns the samples (the first at step 0).
    pub fn evolve(&mut self, st: &mut State, steps: u64, every: u64) -> Result<Vec<f64>> {
        let mut work = std::mem::take(&mut self.work);
        let law = self.law;
        let pen = self.penalty(&st.target);
        let sys = self.system(&law, pen.as_ref(), &st.target);
        let dt = self.dt;
        let d = &mut st.dynamics;
        let mut out = Vec::new();
        integrate::forces(&sys, d, &mut st.pairs, &mut work, 0.0);
        for step in 0..steps {
            let sample = step.is_multiple_of(every.max(1));
            let (u, vold) = if sample {
                (
                    integrate::elastic_energy(&sys, d, &st.pairs),
                    Some((d.vx.clone(), d.vy.clone(), d.w.clone())),
                )
            } else {
                (0.0, None)
            };
            let disp2 = integrate::cundall::advance(
                d,
                &work,
                sys.inv_m,
                sys.inv_i,
                &st.pairs.xb,
                &st.pairs.yb,
                0.0,
                dt,
                integrate::rebuild_limit2(&sys),
            );
            if let Some((vx, vy, w)) = vold {
                let mut k = 0.0;
                for q in 0..vx.len() {
                    k += 0.5 * (vx[q] * d.vx[q] + vy[q] * d.vy[q]) / sys.inv_m[q]
                        + 0.5 * w[q] * d.w[q] / sys.inv_i[q];
                }
                out.push(u + k);
            }
            integrate::maybe_rebuild(&sys, d, &mut st.pairs, disp2);
            integrate::forces(&sys, d, &mut st.pairs, &mut work, dt);
            if !d.is_finite() {
                self.work = work;
                return Err(crate::Error::Diverged { steps: step });
            }
        }
        self.work = work;
        Ok(out)
    }
}
