//! The driver: setup once, then load steps of Newton-Raphson iterations with line search and
//! automatic load-step cutting (THEORY.md section 3).
//!
//! Life cycle, deal.II style: [`Solver::new`] sets up the system (dof numbering, Gauss data,
//! load vectors, sparsity pattern; the symbolic factorization follows on the first solve),
//! [`Solver::run`] loops over load steps; each step is a predictor plus Newton iterations,
//! then `commit`, reactions and the observer call.

use super::linear::LinearSolver;
use super::loading::{LoadVectors, Loading};
use super::observer::{GaussPointState, SolutionView, StepControl, StepObserver, StepReport};
use super::secant::PointSecant;
use crate::assembly::{Assembled, CosseratOperator, DofMap, Field, GaussData, Pattern};
use crate::element::{ElementKind, QuadratureRule};
use crate::error::{Error, Result};
use crate::material::{Material, MaterialError, MaterialInput, TrialId};
use crate::mesh::Mesh;
use cosdem_common::{GaussPointId, MicroResponse};
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
}

/// Most nominal load steps of a run: a cap so that a tiny `increment` cannot ask for 10^300
/// steps (a hang). The paper's runs use tens to hundreds.
pub const MAX_LOAD_STEPS: usize = 1_000_000;

/// Smallest allowed `min_increment_fraction`: with at most [`MAX_LOAD_STEPS`] steps the
/// smallest increment stays above 1e-18, which the load factor (at most 1) can still resolve
/// to within a factor of 10, so a step cut to the minimum still moves the load.
pub const MIN_INCREMENT_FRACTION: f64 = 1e-12;

/// Newton-Raphson and step-control parameters.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolverSettings {
    /// Nominal number of equal load steps from `lambda = 0` to 1.
    pub steps: usize,
    /// Newton iterations allowed per attempt before the step is cut.
    pub max_iterations: u32,
    /// Force criterion: `|r_free| <= force_tolerance * max(|f_int|, |f_ext|)`.
    pub force_tolerance: f64,
    /// Displacement criterion: `|du| <= displacement_tolerance * |u - u_n|` (the step's
    /// accumulated increment), `du` the full Newton correction of the last iteration, before
    /// any line-search halving (a damped update is no sign of convergence). Either criterion
    /// ends the iteration (the paper's section 3).
    pub displacement_tolerance: f64,
    /// Backtrack (halve the update) while the residual norm grows.
    pub line_search: bool,
    /// Halvings allowed per line search.
    pub max_line_search: u32,
    /// Smallest increment as a fraction of the nominal `1 / steps`; a step that still fails
    /// below it ends the run with [`Error::StepTooSmall`].
    pub min_increment_fraction: f64,
    /// A step converged within this many iterations lets the increment grow (so does a
    /// step that needed no cut of its own, whatever its iterations).
    pub easy_iterations: u32,
    /// Tolerated relative force residual (0: off). When an attempt uses up `max_iterations`
    /// and the smallest relative residual of its iterates is at or below this value, that
    /// iterate is accepted (evaluated again if it was not the last: its residual is then the
    /// step's last) as a *tolerated* step (reported in
    /// [`StepReport::tolerated`], counted in the summary) instead of cutting the step. Past
    /// the peak the DEM assemblies soften while the paper tangent stays elastic, so Newton
    /// converges slowly or stalls above the force tolerance; this is the engineering codes'
    /// "tolerated error" that lets a run reach the residual plateau with its imbalance shown.
    pub tolerated_residual: f64,
    /// Stall limit (0: off). An attempt whose smallest relative residual is already within
    /// `tolerated_residual` and has not fallen for this many iterations in a row ends there
    /// and accepts that best iterate as tolerated, without running to `max_iterations`.
    /// Past a peak the relaxed assemblies answer a move smaller than their slips with a
    /// residual that wanders around a floor instead of falling (the biaxial example: 84 of
    /// its 113 steps run to the cap at 0.5-5 %), and the iterations after the floor is
    /// reached mostly cost relaxations. An attempt whose best is above the tolerated
    /// residual iterates on: ending it early would cut steps that later iterations bring
    /// within it (tried on the biaxial example: it then failed at 6.85 mm).
    #[serde(default)]
    pub stall_iterations: u32,
    /// Forced residual (0: off). The attempt at the smallest increment (one more halving
    /// would go below `min_increment_fraction`) accepts its best iterate up to this relative
    /// residual instead of ending the run, as a *forced* step (tolerated too: reported in
    /// [`StepReport::forced`], counted in the summary, logged with its residual). Past a
    /// peak a relaxed assembly can answer moves of 1e-5 of a step with different slips,
    /// so the residual has a floor that no increment gets below (the biaxial example's seed
    /// 9: 6-16 % at 1/1024 of the step, the force residual's, with the iterations' rotation
    /// corrections of 2e-3 rad at every cut). The residual is the total one, so the
    /// next step starts by removing the imbalance this step leaves. Only steps that would
    /// otherwise end the run are changed: a run that finishes without it is the same bits.
    #[serde(default)]
    pub forced_residual: f64,
    /// Growth factor of the increment after an easy or uncut step (capped at the nominal
    /// increment).
    pub growth: f64,
    /// Gauss-point secant updates of the iteration matrix within a step
    /// ([`super::secant`]): every point's matrix, from the material's tangent at the step's
    /// start, is softened along each move of the point to the stiffness that move measured
    /// (a rank-one update), so that a soft mode converges as the secant method instead of a
    /// fixed-point iteration with the elastic slope. Off: the material's tangent of every
    /// answer.
    #[serde(default)]
    pub secant_updates: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            steps: 10,
            max_iterations: 25,
            force_tolerance: 1e-8,
            // Tight by default so that the force criterion decides on smooth problems; the
            // paper's looser displacement criterion is a job-file choice.
            displacement_tolerance: 1e-12,
            line_search: true,
            max_line_search: 5,
            // 1/1024: ten halvings of the nominal increment.
            min_increment_fraction: 1.0 / 1024.0,
            easy_iterations: 4,
            growth: 2.0,
            tolerated_residual: 0.0,
            secant_updates: false,
            stall_iterations: 0,
            forced_residual: 0.0,
        }
    }
}

