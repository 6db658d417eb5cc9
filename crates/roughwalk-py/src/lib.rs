//! PyO3 bindings of `roughwalk-core`. Type and error conversion only: every
//! computation lives in the core crate. One file per core concept, each with
//! a `register` function called here.

// PyO3 extracts arguments by value (readonly array views, owned strings), so
// `needless_pass_by_value` fires on every binding; tuple-of-arrays return types
// are what the Python API promises, so `type_complexity` adds nothing here.
#![allow(clippy::needless_pass_by_value, clippy::type_complexity)]

use pyo3::prelude::*;

mod errors;
mod footstep;
mod heightfield;
mod robot;
mod sdf;
mod trajectory;

/// The compiled module `roughwalk._core`.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    heightfield::register(m)?;
    sdf::register(m)?;
    robot::register(m)?;
    footstep::register(m)?;
    trajectory::register(m)?;
    Ok(())
}
