//! One job, run to its end into a run directory: the library side of `cosdem run`.
//!
//! [`Run`] is the one run driver: `cosdem run`, the speed/accuracy sweep, the RVE-size study
//! and the tests all run a job through it. [`material_for`] turns the job's `[material]` into
//! what answers at the Gauss points (an analytical material, or a pool of DEM workers holding
//! one assembly per Gauss point); [`observer`] is the per-step hook the run directory, the
//! checkpoints and the caller's [`RunObserver`] hang on. The CLI adds the progress bar, logging
//! and the printed summary; [`run_job`] is the plain run the sweep makes.

/// The [`Run`] builder: options, order of a run, outcome.
pub mod driver;
/// The in-situ mean stress of every Gauss point, for consolidating the DEM assemblies.
pub mod in_situ;
/// The job's materials per region and the DEM specimens per point ([`material_for`]).
pub mod material;
/// What a caller sees of a run ([`RunObserver`]) and the per-step hook.
pub mod observer;
/// What a run does before its first step, shared by the driver and the stepper.
pub(crate) mod setup;

pub use driver::{BuildMaterial, Ending, Run, RunOutcome};
pub use material::{Built, SpecimenReport, material_for};
pub use observer::{HookError, PROGRESS_TEMPLATE, RunObserver, step_message};

use crate::output::run_dir::{RunSettings, Summary};
use cosdem_common::GaussPointId;
use cosdem_fem::solve::Solver;
use cosdem_job::{Job, MaterialSection};
use cosdem_pool::PoolConfig;
use std::path::Path;

