//! The driver: setup once, then load steps of Newton-Raphson iterations with line search and
//! automatic load-step cutting (THEORY.md section 3).
//!
//! Life cycle, deal.II style: [`Solver::new`] sets up the system (dof numbering, Gauss data,
//! load vectors, sparsity pattern; the symbolic factorization follows on the first solve),
//! [`Solver::run`] loops over load steps; each step is a predictor plus Newton iterations,
//! then `commit`, reactions and the observer call.

use super::control::ControlDofs;
use super::follower::Followers;
use super::linear::LinearSolver;
use super::loading::{LoadVectors, Loading};
use super::newton::Attempt;
use super::observer::{GaussPointState, SolutionView, StepControl, StepObserver, StepReport};
use super::settings::SolverSettings;
use crate::assembly::{CosseratOperator, DofMap, Field, GaussData, Kinematics, Pattern};
use crate::element::{ElementKind, QuadratureRule};
use crate::error::{Error, Result};
use crate::material::Material;
use crate::mesh::Mesh;
use cosdem_common::MicroResponse;
use std::collections::BTreeMap;

/// What is solved: mesh, field, integration rule and loading.
#[derive(Clone, Debug)]
pub struct Model {
    /// The mesh.
    pub mesh: Mesh,
    /// Cosserat or Cauchy continuum.
    pub field: Field,
    /// Gauss rule (the paper: 2x2 on Q8).
    pub rule: QuadratureRule,
    /// Boundary conditions and loads.
    pub loading: Loading,
    /// Small strain (the paper's) or updated Lagrangian.
    pub kinematics: Kinematics,
}

/// The evolving state of a [`Solver`] at a converged step (see [`Solver::state`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolverState {
    /// Nodal dofs (all dofs).
    pub u: Vec<f64>,
    /// Converged load factor.
    pub lambda: f64,
    /// Converged steps.
    pub step: u64,
    /// Increment of the next attempt.
    pub increment: f64,
    /// Responses at the converged state (the next predictor's tangent).
    pub committed: Option<Vec<MicroResponse>>,
    /// Gauss-point states.
    pub gauss_points: Vec<GaussPointState>,
    /// Reactions of the named node sets.
    pub reactions: BTreeMap<String, [f64; 3]>,
    /// The stage the step belongs to (0-based).
    pub stage: u32,
    /// Every dof's value at the start of that stage (`None` in the first stage): what its
    /// prescribed dofs move from ([`Solver::resume_stage`]).
    pub stage_start: Option<Vec<f64>>,
    /// Converged progress of a path-controlled stage (0 to 1; 0 without a path control).
    pub progress: f64,
}

/// The whole run's step reports.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunSummary {
    /// One report per converged step.
    pub steps: Vec<StepReport>,
}

/// The macro solver: owns the model, the discrete system and the converged state.
pub struct Solver {
    pub(super) model: Model,
    pub(super) settings: SolverSettings,
    pub(super) operator: CosseratOperator,
    pub(super) dofs: DofMap,
    pub(super) gauss: GaussData,
    pub(super) pattern: Pattern,
    pub(super) linear: LinearSolver,
    pub(super) loads: LoadVectors,
    /// Pressures that follow the deformed edges (updated Lagrangian; empty under small
    /// strain, where `loads` holds them).
    pub(super) followers: Followers,
    pub(super) values: Vec<f64>,
    /// Converged nodal dofs (all dofs).
    pub(super) u: Vec<f64>,
    /// Converged load factor.
    pub(super) lambda: f64,
    /// The stage's path control, if any ([`super::control`]).
    pub(super) control: Option<ControlDofs>,
    /// Converged progress of a path-controlled stage (0 to 1): what its steps advance.
    pub(super) progress: f64,
    /// Converged steps so far.
    pub(super) step: u64,
    /// The stage being run (0-based; see [`Solver::begin_stage`]).
    pub(super) stage: u32,
    /// The stage start of a restored state, until [`Solver::resume_stage`] takes it.
    pub(super) saved_stage_start: Option<Vec<f64>>,
    /// Load-factor increment of the next attempt (grows after easy or uncut steps, halves on
    /// cuts).
    pub(super) increment: f64,
    /// Responses at the converged state (the next predictor's tangent), if known.
    pub(super) committed: Option<Vec<MicroResponse>>,
    /// Gauss-point states at the converged state.
    pub(super) states: Vec<GaussPointState>,
    /// Reactions at the converged state.
    pub(super) reactions: BTreeMap<String, [f64; 3]>,
    /// DEM steps of every evaluation since the last converged step (all iterations, line
    /// search trials and cut attempts that answered): the step's real relaxation cost.
    pub(super) evaluated_steps: std::cell::Cell<u64>,
}

