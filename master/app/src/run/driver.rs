//! [`Run`]: the one way a job is run, whoever runs it (`cosdem run`, the speed/accuracy sweep,
//! the RVE-size study, the tests).
//!
//! The order of a run: the setup (`run/setup.rs`, shared with the stepper: the accuracy
//! plan, admission, the run directory claimed and told to the caller ([`RunObserver::on_dir`]),
//! a resume's checkpoint read and checked, the solver and the material built with the
//! checkpoint's states, the run writer created or continued); the checkpoint's solver state
//! restored in its stage; then the solver runs with one per-step hook ([`super::observer`])
//! and the summary gets its status.

use super::observer::{RunObserver, Silent, StepHook};
use super::setup::{Loads, Prepared, ResumeFrom, Setup};
use super::{RunError, WorkerChoice};
use crate::checkpoint::{self, Checkpointer};
use crate::output::claim::Mode;
use crate::output::provenance::Origin;
use crate::output::run_dir::Summary;
use cosdem_common::GaussPointId;
use cosdem_fem::material::Material;
use cosdem_fem::solve::{Solver, StepObserver};
use cosdem_job::{Job, SolverStage};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// Builds the material of a run from the Gauss points of its mesh (element-major).
pub type BuildMaterial<'a> =
    Box<dyn FnOnce(&[GaussPointId]) -> Result<Box<dyn Material>, RunError> + 'a>;

/// What may stop a run cleanly after a step (checkpoint written, status `interrupted`).
enum Stop {
    Never,
    Flag(Arc<AtomicBool>),
    Signals,
}

/// How a run ended.
#[derive(Debug)]
pub enum Ending {
    /// Every load step converged.
    Finished,
    /// A step could not be solved (cut as far as allowed, a worker lost, ...); the finished
    /// steps are written.
    Failed(cosdem_fem::Error),
    /// Stopped on request ([`Run::stop_flag`], Ctrl-C, SIGTERM) with its checkpoint written.
    Interrupted,
    /// Stopped at [`Run::max_steps`] with its checkpoint written.
    Stopped,
}

impl Ending {
    /// The summary's `status`: `finished`, `failed: <reason>`, `interrupted` or `stopped`.
    pub fn status(&self) -> String {
        match self {
            Self::Finished => "finished".into(),
            Self::Failed(e) => format!("failed: {e}"),
            Self::Interrupted => "interrupted".into(),
            Self::Stopped => "stopped".into(),
        }
    }
}

/// What [`Run::execute`] returns.
#[derive(Debug)]
pub struct RunOutcome {
    /// How the run ended.
    pub ending: Ending,
    /// The final summary (also `summary.json`); `None` for a run without a directory.
    pub summary: Option<Summary>,
    /// `(displacement, load)` per committed step, resumed steps included; empty for a run
    /// without a directory.
    pub curve: Vec<(f64, f64)>,
    /// The last committed step.
    pub steps: u64,
    /// DEM steps of the failed attempts of the step that ended the run (already in the
    /// summary's `dem_steps`).
    pub uncommitted_dem_steps: u64,
}

/// One job run to its end: a builder. `Run::new(&job, dir).execute()` is a plain run into
/// `dir` with the job's material (in-process workers for a DEM job), no checkpoints, no
/// particle snapshots; each option adds what `cosdem run` does.
pub struct Run<'a> {
    job: &'a Job,
    dir: Option<&'a Path>,
    workers: WorkerChoice,
    material: Option<BuildMaterial<'a>>,
    resume: Option<bool>,
    overwrite: bool,
    max_memory: Option<u64>,
    origin: Option<Origin>,
    checkpoints: bool,
    snapshots: bool,
    max_steps: Option<u64>,
    stop: Stop,
    observer: Option<&'a mut dyn RunObserver>,
}

impl<'a> Run<'a> {
    /// A run of `job` into the run directory `dir` (created if needed).
    pub fn new(job: &'a Job, dir: &'a Path) -> Self {
        Self { dir: Some(dir), ..Self::without_dir(job) }
    }

    /// A run of `job` that writes nothing: the caller's observer ([`Run::observer`]) sees the
    /// steps (the RVE-size study). No resume, checkpoints or stop.
    pub fn without_dir(job: &'a Job) -> Self {
        Self {
            job,
            dir: None,
            workers: WorkerChoice::default(),
            material: None,
            resume: None,
            overwrite: false,
            max_memory: None,
            origin: None,
            checkpoints: false,
            snapshots: false,
            max_steps: None,
            stop: Stop::Never,
            observer: None,
        }
    }

