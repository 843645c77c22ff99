//! One attempt at a load step: the predictor, then Newton iterations with line search, the
//! convergence criteria, and the tolerated, stalled and forced acceptances of a best iterate
//! (see [`SolverSettings`](super::SolverSettings)).

use super::secant::PointSecant;
use super::solver::Solver;
use super::system::norm;
use crate::assembly::Assembled;
use crate::error::Result;
use crate::material::{Material, MaterialInput, TrialId};
use cosdem_common::{GaussPointId, MicroResponse};

/// Why one attempt at a load step failed (the step is then cut).
#[derive(Debug)]
pub(super) enum Failure {
    Material(Vec<(GaussPointId, String)>),
    /// Gauss points of the iterate with `det F <= 0` or a non-finite deformation: never
    /// sent to the material.
    Inverted(Vec<(GaussPointId, String)>),
    NotFinite(Vec<(GaussPointId, String)>),
    Singular(String),
    MaxIterations(u32, f64),
}

impl Failure {
    pub(super) fn reason(&self) -> String {
        match self {
            Self::Material(p) => format!("material failed at {} gauss point(s)", p.len()),
            Self::Inverted(p) => {
                let mut elements: Vec<u32> = p.iter().map(|(g, _)| g.element).collect();
                elements.dedup();
                let list: Vec<String> = elements.iter().take(8).map(u32::to_string).collect();
                format!(
                    "the iterate inverts element(s) {} ({} gauss point(s) with det F <= 0)",
                    list.join(", "),
                    p.len()
                )
            }
            Self::NotFinite(p) => format!("non-finite response at {} gauss point(s)", p.len()),
            Self::Singular(s) => format!("linear solve failed: {s}"),
            Self::MaxIterations(n, r) => {
                format!("no convergence in {n} iterations (relative residual {r:.3e})")
            }
        }
    }

    pub(super) fn points(self) -> Vec<(GaussPointId, String)> {
        match self {
            Self::Material(p) | Self::Inverted(p) | Self::NotFinite(p) => p,
            _ => Vec::new(),
        }
    }
}

/// One evaluated iterate: the answers, the kinematics they answer, the assembled system and
/// the residual on the free dofs with its force scale.
pub(super) struct Trial {
    pub(super) responses: Vec<MicroResponse>,
    pub(super) inputs: Vec<MaterialInput>,
    pub(super) asm: Assembled,
    /// The external force at the iterate (follower pressures depend on it).
    pub(super) f_ext: Vec<f64>,
    pub(super) r: Vec<f64>,
    pub(super) scale: f64,
}

impl Trial {
    /// The relative residual `|r| / scale` of a residual norm (0 without a force scale).
    fn relative_of(norm: f64, scale: f64) -> f64 {
        if scale > 0.0 { norm / scale } else { 0.0 }
    }

    /// This iterate's relative residual.
    fn relative(&self) -> f64 {
        Self::relative_of(norm(&self.r), self.scale)
    }
}

/// How one attempt at a load step ended.
pub(super) enum Attempt {
    /// `lambda`: the load factor reached (the target, or under a path control the one
    /// solved for).
    Converged {
        iterations: u32,
        residuals: Vec<f64>,
        halvings: u32,
        tolerated: bool,
        forced: bool,
        lambda: f64,
    },
    Failed(Failure),
}

