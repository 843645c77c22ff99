//! Arrays handed to Python as `(dtype, buffer, shape)`: the values' little-endian bytes in a
//! `bytearray`, which `cosdem/_arrays.py` views as a writable numpy array without a copy (the
//! extension does not link numpy).

use pyo3::prelude::*;
use pyo3::types::PyByteArray;

/// `(dtype, bytearray, shape)` of `values` (row-major, `shape` multiplying to their count).
pub fn f64s<'py>(py: Python<'py>, values: &[f64], shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    packed(py, "<f8", &bytes, values.len(), shape)
}

/// `(dtype, bytearray, shape)` of integer `values`.
pub fn i64s<'py>(py: Python<'py>, values: &[i64], shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    packed(py, "<i8", &bytes, values.len(), shape)
}

/// `(dtype, bytearray, shape)` of rows of two (positions, vectors): shape `(n, 2)`.
pub fn pairs<'py>(py: Python<'py>, rows: &[[f64; 2]]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    f64s(py, &flat, &[rows.len(), 2])
}

fn packed<'py>(
    py: Python<'py>,
    dtype: &str,
    bytes: &[u8],
    count: usize,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    debug_assert_eq!(shape.iter().product::<usize>(), count, "shape {shape:?} of {count} values");
    (dtype, PyByteArray::new(py, bytes), shape.to_vec()).into_pyobject(py).map(Bound::into_any)
}
