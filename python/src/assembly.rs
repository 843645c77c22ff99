//! `cosdem.Assembly`: one DEM assembly driven from Python (calibration): a trial solve for a
//! macro deformation, then commit or roll back, as a Gauss point of a run does and as the
//! laboratory paths of `cosdem rve` do.

use crate::arrays::{f64s, pairs};
use crate::convert::{json_to_py, table_from_py};
use crate::errors::{job_error, run_error};
use crate::job::PyJob;
use cosdem_common::MacroDeformation;
use cosdem_dem::{Assembly, AssemblySpec};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// One assembly (the native half of `cosdem.Assembly`).
#[pyclass(module = "cosdem._native", name = "Assembly")]
pub struct PyAssembly {
    assembly: Assembly,
}

/// The assembly spec of a DEM job, or of a dict of `[material.assembly]`'s keys.
fn spec_of(py: Python<'_>, source: &Bound<'_, PyAny>) -> PyResult<AssemblySpec> {
    if let Ok(job) = source.cast::<PyJob>() {
        return match &job.get().job.material {
            cosdem_job::MaterialSection::Dem { assembly } => Ok((**assembly).clone()),
            _ => Err(job_error(
                py,
                "an Assembly needs a job with [material] kind = \"dem\" (this job's material is elastic)",
            )),
        };
    }
    let Ok(dict) = source.cast::<PyDict>() else {
        return Err(job_error(
            py,
            "an Assembly is made from a DEM job or a dict of [material.assembly]",
        ));
    };
    let table = table_from_py(py, dict, "")?;
    let spec: AssemblySpec =
        cosdem_job::from_table(&table, "assembly dict").map_err(|e| job_error(py, e))?;
    spec.validate().map_err(|e| job_error(py, format!("assembly dict: {e}")))?;
    Ok(spec)
}

#[pymethods]
impl PyAssembly {
    /// Builds (packs) the assembly; the GIL is released meanwhile.
    #[new]
    fn new(py: Python<'_>, source: &Bound<'_, PyAny>) -> PyResult<Self> {
        let spec = spec_of(py, source)?;
        let assembly = py.detach(|| Assembly::new(&spec)).map_err(|e| job_error(py, e))?;
        Ok(Self { assembly })
    }

    /// Discs in the assembly.
    #[getter]
    fn disc_count(&self) -> usize {
        self.assembly.disc_count()
    }

    /// Reference area of the assembly's cell (m^2 per metre of thickness).
    #[getter]
    fn area(&self) -> f64 {
        self.assembly.area()
    }

    /// Trial solve for the deformation gradient `f` (row a, column b: `delta_ab + du_a/dx_b`),
    /// micro-rotation `w` and curvature `kappa`, from the committed state. Returns the
    /// Voigt stress `[s_xx, s_yy, s_xy, s_yx, m_x, m_y]`, the 6x6 tangent and the
    /// diagnostics. The GIL is released during the relaxation.
    fn solve<'py>(
        &mut self,
        py: Python<'py>,
        f: [[f64; 2]; 2],
        w: f64,
        kappa: [f64; 2],
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let target = MacroDeformation { f, w, kappa };
        target.validate().map_err(|e| PyValueError::new_err(e.to_string()))?;
        let assembly = &mut self.assembly;
        let response = py.detach(|| assembly.solve(&target)).map_err(|e| run_error(py, e, None))?;
        let tangent: Vec<f64> = response.tangent.iter().flatten().copied().collect();
        let diagnostics =
            serde_json::to_value(&response.diagnostics).map_err(|e| run_error(py, e, None))?;
        Ok((
            f64s(py, &response.stress, &[6])?,
            f64s(py, &tangent, &[6, 6])?,
            json_to_py(py, &diagnostics)?,
        ))
    }

    /// Accepts the last trial state: the next solve starts from it.
    fn commit(&mut self) {
        self.assembly.commit();
    }

    /// Drops the last trial state: the next solve starts from the committed one again.
    fn rollback(&mut self) {
        self.assembly.rollback();
    }

    /// The particles of the committed state: centres and radii.
    fn particles<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let s = self.assembly.snapshot();
        let positions: Vec<[f64; 2]> = s.x.iter().zip(&s.y).map(|(&x, &y)| [x, y]).collect();
        Ok((pairs(py, &positions)?, f64s(py, &s.r, &[s.r.len()])?))
    }
}