impl Solver {
    /// One attempt at reaching load factor `target` from the converged state, or under a path
    /// control progress `target` (the load factor then solved for with the dofs);
    /// `at_minimum`: the run ends if it fails (see
    /// [`SolverSettings::forced_residual`](super::SolverSettings::forced_residual)).
    pub(super) fn attempt(
        &mut self,
        material: &mut dyn Material,
        step: u64,
        iteration: &mut u32,
        target: f64,
        at_minimum: bool,
    ) -> Result<Attempt> {
        // The largest residual whose best iterate this attempt accepts.
        let tolerated_residual = self.settings.tolerated_residual;
        let accepted = if at_minimum {
            tolerated_residual.max(self.settings.forced_residual)
        } else {
            tolerated_residual
        };
        // The secant update keeps a symmetric tangent symmetric (`(B de)(B de)^T`).
        let symmetric = material.is_symmetric();
        let du_c: Vec<f64> = self
            .u
            .iter()
            .zip(&self.loads.prescribed)
            .enumerate()
            .map(|(k, (u, &p))| if p { self.loads.prescribed_at(k, target) - u } else { 0.0 })
            .collect();
        let next_trial = |it: &mut u32| {
            let t = TrialId { step, iteration: *it };
            *it += 1;
            t
        };

        // Predictor: tangent at the converged state, Dirichlet increment through -K_fc du_c.
        let responses = match self.committed.take() {
            Some(r) => r,
            None => match self.evaluate(material, next_trial(iteration), &self.u)? {
                Ok((r, _)) => r,
                Err(f) => return Ok(Attempt::Failed(f)),
            },
        };
        let u_n = self.u.clone();
        // Under a path control: the prescribed dofs' rate, and the control quantity's target.
        let controlled =
            self.control.as_ref().map(|c| (self.loads.prescribed_rate(), c.target(target)));
        let mut lambda = if controlled.is_some() { self.lambda } else { target };
        let asm = match &controlled {
            Some((g, _)) => self.assemble(&responses, &u_n, lambda, Some(g)),
            None => self.assemble(&responses, &u_n, target, Some(&du_c)),
        };
        // Secant updates start from the material's tangent at the step's start (the converged
        // strains are the Gauss-point states').
        let mut secants: Option<Vec<PointSecant>> = self.settings.secant_updates.then(|| {
            self.states
                .iter()
                .zip(&responses)
                .map(|(g, r)| PointSecant::new(g.strain, r.stress, r.tangent))
                .collect()
        });
        self.committed = Some(responses);
        let (r0, _) = self.residual(&asm.f_int, &self.external(lambda, &u_n));
        let mut u = u_n.clone();
        // The load factor's change of the last update (path control only).
        let mut dl = 0.0;
        let mut du = if let Some((g, tau)) = &controlled {
            let _s = tracing::info_span!("predictor").entered();
            let q = self.lambda_rate(&asm.k_fc_du, &u_n);
            match self.controlled_correction(&r0, &q, &u_n, g, *tau, symmetric) {
                Ok((d, l)) => {
                    (lambda, dl) = (self.move_to(&mut u, &d, 1.0, lambda, l), l);
                    d
                }
                Err(f) => return Ok(Attempt::Failed(f)),
            }
        } else {
            let mut rhs: Vec<f64> = r0.iter().zip(&asm.k_fc_du).map(|(r, k)| -(r + k)).collect();
            if let Err(s) = {
                let _s = tracing::info_span!("predictor").entered();
                self.linear.solve(&self.values, &mut rhs, symmetric)
            } {
                return Ok(Attempt::Failed(Failure::Singular(s)));
            }
            self.add_free(&mut u, &rhs, 1.0);
            for (x, d) in u.iter_mut().zip(&du_c) {
                *x += d;
            }
            rhs
        };
        let mut residuals = Vec::new();
        // (u before the update, |r| there, the load factor there)
        let mut previous: Option<(Vec<f64>, f64, f64)> = None;
        let mut last_rel = f64::INFINITY;
        // The iterate of the attempt with the smallest residual (relative residual, u, load
        // factor): what a tolerated step accepts (see `tolerated_residual`).
        let mut best: Option<(f64, Vec<f64>, f64)> = None;
        let mut best_at = 0u32;
        let mut halvings = 0;
        for k in 1..=self.settings.max_iterations + 1 {
            let span = tracing::info_span!("newton", iteration = k);
            let _enter = span.enter();
            let mut alpha = 1.0;
            let Trial { responses, inputs, asm, f_ext, r, scale } = loop {
                let rate = controlled.as_ref().map(|(g, _)| g.as_slice());
                let trial = match self.trial(material, next_trial(iteration), &u, lambda, rate)? {
                    Ok(t) => t,
                    Err(f) => return Ok(Attempt::Failed(f)),
                };
                let grows = previous.as_ref().is_some_and(|(_, rp, _)| norm(&trial.r) > *rp);
                let can_cut = self.settings.line_search
                    && grows
                    && alpha > 0.5f64.powi(self.settings.max_line_search as i32);
                if !can_cut {
                    break trial;
                }
                alpha *= 0.5;
                halvings += 1;
                let (u_prev, _, l_prev) =
                    previous.as_ref().expect("grows implies a previous iterate");
                u.clone_from(u_prev);
                if controlled.is_some() {
                    lambda = self.move_to(&mut u, &du, alpha, *l_prev, dl);
                } else {
                    self.add_free(&mut u, &du, alpha);
                }
                tracing::debug!(alpha, "line search");
            };
            let rn = norm(&r);
            if !rn.is_finite() {
                return Ok(Attempt::Failed(Failure::Singular("residual not finite".into())));
            }
            let rel = Trial::relative_of(rn, scale);
            residuals.push(rel);
            last_rel = rel;
            let step_norm: f64 =
                u.iter().zip(&u_n).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
            // The displacement criterion measures the full Newton correction, not the part of
            // it the line search let through: a correction halved five times is 1/32 of what
            // the linearization asks for, and measuring that made damped iterations of a
            // stalled post-peak step "converge" at residuals of up to 10 %
            // (docs/notes/load-step-biaxial.md).
            let du_norm = norm(&du);
            if tracing::enabled!(tracing::Level::DEBUG) {
                let (r_force, r_moment) = self.split_norms(&r);
                let (du_u, du_w) = self.split_norms(&du);
                tracing::debug!(
                    relative_residual = rel,
                    du = du_norm,
                    alpha,
                    r_force,
                    r_moment,
                    du_u,
                    du_w,
                    "iteration"
                );
            }
            let by_force = rel <= self.settings.force_tolerance;
            let by_displacement =
                k > 1 && du_norm <= self.settings.displacement_tolerance * step_norm;
            if by_force || by_displacement {
                self.accept(u, &inputs, responses, &asm.f_int, &f_ext);
                return Ok(Attempt::Converged {
                    iterations: k,
                    residuals,
                    halvings,
                    tolerated: false,
                    forced: false,
                    lambda,
                });
            }
            // Only a tolerated step uses the best iterate: without one, no copy of `u`.
            let tolerating = accepted > 0.0;
            if tolerating && best.as_ref().is_none_or(|(b, _, _)| rel < *b) {
                best = Some((rel, u.clone(), lambda));
                best_at = k;
            }
            let tolerated = best.as_ref().is_some_and(|(b, _, _)| *b <= accepted);
            let stall = self.settings.stall_iterations;
            // The stall ends only an attempt tolerated without the forced residual: one
            // forced early could have come within the tolerated residual later.
            let within = best.as_ref().is_some_and(|(b, _, _)| *b <= tolerated_residual);
            let stalled = stall > 0 && within && k - best_at >= stall;
            if stalled {
                tracing::debug!(iterations = k, since = best_at, "stalled");
            }
            if k > self.settings.max_iterations || stalled {
                let Some((_, best_u, best_lambda)) = best.take().filter(|_| tolerated) else {
                    break;
                };
                let (u, trial) = if best_at == k {
                    (u, Trial { responses, inputs, asm, f_ext, r, scale })
                } else {
                    // An earlier iterate was better: the material holds the last trial only,
                    // so the best one is evaluated again (from the committed state: the same
                    // answer unless the material warm-starts) and accepted if it is still
                    // tolerated.
                    let rate = controlled.as_ref().map(|(g, _)| g.as_slice());
                    let id = next_trial(iteration);
                    let trial = match self.trial(material, id, &best_u, best_lambda, rate)? {
                        Ok(t) => t,
                        Err(f) => return Ok(Attempt::Failed(f)),
                    };
                    last_rel = trial.relative();
                    residuals.push(last_rel);
                    if last_rel > accepted {
                        break;
                    }
                    (best_u, trial)
                };
                self.accept(u, &trial.inputs, trial.responses, &trial.asm.f_int, &trial.f_ext);
                return Ok(Attempt::Converged {
                    iterations: k,
                    residuals,
                    halvings,
                    tolerated: true,
                    forced: last_rel > tolerated_residual,
                    lambda: best_lambda,
                });
            }
            // An iteration that did not contract ends the secant updates of this attempt: the
            // rest of it iterates with the answers' own tangents (as without the option; the
            // matrix in `self.values` is this iteration's answers' own, assembled above).
            let n = residuals.len();
            if n >= 2 && rel > super::secant::RESTART_CONTRACTION * residuals[n - 2] {
                secants = None;
            }
            if let Some(secants) = &mut secants {
                // The iteration matrix from the points' updated tangents (the residual above
                // is the answers' own; only the matrix changes).
                let mut updated = responses.clone();
                for ((p, i), r) in secants.iter_mut().zip(&inputs).zip(&mut updated) {
                    p.advance(self.strain_of(&i.deformation), r.stress);
                    r.tangent = p.matrix;
                }
                self.assemble(&updated, &u, lambda, None);
            }
            if let Some((g, tau)) = &controlled {
                let q = self.lambda_rate(&asm.k_fc_du, &u);
                let (d, l) = match self.controlled_correction(&r, &q, &u, g, *tau, symmetric) {
                    Ok(c) => c,
                    Err(f) => return Ok(Attempt::Failed(f)),
                };
                previous = Some((u.clone(), rn, lambda));
                (lambda, dl) = (self.move_to(&mut u, &d, 1.0, lambda, l), l);
                du = d;
                continue;
            }
            let mut rhs: Vec<f64> = r.iter().map(|x| -x).collect();
            if let Err(s) = self.linear.solve(&self.values, &mut rhs, symmetric) {
                return Ok(Attempt::Failed(Failure::Singular(s)));
            }
            previous = Some((u.clone(), rn, lambda));
            self.add_free(&mut u, &rhs, 1.0);
            du = rhs;
        }
        Ok(Attempt::Failed(Failure::MaxIterations(self.settings.max_iterations, last_rel)))
    }

