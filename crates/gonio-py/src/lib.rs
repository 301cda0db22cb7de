//! Python bindings of gonio: the native module `gonio._gonio`, re-exported by the package `gonio`
//! (`python/gonio/__init__.py`). Built with maturin as an abi3 wheel; see `docs/PYTHON.md`.
//!
//! The bindings add no second design: reading goes through [`gonio::photometry`] and
//! [`gonio::Diagram`], samplers come from the library's factory, batches through
//! the [`gonio::Sampler`] structure-of-arrays batch calls on rayon threads with the GIL released, the battery through
//! [`gonio::check`]. What the bindings add is the conversion between numpy arrays and the
//! library's types, and the mapping of every library error to a Python exception:
//!
//! * `gonio.GonioError(ValueError)` — the base of every error from input;
//!   `gonio.ParseError` (a file or text could not be read; attributes `file`, `line`, `column`,
//!   `message`), `gonio.DiagramError` (a diagram was refused), `gonio.BuildError` (no sampler of
//!   that method for that diagram), `gonio.InputError` (an array or argument is not acceptable;
//!   rows are named by their 0-based index);
//! * `gonio.InternalError(RuntimeError)` — a bug: a panic inside the library, caught before it
//!   can cross into Python.
#![warn(missing_docs)]

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

mod arrays;
mod batch;
mod brdf;
mod diagram;
mod envmap;
mod mesh;
mod misc;
mod progress;
mod sampler;
mod types;

create_exception!(
    gonio,
    GonioError,
    PyValueError,
    "Base of every gonio error caused by input (a ValueError)."
);
create_exception!(
    gonio,
    ParseError,
    GonioError,
    "A file or text could not be read. Attributes: file, line, column (1-based; 0 when the \
     problem concerns the file as a whole or the column is unknown), message."
);
create_exception!(
    gonio,
    DiagramError,
    GonioError,
    "A goniometric diagram was refused (angles, shape or values)."
);
create_exception!(
    gonio,
    BuildError,
    GonioError,
    "No sampler of the requested method can be built for the diagram on the requested domain."
);
create_exception!(
    gonio,
    InputError,
    GonioError,
    "An array or argument is not acceptable (shape, dtype, a value outside its range); rows are \
     named by their 0-based index."
);
create_exception!(
    gonio,
    InternalError,
    PyRuntimeError,
    "A bug in gonio: a panic was caught before it could cross into Python. Please report it."
);

/// Runs `f`, turning a panic into [`InternalError`] so that no panic unwinds into Python.
pub(crate) fn no_panic<T>(what: &str, f: impl FnOnce() -> T) -> PyResult<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).map_err(|p| panic_error(what, p))
}

/// The [`InternalError`] of a caught panic's payload.
pub(crate) fn panic_error(what: &str, p: Box<dyn std::any::Any + Send>) -> PyErr {
    let msg = p
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    InternalError::new_err(format!("{what}: internal error (a bug in gonio): {msg}"))
}

/// Runs `f` with the GIL released (other Python threads run meanwhile), catching panics.
pub(crate) fn detached<T: Send>(
    py: Python<'_>,
    what: &str,
    f: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    py.detach(|| no_panic(what, f))
}

/// The native module `gonio._gonio`.
#[pymodule]
fn _gonio(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    // numpy's C API is looked up on first use, and a failure there (e.g. a Ctrl-C while numpy's
    // core module loads) would be a panic inside a call; look it up now, so that such a failure
    // is the import's own exception (KeyboardInterrupt) and later calls cannot meet it.
    py.import("numpy")?;
    // SAFETY: a query of the API's version, no argument.
    no_panic("import gonio", || unsafe {
        numpy::PY_ARRAY_API.PyArray_GetNDArrayCVersion(py)
    })
    .map_err(|e| pyo3::exceptions::PyImportError::new_err(e.to_string()))?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("GonioError", py.get_type::<GonioError>())?;
    m.add("ParseError", py.get_type::<ParseError>())?;
    m.add("DiagramError", py.get_type::<DiagramError>())?;
    m.add("BuildError", py.get_type::<BuildError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add_class::<types::PyDiagram>()?;
    m.add_class::<sampler::PySampler>()?;
    m.add_class::<envmap::PyEnvMap>()?;
    brdf::register(m)?;
    m.add_function(wrap_pyfunction!(diagram::read, m)?)?;
    m.add_function(wrap_pyfunction!(diagram::read_bytes, m)?)?;
    m.add_function(wrap_pyfunction!(diagram::example, m)?)?;
    m.add_function(wrap_pyfunction!(misc::sequence, m)?)?;
    m.add_function(wrap_pyfunction!(misc::check, m)?)?;
    m.add_function(wrap_pyfunction!(misc::convert, m)?)?;
    m.add_function(wrap_pyfunction!(misc::methods, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::texture_uv, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(misc::read_limit, m)?)?;
    m.add_function(wrap_pyfunction!(misc::set_read_limit, m)?)?;
    m.add_function(wrap_pyfunction!(misc::panic_for_test, m)?)?;
    m.add_function(wrap_pyfunction!(misc::bench_rust_batch, m)?)?;
    Ok(())
}
