//! numpy ↔ Rust: batches of points (n, 2) and directions (n, 3) in, float64 arrays out.
//!
//! Inputs may be numpy arrays of a real dtype (bool, integers, float16/32/64) in C or Fortran
//! order (or any strides), or anything `numpy.asarray(x)` turns into one. Complex, datetime,
//! timedelta, structured, string and object arrays are refused (InputError): numpy would convert
//! some of them silently (dropping an imaginary part, parsing text). A C-contiguous float64 array
//! is read in place (no copy); every other input is copied once into a contiguous float64 buffer,
//! allocated fallibly (MemoryError, never an abort).
//!
//! Outputs are allocated by numpy through a call that reports failure (MemoryError), or are the
//! caller's `out=` arrays, which must not share memory with an input read in place or with each
//! other: overlap is decided by address range, as `numpy.shares_memory` does for contiguous
//! arrays, whatever objects own the memory.

use crate::InputError;
use numpy::ndarray::{ArrayView2, Dimension};
use numpy::npyffi::npy_intp;
use numpy::{
    Element, PyArray, PyArray1, PyArray2, PyArrayDescrMethods, PyArrayMethods, PyReadonlyArray2,
    PyUntypedArray, PyUntypedArrayMethods, PY_ARRAY_API,
};
use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError};
use pyo3::prelude::*;
use std::borrow::Cow;

/// A half-open range of addresses `[start, end)` that an array's elements occupy.
pub(crate) type Span = Option<(usize, usize)>;

/// A batch of rows of `K` coordinates, borrowed from numpy when possible.
pub(crate) struct Rows<'py, const K: usize> {
    f64: Option<PyReadonlyArray2<'py, f64>>,
    owned: Vec<[f64; K]>,
    /// The memory read in place (None when the rows were copied or there are none).
    pub(crate) span: Span,
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

/// The address range of the elements of an array (numpy's `byte_bounds`); None when empty.
pub(crate) fn span<T: Element, D: Dimension>(a: &Bound<'_, PyArray<T, D>>) -> Span {
    let shape = a.shape();
    if shape.contains(&0) {
        return None;
    }
    let base = a.data() as usize as i128;
    let (mut lo, mut hi) = (base, base);
    for (&n, &s) in shape.iter().zip(a.strides()) {
        let ext = s as i128 * (n as i128 - 1);
        if ext < 0 {
            lo += ext;
        } else {
            hi += ext;
        }
    }
    Some((lo as usize, hi as usize + std::mem::size_of::<T>()))
}

/// InputError when two of the named spans overlap (the later one is named).
pub(crate) fn check_disjoint(spans: &[(&str, Span)]) -> PyResult<()> {
    for (j, (b_name, b)) in spans.iter().enumerate() {
        for (a_name, a) in &spans[..j] {
            if let (Some(a), Some(b)) = (a, b) {
                if a.0 < b.1 && b.0 < a.1 {
                    return Err(InputError::new_err(format!(
                        "{b_name}: shares memory with {a_name}; pass arrays that do not overlap"
                    )));
                }
            }
        }
    }
    Ok(())
}

/// A `MemoryError` naming what could not be allocated.
pub(crate) fn no_memory(what: &str, bytes: usize) -> PyErr {
    PyMemoryError::new_err(format!(
        "{what}: cannot allocate {bytes} bytes for a converted copy"
    ))
}

/// A vector of `n` elements allocated fallibly (MemoryError instead of an abort).
pub(crate) fn try_vec<T>(n: usize, what: &str) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| no_memory(what, n.saturating_mul(std::mem::size_of::<T>())))?;
    Ok(v)
}

fn copy_rows<T: Copy + Into<f64>, const K: usize>(
    a: ArrayView2<'_, T>,
    what: &str,
) -> PyResult<Vec<[f64; K]>> {
    let mut v = try_vec(a.nrows(), what)?;
    v.extend(
        a.rows()
            .into_iter()
            .map(|r| std::array::from_fn(|k| r[k].into())),
    );
    Ok(v)
}

