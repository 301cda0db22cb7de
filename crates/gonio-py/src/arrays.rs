//! numpy ↔ Rust: batches of points (n, 2) and directions (n, 3) in, new float64 arrays out.
//!
//! Inputs may be float64 or float32 numpy arrays in C or Fortran order (or any strides), or
//! anything `numpy.asarray(x, dtype=float64)` accepts. A C-contiguous float64 array is read in
//! place (no copy); every other input is copied once into a contiguous float64 buffer.

use crate::InputError;
use numpy::ndarray::{Array1, Array2, ArrayView2, Dimension, IxDyn};
use numpy::{
    IntoPyArray, PyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use std::borrow::Cow;

/// A batch of rows of `K` coordinates, borrowed from numpy when possible.
pub(crate) struct Rows<'py, const K: usize> {
    f64: Option<PyReadonlyArray2<'py, f64>>,
    owned: Vec<[f64; K]>,
}

impl<const K: usize> Rows<'_, K> {
    /// The rows as one contiguous slice.
    pub(crate) fn as_slice(&self) -> Cow<'_, [[f64; K]]> {
        // `f64` is only set for a C-contiguous array (checked in `rows`).
        if let Some(a) = &self.f64 {
            if let Ok(s) = a.as_slice() {
                let (rows, rest) = s.as_chunks::<K>();
                debug_assert!(rest.is_empty());
                return Cow::Borrowed(rows);
            }
        }
        Cow::Borrowed(&self.owned)
    }
}

fn copy_rows<T: Copy + Into<f64>, const K: usize>(a: ArrayView2<'_, T>) -> Vec<[f64; K]> {
    a.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k].into()))
        .collect()
}

/// Reads `obj` as an array of shape (n, K); `what` names the argument in messages.
pub(crate) fn rows<'py, const K: usize>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Rows<'py, K>> {
    let py = obj.py();
    // Anything that is not already a float64/float32 numpy array goes through numpy.asarray.
    let arr: Bound<'py, PyUntypedArray> = match obj.cast::<PyUntypedArray>() {
        Ok(a) => a.clone(),
        Err(_) => {
            let np = py.import("numpy")?;
            let a = np
                .call_method1("asarray", (obj, np.getattr("float64")?))
                .map_err(|e| {
                    InputError::new_err(format!(
                        "{what}: cannot be read as an array of numbers ({})",
                        e.value(py)
                    ))
                })?;
            a.cast_into::<PyUntypedArray>()
                .map_err(|e| InputError::new_err(format!("{what}: {e}")))?
        }
    };
    let shape = arr.shape().to_vec();
    if shape.len() != 2 || shape[1] != K {
        return Err(InputError::new_err(format!(
            "{what}: expected an array of shape (n, {K}), got shape {}",
            fmt_shape(&shape)
        )));
    }
    if let Ok(a) = arr.cast::<PyArray2<f64>>() {
        let ro = a.readonly();
        // `as_slice` also accepts Fortran order: only a C-ordered array is row-major.
        if a.is_c_contiguous() && ro.as_slice().is_ok() {
            return Ok(Rows {
                f64: Some(ro),
                owned: Vec::new(),
            });
        }
        return Ok(Rows {
            f64: None,
            owned: copy_rows(ro.as_array()),
        });
    }
    if let Ok(a) = arr.cast::<PyArray2<f32>>() {
        let ro = a.readonly();
        return Ok(Rows {
            f64: None,
            owned: copy_rows(ro.as_array()),
        });
    }
    // Other dtypes (integers, float16, ...): let numpy convert, refusing what it cannot.
    let np = py.import("numpy")?;
    let a = np
        .call_method1("asarray", (&arr, np.getattr("float64")?))
        .map_err(|e| {
            InputError::new_err(format!(
                "{what}: dtype {} cannot be converted to float64 ({})",
                arr.dtype(),
                e.value(py)
            ))
        })?;
    let a = a
        .cast_into::<PyArray2<f64>>()
        .map_err(|e| InputError::new_err(format!("{what}: {e}")))?;
    let ro = a.readonly();
    let owned = copy_rows(ro.as_array());
    Ok(Rows { f64: None, owned })
}

