//! Array shapes at the boundary: checked views of numpy arrays as rows of 3 (or 2) values, and
//! rows back into `(n, 3)` arrays. A wrong shape is a `ValueError` naming the argument.

use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The rows of an `(n, W)` C-contiguous array, as a flat slice (`n * W` values).
pub fn rows<'a, T: numpy::Element, const W: usize>(
    a: &'a PyReadonlyArray2<'_, T>,
    name: &str,
) -> PyResult<&'a [T]> {
    let shape = a.shape();
    if shape[1] != W {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an array of shape (n, {W}), got ({}, {})",
            shape[0], shape[1]
        )));
    }
    a.as_slice().map_err(|_| PyValueError::new_err(format!("{name}: not C-contiguous")))
}

/// A 1-d C-contiguous array as a slice.
pub fn flat<'a, T: numpy::Element>(
    a: &'a PyReadonlyArray1<'_, T>,
    name: &str,
) -> PyResult<&'a [T]> {
    a.as_slice().map_err(|_| PyValueError::new_err(format!("{name}: not C-contiguous")))
}

/// `(n, 3)` rows of a flat slice.
pub fn as_vec3<T: Copy>(flat: &[T]) -> Vec<[T; 3]> {
    flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// Checks that the named lengths agree.
pub fn same_len(lens: &[(&str, usize)]) -> PyResult<usize> {
    let (first, n) = lens[0];
    for &(name, len) in &lens[1..] {
        if len != n {
            return Err(PyValueError::new_err(format!(
                "{name} has {len} rows but {first} has {n}"
            )));
        }
    }
    Ok(n)
}

/// Rows of 3 as an `(n, 3)` array.
pub fn to_array2<'py, T: numpy::Element + Copy>(
    py: Python<'py>,
    rows: &[[T; 3]],
) -> Bound<'py, PyArray2<T>> {
    let flat: Vec<T> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), 3), flat).expect("n * 3 values").into_pyarray(py)
}

/// Rows of 2 as an `(n, 2)` array.
pub fn to_array2_2<'py, T: numpy::Element + Copy>(
    py: Python<'py>,
    rows: &[[T; 2]],
) -> Bound<'py, PyArray2<T>> {
    let flat: Vec<T> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), 2), flat).expect("n * 2 values").into_pyarray(py)
}

/// A vector as a 1-d array.
pub fn to_array1<T: numpy::Element>(py: Python<'_>, v: Vec<T>) -> Bound<'_, PyArray1<T>> {
    v.into_pyarray(py)
}
