//! The discrete system at one iterate: the material evaluated at the Gauss points, the
//! assembled residual and tangent, the residual on the free dofs, the converged state stored,
//! and the timed work of one iteration for benchmarks.

use super::newton::{Failure, Trial};
use super::solver::Solver;
use crate::assembly::{Assembled, Kinematics};
use crate::error::{Error, Result};
use crate::material::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_common::MicroResponse;

/// One evaluation of the material: the answers and the kinematics they answer.
type Evaluation = (Vec<MicroResponse>, Vec<MaterialInput>);

/// Euclidean norm.
pub(super) fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl Solver {
    /// Evaluates the material at `u`: the answers and the kinematics they answer; material
    /// failures become [`Failure`]s.
    pub(super) fn evaluate(
        &self,
        material: &mut dyn Material,
        trial: TrialId,
        u: &[f64],
    ) -> Result<std::result::Result<Evaluation, Failure>> {
        let inputs = self.operator.kinematics(&self.model.mesh, &self.gauss, u);
        // Under the updated-Lagrangian option an inverted point has no current configuration
        // to integrate on: it is never sent to the material (no det F is clamped). Under
        // small strain the material decides, as before (the pool refuses det F <= 0, an
        // analytical law answers).
        let checked =
            if self.model.kinematics == Kinematics::UpdatedLagrangian { &inputs[..] } else { &[] };
        let inverted: Vec<_> = checked
            .iter()
            .filter_map(|i| {
                let why = i.deformation.validate().err()?;
                Some((i.gauss_point, format!("element {} inverted: {why}", i.gauss_point.element)))
            })
            .collect();
        if !inverted.is_empty() {
            return Ok(Err(Failure::Inverted(inverted)));
        }
        match material.evaluate(trial, &inputs) {
            Ok(r) if r.len() != inputs.len() => {
                Err(Error::ResponseCount { expected: inputs.len(), got: r.len() })
            }
            Ok(r) => {
                let steps = r.iter().fold(0u64, |a, x| a.saturating_add(x.diagnostics.steps));
                self.evaluated_steps.set(self.evaluated_steps.get().saturating_add(steps));
                let bad: Vec<_> = r
                    .iter()
                    .zip(&inputs)
                    .filter(|(r, _)| !r.is_finite())
                    .map(|(_, i)| (i.gauss_point, "non-finite stress or tangent".to_string()))
                    .collect();
                if bad.is_empty() { Ok(Ok((r, inputs))) } else { Ok(Err(Failure::NotFinite(bad))) }
            }
            Err(MaterialError::GaussPoints(p)) => Ok(Err(Failure::Material(p))),
            Err(e @ MaterialError::Unavailable(_)) => Err(e.into()),
        }
    }

    /// Residual, internal force and tangent values (into `self.values`) from the Gauss-point
    /// responses at `u`; `du_c` is the prescribed increment of the predictor, if any. Under
    /// the updated-Lagrangian option the tangent includes the follower pressures' stiffness at
    /// load factor `lambda`.
    pub(super) fn assemble(
        &mut self,
        responses: &[MicroResponse],
        u: &[f64],
        lambda: f64,
        du_c: Option<&[f64]>,
    ) -> Assembled {
        let mut asm = self.operator.assemble(
            &self.model.mesh,
            &self.dofs,
            &self.gauss,
            &self.pattern,
            u,
            responses,
            Some(&mut self.values),
            du_c,
        );
        if !self.followers.is_empty() {
            self.followers.add_stiffness(
                &self.dofs,
                &self.pattern,
                lambda,
                Some(&mut self.values),
                du_c,
                &mut asm.k_fc_du,
            );
        }
        asm
    }

    /// External force at load factor `lambda` and displacements `u` (the follower pressures
    /// depend on `u`; the dead loads do not).
    pub(super) fn external(&self, lambda: f64, u: &[f64]) -> Vec<f64> {
        let mut f = self.loads.f_ext(lambda);
        if !self.followers.is_empty() {
            self.followers.add_force(&self.model.mesh, self.dofs.field.ndf(), u, lambda, &mut f);
        }
        f
    }

    /// The strain a Gauss-point state records and the secant updates measure: the Cosserat
    /// strain under small strain, the objective stretch strain `R(w)^T F - I` under the
    /// updated-Lagrangian option (a rigid rotation is no strain).
    pub(super) fn strain_of(&self, d: &cosdem_common::MacroDeformation) -> [f64; 6] {
        match self.model.kinematics {
            Kinematics::Small => d.strain(),
            Kinematics::UpdatedLagrangian => d.stretch_strain(),
        }
    }

    /// The largest magnitude of a prescribed dof value at load factor `lambda` (the platen
    /// displacement of a compression), for the error that ends a run.
    pub(super) fn largest_prescribed(&self, lambda: f64) -> f64 {
        (0..self.loads.prescribed.len())
            .filter(|&k| self.loads.prescribed[k])
            .map(|k| self.loads.prescribed_at(k, lambda).abs())
            .fold(0.0, f64::max)
    }

    /// Residual on the free dofs and the force scale of the convergence criterion.
    pub(super) fn residual(&self, f_int: &[f64], f_ext: &[f64]) -> (Vec<f64>, f64) {
        let mut r = vec![0.0; self.dofs.n_free];
        for (d, &eq) in self.dofs.equation.iter().enumerate() {
            if eq != usize::MAX {
                r[eq] = f_int[d] - f_ext[d];
            }
        }
        let scale = norm(f_int).max(norm(f_ext));
        (r, scale)
    }

    /// Evaluates the material at `u` and assembles residual and matrix there, at load factor
    /// `lambda`; with `rate` (a path control's prescribed-dof rate) also `K_fc rate`.
    pub(super) fn trial(
        &mut self,
        material: &mut dyn Material,
        trial: TrialId,
        u: &[f64],
        lambda: f64,
        rate: Option<&[f64]>,
    ) -> Result<std::result::Result<Trial, Failure>> {
        let (responses, inputs) = match self.evaluate(material, trial, u)? {
            Ok(e) => e,
            Err(f) => return Ok(Err(f)),
        };
        let asm = self.assemble(&responses, u, lambda, rate);
        let f_ext = self.external(lambda, u);
        let (r, scale) = self.residual(&asm.f_int, &f_ext);
        Ok(Ok(Trial { responses, inputs, asm, f_ext, r, scale }))
    }

    /// Stores the converged state: dofs, Gauss-point states (from the kinematics `inputs` at
    /// `u` and their answers), reactions, and the answers (the next predictor's tangent).
    pub(super) fn accept(
        &mut self,
        u: Vec<f64>,
        inputs: &[MaterialInput],
        responses: Vec<MicroResponse>,
        f_int: &[f64],
        f_ext: &[f64],
    ) {
        let strains: Vec<[f64; 6]> =
            inputs.iter().map(|i| self.strain_of(&i.deformation)).collect();
        for ((s, e), r) in self.states.iter_mut().zip(strains).zip(&responses) {
            s.strain = e;
            s.stress = r.stress;
            s.diagnostics = r.diagnostics.clone();
        }
        self.committed = Some(responses);
        let ndf = self.dofs.field.ndf();
        self.reactions = self
            .model
            .mesh
            .node_sets
            .iter()
            .map(|(name, nodes)| {
                let mut sum = [0.0; 3];
                for &n in nodes {
                    for c in 0..ndf {
                        sum[c] += f_int[n * ndf + c] - f_ext[n * ndf + c];
                    }
                }
                (name.clone(), sum)
            })
            .collect();
        self.u = u;
    }

    /// One Newton iteration's work at the converged state, for benchmarks: material
    /// evaluation, assembly of residual and tangent, numeric factorization and solve.
    pub fn iteration_work(&mut self, material: &mut dyn Material) -> Result<IterationTiming> {
        let symmetric = material.is_symmetric();
        let t = std::time::Instant::now();
        let trial = TrialId { step: self.step + 1, iteration: 0 };
        let responses = match self.evaluate(material, trial, &self.u)? {
            Ok((r, _)) => r,
            Err(f) => return Err(Error::LinearSolver(f.reason())),
        };
        let material_s = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let u = self.u.clone();
        let asm = self.assemble(&responses, &u, 1.0, None);
        let f_ext = self.external(1.0, &u);
        let (r, _) = self.residual(&asm.f_int, &f_ext);
        let assembly_s = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let mut rhs: Vec<f64> = r.iter().map(|x| -x).collect();
        self.linear.solve(&self.values, &mut rhs, symmetric).map_err(Error::LinearSolver)?;
        Ok(IterationTiming { material_s, assembly_s, solve_s: t.elapsed().as_secs_f64() })
    }
}

/// Wall time of the parts of one Newton iteration (see [`Solver::iteration_work`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IterationTiming {
    /// Kinematics and material evaluation (s).
    pub material_s: f64,
    /// Residual and tangent assembly (s).
    pub assembly_s: f64,
    /// Numeric factorization and triangular solves (s; the first call includes the symbolic
    /// analysis).
    pub solve_s: f64,
}
