//! `cosdem.Job`: a job read from a TOML file or a dict, validated as the CLI validates it, and
//! run into a run directory.

use crate::convert::{json_to_py, table_from_py};
use crate::errors::job_error;
use crate::running::{RunOptions, run};
use cosdem_job::Job;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// A validated job (the native half of `cosdem.Job`).
#[pyclass(module = "cosdem._native", name = "Job", frozen)]
pub struct PyJob {
    pub job: Job,
    /// The TOML text the job was read from (a run directory keeps it as `job.toml`).
    text: String,
    /// The job file, for a job read from one.
    file: Option<PathBuf>,
}

#[pymethods]
impl PyJob {
    /// Reads and validates a job file; relative paths in it are relative to the file.
    #[staticmethod]
    fn from_toml(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let job = Job::load(&path).map_err(|e| job_error(py, e))?;
        let text = std::fs::read_to_string(&path).map_err(|e| job_error(py, e))?;
        Ok(Self { job, text, file: Some(path) })
    }

    /// Reads and validates a job given as a dict of its tables (`{"mesh": {...}, ...}`);
    /// errors name the key path (`job dict: at key `mesh.nx`: ...`).
    #[staticmethod]
    fn from_dict(py: Python<'_>, tables: &Bound<'_, PyDict>) -> PyResult<Self> {
        let table = table_from_py(py, tables, "")?;
        let (job, text) = Job::from_table(&table, "job dict").map_err(|e| job_error(py, e))?;
        Ok(Self { job, text, file: None })
    }

    /// The job's tables as written (defaults not filled in), as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let table: toml::Table = toml::from_str(&self.text).map_err(|e| job_error(py, e))?;
        json_to_py(py, &serde_json::to_value(table).map_err(|e| job_error(py, e))?)
    }

    /// The TOML text of the job.
    #[getter]
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The node set whose reaction is the curve's load (`[loading] load_set`).
    #[getter]
    fn load_set(&self) -> &str {
        &self.job.loading.load_set
    }

    /// The job file, or `None` for a job given as a dict.
    #[getter]
    fn file(&self) -> Option<PathBuf> {
        self.file.clone()
    }

    /// The job's title.
    #[getter]
    fn title(&self) -> &str {
        &self.job.title
    }

    /// Whether the job's material is DEM assemblies.
    #[getter]
    fn is_dem(&self) -> bool {
        matches!(self.job.material, cosdem_job::MaterialSection::Dem { .. })
    }

    /// The run directory `run` uses when `out` is not given: the job's `[output] dir`, else
    /// `runs/<job file stem>` (`runs/job` for a job given as a dict).
    fn default_dir(&self) -> PathBuf {
        if let Some(d) = &self.job.output.dir {
            return d.clone();
        }
        let stem = self.file.as_deref().and_then(Path::file_stem);
        Path::new("runs").join(stem.map_or("job".into(), |s| s.to_string_lossy().into_owned()))
    }

    /// Runs the job into `out` (see `cosdem.Job.run`); returns the run's status (`finished`,
    /// `stopped`, `interrupted`). The GIL is released while the run goes.
    #[pyo3(signature = (out, workers=None, progress=true, overwrite=false, resume=false,
        newton_changed=false, max_steps=None, token_file=None, max_memory=None,
        create_timeout=None))]
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        py: Python<'_>,
        out: PathBuf,
        workers: Option<Vec<String>>,
        progress: bool,
        overwrite: bool,
        resume: bool,
        newton_changed: bool,
        max_steps: Option<u64>,
        token_file: Option<PathBuf>,
        max_memory: Option<u64>,
        create_timeout: Option<f64>,
    ) -> PyResult<String> {
        let options = RunOptions {
            out,
            workers,
            progress,
            overwrite,
            resume,
            newton_changed,
            max_steps,
            token_file,
            max_memory,
            create_timeout,
        };
        run(py, &self.job, &self.text, options)
    }

    fn __repr__(&self) -> String {
        match &self.file {
            Some(f) => format!("Job.from_toml({:?}) # {}", f.display().to_string(), self.job.title),
            None => format!("Job({{...}}) # {}", self.job.title),
        }
    }
}
