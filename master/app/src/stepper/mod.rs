//! A job's solver driven one stage at a time by its caller: the library side of a Python
//! loop that sets displacements, pressures and body forces on named sets, solves, reads the
//! reactions, and goes on.
//!
//! [`Stepper::new`] sets a job up as a run does (the setup of [`crate::run`]: the accuracy
//! plan, admission, the material and its workers, in-process by default, and optionally a run
//! directory, claimed fresh or overwritten and written as the stepper goes by the run writer
//! of `cosdem run`: `curve.csv`, VTK, `summary.json`) but applies none of the job's own
//! loading (`[loading]`'s loads, its `[[stage]]`s): the caller's stages are the loading.
//!
//! [`Stepper::step`] runs one caller stage, a [`StageSection`] as a `[[stage]]` table of a job
//! file ([`stage_from_toml`] reads one, `steps` 1 by default), from the current state. Its
//! loading is what [`Job::stages`] gives for a job whose stages are the caller's stages so far
//! followed by it ([`Job::next_stages`], the same code): what an earlier stage set stays in
//! force until a later one changes it, exactly as in a job file. A job whose `[[stage]]` list
//! is S and a stepper given S one stage at a time take the same steps, bit for bit.
//!
//! A stage is all or nothing. When one of its steps cannot be solved (cut down to the
//! smallest increment, a worker lost), the stepper goes back to where the stage started: the
//! solver's state, the assemblies' committed states and the run directory (its rows, VTK
//! files and snapshots of the stage's steps removed), and returns the reason
//! ([`RunError::StageFailed`]); the caller may go on, with an easier stage for instance. For
//! that the assemblies' committed states are exported before each stage, as for a checkpoint,
//! and held in memory until the stage ends.
//!
//! [`Stepper::checkpoint`] writes the solver's state, the assemblies' and the caller's stages
//! so far (a checkpoint of [`crate::checkpoint`]'s format); [`Stepper::resume`] goes on from
//! it, the next stage bit-identical to that of a stepper that never stopped.
//!
//! The files: `step` (a stage run and undone), `solver` (the stages so far and the solver for
//! them), `fields` (what the caller reads: reactions, displacements, Gauss-point fields),
//! `checkpoint`.
//!
//! [`Stepper::new`]: crate::stepper::Stepper::new
//! [`Stepper::step`]: crate::stepper::Stepper::step
//! [`Stepper::checkpoint`]: crate::stepper::Stepper::checkpoint
//! [`Stepper::resume`]: crate::stepper::Stepper::resume
//! [`StageSection`]: cosdem_job::StageSection
//! [`stage_from_toml`]: crate::stepper::stage_from_toml
//! [`Job::stages`]: cosdem_job::Job::stages
//! [`Job::next_stages`]: cosdem_job::Job::next_stages
//! [`RunError::StageFailed`]: crate::run::RunError::StageFailed

mod checkpoint;
mod fields;
mod solver;
mod step;

pub use step::{StageReport, stage_from_toml};

use crate::checkpoint::Digests;
use crate::output::claim::{Mode, RunLock};
use crate::output::provenance::Origin;
use crate::output::run_dir::{RunWriter, Summary};
use crate::run::observer::Silent;
use crate::run::setup::{Loads, Prepared, ResumeFrom, Setup};
use crate::run::{BuildMaterial, RunError, WorkerChoice};
use cosdem_common::GaussPointId;
use cosdem_fem::material::Material;
use cosdem_fem::solve::{Model, Solver, SolverSettings};
use cosdem_job::{Job, StageSection};
use solver::History;
use std::path::{Path, PathBuf};

/// How a [`Stepper`] is set up. The default: the job's in-process workers, no run directory.
#[derive(Default)]
pub struct StepperOptions {
    /// Where the DEM assemblies are solved (default: the job's `[workers] in_process`
    /// in-process workers).
    pub workers: WorkerChoice,
    /// The run directory the stepper writes as it goes (created; a new stepper refuses one that
    /// holds a previous run unless `overwrite`; [`Stepper::resume`] continues it, cut back to
    /// the checkpoint's step). `None`: nothing is written.
    pub dir: Option<PathBuf>,
    /// A new stepper into a directory that holds a previous run: once the setup has succeeded
    /// the old directory is renamed `RUN.old-N` and the stepper starts in a fresh one.
    pub overwrite: bool,
    /// Refuses, before anything is allocated, a job whose estimated memory in this process
    /// exceeds this many bytes; default: 80 % of the machine's memory. `u64::MAX`: no limit.
    pub max_memory: Option<u64>,
    /// Where the job comes from, for the run directory's provenance (default: the process's
    /// command line, the job written out as TOML).
    pub origin: Option<Origin>,
    /// Writes the particle snapshots of the job's `[output] snapshots` and the field data of
    /// its `field_plots_at` (the field data of every stage's last step is always written).
    pub snapshots: bool,
    /// [`Stepper::resume`]: the job's `[newton]` settings may differ from the checkpoint's.
    pub newton_changed: bool,
    /// The material the stepper uses instead of the job's, built for the mesh's Gauss points
    /// (element-major); a resume restores the checkpoint's states into it.
    pub material: Option<BuildMaterial<'static>>,
}

