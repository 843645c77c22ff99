//! One caller stage run from the current state, all or nothing.
//!
//! The stage is expanded after the stages so far (a bad stage is refused before anything
//! moves); the solver's state and the assemblies' committed states are kept; each solver stage
//! it expands to is begun ([`Solver::begin_stage`]; the very first is the one the solver is
//! built with) and run to its end, every committed step recorded as a run records it (the
//! run directory, then the caller's observer). If a step cannot be solved, the stage is undone:
//! the assemblies get their kept states back (when a step of the stage was committed), the
//! solver is rebuilt at the kept state, and the run directory is cut back to the step the
//! stage started from, as a resume cuts it back ([`RunWriter::resume`]); the DEM steps the
//! stage spent stay counted in the summary.

use super::Stepper;
use super::solver::fresh;
use crate::output::run_dir::RunWriter;
use crate::run::observer::{Silent, StepHook};
use crate::run::{RunError, RunObserver, run_settings};
use cosdem_common::micro::AssemblyState;
use cosdem_fem::material::Material;
use cosdem_fem::solve::{SolutionView, Solver, SolverState, StepObserver, StepReport};
use cosdem_job::{SolverStage, StageSection};

/// What a caller stage did.
#[derive(Clone, Debug, PartialEq)]
pub struct StageReport {
    /// The stage's index among the caller's stages (0-based).
    pub index: usize,
    /// Its committed steps, in order: load factor, iterations, cuts, reactions, DEM steps.
    pub steps: Vec<StepReport>,
}

/// A caller stage from the text of a `[[stage]]` table of a job file (the TOML between the
/// header and the next one, or an inline table's contents): `steps` is 1 when not given (a
/// job file's default is 10). Unknown keys and wrong types are refused naming the key.
pub fn stage_from_toml(text: &str) -> Result<StageSection, RunError> {
    let refuse = |reason: String| RunError::StageText { text: text.to_string(), reason };
    let mut table: toml::Table = toml::from_str(text).map_err(|e| refuse(e.to_string()))?;
    table.entry("steps").or_insert(toml::Value::Integer(1));
    table.try_into().map_err(|e: toml::de::Error| refuse(e.to_string()))
}

/// The run's per-step hook, keeping each step's report.
struct Recorder<'h> {
    hook: StepHook<'h>,
    reports: Vec<StepReport>,
}

impl StepObserver for Recorder<'_> {
    fn on_step(&mut self, report: &StepReport, view: &SolutionView<'_>) -> cosdem_fem::Result<()> {
        self.hook.on_step(report, view)?;
        self.reports.push(report.clone());
        Ok(())
    }
}

/// Runs the solver stages of one caller stage; `begun`: the solver is built with the first.
fn run(
    solver: &mut Solver,
    stages: &[SolverStage],
    begun: bool,
    material: &mut dyn Material,
    hook: &mut dyn StepObserver,
) -> cosdem_fem::Result<()> {
    for (j, s) in stages.iter().enumerate() {
        if j > 0 || !begun {
            solver.begin_stage(s.loading.clone(), s.steps)?;
        }
        let span = tracing::info_span!("stage", stage = solver.stage(), name = s.name.as_str());
        let _enter = span.enter();
        solver.run(material, hook)?;
    }
    Ok(())
}

impl Stepper {
    /// Runs `stage` (its `steps` load steps, cut as any step when Newton fails) from the
    /// current state: see the [module](super) doc. Errors: a stage the job file would refuse
    /// (its key named, `stage[i]...` with `i` its index among the caller's; nothing has
    /// moved), [`RunError::StageFailed`] (the stage undone: the stepper is where it was and
    /// can go on), [`RunError::Broken`] (the stage could not be undone).
    pub fn step(&mut self, stage: StageSection) -> Result<StageReport, RunError> {
        self.step_observed(stage, &mut Silent)
    }

    /// [`Stepper::step`], telling `observer` each committed step after the run directory has
    /// recorded it ([`RunObserver::on_step`]: a progress bar).
    pub fn step_observed(
        &mut self,
        stage: StageSection,
        observer: &mut dyn RunObserver,
    ) -> Result<StageReport, RunError> {
        if let Some(reason) = &self.broken {
            return Err(RunError::Broken { reason: reason.clone() });
        }
        let index = self.history.stages.len();
        let name = stage.name.clone();
        let (next, expanded) = self.history.next(&self.job, stage, &self.model.mesh)?;
        // Where the stage starts, to go back to.
        let before = self.solver.state();
        let kept = self.material.committed_states().map_err(cosdem_fem::Error::from)?;
        let begun = index == 0;
        if begun {
            self.solver = fresh(&self.model, &self.settings, expanded.first())?;
        }
        let mut tap;
        let material: &mut dyn Material = match self.writer.as_ref() {
            Some(w) if self.snapshots => {
                tap = w.tap(self.material.as_mut());
                &mut tap
            }
            _ => self.material.as_mut(),
        };
        let mut recorder =
            Recorder { hook: StepHook { writer: self.writer.as_mut(), observer }, reports: vec![] };
        let outcome = run(&mut self.solver, &expanded, begun, material, &mut recorder);
        let reports = recorder.reports;
        match outcome {
            Ok(()) => {
                self.history.push(next);
                Ok(StageReport { index, steps: reports })
            }
            Err(source) => {
                let spent = reports.iter().map(|r| r.dem_steps).sum::<u64>()
                    + self.solver.uncommitted_dem_steps();
                let step = before.step;
                if let Err(e) = self.undo(before, kept, !reports.is_empty(), spent) {
                    let reason = format!(
                        "stage {index} ({name:?}) failed ({source}) and could not be undone: {e}"
                    );
                    self.broken = Some(reason.clone());
                    return Err(RunError::Broken { reason });
                }
                Err(RunError::StageFailed { index, name, step, source: Box::new(source) })
            }
        }
    }

    /// Goes back to the state `before` a failed stage: the assemblies' `kept` states (when
    /// the stage `committed` a step), the solver, and the run directory, whose summary keeps
    /// the `spent` DEM steps.
    fn undo(
        &mut self,
        before: SolverState,
        kept: Option<Vec<AssemblyState>>,
        committed: bool,
        spent: u64,
    ) -> Result<(), RunError> {
        let step = before.step;
        if committed && let Some(states) = kept {
            self.material.restore_states(states).map_err(cosdem_fem::Error::from)?;
        }
        self.solver = self.solver_at(&self.history, before)?;
        let Some(mut w) = self.writer.take() else { return Ok(()) };
        if committed {
            let dir = w.dir().to_path_buf();
            let (workers, specimens) = (w.summary().workers, w.summary().specimens.clone());
            drop(w);
            w = RunWriter::resume(&dir, run_settings(&self.job), step)?;
            if !self.job.region.is_empty() {
                w.set_regions(&self.job, &self.job.element_materials(&self.model.mesh)?);
            }
            w.set_workers(workers);
            if let Some(s) = specimens {
                w.set_specimens(s);
            }
        }
        w.add_uncommitted_dem_steps(spent);
        self.writer = Some(w);
        if committed {
            self.watch();
        }
        Ok(())
    }
}