fn fmt_shape(s: &[usize]) -> String {
    match s {
        [a] => format!("({a},)"),
        _ => format!(
            "({})",
            s.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// A 1-D float64 array of angles or values, copied.
pub(crate) fn vector(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let a = np
        .call_method1("asarray", (obj, np.getattr("float64")?))
        .map_err(|e| {
            InputError::new_err(format!(
                "{what}: cannot be read as numbers ({})",
                e.value(py)
            ))
        })?;
    let a = a.cast_into::<PyUntypedArray>()?;
    if a.ndim() != 1 {
        return Err(InputError::new_err(format!(
            "{what}: expected a 1-D array, got shape {}",
            fmt_shape(a.shape())
        )));
    }
    let a = a.cast_into::<PyArray1<f64>>()?;
    Ok(a.readonly().as_array().to_vec())
}

/// A 2-D float64 table, copied row-major, with its shape.
pub(crate) fn table(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<f64>, [usize; 2])> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let a = np
        .call_method1("asarray", (obj, np.getattr("float64")?))
        .map_err(|e| {
            InputError::new_err(format!(
                "{what}: cannot be read as a table of numbers ({})",
                e.value(py)
            ))
        })?;
    let a = a.cast_into::<PyUntypedArray>()?;
    if a.ndim() != 2 {
        return Err(InputError::new_err(format!(
            "{what}: expected a 2-D array, got shape {}",
            fmt_shape(a.shape())
        )));
    }
    let a = a.cast_into::<PyArray2<f64>>()?;
    let ro = a.readonly();
    let v = ro.as_array();
    let shape = [v.nrows(), v.ncols()];
    Ok((v.iter().copied().collect(), shape))
}

/// A new (n, K) float64 array from a row-major buffer of n·K values (no copy).
pub(crate) fn new_2d<'py>(py: Python<'py>, data: Vec<f64>, k: usize) -> Bound<'py, PyArray2<f64>> {
    let n = data.len() / k;
    Array2::from_shape_vec((n, k), data)
        .expect("buffer of n·k values")
        .into_pyarray(py)
}

/// The output array of a batch, of shape `shape` (`[n]` or `[n, k]`): the caller's `out`, which
/// must be a C-contiguous float64 numpy array of that shape (InputError naming `what` otherwise;
/// [`fill`] checks the rest), or a new array of zeros allocated by numpy. numpy asks the kernel for huge
/// pages for arrays of 4 MiB and more, so filling a fresh output faults 512× fewer pages than a
/// fresh `Vec` (whose 4 KiB page faults took ~20 % of `Sampler.sample`).
pub(crate) fn output<'py, D: Dimension>(
    py: Python<'py>,
    out: Option<&Bound<'py, PyAny>>,
    what: &str,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArray<f64, D>>> {
    let want = fmt_shape(shape);
    let Some(out) = out else {
        let dim = D::from_dimension(&IxDyn(shape)).ok_or_else(|| {
            crate::InternalError::new_err(format!("{what}: an output of shape {want}"))
        })?;
        return Ok(PyArray::zeros(py, dim, false));
    };
    let a = out.cast::<PyArray<f64, D>>().map_err(|_| {
        InputError::new_err(format!(
            "{what}: expected a float64 numpy array of shape {want}"
        ))
    })?;
    if a.shape() != shape {
        return Err(InputError::new_err(format!(
            "{what}: shape {} where {want} is needed",
            fmt_shape(a.shape())
        )));
    }
    // `fill` accepts any contiguous data, and a Fortran-ordered array is contiguous too.
    if !a.is_c_contiguous() {
        return Err(InputError::new_err(format!("{what}: must be C-contiguous")));
    }
    Ok(a.clone())
}

/// Runs `fill` on the contiguous data of `a`, an output array from [`output`]. Raises InputError
/// when `a` is not C-contiguous and aligned, cannot be written, or overlaps an array the call is
/// reading or writing (numpy's borrow check).
pub(crate) fn fill<'py, D: Dimension, T>(
    a: &Bound<'py, PyArray<f64, D>>,
    what: &str,
    fill: impl FnOnce(&mut [f64]) -> PyResult<T>,
) -> PyResult<T> {
    let mut w = a.try_readwrite().map_err(|e| {
        InputError::new_err(format!(
            "{what}: cannot be written ({e}): it is read-only or overlaps another argument"
        ))
    })?;
    let data = w.as_slice_mut().map_err(|e| {
        InputError::new_err(format!("{what}: must be C-contiguous and aligned ({e})"))
    })?;
    fill(data)
}

/// A new 1-D float64 array (no copy).
pub(crate) fn new_1d<'py>(py: Python<'py>, data: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    Array1::from_vec(data).into_pyarray(py)
}
