//! The discrete system at one iterate: the material evaluated at the Gauss points, the
//! assembled residual and tangent, the residual on the free dofs, the converged state stored,
//! and the timed work of one iteration for benchmarks.

use super::newton::{Failure, Trial};
use super::solver::Solver;
use crate::assembly::Assembled;
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
    /// responses; `du_c` is the prescribed increment of the predictor, if any.
    pub(super) fn assemble(
        &mut self,
        responses: &[MicroResponse],
        du_c: Option<&[f64]>,
    ) -> Assembled {
        self.operator.assemble(
            &self.model.mesh,
            &self.dofs,
            &self.gauss,
            &self.pattern,
            responses,
            Some(&mut self.values),
            du_c,
        )
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

    /// Evaluates the material at `u` and assembles residual and matrix there.
    pub(super) fn trial(
        &mut self,
        material: &mut dyn Material,
        trial: TrialId,
        u: &[f64],
        f_ext: &[f64],
    ) -> Result<std::result::Result<Trial, Failure>> {
        let (responses, inputs) = match self.evaluate(material, trial, u)? {
            Ok(e) => e,
            Err(f) => return Ok(Err(f)),
        };
        let asm = self.assemble(&responses, None);
        let (r, scale) = self.residual(&asm.f_int, f_ext);
        Ok(Ok(Trial { responses, inputs, asm, r, scale }))
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
        for ((s, i), r) in self.states.iter_mut().zip(inputs).zip(&responses) {
            s.strain = i.deformation.strain();
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
        let asm = self.assemble(&responses, None);
        let f_ext = self.loads.f_ext(1.0);
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