impl Solver {
    /// Sets up the discrete system: dofs, Gauss data, load vectors and sparsity pattern.
    pub fn new(model: Model, settings: SolverSettings) -> Result<Self> {
        settings.check()?;
        if model.mesh.kinds.contains(&ElementKind::Q9)
            && model.rule.on(ElementKind::Q9) == QuadratureRule::Gauss2x2
        {
            // Unlike Q8's, the zero-energy modes of 2x2-integrated Q9 elements can spread
            // through a mesh.
            tracing::warn!("Q9 elements with 2x2 Gauss points have communicable spurious modes");
        }
        let (prescribed, _) = model.loading.prescribed(&model.mesh, model.field)?;
        let dofs = DofMap::new(model.field, model.mesh.n_nodes(), &prescribed);
        let gauss = GaussData::new(&model.mesh, model.rule)?;
        let (loads, followers) = Self::load_vectors(&model, &model.loading, &dofs, &gauss, None)?;
        let pattern = Pattern::new(&model.mesh, &dofs);
        let linear = LinearSolver::new(&pattern)?;
        let control = Self::control_of(&model, &model.loading, None)?;
        let states = (0..gauss.len())
            .map(|g| GaussPointState {
                id: gauss.id(g),
                position: gauss.x[g],
                strain: [0.0; 6],
                stress: [0.0; 6],
                diagnostics: Default::default(),
            })
            .collect();
        tracing::info!(
            nodes = model.mesh.n_nodes(),
            elements = model.mesh.n_elements(),
            free_dofs = dofs.n_free,
            nnz = pattern.nnz(),
            gauss_points = gauss.len(),
            "system set up"
        );
        let first_increment = 1.0 / settings.steps as f64;
        Ok(Self {
            operator: CosseratOperator { field: model.field, kinematics: model.kinematics },
            values: vec![0.0; pattern.nnz()],
            u: vec![0.0; dofs.n_dofs()],
            model,
            settings,
            dofs,
            gauss,
            pattern,
            linear,
            loads,
            followers,
            lambda: 0.0,
            control,
            progress: 0.0,
            step: 0,
            stage: 0,
            saved_stage_start: None,
            increment: first_increment,
            committed: None,
            states,
            reactions: BTreeMap::new(),
            evaluated_steps: std::cell::Cell::new(0),
        })
    }

    /// The dead load vectors of `loading` and, under the updated-Lagrangian option, its
    /// pressures as follower loads (taken out of the dead vectors).
    pub(super) fn load_vectors(
        model: &Model,
        loading: &Loading,
        dofs: &DofMap,
        gauss: &GaussData,
        start: Option<&[f64]>,
    ) -> Result<(LoadVectors, Followers)> {
        match model.kinematics {
            Kinematics::Small => {
                Ok((loading.vectors_from(&model.mesh, dofs, gauss, start)?, Followers::default()))
            }
            Kinematics::UpdatedLagrangian => Ok((
                loading.without_pressures().vectors_from(&model.mesh, dofs, gauss, start)?,
                Followers::new(loading, &model.mesh)?,
            )),
        }
    }

    /// The path control of `loading`, resolved on the model's mesh from the dof values
    /// `start` of the stage.
    pub(super) fn control_of(
        model: &Model,
        loading: &Loading,
        start: Option<&[f64]>,
    ) -> Result<Option<ControlDofs>> {
        loading
            .control
            .as_ref()
            .map(|c| ControlDofs::new(c, &model.mesh, model.field, start))
            .transpose()
    }