/// Errors that must reach the caller as they are, not as an InputError: memory exhaustion and
/// a signal (Ctrl-C) raised while numpy converted.
fn pass_through(py: Python<'_>, e: &PyErr) -> bool {
    e.is_instance_of::<PyMemoryError>(py) || e.is_instance_of::<PyKeyboardInterrupt>(py)
}

/// numpy's borrow check refused to read an array (another call is writing it).
fn borrow_error(what: &str, e: numpy::BorrowError) -> PyErr {
    InputError::new_err(format!(
        "{what}: cannot be read ({e}): another call is writing this array"
    ))
}

/// `obj` as a numpy array of a real dtype (bool, integer, float), converting non-arrays with
/// `numpy.asarray`; InputError for anything else.
pub(crate) fn real_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    let py = obj.py();
    let arr = match obj.cast::<PyUntypedArray>() {
        Ok(a) => a.clone(),
        Err(_) => {
            let np = py.import("numpy")?;
            let a = np.call_method1("asarray", (obj,)).map_err(|e| {
                if pass_through(py, &e) {
                    return e;
                }
                InputError::new_err(format!(
                    "{what}: cannot be read as an array of numbers ({})",
                    e.value(py)
                ))
            })?;
            a.cast_into::<PyUntypedArray>()
                .map_err(|e| InputError::new_err(format!("{what}: {e}")))?
        }
    };
    let dtype = arr.dtype();
    let kind = dtype.kind();
    if dtype.has_fields() || !matches!(kind, b'b' | b'i' | b'u' | b'f') {
        let why = match kind {
            b'c' => "complex numbers are not accepted (pass the real part explicitly)",
            b'M' | b'm' => "dates and time spans are not numbers here",
            b'S' | b'U' => "text is not accepted as numbers (convert it explicitly)",
            b'V' => "structured arrays are not accepted",
            b'O' => "object arrays are not accepted (pass an array of numbers)",
            _ => "only real numbers are accepted",
        };
        return Err(InputError::new_err(format!(
            "{what}: dtype {dtype} cannot be converted to float64: {why}"
        )));
    }
    Ok(arr)
}

/// `arr` converted to float64 by numpy (a new array), MemoryError and signals passed through.
fn to_f64<'py>(arr: &Bound<'py, PyUntypedArray>, what: &str) -> PyResult<Bound<'py, PyAny>> {
    let py = arr.py();
    let np = py.import("numpy")?;
    np.call_method1("asarray", (arr, np.getattr("float64")?))
        .map_err(|e| {
            if pass_through(py, &e) {
                return e;
            }
            InputError::new_err(format!(
                "{what}: dtype {} cannot be converted to float64 ({})",
                arr.dtype(),
                e.value(py)
            ))
        })
}

/// Reads `obj` as an array of shape (n, K); `what` names the argument in messages.
pub(crate) fn rows<'py, const K: usize>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Rows<'py, K>> {
    let arr = real_array(obj, what)?;
    let shape = arr.shape().to_vec();
    if shape.len() != 2 || shape[1] != K {
        return Err(InputError::new_err(format!(
            "{what}: expected an array of shape (n, {K}), got shape {}",
            fmt_shape(&shape)
        )));
    }
    if let Ok(a) = arr.cast::<PyArray2<f64>>() {
        let ro = a.try_readonly().map_err(|e| borrow_error(what, e))?;
        // `as_slice` also accepts Fortran order: only a C-ordered array is row-major.
        if a.is_c_contiguous() && ro.as_slice().is_ok() {
            return Ok(Rows {
                span: span(a),
                f64: Some(ro),
                owned: Vec::new(),
            });
        }
        return Ok(Rows {
            f64: None,
            owned: copy_rows(ro.as_array(), what)?,
            span: None,
        });
    }
    if let Ok(a) = arr.cast::<PyArray2<f32>>() {
        let ro = a.try_readonly().map_err(|e| borrow_error(what, e))?;
        return Ok(Rows {
            f64: None,
            owned: copy_rows(ro.as_array(), what)?,
            span: None,
        });
    }
    // Other real dtypes (integers, bool, float16, ...): numpy converts.
    let a = to_f64(&arr, what)?
        .cast_into::<PyArray2<f64>>()
        .map_err(|e| InputError::new_err(format!("{what}: {e}")))?;
    let ro = a.try_readonly().map_err(|e| borrow_error(what, e))?;
    let owned = copy_rows(ro.as_array(), what)?;
    Ok(Rows {
        f64: None,
        owned,
        span: None,
    })
}

