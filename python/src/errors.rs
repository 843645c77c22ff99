//! Rust errors as the package's Python exceptions (`cosdem/_errors.py`): a job that cannot be
//! read is a `JobError` (also a `ValueError`), a run that stopped on an error a `RunError`
//! (also a `RuntimeError`, with the run directory), a step or point that was not saved a
//! `ResultsError` (also a `LookupError`). The message is the CLI's, unchanged.

use pyo3::prelude::*;
use std::path::Path;

/// The exception class `kind` of `cosdem._errors` raised with `args`.
fn raise<'py>(py: Python<'py>, kind: &str, args: impl pyo3::call::PyCallArgs<'py>) -> PyErr {
    let made = py
        .import("cosdem._errors")
        .and_then(|m| m.getattr(kind))
        .and_then(|class| class.call1(args));
    match made {
        Ok(exception) => PyErr::from_value(exception),
        Err(e) => e,
    }
}

/// A job that cannot be read or is invalid (`cosdem.JobError`).
pub fn job_error(py: Python<'_>, message: impl std::fmt::Display) -> PyErr {
    raise(py, "JobError", (message.to_string(),))
}

/// A run that could not start or stopped on an error (`cosdem.RunError`); `dir` is the run
/// directory where the finished steps are, when there is one.
pub fn run_error(py: Python<'_>, message: impl std::fmt::Display, dir: Option<&Path>) -> PyErr {
    let dir = dir.map(|d| d.to_string_lossy().into_owned());
    raise(py, "RunError", (message.to_string(), dir))
}

/// A run directory that cannot be read, or a step or point it did not save
/// (`cosdem.ResultsError`).
pub fn results_error(py: Python<'_>, message: impl std::fmt::Display) -> PyErr {
    raise(py, "ResultsError", (message.to_string(),))
}