    /// Where the job's DEM assemblies are solved (default: the job's in-process workers).
    pub fn workers(mut self, workers: WorkerChoice) -> Self {
        self.workers = workers;
        self
    }

    /// Runs with the material `build` makes for the mesh's Gauss points instead of the job's
    /// (e.g. [`cosdem_pool::DirectDem`], every assembly on the run's thread). The summary
    /// counts 0 workers. On a resume the checkpoint's states are restored into it.
    pub fn material(
        mut self,
        build: impl FnOnce(&[GaussPointId]) -> Result<Box<dyn Material>, RunError> + 'a,
    ) -> Self {
        self.material = Some(Box::new(build));
        self
    }

    /// Goes on from the run directory's checkpoint instead of starting again (checkpoints
    /// on). `newton_changed`: the job's `[newton]` settings may differ from the checkpoint's
    /// (see [`crate::checkpoint::Checkpoint::check_job`]).
    pub fn resume(mut self, newton_changed: bool) -> Self {
        self.resume = Some(newton_changed);
        self.checkpoints = true;
        self
    }

    /// A new run into a directory that holds a previous run: once the setup has succeeded the
    /// old directory is renamed `RUN.old-N` and the run starts in a fresh one (without it, such
    /// a directory is refused: [`crate::output::claim::ClaimError::NotEmpty`]).
    pub fn overwrite(mut self, on: bool) -> Self {
        self.overwrite = on;
        self
    }

    /// Refuses, before anything is allocated, a job whose estimated memory in this process
    /// exceeds `bytes` ([`cosdem_job::admission`]); default: 80 % of the machine's memory
    /// ([`cosdem_job::admission::default_memory_limit`]). `u64::MAX`: no limit.
    pub fn max_memory(mut self, bytes: Option<u64>) -> Self {
        self.max_memory = bytes;
        self
    }

    /// Where the job comes from, for the run directory's provenance (`provenance.json`, the
    /// copy of the job): the command line and the job file's text. Default: the process's
    /// command line, the job written out as TOML.
    pub fn origin(mut self, origin: Origin) -> Self {
        self.origin = Some(origin);
        self
    }

    /// Writes `checkpoint.bin` every `[output] checkpoint_every` steps and when stopped.
    pub fn checkpoints(mut self, on: bool) -> Self {
        self.checkpoints = on;
        self
    }

    /// Writes the particle snapshots of the job's `[output] snapshots` and the field data of
    /// its `field_plots_at` (the field data of the last step is always written).
    pub fn snapshots(mut self, on: bool) -> Self {
        self.snapshots = on;
        self
    }

    /// Stops cleanly once `max_steps` steps are committed (resumed steps included): status
    /// `stopped`, checkpoint written (checkpoints on), [`Run::resume`] goes on.
    pub fn max_steps(mut self, max_steps: Option<u64>) -> Self {
        self.max_steps = max_steps;
        if max_steps.is_some() {
            self.checkpoints = true;
        }
        self
    }

    /// Stops cleanly after the step during which `flag` is set: status `interrupted`,
    /// checkpoint written (checkpoints on).
    pub fn stop_flag(mut self, flag: Arc<AtomicBool>) -> Self {
        self.stop = Stop::Flag(flag);
        self.checkpoints = true;
        self
    }

    /// Stops cleanly on the first Ctrl-C or SIGTERM, as [`Run::stop_flag`]
    /// ([`checkpoint::ctrl_c_flag`], installed just before the first step).
    pub fn stop_on_signals(mut self) -> Self {
        self.stop = Stop::Signals;
        self.checkpoints = true;
        self
    }

    /// Tells `observer` about the run as it goes.
    pub fn observer(mut self, observer: &'a mut dyn RunObserver) -> Self {
        self.observer = Some(observer);
        self
    }

