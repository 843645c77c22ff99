//! What a caller of the run driver sees as a run goes ([`RunObserver`]), and the one per-step
//! hook the driver hands the solver ([`StepHook`]).
//!
//! Every committed step goes through the same hook: the run directory records it (curve row,
//! VTK, the particle snapshots and field data the step calls for, summary), then the caller's
//! observer sees it (a progress bar, a study's own curve); a run that can stop wraps the hook
//! in a [`crate::checkpoint::Checkpointer`], which writes the checkpoint after the step and
//! asks the solver to stop.

use crate::output::run_dir::RunWriter;
use cosdem_fem::solve::{SolutionView, StepObserver, StepReport};
use std::path::Path;

/// An error of a caller's hook, passed through the driver unchanged.
pub type HookError = Box<dyn std::error::Error + Send + Sync>;

/// What a caller of [`super::Run`] is told as the run goes, in this order. Every method does
/// nothing by default.
pub trait RunObserver {
    /// The run directory exists and nothing has been written into it yet (the CLI opens its
    /// log file there). Not called for a run without a directory.
    fn on_dir(&mut self, _dir: &Path) -> Result<(), HookError> {
        Ok(())
    }

    /// One line of the accuracy plan (a job with `accuracy`); the driver logs it too.
    fn on_plan_line(&mut self, _line: &str) {}

    /// The material is in place and the solver is about to take its first step.
    fn on_start(&mut self) -> Result<(), HookError> {
        Ok(())
    }

    /// A committed step, after the run directory (`record`, `None` for a run without one)
    /// has recorded it.
    fn on_step(
        &mut self,
        _report: &StepReport,
        _view: &SolutionView<'_>,
        _record: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
        Ok(())
    }

    /// The solver has returned; the summary is not finished yet.
    fn on_end(&mut self) {}
}

/// The indicatif template of the progress bars of `cosdem run` and the Python package: the
/// elapsed time, the bar and percentage of the load factor, the ETA, [`step_message`].
pub const PROGRESS_TEMPLATE: &str = "[{elapsed_precise}] {bar:30} {percent:>3}% ETA {eta} {msg}";

/// The progress line of a committed step that `record` has recorded, `seconds` into the run
/// (what the CLI's and the Python package's progress bars show): step, displacement and load
/// of the curve, Newton iterations, DEM relaxation steps per second.
pub fn step_message(report: &StepReport, record: &RunWriter, seconds: f64) -> String {
    let sum = record.summary();
    format!(
        "step {} d={:.4e} m load={:.4e} N it={} DEM {:.2e} relax-steps/s",
        report.step,
        sum.displacement,
        record.curve().last().map_or(0.0, |p| p.1),
        report.iterations,
        sum.dem_steps as f64 / seconds.max(1e-9)
    )
}

/// The observer of a run whose caller watches nothing.
pub(crate) struct Silent;

impl RunObserver for Silent {}

/// The per-step hook: the run directory first, then the caller's observer.
pub(crate) struct StepHook<'h> {
    /// The run directory's writer, if the run has one.
    pub writer: Option<&'h mut RunWriter>,
    /// The caller's observer.
    pub observer: &'h mut dyn RunObserver,
}

impl StepObserver for StepHook<'_> {
    fn on_step(&mut self, report: &StepReport, view: &SolutionView<'_>) -> cosdem_fem::Result<()> {
        if let Some(w) = self.writer.as_deref_mut() {
            w.on_step(report, view)?;
        }
        self.observer.on_step(report, view, self.writer.as_deref())
    }
}
