//! The caller's stages so far, and the solver for them.
//!
//! The stages are expanded one at a time by [`Job::next_stages`], which keeps what they leave
//! in force ([`StagesSoFar`]): the solver stages of a new caller stage are those
//! [`Job::stages`] gives it after the earlier ones, at a constant cost per stage. The solver
//! starts from the first one: it is built from the model of the job without loads with the
//! first solver stage's loading and steps, which is the solver of a job whose `[[stage]]` list
//! starts with that stage (its model's loading is its first stage's). A solver at a saved state
//! (a resume, a failed stage undone) is built as a resumed run builds its own: that solver, the
//! state restored, and the loading of the state's stage installed.

use super::Stepper;
use crate::run::RunError;
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{Model, Solver, SolverSettings, SolverState};
use cosdem_job::{Job, SolverStage, StageSection, StagesSoFar};

/// The caller's stages that finished and what they leave in force.
#[derive(Clone, Debug, Default)]
pub(super) struct History {
    /// The caller's stages, in order.
    pub stages: Vec<StageSection>,
    /// What they leave in force.
    pub so_far: StagesSoFar,
    /// The first solver stage of the first caller stage: the solver's model's loading.
    pub first: Option<SolverStage>,
    /// The last solver stage: the one the solver is in.
    pub last: Option<SolverStage>,
}

/// What a caller stage adds to a [`History`] once it has run.
pub(super) struct Next {
    stage: StageSection,
    so_far: StagesSoFar,
    first: Option<SolverStage>,
    last: Option<SolverStage>,
}

impl History {
    /// The solver stages of `stage` after these stages, and what it adds to them
    /// ([`History::push`]); the history itself is unchanged. Errors name the stage's keys
    /// (`stage[i]...`, `i` its index among the caller's).
    pub fn next(
        &self,
        job: &Job,
        stage: StageSection,
        mesh: &Mesh,
    ) -> Result<(Next, Vec<SolverStage>), RunError> {
        let mut so_far = self.so_far.clone();
        let expanded = job.next_stages(&stage, &mut so_far, mesh)?;
        let first = self.first.clone().or_else(|| expanded.first().cloned());
        let last = expanded.last().cloned().or_else(|| self.last.clone());
        Ok((Next { stage, so_far, first, last }, expanded))
    }

    /// Adds a stage that has run.
    pub fn push(&mut self, next: Next) {
        self.stages.push(next.stage);
        (self.so_far, self.first, self.last) = (next.so_far, next.first, next.last);
    }

    /// The history of the caller's `stages` (a checkpoint's).
    pub fn replay(job: &Job, stages: &[StageSection], mesh: &Mesh) -> Result<Self, RunError> {
        let mut h = Self::default();
        for s in stages {
            let (next, _) = h.next(job, s.clone(), mesh)?;
            h.push(next);
        }
        Ok(h)
    }
}

/// A solver at the start of `first` (`None`: of the job without loads) with `model`'s mesh,
/// field, rule and kinematics and `settings`' Newton settings.
pub(super) fn fresh(
    model: &Model,
    settings: &SolverSettings,
    first: Option<&SolverStage>,
) -> Result<Solver, RunError> {
    let solver = match first {
        None => Solver::new(model.clone(), settings.clone())?,
        Some(s) => Solver::new(
            Model { loading: s.loading.clone(), ..model.clone() },
            SolverSettings { steps: s.steps, ..settings.clone() },
        )?,
    };
    Ok(solver)
}

impl Stepper {
    /// A solver for the stages of `history` at `state` (a committed step at the end of one
    /// of them, or the start), built as a resumed run builds its own.
    pub(super) fn solver_at(
        &self,
        history: &History,
        state: SolverState,
    ) -> Result<Solver, RunError> {
        let mut solver = fresh(&self.model, &self.settings, history.first.as_ref())?;
        solver.restore(state)?;
        if let Some(at) = &history.last {
            solver.resume_stage(at.loading.clone(), at.steps)?;
        }
        Ok(solver)
    }
}
