//! `cosdem.Solver`: a job's solver driven one step at a time from a Python loop, as FEMxDEM
//! scripts drive theirs: the application's [`Stepper`], each `step()` one stage of the job
//! file's `[[stage]]` semantics (what the script set stays in force until it changes it),
//! run with the GIL released.

use crate::arrays::f64s;
use crate::convert::table_from_py;
use crate::errors::job_error;
use crate::job::PyJob;
use crate::results::gauss_dict;
use crate::running::{command_line, from_run_error, worker_choice};
use cosdem_app::output::provenance::Origin;
use cosdem_app::run::WorkerChoice;
use cosdem_app::stepper::{Stepper, StepperOptions};
use cosdem_job::StageSection;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

/// A stepped solver (the native half of `cosdem.Solver`). `None` once finished.
#[pyclass(module = "cosdem._native", name = "Solver")]
pub struct PySolver {
    stepper: Mutex<Option<Stepper>>,
    dir: Option<PathBuf>,
}

/// The options both constructors share: [`StepperOptions`] but for its material builder
/// (not `Send`; always the job's material here), so that they go to the thread that builds
/// the stepper without the GIL.
struct Options {
    workers: WorkerChoice,
    dir: Option<PathBuf>,
    overwrite: bool,
    max_memory: Option<u64>,
    origin: Origin,
    snapshots: bool,
    newton_changed: bool,
}

impl Options {
    fn stepper_options(self) -> StepperOptions {
        StepperOptions {
            workers: self.workers,
            dir: self.dir,
            overwrite: self.overwrite,
            max_memory: self.max_memory,
            origin: Some(self.origin),
            snapshots: self.snapshots,
            newton_changed: self.newton_changed,
            material: None,
        }
    }
}

impl PySolver {
    fn stepper(&self) -> PyResult<MutexGuard<'_, Option<Stepper>>> {
        let guard = self
            .stepper
            .lock()
            .map_err(|_| PyRuntimeError::new_err("the solver was poisoned by a panic"))?;
        if guard.is_none() {
            return Err(PyRuntimeError::new_err("the solver is finished"));
        }
        Ok(guard)
    }
}

