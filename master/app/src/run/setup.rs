//! What a run of a job does before its first step, whoever then drives the steps: the run
//! driver ([`super::Run`], the job's own loading) and the stepper
//! ([`crate::stepper::Stepper`], a caller's stages).
//!
//! In order: the accuracy target is planned ([`super::tuned`]); admission refuses a job too
//! large for this machine before anything is built; the run directory is claimed (locked; a
//! new run refused in a directory that holds one); a resume reads and checks its checkpoint;
//! the solver and the material are built (the job's pool, or the caller's material, the
//! checkpoint's states restored into it). Everything that can fail before the first step
//! comes before the writer opens the run directory, so that a failed setup leaves a previous
//! run's files as they were. Then the claim is committed (the caller's observer told, the
//! provenance and the accuracy report written) and the run writer created or continued.

use super::observer::RunObserver;
use super::{BuildMaterial, RunError, WorkerChoice, gauss_point_ids, material_for, run_settings};
use crate::checkpoint::Checkpoint;
use crate::output::claim::{Claim, Mode, RunLock};
use crate::output::provenance::{self, Origin};
use crate::output::run_dir::RunWriter;
use crate::output::snapshots::resolve_snapshot_ids;
use cosdem_common::GaussPointId;
use cosdem_fem::material::Material;
use cosdem_fem::solve::Solver;
use cosdem_job::{Job, SolverStage, admission};
use std::path::{Path, PathBuf};

/// Whose loading the solver is built with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Loads {
    /// The job's own (`[loading]` or its `[[stage]]`s): a run.
    Job,
    /// None: the job without its loads ([`without_loads`]), whose stages a caller gives one
    /// at a time (the stepper). The material is still the job's (its in-situ consolidation
    /// follows the job's own first stage).
    Caller,
}

/// A checkpoint to go on from.
pub(crate) struct ResumeFrom {
    /// The checkpoint file.
    pub file: PathBuf,
    /// The job's `[newton]` settings may differ from the checkpoint's.
    pub newton_changed: bool,
}

/// What the setup needs.
pub(crate) struct Setup<'a> {
    /// The job as the caller gave it (its provenance copy).
    pub job: &'a Job,
    /// The run directory, if the run writes one.
    pub dir: Option<&'a Path>,
    /// How the directory is claimed.
    pub mode: Mode,
    /// The checkpoint of a resume.
    pub resume: Option<ResumeFrom>,
    /// Where the DEM assemblies are solved.
    pub workers: &'a WorkerChoice,
    /// The caller's material instead of the job's.
    pub material: Option<BuildMaterial<'a>>,
    /// Admission's memory limit (`None`: the default).
    pub max_memory: Option<u64>,
    /// Where the job comes from (provenance).
    pub origin: Option<Origin>,
    /// Whether the job's particle snapshots are written.
    pub snapshots: bool,
    /// Whose loading the solver is built with.
    pub loads: Loads,
}

/// A run ready for its first step.
pub(crate) struct Prepared {
    /// The job as run: the tuned job, without its loads for [`Loads::Caller`].
    pub job: Job,
    /// The solver at its start (a resume restores the checkpoint's state into it).
    pub solver: Solver,
    /// The job's stages ([`Job::stages`]; for [`Loads::Caller`], the one stage of no loads).
    pub stages: Vec<SolverStage>,
    /// What answers at the Gauss points (a resume's states already restored).
    pub material: Box<dyn Material>,
    /// The checkpoint of a resume.
    pub checkpoint: Option<Checkpoint>,
    /// The run directory's writer (its regions, workers and specimens set).
    pub writer: Option<RunWriter>,
    /// The run directory's lock, held as long as the run writes it.
    pub lock: Option<RunLock>,
    /// The Gauss points whose particle snapshots are written.
    pub watched: Vec<GaussPointId>,
}

/// `job` without its loads: no `[loading]` compression, prescribed dofs, pressures or
/// increment, no `[[stage]]` (its `load_set` and `steps` kept), and no `accuracy` (a tuned
/// job already has the settings it picked). Without `[output.curve]`, the curve is that of
/// the load set as the caller moves it: the settlement `-u_y` (mean over its nodes) against
/// `-R_y`, as a compression's curve is (a job without loads has no compression to measure).
pub(crate) fn without_loads(job: &Job) -> Job {
    let mut j = job.clone();
    if j.output.curve.is_none() {
        let settlement = |set: &str| cosdem_job::CurveQuantity {
            set: set.to_string(),
            component: cosdem_job::ComponentChoice::Uy,
            scale: -1.0,
        };
        j.output.curve = Some(cosdem_job::CurveSection {
            control: settlement(&j.loading.load_set),
            load: settlement(&j.loading.load_set),
            reactions: Vec::new(),
        });
    }
    j.loading.compression = None;
    j.loading.prescribed.clear();
    j.loading.pressure.clear();
    j.loading.increment = None;
    j.stage.clear();
    j.accuracy = None;
    j
}