pub(crate) fn fmt_shape(s: &[usize]) -> String {
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

/// `obj` as a float64 array of `ndim` dimensions (real dtypes only), with its elements copied
/// out in row-major order and its shape.
fn copied(obj: &Bound<'_, PyAny>, what: &str, ndim: usize) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let arr = real_array(obj, what)?;
    if arr.ndim() != ndim {
        let want = if ndim == 1 { "a 1-D" } else { "a 2-D" };
        return Err(InputError::new_err(format!(
            "{what}: expected {want} array, got shape {}",
            fmt_shape(arr.shape())
        )));
    }
    let a = to_f64(&arr, what)?;
    let a = a
        .cast_into::<PyArray<f64, numpy::IxDyn>>()
        .map_err(|e| InputError::new_err(format!("{what}: {e}")))?;
    let ro = a.try_readonly().map_err(|e| borrow_error(what, e))?;
    let v = ro.as_array();
    let mut out = try_vec(v.len(), what)?;
    out.extend(v.iter().copied());
    Ok((out, v.shape().to_vec()))
}

/// A 1-D float64 array of angles or values, copied.
pub(crate) fn vector(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    Ok(copied(obj, what, 1)?.0)
}

/// A 2-D float64 table, copied row-major, with its shape.
pub(crate) fn table(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<f64>, [usize; 2])> {
    let (v, s) = copied(obj, what, 2)?;
    Ok((v, [s[0], s[1]]))
}

/// A new C-ordered array of zeros of `shape` (float64 or float32), allocated by numpy:
/// MemoryError (not a panic) when it cannot be.
pub(crate) fn zeros<'py, T: Element, D: Dimension>(
    py: Python<'py>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArray<T, D>>> {
    if D::NDIM.is_some_and(|n| n != shape.len()) {
        return Err(crate::InternalError::new_err(format!(
            "an output of shape {} of the wrong dimension",
            fmt_shape(shape)
        )));
    }
    let mut dims: Vec<npy_intp> = Vec::with_capacity(shape.len());
    for &s in shape {
        dims.push(npy_intp::try_from(s).map_err(|_| {
            PyMemoryError::new_err(format!(
                "an array of shape {} is too large",
                fmt_shape(shape)
            ))
        })?);
    }
    // SAFETY: `dims` holds `shape.len()` sizes; PyArray_Zeros steals the dtype reference and
    // returns a new reference or NULL with an exception set.
    unsafe {
        let ptr = PY_ARRAY_API.PyArray_Zeros(
            py,
            dims.len() as std::ffi::c_int,
            dims.as_mut_ptr(),
            T::get_dtype(py).into_dtype_ptr(),
            0,
        );
        let any = Bound::from_owned_ptr_or_err(py, ptr)?;
        Ok(any.cast_into_unchecked())
    }
}

/// A new (n, K) float64 (or float32) array with a copy of a row-major buffer of n·K values.
pub(crate) fn new_2d<'py, T: Element + Copy>(
    py: Python<'py>,
    data: &[T],
    k: usize,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let n = data.len().checked_div(k).unwrap_or(0);
    let a = zeros::<T, numpy::Ix2>(py, &[n, k])?;
    fill(&a, "a new array", |out| {
        out.copy_from_slice(&data[..n * k]);
        Ok(())
    })?;
    Ok(a)
}

