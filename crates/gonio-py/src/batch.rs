//! Batches of rows with the GIL released: consecutive slices with signal checks between them,
//! and a row-wise map on rayon threads. Used by every class's batch methods.

use crate::{arrays, detached, InputError};
use gonio::batch::PAR_CHUNK;
use numpy::PyArray1;
use pyo3::prelude::*;
use rayon::prelude::*;

/// Rows per slice of a batch: between slices the GIL is taken back and pending signals are
/// handled (Ctrl-C raises KeyboardInterrupt within one slice's time, a few ms).
pub(crate) const SLICE: usize = 1 << 18;

/// Runs `f` on consecutive ranges of at most [`SLICE`] of `n` rows with the GIL released,
/// handling signals between them; `f` returns the first bad row of its range (relative to the
/// range's start), which stops the batch. Returns the first bad row of the whole batch.
pub(crate) fn in_slices(
    py: Python<'_>,
    what: &str,
    n: usize,
    mut f: impl FnMut(std::ops::Range<usize>) -> Option<usize> + Send,
) -> PyResult<Option<usize>> {
    let mut start = 0;
    while start < n {
        let end = n.min(start + SLICE);
        if let Some(k) = detached(py, what, || f(start..end))? {
            return Ok(Some(start + k));
        }
        start = end;
        if start < n {
            py.check_signals()?;
        }
    }
    Ok(None)
}

/// Applies `f` to every row on all rayon threads with the GIL released, into a new array; `None`
/// from `f` marks an invalid row, and the first invalid row (lowest index) is reported.
pub(crate) fn map_rows<'py, const K: usize>(
    py: Python<'py>,
    what: &str,
    rows: &[[f64; K]],
    f: impl Fn(&[f64; K]) -> Option<f64> + Sync,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let arr = arrays::output(py, None, what, &[rows.len()])?;
    let bad = arrays::fill(&arr, what, |out| {
        in_slices(py, what, rows.len(), |r| {
            let rows = &rows[r.clone()];
            out[r]
                .par_chunks_mut(PAR_CHUNK)
                .zip(rows.par_chunks(PAR_CHUNK))
                .enumerate()
                .filter_map(|(c, (o, r))| {
                    let mut first_bad = None;
                    for (k, (o, r)) in o.iter_mut().zip(r).enumerate() {
                        match f(r) {
                            Some(v) => *o = v,
                            None => {
                                first_bad.get_or_insert(c * PAR_CHUNK + k);
                            }
                        }
                    }
                    first_bad
                })
                .min()
        })
    })?;
    match bad {
        None => Ok(arr),
        Some(k) => Err(InputError::new_err(format!(
            "{what}: row {k}: direction {} is zero or not finite",
            fmt_row(&rows[k])
        ))),
    }
}

/// A row of numbers for a message, `(x, y, z)`, each in the shortest form that reads back (exponent
/// form for tiny and huge magnitudes: no 300-digit decimals).
pub(crate) fn fmt_row(r: &[f64]) -> String {
    let parts: Vec<String> = r.iter().map(|&x| gonio::decimal::shortest(x)).collect();
    format!("({})", parts.join(", "))
}
