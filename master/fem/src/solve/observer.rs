//! What the solver hands out after every converged load step.

use crate::assembly::Field;
use crate::error::Result;
use crate::material::Material;
use crate::mesh::Mesh;
use crate::solve::Solver;
use cosdem_common::{GaussPointId, MicroDiagnostics};
use std::collections::BTreeMap;

/// Summary of one converged load step.
#[derive(Clone, Debug, PartialEq)]
pub struct StepReport {
    /// Converged step number (1-based; the `step` given to `Material::commit`).
    pub step: u64,
    /// Stage of the step (0-based, repetitions of a stage counted; 0 for a one-stage job).
    pub stage: u32,
    /// Load factor reached within the stage (1 = the stage's full loading).
    pub load_factor: f64,
    /// Pseudo-time: stages finished before this step plus its load factor, or under a path
    /// control its progress (increasing over the whole run; equal to `load_factor` in a
    /// one-stage job without a path control).
    pub time: f64,
    /// Load factor increment of this step (after any cuts); under a path control, the
    /// progress's.
    pub increment: f64,
    /// Newton iterations of the successful attempt (solves after the predictor).
    pub iterations: u32,
    /// Relative force residual after the predictor and after each iteration.
    pub residuals: Vec<f64>,
    /// Line-search halvings taken in the successful attempt.
    pub line_search_halvings: u32,
    /// Failed attempts (step cuts) before this step converged.
    pub cuts: u32,
    /// The step ran out of iterations and was accepted under
    /// [`crate::solve::SolverSettings::tolerated_residual`] (its last residual is in
    /// `residuals`), not converged to the force or displacement tolerance.
    pub tolerated: bool,
    /// A tolerated step accepted at the smallest increment above `tolerated_residual`, under
    /// [`crate::solve::SolverSettings::forced_residual`].
    pub forced: bool,
    /// Reaction `[R_x, R_y, R_w]` (N, N, N m per metre of thickness) of every named node set:
    /// the sum of `f_int - f_ext` over the set's dofs.
    pub reactions: BTreeMap<String, [f64; 3]>,
    /// DEM steps of every relaxation of the step: all its Newton iterations, line-search
    /// trials and cut attempts that answered (the converged state's own are a part).
    pub dem_steps: u64,
}

/// State of one Gauss point at a converged step.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GaussPointState {
    /// Which point.
    pub id: GaussPointId,
    /// Physical position (m).
    pub position: [f64; 2],
    /// Strain vector `[e_xx, e_yy, e_xy, e_yx, k_x, k_y]`.
    pub strain: [f64; 6],
    /// Stress vector `[s_xx, s_yy, s_xy, s_yx, m_x, m_y]`.
    pub stress: [f64; 6],
    /// Diagnostics of the material's last evaluation.
    pub diagnostics: MicroDiagnostics,
}

/// Read-only view of the converged solution.
#[derive(Clone, Copy, Debug)]
pub struct SolutionView<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// Field (dofs per node).
    pub field: Field,
    /// Nodal dofs, `field.ndf()` per node (`u_x, u_y[, w]`).
    pub dofs: &'a [f64],
    /// Every Gauss point, in `GaussPointId` order (element-major).
    pub gauss_points: &'a [GaussPointState],
}

impl SolutionView<'_> {
    /// `[u_x, u_y]` of every node.
    pub fn displacements(&self) -> Vec<[f64; 2]> {
        let ndf = self.field.ndf();
        self.dofs.chunks(ndf).map(|d| [d[0], d[1]]).collect()
    }

    /// Micro-rotation of every node (zeros for the Cauchy field).
    pub fn rotations(&self) -> Vec<f64> {
        match self.field {
            Field::Cosserat => self.dofs.chunks(3).map(|d| d[2]).collect(),
            Field::Cauchy => vec![0.0; self.mesh.n_nodes()],
        }
    }
}

/// What the solver does after a step has been observed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepControl {
    /// Go on with the next step.
    Continue,
    /// End the run now ([`crate::Error::Interrupted`]); the step is committed and observed.
    Stop,
}

/// Called after every converged (committed) step, e.g. to write output as the run goes.
pub trait StepObserver {
    /// Sees the step; an error stops the run.
    fn on_step(&mut self, report: &StepReport, state: &SolutionView<'_>) -> Result<()>;

    /// Called after [`StepObserver::on_step`] with the solver and the material at the
    /// committed step (what a checkpoint saves); may stop the run cleanly.
    fn after_step(&mut self, solver: &Solver, material: &mut dyn Material) -> Result<StepControl> {
        let _ = (solver, material);
        Ok(StepControl::Continue)
    }
}

/// Ignores every step.
impl StepObserver for () {
    fn on_step(&mut self, _: &StepReport, _: &SolutionView<'_>) -> Result<()> {
        Ok(())
    }
}

/// Keeps every step report (the load-displacement curve lives in the reactions).
impl StepObserver for Vec<StepReport> {
    fn on_step(&mut self, report: &StepReport, _: &SolutionView<'_>) -> Result<()> {
        self.push(report.clone());
        Ok(())
    }
}