/// A new 1-D float64 (or float32) array with a copy of `data`.
pub(crate) fn new_1d<'py, T: Element + Copy>(
    py: Python<'py>,
    data: &[T],
) -> PyResult<Bound<'py, PyArray1<T>>> {
    let a = zeros::<T, numpy::Ix1>(py, &[data.len()])?;
    fill(&a, "a new array", |out| {
        out.copy_from_slice(data);
        Ok(())
    })?;
    Ok(a)
}

/// The output array of a batch, of shape `shape` (`[n]` or `[n, k]`): the caller's `out`, which
/// must be a C-contiguous numpy array of the batch's dtype (float64, or float32 for float32
/// input) and of that shape (InputError naming `what` otherwise;
/// [`fill`] checks the rest), or a new array of zeros allocated by numpy. numpy asks the kernel for huge
/// pages for arrays of 4 MiB and more, so filling a fresh output faults 512× fewer pages than a
/// fresh `Vec` (whose 4 KiB page faults took ~20 % of `Sampler.sample`).
pub(crate) fn output<'py, T: Element, D: Dimension>(
    py: Python<'py>,
    out: Option<&Bound<'py, PyAny>>,
    what: &str,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArray<T, D>>> {
    let want = fmt_shape(shape);
    let Some(out) = out else {
        return zeros(py, shape);
    };
    let a = out.cast::<PyArray<T, D>>().map_err(|_| {
        InputError::new_err(format!(
            "{what}: expected a {} numpy array of shape {want}",
            dtype_name::<T>()
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
pub(crate) fn fill<'py, E: Element, D: Dimension, T>(
    a: &Bound<'py, PyArray<E, D>>,
    what: &str,
    fill: impl FnOnce(&mut [E]) -> PyResult<T>,
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

/// "float64" or "float32", for messages.
fn dtype_name<T: Element>() -> &'static str {
    if std::mem::size_of::<T>() == 4 {
        "float32"
    } else {
        "float64"
    }
}

/// A batch of float32 rows of `K` coordinates, borrowed from numpy when C-contiguous.
pub(crate) struct Rows32<'py, const K: usize> {
    borrowed: Option<PyReadonlyArray2<'py, f32>>,
    owned: Vec<[f32; K]>,
    /// The memory read in place (None when the rows were copied or there are none).
    pub(crate) span: Span,
}

impl<const K: usize> Rows32<'_, K> {
    /// The rows as one contiguous slice.
    pub(crate) fn as_slice(&self) -> &[[f32; K]] {
        if let Some(a) = &self.borrowed {
            if let Ok(s) = a.as_slice() {
                return s.as_chunks::<K>().0;
            }
        }
        &self.owned
    }
}

/// `obj` as float32 rows of shape (n, K) when it is a float32 numpy array (the float32 batches:
/// float32 in, float32 out); `None` for anything else, which [`rows`] reads as float64.
pub(crate) fn rows32<'py, const K: usize>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Option<Rows32<'py, K>>> {
    let Ok(a) = obj.cast::<PyArray2<f32>>() else {
        return Ok(None);
    };
    let shape = a.shape();
    if shape[1] != K {
        return Err(InputError::new_err(format!(
            "{what}: expected an array of shape (n, {K}), got shape {}",
            fmt_shape(shape)
        )));
    }
    let ro = a.try_readonly().map_err(|e| borrow_error(what, e))?;
    if a.is_c_contiguous() && ro.as_slice().is_ok() {
        return Ok(Some(Rows32 {
            span: span(a),
            borrowed: Some(ro),
            owned: Vec::new(),
        }));
    }
    let v = ro.as_array();
    let mut owned = try_vec(v.nrows(), what)?;
    owned.extend(v.rows().into_iter().map(|r| std::array::from_fn(|k| r[k])));
    Ok(Some(Rows32 {
        borrowed: None,
        owned,
        span: None,
    }))
}
