//! Python bindings (placeholder).
use pyo3::prelude::*;

/// The module.
#[pymodule]
fn het_bssrdf(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