/// A job's solver, driven one caller stage at a time (see the [module](self) doc).
pub struct Stepper {
    /// The job as run: the tuned job without its loads.
    job: Job,
    /// The model of the job without loads, whose loading a first stage replaces.
    model: Model,
    /// The job's solver settings, whose steps a first stage replaces.
    settings: SolverSettings,
    /// The caller's stages that finished and what they leave in force.
    history: History,
    /// The solver at the last committed step.
    solver: Solver,
    /// What answers at the Gauss points.
    material: Box<dyn Material>,
    /// The run directory's writer.
    writer: Option<RunWriter>,
    /// Particle snapshots and field plots are written.
    snapshots: bool,
    /// The Gauss points whose snapshots are written.
    watched: Vec<GaussPointId>,
    /// The job's digests, for checkpoints.
    digests: Digests,
    /// Why the stepper can go on no more (a failed stage that could not be undone).
    broken: Option<String>,
    /// The summary has its final status.
    finished: bool,
    /// The run directory's lock (after the writer: released once its files are closed).
    _lock: Option<RunLock>,
}

impl Stepper {
    /// Sets `job` up for a caller's stages: its mesh, material, solver and Newton settings, its
    /// workers, and the run directory of `options.dir`; none of its own loading is applied.
    /// Errors are those of a run's setup (the job, admission, the workers, the directory).
    pub fn new(job: &Job, options: StepperOptions) -> Result<Self, RunError> {
        Self::start(job, options, None)
    }

    /// A stepper of `job` going on from the checkpoint `path` written by
    /// [`Stepper::checkpoint`]: the caller's stages so far, the solver's state and the
    /// assemblies' are the checkpoint's, and `options.dir` (if any) is continued, cut back to
    /// the checkpoint's step. Refused, naming the file: another job's checkpoint (mesh,
    /// loading or material changed; `[newton]` unless `options.newton_changed`), a run's.
    pub fn resume(path: &Path, job: &Job, options: StepperOptions) -> Result<Self, RunError> {
        Self::start(job, options, Some(path))
    }

    fn start(job: &Job, options: StepperOptions, from: Option<&Path>) -> Result<Self, RunError> {
        let StepperOptions {
            workers,
            dir,
            overwrite,
            max_memory,
            origin,
            snapshots,
            newton_changed,
            material,
        } = options;
        let mode = match (from.is_some(), overwrite) {
            (true, _) => Mode::Resume,
            (false, true) => Mode::Overwrite,
            (false, false) => Mode::Fresh,
        };
        let resume = from.map(|file| ResumeFrom { file: file.to_path_buf(), newton_changed });
        let Prepared { job, solver, material, checkpoint, writer, lock, watched, .. } = Setup {
            job,
            dir: dir.as_deref(),
            mode,
            resume,
            workers: &workers,
            material,
            max_memory,
            origin,
            snapshots,
            loads: Loads::Caller,
        }
        .prepare(&mut Silent)?;
        let mut stepper = Self {
            model: solver.model().clone(),
            settings: job.solver_settings()?,
            digests: Digests::of(&job),
            job,
            history: History::default(),
            solver,
            material,
            writer,
            snapshots,
            watched,
            broken: None,
            finished: false,
            _lock: lock,
        };
        if let Some(c) = checkpoint {
            let stages = c.stages.unwrap_or_default();
            stepper.history = History::replay(&stepper.job, &stages, &stepper.model.mesh)?;
            stepper.solver = stepper.solver_at(&stepper.history, c.solver)?;
        }
        stepper.watch();
        Ok(stepper)
    }

    /// Sets up the run writer's snapshots and field plots (with [`StepperOptions::snapshots`]).
    fn watch(&mut self) {
        if let Some(w) = self.writer.as_mut().filter(|_| self.snapshots) {
            let ids = self.watched.clone();
            w.watch(self.material.as_mut(), ids, &self.job.output.field_plots_at);
        }
    }

    /// The job as the stepper runs it: the job given (with the settings its `accuracy`
    /// target picked) without its loads.
    pub fn job(&self) -> &Job {
        &self.job
    }

    /// The caller's stages so far (those that finished), in order.
    pub fn stages(&self) -> &[StageSection] {
        &self.history.stages
    }

    /// Committed steps so far (all stages).
    pub fn steps(&self) -> u64 {
        self.solver.step()
    }

    /// The load factor reached in the solver's stage (1 once a stage has finished; 0 before
    /// the first).
    pub fn load_factor(&self) -> f64 {
        self.solver.load_factor()
    }

    /// The solver's stage (0-based; a caller stage with `repeat` or a `path` runs several).
    pub fn solver_stage(&self) -> u32 {
        self.solver.stage()
    }

    /// The run directory, if the stepper writes one.
    pub fn dir(&self) -> Option<&Path> {
        self.writer.as_ref().map(RunWriter::dir)
    }

    /// The run directory's summary so far (`None` without a directory).
    pub fn summary(&self) -> Option<&Summary> {
        self.writer.as_ref().map(RunWriter::summary)
    }

    /// The run directory's curve so far: `(displacement, load)` per committed step (`None`
    /// without a directory).
    pub fn curve(&self) -> Option<&[(f64, f64)]> {
        self.writer.as_ref().map(RunWriter::curve)
    }

    /// Ends the stepper: the run directory's summary gets its final status (`finished`, or
    /// `failed: ...` for a stepper that could not go on) and is returned. Dropping a stepper
    /// does the same, but cannot report an error.
    pub fn finish(mut self) -> Result<Option<Summary>, RunError> {
        self.write_status()?;
        Ok(self.summary().cloned())
    }

    fn write_status(&mut self) -> Result<(), RunError> {
        if self.finished {
            return Ok(());
        }
        self.finished = true;
        if let Some(w) = self.writer.as_mut() {
            match &self.broken {
                None => w.finish(Ok(()))?,
                Some(why) => w.finish(Err(why.clone()))?,
            }
        }
        Ok(())
    }
}

impl Drop for Stepper {
    fn drop(&mut self) {
        if let Err(e) = self.write_status() {
            tracing::warn!(error = %e, "the stepper's summary could not be finished");
        }
    }
}