impl Setup<'_> {
    /// Runs the setup, telling `observer` the plan's lines and the run directory.
    pub(crate) fn prepare(self, observer: &mut dyn RunObserver) -> Result<Prepared, RunError> {
        let Setup {
            job: given,
            dir,
            mode,
            resume,
            workers,
            material,
            max_memory,
            origin,
            snapshots,
            loads,
        } = self;
        // `accuracy`: the settings picked for the target replace the job's (a pure function
        // of the job, so a resume picks the same ones).
        let (tuned, report) = super::tuned(given)?;
        // Admission: a job too large for this machine is refused before anything is built.
        let in_process = material.is_some() || workers.addresses.is_empty();
        let limit = max_memory.or_else(admission::default_memory_limit);
        for line in super::admit(&tuned, limit, in_process, workers.config.max_message_bytes)? {
            observer.on_plan_line(&line);
        }
        // The directory is claimed (locked; a new run refused in a directory that holds
        // one) before anything is built, and committed once the setup has succeeded.
        let claim = match dir {
            Some(dir) => Some(Claim::take(dir, mode)?),
            None => None,
        };
        if let Some(report) = &report {
            for line in report.lines() {
                observer.on_plan_line(&line);
                tracing::info!("{line}");
            }
        }
        let stripped = (loads == Loads::Caller).then(|| without_loads(&tuned));
        let job = stripped.as_ref().unwrap_or(&tuned);
        let checkpoint = match resume {
            Some(ResumeFrom { file, newton_changed }) => {
                let c = Checkpoint::read(&file)?;
                c.check_kind(&file, loads == Loads::Caller)?;
                c.check_job(job, &file, newton_changed)?;
                tracing::info!(step = c.solver.step, "resuming from {}", file.display());
                Some(c)
            }
            None => None,
        };
        // Everything that can fail before the first step (the model, the snapshot ids, the
        // workers and their assemblies) comes before the writer opens the run directory: a
        // failed setup leaves a previous run's files as they were.
        let setup = std::time::Instant::now();
        let solver = Solver::new(job.model()?, job.solver_settings()?)?;
        let stages = job.stages()?;
        let ids = gauss_point_ids(&solver);
        let watched = if snapshots {
            resolve_snapshot_ids(&job.output.snapshots, &solver.gauss().counts())?
        } else {
            Vec::new()
        };
        let saved = checkpoint.as_ref().map(Checkpoint::assembly_states);
        let (material, n_workers, specimens) = match material {
            None => {
                let built = material_for(&tuned, workers, &solver.model().mesh, &ids, saved)?;
                (built.material, built.workers, built.specimens)
            }
            Some(build) => {
                let mut m = build(&ids)?;
                if let Some(states) = saved {
                    m.restore_states(states).map_err(cosdem_fem::Error::from)?;
                }
                (m, 0, None)
            }
        };
        // The setup has succeeded: the run directory is the run's from here on.
        let lock = match (claim, dir) {
            (Some(claim), Some(dir)) => {
                let lock = claim.commit()?;
                observer.on_dir(dir).map_err(RunError::Observer)?;
                let origin = origin.unwrap_or_else(Origin::of_process);
                let resumed_at = checkpoint.as_ref().map(|c| c.solver.step);
                provenance::record(dir, given, &origin, resumed_at)?;
                if let Some(report) = &report {
                    super::write_accuracy_report(report, dir)?;
                }
                Some(lock)
            }
            _ => None,
        };
        let mut writer = match (dir, &checkpoint) {
            (Some(dir), Some(c)) => Some(RunWriter::resume(dir, run_settings(job), c.solver.step)?),
            (Some(dir), None) => Some(RunWriter::create(dir, run_settings(job))?),
            (None, _) => None,
        };
        if let Some(w) = writer.as_mut() {
            w.add_setup_time(setup.elapsed());
            if !job.region.is_empty() {
                w.set_regions(job, &job.element_materials(&solver.model().mesh)?);
            }
            w.set_workers(n_workers);
            if let Some(report) = specimens {
                w.set_specimens(report);
            }
        }
        let job = stripped.unwrap_or(tuned);
        Ok(Prepared { job, solver, stages, material, checkpoint, writer, lock, watched })
    }
}