    /// Runs the job. A run that ends early (a step that cannot be cut further, a lost worker,
    /// a stop) still returns its outcome, the finished steps written: only errors before the
    /// first step (the job, the checkpoint, the material, the run directory) and failures to
    /// write the summary are `Err`.
    pub fn execute(self) -> Result<RunOutcome, RunError> {
        let Run {
            dir,
            workers,
            material,
            resume,
            overwrite,
            max_memory,
            origin,
            checkpoints,
            snapshots,
            max_steps,
            stop,
            ..
        } = self;
        let mut silent = Silent;
        let observer: &mut dyn RunObserver = match self.observer {
            Some(o) => o,
            None => &mut silent,
        };
        if dir.is_none() && checkpoints {
            return Err(RunError::NoRunDirectory);
        }
        let mode = match (resume.is_some(), overwrite) {
            (true, _) => Mode::Resume,
            (false, true) => Mode::Overwrite,
            (false, false) => Mode::Fresh,
        };
        let resume = match (resume, dir) {
            (Some(newton_changed), Some(dir)) => {
                Some(ResumeFrom { file: dir.join(checkpoint::FILE), newton_changed })
            }
            _ => None,
        };
        let Prepared {
            job,
            mut solver,
            stages,
            mut material,
            checkpoint,
            mut writer,
            lock,
            watched,
        } = Setup {
            job: self.job,
            dir,
            mode,
            resume,
            workers: &workers,
            material,
            max_memory,
            origin,
            snapshots,
            loads: Loads::Job,
        }
        .prepare(observer)?;
        let _lock = lock;
        let job = &job;
        if let Some(c) = checkpoint {
            solver.restore(c.solver)?;
            let at = &stages[(solver.stage() as usize).min(stages.len() - 1)];
            solver.resume_stage(at.loading.clone(), at.steps)?;
        }
        let (stop, stopped_by) = match stop {
            Stop::Never => (Arc::new(AtomicBool::new(false)), ""),
            Stop::Flag(flag) => (flag, "stop requested"),
            Stop::Signals => (
                checkpoint::ctrl_c_flag().map_err(RunError::Signals)?,
                "stopped by Ctrl-C or SIGTERM",
            ),
        };
        let mut tap;
        let material: &mut dyn Material = match writer.as_mut() {
            Some(w) if snapshots => {
                tap = w.watch(material.as_mut(), watched, &job.output.field_plots_at);
                &mut tap
            }
            _ => material.as_mut(),
        };
        observer.on_start().map_err(RunError::Observer)?;
        let (outcome, reached_max) = {
            let hook = StepHook { writer: writer.as_mut(), observer: &mut *observer };
            match dir {
                Some(dir) if checkpoints => {
                    let every = job.output.checkpoint_every;
                    let mut hook =
                        Checkpointer::new(hook, dir, every, job, stop).stop_at(max_steps);
                    let outcome = run_stages(&mut solver, &stages, material, &mut hook);
                    (outcome, hook.reached(solver.step()))
                }
                _ => {
                    let mut hook = hook;
                    (run_stages(&mut solver, &stages, material, &mut hook), false)
                }
            }
        };
        observer.on_end();
        let uncommitted_dem_steps = solver.uncommitted_dem_steps();
        let ending = match outcome {
            Ok(_) => Ending::Finished,
            Err(cosdem_fem::Error::Interrupted { .. }) if checkpoints && reached_max => {
                Ending::Stopped
            }
            Err(cosdem_fem::Error::Interrupted { .. }) if checkpoints => Ending::Interrupted,
            Err(e) => Ending::Failed(e),
        };
        if let Some(w) = writer.as_mut() {
            w.add_uncommitted_dem_steps(uncommitted_dem_steps);
            match &ending {
                Ending::Finished => w.finish(Ok(()))?,
                Ending::Failed(e) => w.finish(Err(e.to_string()))?,
                Ending::Interrupted => w.finish_interrupted(&format!(
                    "{stopped_by} after step {}; the checkpoint is written, go on with --resume",
                    solver.step()
                ))?,
                Ending::Stopped => w.finish_stopped()?,
            }
        }
        Ok(RunOutcome {
            ending,
            summary: writer.as_ref().map(|w| w.summary().clone()),
            curve: writer.as_ref().map_or_else(Vec::new, |w| w.curve().to_vec()),
            steps: solver.step(),
            uncommitted_dem_steps,
        })
    }
}

/// Runs the solver's current stage to its end, then every stage after it
/// ([`Solver::begin_stage`]), each in a `stage` span.
fn run_stages(
    solver: &mut Solver,
    stages: &[SolverStage],
    material: &mut dyn Material,
    hook: &mut dyn StepObserver,
) -> cosdem_fem::Result<()> {
    loop {
        let k = solver.stage() as usize;
        let name = stages.get(k).map_or("", |s| s.name.as_str());
        let span = tracing::info_span!("stage", stage = k, name);
        let _enter = span.enter();
        solver.run(material, hook)?;
        let Some(next) = stages.get(k + 1) else {
            return Ok(());
        };
        solver.begin_stage(next.loading.clone(), next.steps)?;
    }
}