    /// The norms of an equation-space vector's translation and rotation parts (forces and
    /// moments for a residual); the second is 0 for a Cauchy field. For the debug log.
    fn split_norms(&self, v: &[f64]) -> (f64, f64) {
        let ndf = self.dofs.field.ndf();
        let (mut t, mut w) = (0.0, 0.0);
        for (d, &eq) in self.dofs.equation.iter().enumerate() {
            if eq != usize::MAX {
                if d % ndf == 2 { w += v[eq] * v[eq] } else { t += v[eq] * v[eq] }
            }
        }
        (f64::sqrt(t), f64::sqrt(w))
    }

    /// Path control: the residual's rate in the load factor on the free rows,
    /// `q = K_fc g - d f_ext / d lambda`, from `k_fc_g = K_fc g` (the loads are affine in the
    /// load factor, so the difference of the external forces at 1 and 0 is their rate).
    fn lambda_rate(&self, k_fc_g: &[f64], u: &[f64]) -> Vec<f64> {
        let (f1, f0) = (self.external(1.0, u), self.external(0.0, u));
        let mut q = k_fc_g.to_vec();
        for (d, &eq) in self.dofs.equation.iter().enumerate() {
            if eq != usize::MAX {
                q[eq] -= f1[d] - f0[d];
            }
        }
        q
    }