    /// Where the stage stands: the converged progress of a path-controlled stage, else the
    /// converged load factor (both 1 at the stage's end).
    pub(super) fn position(&self) -> f64 {
        if self.control.is_some() { self.progress } else { self.lambda }
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The dof numbering.
    pub fn dofs(&self) -> &DofMap {
        &self.dofs
    }

    /// The mapped Gauss points.
    pub fn gauss(&self) -> &GaussData {
        &self.gauss
    }

    /// The sparsity pattern of the free-dof tangent.
    pub fn pattern(&self) -> &Pattern {
        &self.pattern
    }

    /// DEM steps of the relaxations since the last committed step: the failed attempts of
    /// the step that ended a run (`StepTooSmall`), which no [`StepReport`] carries. Zero
    /// after a run that finished or was interrupted between steps.
    pub fn uncommitted_dem_steps(&self) -> u64 {
        self.evaluated_steps.get()
    }

    /// Converged load factor.
    pub fn load_factor(&self) -> f64 {
        self.lambda
    }

    /// The converged solution.
    pub fn solution(&self) -> SolutionView<'_> {
        SolutionView {
            mesh: &self.model.mesh,
            field: self.model.field,
            dofs: &self.u,
            gauss_points: &self.states,
        }
    }

    /// Reactions of every named node set at the converged state.
    pub fn reactions(&self) -> &BTreeMap<String, [f64; 3]> {
        &self.reactions
    }

    /// Everything that evolves from step to step, at the last converged step: what a
    /// checkpoint saves (with the material's committed states).
    pub fn state(&self) -> SolverState {
        SolverState {
            u: self.u.clone(),
            lambda: self.lambda,
            step: self.step,
            increment: self.increment,
            committed: self.committed.clone(),
            gauss_points: self.states.clone(),
            reactions: self.reactions.clone(),
            stage: self.stage,
            stage_start: self.loads.prescribed_start.clone(),
            progress: self.progress,
        }
    }