impl SolverSettings {
    /// Number of nominal steps that moves a boundary by `total` in increments of at most
    /// `increment` (for jobs that give a displacement increment instead of a step count).
    pub fn steps_for_increment(total: f64, increment: f64) -> Result<usize> {
        if !(increment.abs() > 0.0 && increment.is_finite() && total.is_finite()) {
            return Err(Error::InvalidSetting {
                field: "increment",
                value: increment.to_string(),
                reason: "must be finite and non-zero".into(),
            });
        }
        let steps = ((total / increment).abs() - 1e-9).ceil().max(1.0);
        if steps.is_nan() || steps > MAX_LOAD_STEPS as f64 {
            return Err(Error::InvalidSetting {
                field: "increment",
                value: increment.to_string(),
                reason: format!(
                    "gives {steps:e} load steps for a total of {total}: more than MAX_LOAD_STEPS = \
                     {MAX_LOAD_STEPS}"
                ),
            });
        }
        Ok(steps as usize)
    }

    fn check(&self) -> Result<()> {
        let bad = |field: &'static str, value: String, reason: &str| {
            Err(Error::InvalidSetting { field, value, reason: reason.into() })
        };
        if self.steps == 0 || self.steps > MAX_LOAD_STEPS {
            return bad("steps", self.steps.to_string(), "must be in [1, MAX_LOAD_STEPS = 10^6]");
        }
        if self.max_iterations == 0 {
            return bad("max_iterations", "0".into(), "must be >= 1");
        }
        if !(self.force_tolerance >= 0.0 && self.displacement_tolerance >= 0.0) {
            return bad("tolerances", format!("{self:?}"), "must be >= 0");
        }
        if !(self.min_increment_fraction >= MIN_INCREMENT_FRACTION
            && self.min_increment_fraction <= 1.0)
        {
            return bad(
                "min_increment_fraction",
                self.min_increment_fraction.to_string(),
                "in [1e-12, 1]",
            );
        }
        if !(self.tolerated_residual.is_finite() && self.tolerated_residual >= 0.0) {
            return bad("tolerated_residual", self.tolerated_residual.to_string(), "finite, >= 0");
        }
        if !(self.forced_residual.is_finite() && self.forced_residual >= 0.0) {
            return bad("forced_residual", self.forced_residual.to_string(), "finite, >= 0");
        }
        if self.growth.is_nan() || self.growth < 1.0 {
            return bad("growth", self.growth.to_string(), "must be >= 1");
        }
        Ok(())
    }
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
}

