//! `Job.run`: the application's run driver ([`cosdem_app::run::Run`]) with the CLI's options
//! (`cosdem run`), on a thread of its own while the calling thread waits without the GIL and
//! checks for Ctrl-C: the first one stops the run cleanly after its step (checkpoint written,
//! status `interrupted`, resumable) and is raised again as `KeyboardInterrupt`.

use crate::errors::{job_error, run_error};
use cosdem_app::output::provenance::Origin;
use cosdem_app::output::run_dir::RunWriter;
use cosdem_app::run::{
    Ending, HookError, PROGRESS_TEMPLATE, Run, RunError, RunObserver, WorkerChoice, step_message,
};
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_job::Job;
use cosdem_pool::PoolConfig;
use cosdem_worker::Token;
use indicatif::{ProgressBar, ProgressStyle};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// The options of `Job.run`, those of `cosdem run`.
pub struct RunOptions {
    pub out: PathBuf,
    /// Remote workers (`host:port`, `dns:NAME:PORT`); `None`: the job's, else in-process.
    pub workers: Option<Vec<String>>,
    pub progress: bool,
    pub overwrite: bool,
    pub resume: bool,
    pub newton_changed: bool,
    pub max_steps: Option<u64>,
    pub token_file: Option<PathBuf>,
    /// Bytes; `None`: 80 % of the machine's memory.
    pub max_memory: Option<u64>,
    /// Seconds.
    pub create_timeout: Option<f64>,
}

impl RunOptions {
    /// The combinations and ranges `cosdem run` refuses.
    fn check(&self) -> PyResult<()> {
        let refuse = |m: String| Err(PyValueError::new_err(m));
        if self.resume && self.overwrite {
            return refuse("resume=True and overwrite=True exclude each other".into());
        }
        if self.newton_changed && !self.resume {
            return refuse("newton_changed=True needs resume=True".into());
        }
        if self.max_steps == Some(0) {
            return refuse("max_steps=0: a run stops after at least one step".into());
        }
        if let Some(t) = self.create_timeout
            && !(t > 0.0 && t <= 3.2e7)
        {
            return refuse(format!("create_timeout={t}: seconds must be a number in (0, 3.2e7]"));
        }
        if self.max_memory == Some(0) {
            return refuse("max_memory=0: a memory limit is at least one byte".into());
        }
        Ok(())
    }
}

/// Runs `job` (read from `text`) into `options.out`; the status of a run that ended well
/// (`finished`, `stopped` at `max_steps`, `interrupted` by a stop that was not Ctrl-C).
pub fn run(py: Python<'_>, job: &Job, text: &str, options: RunOptions) -> PyResult<String> {
    options.check()?;
    let dir = options.out.clone();
    let choice = worker_choice(
        py,
        job,
        options.workers.clone(),
        options.token_file.as_deref(),
        options.create_timeout,
    )?;
    let origin = Origin { command: command_line(py), job_text: Some(text.to_string()) };
    let stop = Arc::new(AtomicBool::new(false));

    let (outcome, interrupt) = std::thread::scope(|scope| {
        let thread_stop = stop.clone();
        let dir = &dir;
        let options = &options;
        let handle = scope.spawn(move || {
            let mut bar = Bar::new(options.progress);
            let mut run = Run::new(job, dir)
                .workers(choice)
                .checkpoints(true)
                .snapshots(true)
                .max_steps(options.max_steps)
                .overwrite(options.overwrite)
                .origin(origin)
                .max_memory(options.max_memory)
                .stop_flag(thread_stop)
                .observer(&mut bar);
            if options.resume {
                run = run.resume(options.newton_changed);
            }
            run.execute()
        });
        let mut interrupt = None;
        while !handle.is_finished() {
            py.detach(|| std::thread::sleep(Duration::from_millis(20)));
            if interrupt.is_none()
                && let Err(e) = py.check_signals()
            {
                stop.store(true, Ordering::SeqCst);
                interrupt = Some(e);
            }
        }
        let outcome = handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (outcome, interrupt)
    });

    let outcome = outcome.map_err(|e| from_run_error(py, e, Some(&dir)))?;
    match (outcome.ending, interrupt) {
        (Ending::Failed(e), _) => Err(run_error(
            py,
            format!("run stopped: {e}; the finished steps are in {}", dir.display()),
            Some(&dir),
        )),
        // Ctrl-C: the run stopped cleanly after its step; the interrupt goes on to the caller.
        (_, Some(interrupt)) => Err(interrupt),
        (ending, None) => Ok(ending.status()),
    }
}

