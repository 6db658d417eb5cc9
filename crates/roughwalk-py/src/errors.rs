//! Maps `CoreError` to the Python exception classes of `roughwalk.errors`.
//!
//! The classes live in Python (so that users can import and subclass them);
//! this module looks them up once per raise.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use roughwalk_core::CoreError;

fn python_class<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("roughwalk.errors")?.getattr(name)
}

/// Converts a core error into the matching `roughwalk.errors` exception.
pub fn to_py(err: CoreError) -> PyErr {
    let (class, msg) = match err {
        CoreError::Terrain(m) => ("TerrainError", m),
        CoreError::RobotModel(m) => ("RobotModelError", m),
        CoreError::Planning(m) => ("PlanningError", m),
        CoreError::InvalidArgument(m) => ("InvalidArgumentError", m),
    };
    Python::attach(|py| match python_class(py, class) {
        Ok(cls) => match cls.call1((msg.clone(),)) {
            Ok(inst) => PyErr::from_value(inst),
            Err(e) => e,
        },
        Err(_) => PyValueError::new_err(msg),
    })
}

/// Extension trait: `result.py()?` turns a `CoreResult` into a `PyResult`.
pub trait IntoPyResult<T> {
    /// Converts the error side into a Python exception.
    fn py(self) -> PyResult<T>;
}

impl<T> IntoPyResult<T> for Result<T, CoreError> {
    fn py(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}
