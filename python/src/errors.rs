//! Library errors as Python exceptions carrying the command line's one-line message (the CLI
//! prints `irpol: error: {error:#}`): `OSError` when a file could not be read or written,
//! `ValueError` for everything else (bad input).

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::PyErr;
use std::path::Path;

/// `error` as the exception Python code should catch. `inputs` are the files the call reads: a
/// missing one makes the error an `OSError` even where the library reports it as text.
pub fn raised(error: anyhow::Error, inputs: &[&Path]) -> PyErr {
    let message = format!("{error:#}");
    let io = error
        .chain()
        .any(|cause| cause.downcast_ref::<std::io::Error>().is_some());
    if io || inputs.iter().any(|p| !p.exists()) {
        PyOSError::new_err(message)
    } else {
        PyValueError::new_err(message)
    }
}

/// A bad argument (not a library error), as `ValueError`.
pub fn bad_argument(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