    /// Path control: the correction `(du_f, dlambda)` of the iterate `u` with residual `r`
    /// and rate `q` that meets the control's constraint `tau = tau_target` (module
    /// [`super::control`]).
    fn controlled_correction(
        &mut self,
        r: &[f64],
        q: &[f64],
        u: &[f64],
        g: &[f64],
        tau_target: f64,
        symmetric: bool,
    ) -> std::result::Result<(Vec<f64>, f64), Failure> {
        let n = r.len();
        let mut rhs: Vec<f64> = r.iter().chain(q).map(|x| -x).collect();
        self.linear
            .solve_columns(&self.values, &mut rhs, n, symmetric)
            .map_err(Failure::Singular)?;
        let (a, b) = rhs.split_at(n);
        let control = self.control.as_ref().expect("a path-controlled attempt has a control");
        let dl = control.correction(&self.dofs, u, a, b, g, tau_target).ok_or_else(|| {
            Failure::Singular(
                "the path control's quantity does not move with the load factor".into(),
            )
        })?;
        tracing::debug!(dlambda = dl, tau = control.tau(u), tau_target, "path control");
        Ok((a.iter().zip(b).map(|(a, b)| a + dl * b).collect(), dl))
    }

    /// Path control: moves the iterate by `alpha` times the correction `(du, dlambda)` from
    /// `(u, lambda)` (the free dofs by `alpha du`, the prescribed ones to their values at the
    /// new load factor) and returns that load factor.
    fn move_to(&self, u: &mut [f64], du: &[f64], alpha: f64, lambda: f64, dlambda: f64) -> f64 {
        self.add_free(u, du, alpha);
        let lambda = lambda + alpha * dlambda;
        self.set_prescribed(u, lambda);
        lambda
    }

    /// Sets every prescribed dof of `u` to its value at load factor `lambda`.
    fn set_prescribed(&self, u: &mut [f64], lambda: f64) {
        for (k, x) in u.iter_mut().enumerate() {
            if self.loads.prescribed[k] {
                *x = self.loads.prescribed_at(k, lambda);
            }
        }
    }

    /// `u[free] += alpha * du[eq]`.
    fn add_free(&self, u: &mut [f64], du: &[f64], alpha: f64) {
        for (d, &eq) in self.dofs.equation.iter().enumerate() {
            if eq != usize::MAX {
                u[d] += alpha * du[eq];
            }
        }
    }
}
