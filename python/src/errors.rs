//! Library errors as Python exceptions carrying the command line's one-line message (the CLI
//! prints `irpol: error: ` and the error with its causes, [`one_line`]), the exception chosen by
//! the error's type: `OSError` when a file could not be read or written (an I/O error among its
//! causes, [`AppError::is_io`]), `ValueError` for everything else (bad input).

use irpol::app::{one_line, AppError};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::PyErr;

/// `error` as the exception Python code should catch.
pub fn raised(error: impl Into<AppError>) -> PyErr {
    let error = error.into();
    let message = one_line(&error);
    if error.is_io() {
        PyOSError::new_err(message)
    } else {
        PyValueError::new_err(message)
    }
}

/// A bad argument (not a library error), as `ValueError`.
pub fn bad_argument(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