/// Where the DEM assemblies are solved: `workers` (`host:port`, `dns:NAME:PORT`), else the
/// job's `[workers]`, else in-process; the token from `token_file`, else `COSDEM_TOKEN`.
pub fn worker_choice(
    py: Python<'_>,
    job: &Job,
    workers: Option<Vec<String>>,
    token_file: Option<&Path>,
    create_timeout: Option<f64>,
) -> PyResult<WorkerChoice> {
    let token = Token::load(token_file).map_err(|e| run_error(py, e, None))?;
    let addresses = workers.unwrap_or_else(|| job.workers.addresses.clone());
    let create_timeout = create_timeout.map(Duration::from_secs_f64);
    let config = PoolConfig { token, create_timeout, ..PoolConfig::default() };
    Ok(WorkerChoice { addresses, config })
}

/// A run's or a stepper's error: the job's own (a mesh that cannot be built, an unknown set,
/// an invalid setting or stage) as a `JobError`, the rest (the run directory, the workers, the
/// checkpoint, a step that cannot be solved) as a `RunError` naming `dir` when it exists.
pub fn from_run_error(py: Python<'_>, e: RunError, dir: Option<&Path>) -> PyErr {
    use cosdem_fem::Error as Fem;
    match &e {
        RunError::Solver(
            Fem::InvalidMesh { .. }
            | Fem::UnknownSet { .. }
            | Fem::InvertedElement { .. }
            | Fem::JobFile { .. }
            | Fem::InvalidSetting { .. },
        )
        | RunError::StageText { .. }
        | RunError::Unknown { .. } => job_error(py, e),
        _ => run_error(py, e, dir.filter(|d| d.exists())),
    }
}

/// The script's command line for the run's provenance: `python` and `sys.argv`.
pub fn command_line(py: Python<'_>) -> Vec<String> {
    let argv: Vec<String> = py
        .import("sys")
        .and_then(|sys| sys.getattr("argv"))
        .and_then(|argv| argv.extract())
        .unwrap_or_default();
    std::iter::once("python".to_string()).chain(argv).collect()
}

/// The progress bar of `Job.run(progress=True)`: the CLI's bar and step line (drawn only
/// when stderr is a terminal).
struct Bar {
    shown: bool,
    bar: ProgressBar,
    started: Instant,
}

impl Bar {
    fn new(shown: bool) -> Self {
        Self { shown, bar: ProgressBar::hidden(), started: Instant::now() }
    }
}

impl RunObserver for Bar {
    fn on_plan_line(&mut self, line: &str) {
        if self.shown {
            eprintln!("{line}");
        }
    }

    fn on_start(&mut self) -> Result<(), HookError> {
        if self.shown {
            self.bar = ProgressBar::new(1000);
            self.bar.set_style(
                ProgressStyle::with_template(PROGRESS_TEMPLATE).expect("static template"),
            );
        }
        self.started = Instant::now();
        Ok(())
    }

    fn on_step(
        &mut self,
        report: &StepReport,
        _: &SolutionView<'_>,
        record: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
        if let Some(writer) = record {
            self.bar.set_position((report.load_factor * 1000.0).round() as u64);
            self.bar.set_message(step_message(
                report,
                writer,
                self.started.elapsed().as_secs_f64(),
            ));
        }
        Ok(())
    }

    fn on_end(&mut self) {
        self.bar.finish_and_clear();
    }
}
