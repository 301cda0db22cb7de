//! The `progress=` option of the long calls (`check`, `EnvMap`, `read_brdf`, `texture_uv`):
//! `None`, `True` (a tqdm bar, or a line per stage on stderr without tqdm) or a callable
//! `f(what, fraction)`, normalised by the Python helper `gonio._progress.make`. Reports are made
//! with the GIL held, from the calling thread: a call whose work runs detached reports its stages
//! between them, and `check` forwards its battery's progress through [`crate::misc`]'s
//! interruptible runner, which polls it.

use pyo3::prelude::*;

/// A normalised `progress=` value: the callback and the closer of its bar (both optional).
pub(crate) struct Progress<'py> {
    callback: Option<Bound<'py, PyAny>>,
    close: Option<Bound<'py, PyAny>>,
}

impl<'py> Progress<'py> {
    /// `progress` as given to the call (`desc`: the call's name, for the bar).
    pub(crate) fn new(
        py: Python<'py>,
        progress: Option<&Bound<'py, PyAny>>,
        desc: &str,
    ) -> PyResult<Self> {
        let Some(p) = progress.filter(|p| !p.is_none()) else {
            return Ok(Progress {
                callback: None,
                close: None,
            });
        };
        let made = py
            .import("gonio._progress")?
            .call_method1("make", (p, desc))?;
        let (callback, close): (Bound<'py, PyAny>, Bound<'py, PyAny>) = made.extract()?;
        let some = |b: Bound<'py, PyAny>| (!b.is_none()).then_some(b);
        Ok(Progress {
            callback: some(callback),
            close: some(close),
        })
    }

    /// Whether anything listens.
    pub(crate) fn active(&self) -> bool {
        self.callback.is_some()
    }

    /// Reports `what` running with `fraction` of the call done.
    pub(crate) fn report(&self, what: &str, fraction: f64) -> PyResult<()> {
        match &self.callback {
            Some(cb) => cb.call1((what, fraction.clamp(0.0, 1.0))).map(|_| ()),
            None => Ok(()),
        }
    }
}

impl Drop for Progress<'_> {
    fn drop(&mut self) {
        if let Some(close) = self.close.take() {
            // A bar that cannot close leaves a line on the terminal: nothing to report.
            let _ = close.call0();
        }
    }
}