#[pymethods]
impl PySolver {
    /// Sets `job` up (mesh, material and workers, run directory `out` if given); none of the
    /// job's own loading is applied. The GIL is released while the assemblies are built.
    #[new]
    #[pyo3(signature = (job, out=None, workers=None, overwrite=false, snapshots=true,
        token_file=None, max_memory=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        job: &PyJob,
        out: Option<PathBuf>,
        workers: Option<Vec<String>>,
        overwrite: bool,
        snapshots: bool,
        token_file: Option<PathBuf>,
        max_memory: Option<u64>,
    ) -> PyResult<Self> {
        let o = Options {
            workers: worker_choice(py, &job.job, workers, token_file.as_deref(), None)?,
            dir: out.clone(),
            overwrite,
            max_memory,
            origin: Origin { command: command_line(py), job_text: Some(job.text().to_string()) },
            snapshots,
            newton_changed: false,
        };
        let stepper = py
            .detach(|| Stepper::new(&job.job, o.stepper_options()))
            .map_err(|e| from_run_error(py, e, out.as_deref()))?;
        Ok(Self { stepper: Mutex::new(Some(stepper)), dir: out })
    }

    /// Goes on from a checkpoint written by `checkpoint`: the script's stages so far, the
    /// assemblies' states, and (without `job`) the job the checkpoint holds.
    #[staticmethod]
    #[pyo3(signature = (path, job=None, out=None, workers=None, newton_changed=false,
        snapshots=true, token_file=None, max_memory=None))]
    #[allow(clippy::too_many_arguments)]
    fn resume(
        py: Python<'_>,
        path: PathBuf,
        job: Option<&PyJob>,
        out: Option<PathBuf>,
        workers: Option<Vec<String>>,
        newton_changed: bool,
        snapshots: bool,
        token_file: Option<PathBuf>,
        max_memory: Option<u64>,
    ) -> PyResult<Self> {
        let held;
        let (job, text) = match job {
            Some(j) => (&j.job, Some(j.text().to_string())),
            None => {
                held = Stepper::job_of(&path).map_err(|e| from_run_error(py, e, None))?;
                (&held, None)
            }
        };
        let o = Options {
            workers: worker_choice(py, job, workers, token_file.as_deref(), None)?,
            dir: out.clone(),
            overwrite: false,
            max_memory,
            origin: Origin { command: command_line(py), job_text: text },
            snapshots,
            newton_changed,
        };
        let stepper = py
            .detach(|| Stepper::resume(&path, job, o.stepper_options()))
            .map_err(|e| from_run_error(py, e, out.as_deref()))?;
        Ok(Self { stepper: Mutex::new(Some(stepper)), dir: out })
    }

    /// Runs one stage given as a `[[stage]]` table (`steps` 1 when not given); returns its
    /// committed steps as dicts. The GIL is released while it runs.
    fn step<'py>(
        &self,
        py: Python<'py>,
        stage: &Bound<'py, PyDict>,
    ) -> PyResult<Bound<'py, PyList>> {
        let mut table = table_from_py(py, stage, "")?;
        table.entry("steps").or_insert(toml::Value::Integer(1));
        let stage: StageSection =
            cosdem_job::from_table(&table, "stage").map_err(|e| job_error(py, e))?;
        let mut guard = self.stepper()?;
        let stepper = guard.as_mut().expect("checked");
        let report = py
            .detach(|| stepper.step(stage))
            .map_err(|e| from_run_error(py, e, self.dir.as_deref()))?;
        let steps = PyList::empty(py);
        for r in &report.steps {
            let d = PyDict::new(py);
            d.set_item("step", r.step)?;
            d.set_item("stage", report.index)?;
            d.set_item("load_factor", r.load_factor)?;
            d.set_item("iterations", r.iterations)?;
            d.set_item("cuts", r.cuts)?;
            d.set_item("tolerated", r.tolerated)?;
            d.set_item("dem_steps", r.dem_steps)?;
            steps.append(d)?;
        }
        Ok(steps)
    }

    /// `[R_x, R_y, R_w]` of node set `set` at the last committed step.
    fn reactions(&self, py: Python<'_>, set: &str) -> PyResult<[f64; 3]> {
        let guard = self.stepper()?;
        guard.as_ref().expect("checked").reactions(set).map_err(|e| from_run_error(py, e, None))
    }

    /// `component` (`ux`, `uy`, `w`) at each node of `set`, in ascending node order.
    fn displacement<'py>(
        &self,
        py: Python<'py>,
        set: &str,
        component: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let guard = self.stepper()?;
        let values = guard
            .as_ref()
            .expect("checked")
            .displacement(set, component)
            .map_err(|e| from_run_error(py, e, None))?;
        f64s(py, &values, &[values.len()])
    }

    /// The Gauss-point fields of the last committed step.
    fn gauss_fields<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let guard = self.stepper()?;
        let g = guard
            .as_ref()
            .expect("checked")
            .gauss_fields()
            .map_err(|e| from_run_error(py, e, None))?;
        gauss_dict(py, &g)
    }

    /// Writes a checkpoint to `path`.
    fn checkpoint(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let mut guard = self.stepper()?;
        let stepper = guard.as_mut().expect("checked");
        py.detach(|| stepper.checkpoint(&path)).map_err(|e| from_run_error(py, e, None))
    }

    /// Committed steps so far.
    #[getter]
    fn steps(&self) -> PyResult<u64> {
        Ok(self.stepper()?.as_ref().expect("checked").steps())
    }

    /// The script's stages so far.
    #[getter]
    fn stages(&self) -> PyResult<usize> {
        Ok(self.stepper()?.as_ref().expect("checked").stages().len())
    }

    /// The node set `step(increment=...)` moves: the job's `[loading] load_set`.
    #[getter]
    fn load_set(&self) -> PyResult<String> {
        Ok(self.stepper()?.as_ref().expect("checked").job().loading.load_set.clone())
    }

    /// The run directory, if one is written.
    #[getter]
    fn dir(&self) -> Option<PathBuf> {
        self.dir.clone()
    }

    /// Marks the run directory's summary finished and releases the workers and the directory.
    fn finish(&self, py: Python<'_>) -> PyResult<()> {
        let mut guard = self
            .stepper
            .lock()
            .map_err(|_| PyRuntimeError::new_err("the solver was poisoned by a panic"))?;
        if let Some(stepper) = guard.take() {
            py.detach(|| stepper.finish())
                .map_err(|e| from_run_error(py, e, self.dir.as_deref()))?;
        }
        Ok(())
    }
}