    /// Continues from a saved [`SolverState`] of a solver built from the same model and
    /// settings: the following steps are bit-identical to those of the uninterrupted run
    /// (given the material's committed states of the same step). A state of a later stage
    /// than the first needs that stage's loading: [`Solver::resume_stage`] after this.
    pub fn restore(&mut self, state: SolverState) -> Result<()> {
        let bad = |field: &'static str, value: usize, expected: usize| Error::InvalidSetting {
            field,
            value: value.to_string(),
            reason: format!("the saved state does not fit this model: expected {expected}"),
        };
        if state.u.len() != self.u.len() {
            return Err(bad("checkpoint.u", state.u.len(), self.u.len()));
        }
        if state.gauss_points.len() != self.states.len() {
            return Err(bad(
                "checkpoint.gauss_points",
                state.gauss_points.len(),
                self.states.len(),
            ));
        }
        if let Some(c) = &state.committed
            && c.len() != self.states.len()
        {
            return Err(bad("checkpoint.committed", c.len(), self.states.len()));
        }
        if !(state.progress.is_finite() && (0.0..=1.0).contains(&state.progress)) {
            return Err(Error::InvalidSetting {
                field: "checkpoint.progress",
                value: state.progress.to_string(),
                reason: "must be in [0, 1]".into(),
            });
        }
        if !(state.increment > 0.0 && (state.lambda >= 0.0 || self.control.is_some())) {
            return Err(Error::InvalidSetting {
                field: "checkpoint.increment",
                value: state.increment.to_string(),
                reason: "must be > 0".into(),
            });
        }
        self.u = state.u;
        self.lambda = state.lambda;
        self.progress = state.progress;
        self.step = state.step;
        self.increment = state.increment;
        self.committed = state.committed;
        self.states = state.gauss_points;
        self.reactions = state.reactions;
        self.stage = state.stage;
        self.saved_stage_start = state.stage_start;
        Ok(())
    }

    /// Converged steps so far.
    pub fn step(&self) -> u64 {
        self.step
    }

    /// Runs all load steps to `lambda = 1`, calling `observer` after each converged step.
    ///
    /// After each step, [`StepObserver::after_step`] may ask to stop: the run then ends with
    /// [`Error::Interrupted`] (the step is committed and observed).
    pub fn run(
        &mut self,
        material: &mut dyn Material,
        observer: &mut dyn StepObserver,
    ) -> Result<RunSummary> {
        let nominal = 1.0 / self.settings.steps as f64;
        let min_increment = nominal * self.settings.min_increment_fraction;
        let mut summary = RunSummary::default();
        let mut cuts = 0u32;
        let mut iteration = 0u32; // TrialId.iteration: keeps counting across cuts
        // Ends: every pass either converges (the load factor grows by at least the minimum
        // increment, checked below) or cuts the increment, and at most log2(1 /
        // min_increment_fraction) + 1 cuts in a row end the run with StepTooSmall.
        let controlled = self.control.is_some();
        while self.position() < 1.0 - 1e-12 {
            // The load factor's target, or with a path control the progress's.
            let position = self.position();
            let target = (position + self.increment).min(1.0);
            let step = self.step + 1;
            if target <= position {
                return Err(Error::InvalidSetting {
                    field: "min_increment_fraction",
                    value: self.settings.min_increment_fraction.to_string(),
                    reason: format!(
                        "the increment {:e} no longer moves the load factor \
                         {:.17}: raise it",
                        self.increment, position
                    ),
                });
            }
            let span = tracing::info_span!("load_step", step, lambda = target);
            let _enter = span.enter();
            // The last attempt before the run would end: halving it goes below the minimum.
            let at_minimum = 0.5 * (target - position) < min_increment * (1.0 - 1e-9);
            match self.attempt(material, step, &mut iteration, target, at_minimum)? {
                Attempt::Converged {
                    iterations,
                    residuals,
                    halvings,
                    tolerated,
                    forced,
                    lambda,
                } => {
                    material.commit(step)?;
                    let done = target - position;
                    self.lambda = lambda;
                    if controlled {
                        self.progress = target;
                    }
                    self.step = step;
                    let report = StepReport {
                        step,
                        stage: self.stage,
                        load_factor: lambda,
                        time: f64::from(self.stage) + target,
                        increment: done,
                        iterations,
                        residuals,
                        line_search_halvings: halvings,
                        cuts,
                        tolerated,
                        forced,
                        reactions: self.reactions.clone(),
                        dem_steps: self.evaluated_steps.take(),
                    };
                    let residual = report.residuals.last().copied().unwrap_or(f64::NAN);
                    if forced {
                        tracing::warn!(
                            iterations,
                            cuts,
                            residual,
                            "step forced through at the smallest increment"
                        );
                    } else if tolerated {
                        tracing::warn!(iterations, cuts, residual, "step accepted as tolerated");
                    } else {
                        tracing::info!(iterations, cuts, "step converged");
                    }
                    // The increment grows back after an easy step, and after any step that
                    // needed no cut of its own: past a peak the paper tangent takes 10-20
                    // iterations at every increment, so waiting for an easy step left a cut
                    // increment cut for the rest of the run (the biaxial example's tight
                    // reference, cut to 1/16 by one slip at 9 mm, crawled at 1/16 after it).
                    if iterations <= self.settings.easy_iterations || cuts == 0 {
                        self.increment = (done * self.settings.growth).min(nominal);
                    }
                    cuts = 0;
                    iteration = 0;
                    observer.on_step(&report, &self.solution())?;
                    summary.steps.push(report);
                    if observer.after_step(self, material)? == StepControl::Stop {
                        return Err(Error::Interrupted { step: self.step });
                    }
                }
                Attempt::Failed(failure) => {
                    material.rollback()?;
                    let tried = target - position;
                    tracing::warn!(
                        reason = failure.reason(),
                        increment = tried,
                        "cutting the step"
                    );
                    cuts += 1;
                    self.increment = 0.5 * tried;
                    if self.increment < min_increment * (1.0 - 1e-9) {
                        return Err(Error::StepTooSmall {
                            step,
                            load_factor: self.lambda,
                            displacement: self.largest_prescribed(if controlled {
                                self.lambda
                            } else {
                                target
                            }),
                            increment: tried,
                            min_increment,
                            reason: failure.reason(),
                            gauss_points: failure.points(),
                        });
                    }
                }
            }
        }
        Ok(summary)
    }
}
