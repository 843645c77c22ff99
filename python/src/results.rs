//! `cosdem.open_run`: a run directory read back (finished, stopped or still being written),
//! its fields as arrays for numpy.

use crate::arrays::{f64s, i64s, pairs};
use crate::convert::json_to_py;
use crate::errors::results_error;
use cosdem_app::results::{Array, GaussFields, ResultsError, RunReader};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// A run directory (the native half of `cosdem.Run`).
#[pyclass(module = "cosdem._native", name = "RunDir", frozen)]
pub struct PyRunDir {
    reader: RunReader,
}

fn err(py: Python<'_>) -> impl Fn(ResultsError) -> PyErr + '_ {
    move |e| results_error(py, e)
}

/// `values` of `rows` rows with `components` each: shape `(rows,)` for one component, else
/// `(rows, components)`.
fn field<'py>(py: Python<'py>, a: &Array) -> PyResult<Bound<'py, PyAny>> {
    if a.components == 1 {
        f64s(py, &a.values, &[a.values.len()])
    } else {
        f64s(py, &a.values, &[a.rows(), a.components])
    }
}

fn fields<'py>(py: Python<'py>, into: &Bound<'py, PyDict>, arrays: &[Array]) -> PyResult<()> {
    for a in arrays {
        into.set_item(&a.name, field(py, a)?)?;
    }
    Ok(())
}

/// Gauss-point fields as a dict: `position`, `element`, `point` and every field.
pub fn gauss_dict<'py>(py: Python<'py>, g: &GaussFields) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("position", pairs(py, &g.positions)?)?;
    d.set_item("element", i64s(py, &g.element, &[g.element.len()])?)?;
    d.set_item("point", i64s(py, &g.point, &[g.point.len()])?)?;
    fields(py, &d, &g.arrays)?;
    Ok(d)
}

#[pymethods]
impl PyRunDir {
    #[new]
    fn new(py: Python<'_>, dir: PathBuf) -> PyResult<Self> {
        Ok(Self { reader: RunReader::open(&dir).map_err(err(py))? })
    }

    /// The run directory.
    #[getter]
    fn dir(&self) -> PathBuf {
        self.reader.dir().to_path_buf()
    }

    /// `summary.json` as a dict.
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.reader.summary().map_err(err(py))?)
    }

    /// `curve.csv`: `[(column, array)]` in the file's order.
    fn curve<'py>(&self, py: Python<'py>) -> PyResult<Vec<(String, Bound<'py, PyAny>)>> {
        let curve = self.reader.curve().map_err(err(py))?;
        curve.columns.iter().map(|(name, v)| Ok((name.clone(), f64s(py, v, &[v.len()])?))).collect()
    }

    /// The steps whose mesh and Gauss-point fields are saved.
    fn saved_steps(&self, py: Python<'_>) -> PyResult<Vec<u64>> {
        self.reader.saved_steps().map_err(err(py))
    }

    /// The Gauss-point fields of `step`: `position`, `element`, `point` and every field.
    fn gauss<'py>(&self, py: Python<'py>, step: u64) -> PyResult<Bound<'py, PyDict>> {
        gauss_dict(py, &self.reader.gauss(step).map_err(err(py))?)
    }

    /// The mesh of `step`: `points`, `connectivity` with `offsets` (VTK's), `cell_types`,
    /// and the nodal (`point_data`) and element (`cell_data`) fields.
    fn mesh<'py>(&self, py: Python<'py>, step: u64) -> PyResult<Bound<'py, PyDict>> {
        let m = self.reader.mesh(step).map_err(err(py))?;
        let d = PyDict::new(py);
        d.set_item("points", pairs(py, &m.points)?)?;
        let connectivity: Vec<i64> = m.cells.iter().flatten().copied().collect();
        let offsets: Vec<i64> = m
            .cells
            .iter()
            .scan(0i64, |end, c| {
                *end += c.len() as i64;
                Some(*end)
            })
            .collect();
        d.set_item("connectivity", i64s(py, &connectivity, &[connectivity.len()])?)?;
        d.set_item("offsets", i64s(py, &offsets, &[offsets.len()])?)?;
        let types: Vec<i64> = m.cell_types.iter().map(|&t| i64::from(t)).collect();
        d.set_item("cell_types", i64s(py, &types, &[types.len()])?)?;
        let point_data = PyDict::new(py);
        fields(py, &point_data, &m.point_arrays)?;
        d.set_item("point_data", point_data)?;
        let cell_data = PyDict::new(py);
        fields(py, &cell_data, &m.cell_arrays)?;
        d.set_item("cell_data", cell_data)?;
        Ok(d)
    }

    /// The `(element, point)` pairs with particle snapshots.
    fn snapshot_points(&self, py: Python<'_>) -> PyResult<Vec<(u32, u32)>> {
        self.reader.snapshot_points().map_err(err(py))
    }

    /// The steps saved for the snapshots of `(element, point)`.
    fn snapshot_steps(&self, py: Python<'_>, element: u32, point: u32) -> PyResult<Vec<u64>> {
        self.reader.snapshot_steps(element, point).map_err(err(py))
    }

    /// The particles of Gauss point `point` of `element` at `step`.
    fn snapshot<'py>(
        &self,
        py: Python<'py>,
        element: u32,
        point: u32,
        step: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let s = self.reader.snapshot(element, point, step).map_err(err(py))?;
        let d = PyDict::new(py);
        d.set_item("position", pairs(py, &s.positions)?)?;
        d.set_item("radius", f64s(py, &s.radius, &[s.radius.len()])?)?;
        d.set_item("rotation", f64s(py, &s.rotation, &[s.rotation.len()])?)?;
        d.set_item("fluctuation", pairs(py, &s.fluctuation)?)?;
        let contacts: Vec<i64> = s.contacts.iter().flatten().copied().collect();
        d.set_item("contacts", i64s(py, &contacts, &[s.contacts.len(), 2])?)?;
        d.set_item("normal_force", f64s(py, &s.normal_force, &[s.normal_force.len()])?)?;
        d.set_item(
            "tangential_force",
            f64s(py, &s.tangential_force, &[s.tangential_force.len()])?,
        )?;
        Ok(d)
    }
}