/// Errors of a whole run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The job, the solver or the output failed.
    #[error(transparent)]
    Solver(#[from] cosdem_fem::Error),
    /// The worker pool could not be built or used.
    #[error("worker pool: {0}")]
    Pool(#[from] cosdem_pool::PoolError),
    /// The run directory could not be written.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// The assembly specification could not be encoded.
    #[error("assembly spec: {0}")]
    Spec(#[from] serde_json::Error),
    /// The accuracy target could not be turned into settings.
    #[error(transparent)]
    Accuracy(#[from] cosdem_tune::accuracy::AccuracyError),
    /// The run directory could not be claimed: another run writes it, it holds a previous
    /// run (and neither `--overwrite` nor `--resume` was given), or it is missing on a resume.
    #[error(transparent)]
    Claim(#[from] crate::output::claim::ClaimError),
    /// The job is too large for the memory limit (`--max-memory`).
    #[error("{0}; the limit is `cosdem run --max-memory` (default: 80 % of this machine's memory)")]
    Admission(#[from] cosdem_job::admission::AdmissionError),
    /// One assembly's state would not fit in a message between master and worker.
    #[error(
        "one assembly of material.assembly.packing holds about {discs} discs, whose state takes up to {bytes} bytes: more than the message limit of {limit} bytes (PoolConfig::max_message_bytes, the worker's --max-message-mib); use smaller assemblies (packing.side) or raise both limits"
    )]
    StateTooLarge {
        /// Discs per assembly (the spec's hint).
        discs: u64,
        /// Bound of one state's encoded size.
        bytes: u64,
        /// The message limit.
        limit: usize,
    },
    /// The materials of the regions could not be put together.
    #[error("materials of the regions: {0}")]
    Regions(#[from] cosdem_fem::material::RegionsError),
    /// The Ctrl-C / SIGTERM handler could not be installed.
    #[error("installing the Ctrl-C handler")]
    Signals(#[source] std::io::Error),
    /// A resume, checkpoints or a stop were asked of a run without a directory.
    #[error("a resume, checkpoints or a stop need a run directory")]
    NoRunDirectory,
    /// The caller's [`RunObserver`] failed.
    #[error(transparent)]
    Observer(HookError),
    /// A stage given to a [`crate::stepper::Stepper`] could not be solved; the stepper went
    /// back to where the stage started and can go on.
    #[error(
        "stage {index} ({name:?}) failed: {source}; the stepper is back at step {step}, where the stage started"
    )]
    StageFailed {
        /// The stage's index among the caller's stages (0-based).
        index: usize,
        /// Its name.
        name: String,
        /// The committed step the stepper is back at.
        step: u64,
        /// Why the stage failed (boxed: a [`RunError`] stays small).
        #[source]
        source: Box<cosdem_fem::Error>,
    },
    /// A name a stepper's query gave that the mesh or the field does not have.
    #[error("no {what} {value:?} (known: {known})")]
    Unknown {
        /// What was asked for (`node set`, `component`).
        what: &'static str,
        /// The name given.
        value: String,
        /// The names there are.
        known: String,
    },
    /// A stage given to a stepper as text could not be read.
    #[error("stage {text:?}: {reason}")]
    StageText {
        /// The text given.
        text: String,
        /// What is wrong with it (the key named).
        reason: String,
    },
    /// A stepper whose failed stage could not be undone (its workers gone, its run directory
    /// unwritable) can go on no more.
    #[error("the stepper cannot go on: {reason}")]
    Broken {
        /// What failed, and why it could not be undone.
        reason: String,
    },
}

/// The job to run: `job` itself (unchanged, bit for bit) when it has no `accuracy` key, else
/// the settings [`cosdem_tune::accuracy::tune`] picks for the target, with its report.
pub fn tuned(job: &Job) -> Result<(Job, Option<cosdem_tune::accuracy::Report>), RunError> {
    Ok(match cosdem_tune::accuracy::tune(job)? {
        None => (job.clone(), None),
        Some(plan) => (plan.job, Some(plan.report)),
    })
}

/// Admission control ([`cosdem_job::admission`]): estimates the job's memory and disk before
/// anything is allocated and refuses it when its share in this process (`in_process`: the
/// DEM assemblies too) exceeds `limit` bytes (`None`: not checked). Returns the warnings to
/// show (a run that would write more than 10 GiB or 100 000 files), also logged. A DEM job
/// whose one assembly's exported state cannot fit in a message of `max_message_bytes` (the
/// pool's; states are split over as many messages as they need, but one state is not) is
/// refused naming the packing.
pub fn admit(
    job: &Job,
    limit: Option<u64>,
    in_process: bool,
    max_message_bytes: usize,
) -> Result<Vec<String>, RunError> {
    for material in job.materials() {
        if let MaterialSection::Dem { assembly } = material {
            let discs = assembly.disc_count_hint();
            let bytes = cosdem_dem::spec::state_bytes(discs);
            if bytes > max_message_bytes as u64 {
                return Err(RunError::StateTooLarge { discs, bytes, limit: max_message_bytes });
            }
        }
    }
    use cosdem_job::admission::{MeshCounts, estimate};
    let counts = match MeshCounts::of_job(job) {
        Some(c) => c,
        None => MeshCounts::of_mesh(&job.build_mesh()?),
    };
    let e = estimate(job, counts);
    tracing::info!(
        memory = %cosdem_job::admission::size(e.in_process_share(in_process)),
        disk = %cosdem_job::admission::size(e.disk_total),
        "admission estimate"
    );
    if let Some(limit) = limit {
        e.check(limit, in_process)?;
    }
    let warnings: Vec<String> =
        e.disk_warning().map(|w| format!("warning: {w}")).into_iter().collect();
    for w in &warnings {
        tracing::warn!("{w}");
    }
    Ok(warnings)
}

/// Writes `dir/accuracy.json`: what the accuracy target picked and why.
pub fn write_accuracy_report(
    report: &cosdem_tune::accuracy::Report,
    dir: &Path,
) -> Result<(), crate::output::OutputError> {
    crate::output::write_atomic(&dir.join(cosdem_tune::accuracy::FILE), report.to_json().as_bytes())
}

/// Where the DEM assemblies are solved.
#[derive(Clone, Debug, Default)]
pub struct WorkerChoice {
    /// Remote worker addresses (`host:port`, or a name resolving to several); empty: in-process.
    pub addresses: Vec<String>,
    /// Pool settings (token, deadlines, threads of in-process workers).
    pub config: PoolConfig,
}

/// The internal length used for the equivalent strain of the job's material (m).
pub fn internal_length(job: &Job) -> f64 {
    match &job.material {
        MaterialSection::Elastic { length, .. } => length.unwrap_or(0.01),
        MaterialSection::Dem { .. } => 0.01,
    }
}

/// The run writer's settings for a job.
pub fn run_settings(job: &Job) -> RunSettings {
    RunSettings {
        title: job.title.clone(),
        shortening: job.shortening(),
        load_set: job.loading.load_set.clone(),
        load_scale: job.load_scale(),
        vtk_every: job.output.vtk_every,
        internal_length: internal_length(job),
        linear_range: job.output.linear_range,
        curve: job.output.curve.as_ref().map(crate::output::curve_axes::CurveAxes::from),
        pvd_time: job.pvd_time(),
        vtk_encoding: match job.output.vtk_format {
            cosdem_job::VtkFormat::Ascii => crate::output::Encoding::Ascii,
            cosdem_job::VtkFormat::Binary => crate::output::Encoding::Zlib,
        },
        packings: crate::output::packing::PackingOutput::of(job),
    }
}

/// Every Gauss point of the solver's mesh, element-major.
pub fn gauss_point_ids(solver: &Solver) -> Vec<GaussPointId> {
    solver.gauss().ids()
}

/// Runs `job` into `dir` (created) and returns the final summary and curve: a plain
/// [`Run`] (no checkpoints, no particle snapshots). A run that stops early (a step that cannot
/// be cut further, a failed worker) still returns its summary, with `status = "failed: ..."`
/// and the steps it finished: the curve so far is what the caller judges. Only errors before
/// the first step (the job, the pool, the output directory) are returned as `Err`. A job with
/// `accuracy` runs with the settings [`tuned`] picks, and its report is written to
/// `dir/accuracy.json` and logged.
pub fn run_job(
    job: &Job,
    dir: &Path,
    workers: &WorkerChoice,
) -> Result<(Summary, Vec<(f64, f64)>), RunError> {
    let outcome = Run::new(job, dir).workers(workers.clone()).execute()?;
    let summary = outcome.summary.expect("a run with a directory has a summary");
    Ok((summary, outcome.curve))
}
