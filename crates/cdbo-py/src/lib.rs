//! `import cdbo`: the cdbo library for Python (pyo3, abi3 for CPython ≥ 3.9).
//!
//! The native module `cdbo._cdbo` binds the library, not the command line: the ask/tell
//! `optimizer`s, persistent `study` files, tracks, cars, the simulator and the policy
//! (`sim`), and the library's own race loop (`race`). The pure-Python part of the package
//! (`python/cdbo/`) adds the gymnasium environment and pandas output.
//!
//! Library errors become `ValueError` (bad input) or `OSError` (files, study databases) with
//! the library's one-line message; the GIL is released while a lap, a suggestion or a fit runs.

mod convert;
mod optimizer;
mod preset;
mod race;
mod sim;
mod study;

use pyo3::prelude::*;

/// The native part of the `cdbo` package.
#[pymodule]
fn _cdbo(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "METHODS",
        cdbo::method::Method::ALL.map(|m| m.name()).to_vec(),
    )?;
    m.add(
        "PRESETS",
        cdbo::method::Preset::ALL.map(|p| p.name()).to_vec(),
    )?;
    m.add("DEFAULT_BETA", cdbo::acquisition::ucb::DEFAULT_BETA)?;
    m.add("DEFAULT_BOX_RADIUS", cdbo::optimizers::DEFAULT_BOX_RADIUS)?;
    m.add(
        "LEARNING_OFF_TRACK_MARGIN",
        cdbo::sim::lap::LEARNING_OFF_TRACK_MARGIN,
    )?;
    m.add_class::<optimizer::PyOptimizer>()?;
    m.add_class::<study::PyStudy>()?;
    m.add_class::<study::PyTrial>()?;
    m.add_class::<sim::PyTrack>()?;
    m.add_class::<sim::PyCar>()?;
    m.add_class::<sim::PySimulator>()?;
    m.add_class::<sim::PyLapResult>()?;
    m.add_class::<sim::PyPolicy>()?;
    m.add_class::<sim::PyLimit>()?;
    m.add_class::<race::PyRaceResult>()?;
    m.add_function(wrap_pyfunction!(sim::limit, m)?)?;
    m.add_function(wrap_pyfunction!(race::race, m)?)?;
    m.add_function(wrap_pyfunction!(race::resolve_line, m)?)?;
    m.add_function(wrap_pyfunction!(preset::resolve_stack, m)?)?;
    Ok(())
}
