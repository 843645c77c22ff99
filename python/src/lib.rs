//! The extension module of the `cosdem` Python package (`cosdem._native`), bound from the
//! application library: jobs read and validated as the CLI reads them (`job`, `convert`),
//! runs through the run driver with the GIL released and Ctrl-C a clean stop (`running`),
//! a job's solver stepped from a Python loop (`solver`),
//! run directories read back (`results`), single assemblies for calibration (`assembly`).
//! Arrays cross as little-endian buffers (`arrays`) and errors as the package's exceptions
//! (`errors`); the pure-Python half (`python/cosdem/`) makes numpy arrays of them and holds
//! the user-facing docstrings.

mod arrays;
mod assembly;
mod convert;
mod errors;
mod job;
mod results;
mod running;
mod solver;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<job::PyJob>()?;
    m.add_class::<results::PyRunDir>()?;
    m.add_class::<assembly::PyAssembly>()?;
    m.add_class::<solver::PySolver>()?;
    Ok(())
}
