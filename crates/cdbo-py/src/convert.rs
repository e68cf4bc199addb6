//! Between Python and the library: errors, vectors, data folders.

use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{
    PyFileExistsError, PyFileNotFoundError, PyOSError, PyRuntimeError, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use cdbo::Error;
use cdbo::data_path::DataPath;

/// A library error as a Python exception with the library's one-line message: files and
/// study databases raise `OSError` (`FileNotFoundError` for a missing study,
/// `FileExistsError` for one that already exists), everything else — bad values, unknown
/// names, unparsable files — `ValueError`.
pub fn to_py(e: Error) -> PyErr {
    let message = e.to_string();
    match e {
        Error::AlreadyExists { .. } => PyFileExistsError::new_err(message),
        Error::NoStudy { .. } => PyFileNotFoundError::new_err(message),
        Error::Io { .. }
        | Error::Busy { .. }
        | Error::NotAStudy { .. }
        | Error::Sql { .. }
        | Error::Command { .. } => PyOSError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}

/// A library result as a Python one.
pub trait IntoPy<T> {
    /// The value, or the error as a Python exception.
    fn py(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for cdbo::Result<T> {
    fn py(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}

/// A vector of floats from a 1-D NumPy array (read in place) or any sequence of numbers.
pub fn vector(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    if let Ok(a) = obj.extract::<PyReadonlyArray1<'_, f64>>() {
        return Ok(match a.as_slice() {
            Ok(s) => s.to_vec(),
            Err(_) => a.as_array().to_vec(),
        });
    }
    obj.extract::<Vec<f64>>().map_err(|_| {
        PyValueError::new_err(format!(
            "{what} must be a 1-D array or a sequence of numbers, got {}",
            obj.get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        ))
    })
}

/// A 1-D NumPy array of floats.
pub type Array<'py> = Bound<'py, PyArray1<f64>>;

/// A named column of a table of `T` rows.
pub type Column<T> = (&'static str, fn(&T) -> f64);

/// The columns of `rows` as a dict of NumPy arrays.
pub fn columns<'py, T>(
    py: Python<'py>,
    rows: &[T],
    cols: &[Column<T>],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, f) in cols {
        d.set_item(name, array(py, rows.iter().map(f).collect()))?;
    }
    Ok(d)
}

/// A NumPy array owning `v`.
pub fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

/// The data folders: `data_dir` (one folder or a list) first, then `CDBO_DATA_PATH` and the
/// TORCS / Speed Dreams install folders, as on the command line.
pub fn data_path(data_dir: Option<&Bound<'_, PyAny>>) -> PyResult<DataPath> {
    let extra: Vec<PathBuf> = match data_dir {
        None => Vec::new(),
        Some(d) if d.is_none() => Vec::new(),
        Some(d) => match d.extract::<PathBuf>() {
            Ok(p) => vec![p],
            Err(_) => d.extract::<Vec<PathBuf>>().map_err(|_| {
                PyValueError::new_err("data_dir must be a folder or a list of folders")
            })?,
        },
    };
    Ok(DataPath::new(&extra))
}

/// Locks a value shared with threads that run without the GIL.
pub fn lock<T: ?Sized>(m: &Mutex<T>) -> PyResult<MutexGuard<'_, T>> {
    m.lock()
        .map_err(|_| PyRuntimeError::new_err("a previous call panicked; the object is unusable"))
}
