//! Values between Python and the job's TOML: a `dict` given to `cosdem.Job(...)` becomes a
//! TOML table (read by the job file's own parser), and JSON values (a job's table through
//! serde, a run's `summary.json`) become plain Python objects.

use crate::errors::job_error;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// A Python mapping as a TOML table: `str` keys; values `bool`, `int`, `float`, `str`,
/// `os.PathLike`, lists and tuples, nested mappings; a `None` value leaves its key out (the
/// default applies). Anything else is a `JobError` naming the key path.
pub fn table_from_py(
    py: Python<'_>,
    dict: &Bound<'_, PyDict>,
    path: &str,
) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (key, value) in dict.iter() {
        let Ok(key) = key.extract::<String>() else {
            return Err(job_error(
                py,
                format!(
                    "job dict: at key `{path}`: the keys of a table are strings, not {}",
                    type_name(&key)
                ),
            ));
        };
        let at = if path.is_empty() { key.clone() } else { format!("{path}.{key}") };
        if value.is_none() {
            continue;
        }
        table.insert(key, value_from_py(py, &value, &at)?);
    }
    Ok(table)
}

fn value_from_py(py: Python<'_>, value: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if value.is_instance_of::<PyInt>() {
        return match value.extract::<i64>() {
            Ok(i) => Ok(toml::Value::Integer(i)),
            Err(_) => Err(job_error(
                py,
                format!("job dict: at key `{at}`: {value} does not fit in a 64-bit integer"),
            )),
        };
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if value.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(value.extract()?));
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        return Ok(toml::Value::Table(table_from_py(py, dict, at)?));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for (i, item) in value.try_iter()?.enumerate() {
            items.push(value_from_py(py, &item?, &format!("{at}[{i}]"))?);
        }
        return Ok(toml::Value::Array(items));
    }
    // numpy scalars and arrays, paths: through the protocols they implement.
    if value.hasattr("__fspath__")? {
        let os = py.import("os")?;
        return Ok(toml::Value::String(os.call_method1("fsdecode", (value,))?.extract()?));
    }
    if value.hasattr("tolist")? {
        return value_from_py(py, &value.call_method0("tolist")?, at);
    }
    if value.hasattr("__index__")? {
        return value_from_py(py, &value.call_method0("__index__")?, at);
    }
    if value.hasattr("__float__")? {
        return Ok(toml::Value::Float(value.call_method0("__float__")?.extract()?));
    }
    Err(job_error(
        py,
        format!(
            "job dict: at key `{at}`: a {} cannot be a job value (bool, int, float, str, list or dict)",
            type_name(value)
        ),
    ))
}

fn type_name(value: &Bound<'_, PyAny>) -> String {
    value.get_type().name().map_or_else(|_| "value".into(), |n| n.to_string())
}

/// A JSON value as a Python object (`null` as `None`).
pub fn json_to_py<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            _ => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            PyList::new(py, a.iter().map(|v| json_to_py(py, v)).collect::<PyResult<Vec<_>>>()?)?
                .into_any()
        }
        Value::Object(o) => {
            let dict = PyDict::new(py);
            for (k, v) in o {
                dict.set_item(k, json_to_py(py, v)?)?;
            }
            dict.into_any()
        }
    })
}