/// The whole run's step reports.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunSummary {
    /// One report per converged step.
    pub steps: Vec<StepReport>,
}

/// Why one attempt at a load step failed (the step is then cut).
#[derive(Debug)]
enum Failure {
    Material(Vec<(GaussPointId, String)>),
    NotFinite(Vec<(GaussPointId, String)>),
    Singular(String),
    MaxIterations(u32, f64),
}

impl Failure {
    fn reason(&self) -> String {
        match self {
            Self::Material(p) => format!("material failed at {} gauss point(s)", p.len()),
            Self::NotFinite(p) => format!("non-finite response at {} gauss point(s)", p.len()),
            Self::Singular(s) => format!("linear solve failed: {s}"),
            Self::MaxIterations(n, r) => {
                format!("no convergence in {n} iterations (relative residual {r:.3e})")
            }
        }
    }

    fn points(self) -> Vec<(GaussPointId, String)> {
        match self {
            Self::Material(p) | Self::NotFinite(p) => p,
            _ => Vec::new(),
        }
    }
}

/// One evaluation of the material: the answers and the kinematics they answer.
type Evaluation = (Vec<MicroResponse>, Vec<MaterialInput>);

/// One evaluated iterate: the answers, the kinematics they answer, the assembled system and
/// the residual on the free dofs with its force scale.
struct Trial {
    responses: Vec<MicroResponse>,
    inputs: Vec<MaterialInput>,
    asm: Assembled,
    r: Vec<f64>,
    scale: f64,
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

enum Attempt {
    Converged { iterations: u32, residuals: Vec<f64>, halvings: u32, tolerated: bool, forced: bool },
    Failed(Failure),
}

/// The macro solver: owns the model, the discrete system and the converged state.
pub struct Solver {
    model: Model,
    settings: SolverSettings,
    operator: CosseratOperator,
    dofs: DofMap,
    gauss: GaussData,
    pattern: Pattern,
    linear: LinearSolver,
    loads: LoadVectors,
    values: Vec<f64>,
    /// Converged nodal dofs (all dofs).
    u: Vec<f64>,
    /// Converged load factor.
    lambda: f64,
    /// Converged steps so far.
    step: u64,
    /// Load-factor increment of the next attempt (grows after easy or uncut steps, halves on
    /// cuts).
    increment: f64,
    /// Responses at the converged state (the next predictor's tangent), if known.
    committed: Option<Vec<MicroResponse>>,
    /// Gauss-point states at the converged state.
    states: Vec<GaussPointState>,
    /// Reactions at the converged state.
    reactions: BTreeMap<String, [f64; 3]>,
    /// DEM steps of every evaluation since the last converged step (all iterations, line
    /// search trials and cut attempts that answered): the step's real relaxation cost.
    evaluated_steps: std::cell::Cell<u64>,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl Solver {
    /// Sets up the discrete system: dofs, Gauss data, load vectors and sparsity pattern.
    pub fn new(model: Model, settings: SolverSettings) -> Result<Self> {
        settings.check()?;
        if model.mesh.kind == ElementKind::Q9 && model.rule == QuadratureRule::Gauss2x2 {
            // Unlike Q8's, the zero-energy modes of 2x2-integrated Q9 elements can spread
            // through a mesh.
            tracing::warn!("Q9 elements with 2x2 Gauss points have communicable spurious modes");
        }
        let (prescribed, _) = model.loading.prescribed(&model.mesh, model.field)?;
        let dofs = DofMap::new(model.field, model.mesh.n_nodes(), &prescribed);
        let gauss = GaussData::new(&model.mesh, model.rule)?;
        let loads = model.loading.vectors(&model.mesh, &dofs, &gauss)?;
        let pattern = Pattern::new(&model.mesh, &dofs);
        let linear = LinearSolver::new(&pattern)?;
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
            operator: CosseratOperator { field: model.field },
            values: vec![0.0; pattern.nnz()],
            u: vec![0.0; dofs.n_dofs()],
            model,
            settings,
            dofs,
            gauss,
            pattern,
            linear,
            loads,
            lambda: 0.0,
            step: 0,
            increment: first_increment,
            committed: None,
            states,
            reactions: BTreeMap::new(),
            evaluated_steps: std::cell::Cell::new(0),
        })
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
        }
    }

    /// Continues from a saved [`SolverState`] of a solver built from the same model and
    /// settings: the following steps are bit-identical to those of the uninterrupted run
    /// (given the material's committed states of the same step).
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
        if !(state.increment > 0.0 && state.lambda >= 0.0) {
            return Err(Error::InvalidSetting {
                field: "checkpoint.increment",
                value: state.increment.to_string(),
                reason: "must be > 0".into(),
            });
        }
        self.u = state.u;
        self.lambda = state.lambda;
        self.step = state.step;
        self.increment = state.increment;
        self.committed = state.committed;
        self.states = state.gauss_points;
        self.reactions = state.reactions;
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
        while self.lambda < 1.0 - 1e-12 {
            let target = (self.lambda + self.increment).min(1.0);
            let step = self.step + 1;
            if target <= self.lambda {
                return Err(Error::InvalidSetting {
                    field: "min_increment_fraction",
                    value: self.settings.min_increment_fraction.to_string(),
                    reason: format!(
                        "the increment {:e} no longer moves the load factor \
                         {:.17}: raise it",
                        self.increment, self.lambda
                    ),
                });
            }
            let span = tracing::info_span!("load_step", step, lambda = target);
            let _enter = span.enter();
            // The last attempt before the run would end: halving it goes below the minimum.
            let at_minimum = 0.5 * (target - self.lambda) < min_increment * (1.0 - 1e-9);
            match self.attempt(material, step, &mut iteration, target, at_minimum)? {
                Attempt::Converged { iterations, residuals, halvings, tolerated, forced } => {
                    material.commit(step)?;
                    let done = target - self.lambda;
                    self.lambda = target;
                    self.step = step;
                    let report = StepReport {
                        step,
                        load_factor: target,
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
                    let tried = target - self.lambda;
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

    /// Evaluates the material at `u`: the answers and the kinematics they answer; material
    /// failures become [`Failure`]s.
    fn evaluate(
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
    fn assemble(&mut self, responses: &[MicroResponse], du_c: Option<&[f64]>) -> Assembled {
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
    fn residual(&self, f_int: &[f64], f_ext: &[f64]) -> (Vec<f64>, f64) {
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
    fn trial(
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

    /// One attempt at reaching load factor `target` from the converged state; `at_minimum`:
    /// the run ends if it fails (see [`SolverSettings::forced_residual`]).
    fn attempt(
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
        let f_ext = self.loads.f_ext(target);
        let du_c: Vec<f64> = self
            .loads
            .prescribed_value
            .iter()
            .zip(&self.u)
            .zip(&self.loads.prescribed)
            .map(|((v, u), &p)| if p { target * v - u } else { 0.0 })
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
        let asm = self.assemble(&responses, Some(&du_c));
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
        let (r0, _) = self.residual(&asm.f_int, &f_ext);
        let mut rhs: Vec<f64> = r0.iter().zip(&asm.k_fc_du).map(|(r, k)| -(r + k)).collect();
        if let Err(s) = {
            let _s = tracing::info_span!("predictor").entered();
            self.linear.solve(&self.values, &mut rhs, symmetric)
        } {
            return Ok(Attempt::Failed(Failure::Singular(s)));
        }
        let u_n = self.u.clone();
        let mut u = u_n.clone();
        self.add_free(&mut u, &rhs, 1.0);
        for (x, d) in u.iter_mut().zip(&du_c) {
            *x += d;
        }
        let mut du = rhs;
        let mut residuals = Vec::new();
        let mut previous: Option<(Vec<f64>, f64)> = None; // (u before the update, |r| there)
        let mut last_rel = f64::INFINITY;
        // The iterate of the attempt with the smallest residual (relative residual, u):
        // what a tolerated step accepts (see `tolerated_residual`).
        let mut best: Option<(f64, Vec<f64>)> = None;
        let mut best_at = 0u32;
        let mut halvings = 0;
        for k in 1..=self.settings.max_iterations + 1 {
            let span = tracing::info_span!("newton", iteration = k);
            let _enter = span.enter();
            let mut alpha = 1.0;
            let Trial { responses, inputs, asm, r, scale } = loop {
                let trial = match self.trial(material, next_trial(iteration), &u, &f_ext)? {
                    Ok(t) => t,
                    Err(f) => return Ok(Attempt::Failed(f)),
                };
                let grows = previous.as_ref().is_some_and(|(_, rp)| norm(&trial.r) > *rp);
                let can_cut = self.settings.line_search
                    && grows
                    && alpha > 0.5f64.powi(self.settings.max_line_search as i32);
                if !can_cut {
                    break trial;
                }
                alpha *= 0.5;
                halvings += 1;
                let (u_prev, _) = previous.as_ref().expect("grows implies a previous iterate");
                u.clone_from(u_prev);
                self.add_free(&mut u, &du, alpha);
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
                });
            }
            // Only a tolerated step uses the best iterate: without one, no copy of `u`.
            let tolerating = accepted > 0.0;
            if tolerating && best.as_ref().is_none_or(|(b, _)| rel < *b) {
                best = Some((rel, u.clone()));
                best_at = k;
            }
            let tolerated = best.as_ref().is_some_and(|(b, _)| *b <= accepted);
            let stall = self.settings.stall_iterations;
            // The stall ends only an attempt tolerated without the forced residual: one
            // forced early could have come within the tolerated residual later.
            let within = best.as_ref().is_some_and(|(b, _)| *b <= tolerated_residual);
            let stalled = stall > 0 && within && k - best_at >= stall;
            if stalled {
                tracing::debug!(iterations = k, since = best_at, "stalled");
            }
            if k > self.settings.max_iterations || stalled {
                let Some((_, best_u)) = best.take().filter(|_| tolerated) else { break };
                let (u, trial) = if best_at == k {
                    (u, Trial { responses, inputs, asm, r, scale })
                } else {
                    // An earlier iterate was better: the material holds the last trial only,
                    // so the best one is evaluated again (from the committed state: the same
                    // answer unless the material warm-starts) and accepted if it is still
                    // tolerated.
                    let trial =
                        match self.trial(material, next_trial(iteration), &best_u, &f_ext)? {
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
                self.accept(u, &trial.inputs, trial.responses, &trial.asm.f_int, &f_ext);
                return Ok(Attempt::Converged {
                    iterations: k,
                    residuals,
                    halvings,
                    tolerated: true,
                    forced: last_rel > tolerated_residual,
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
                    p.advance(i.deformation.strain(), r.stress);
                    r.tangent = p.matrix;
                }
                self.assemble(&updated, None);
            }
            let mut rhs: Vec<f64> = r.iter().map(|x| -x).collect();
            if let Err(s) = self.linear.solve(&self.values, &mut rhs, symmetric) {
                return Ok(Attempt::Failed(Failure::Singular(s)));
            }
            previous = Some((u.clone(), rn));
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

    /// `u[free] += alpha * du[eq]`.
    fn add_free(&self, u: &mut [f64], du: &[f64], alpha: f64) {
        for (d, &eq) in self.dofs.equation.iter().enumerate() {
            if eq != usize::MAX {
                u[d] += alpha * du[eq];
            }
        }
    }

    /// Stores the converged state: dofs, Gauss-point states (from the kinematics `inputs` at
    /// `u` and their answers), reactions, and the answers (the next predictor's tangent).
    fn accept(
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
