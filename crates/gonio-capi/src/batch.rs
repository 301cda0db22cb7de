//! Batches: every `*_batch*` function, array-of-structs and structure-of-arrays, f64 and f32.

use super::*;
use gonio::sampler::{Sample, Vec3};
use gonio::{InvertError, Sampler};

// ---------------------------------------------------------------------------------------------
// Batches.

/// The two float types of the batch functions.
trait Real: Copy {
    fn to_f64(self) -> f64;
    fn from_f64(x: f64) -> Self;
}
impl Real for f64 {
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }
}
impl Real for f32 {
    #[inline]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    #[inline]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
}

/// K input components of n elements, array-of-structs (one pointer, stride K) or
/// structure-of-arrays (K pointers, stride 1).
struct In<T, const K: usize> {
    ptr: [*const T; K],
    stride: usize,
}

/// K output components of n elements, as [`In`].
struct Out<T, const K: usize> {
    ptr: [*mut T; K],
    stride: usize,
}

/// The byte size of `n · k` values of `T` must fit in an `isize`.
pub(crate) fn check_len<T>(n: usize, k: usize) -> Result<(), Failure> {
    match n
        .checked_mul(k)
        .and_then(|c| c.checked_mul(std::mem::size_of::<T>()))
    {
        Some(b) if b <= isize::MAX as usize => Ok(()),
        _ => Err(Failure::invalid(format!("n = {n} is too large"))),
    }
}

pub(crate) fn check_in<T>(p: *const T, what: &str) -> Result<(), Failure> {
    if p.is_null() || !p.is_aligned() {
        return Err(Failure::null(what));
    }
    Ok(())
}

impl<T: Real, const K: usize> In<T, K> {
    fn aos(p: *const T, n: usize, what: &str) -> Result<Self, Failure> {
        check_in(p, what)?;
        check_len::<T>(n, K)?;
        let mut ptr = [p; K];
        for (c, q) in ptr.iter_mut().enumerate() {
            *q = p.wrapping_add(c);
        }
        Ok(Self { ptr, stride: K })
    }
    fn soa(ps: [(*const T, &str); K], n: usize) -> Result<Self, Failure> {
        for (p, what) in ps {
            check_in(p, what)?;
        }
        check_len::<T>(n, 1)?;
        Ok(Self {
            ptr: ps.map(|(p, _)| p),
            stride: 1,
        })
    }
    /// Element i as f64.
    ///
    /// # Safety
    /// i < n, and the caller's pointers are valid for n elements.
    #[inline]
    unsafe fn get(&self, i: usize) -> [f64; K] {
        let mut v = [0.0; K];
        for (c, x) in v.iter_mut().enumerate() {
            *x = self.ptr[c].add(i * self.stride).read().to_f64();
        }
        v
    }
}

impl<T: Real, const K: usize> Out<T, K> {
    fn aos(p: *mut T, n: usize, what: &str) -> Result<Self, Failure> {
        check_out(p, what)?;
        check_len::<T>(n, K)?;
        let mut ptr = [p; K];
        for (c, q) in ptr.iter_mut().enumerate() {
            *q = p.wrapping_add(c);
        }
        Ok(Self { ptr, stride: K })
    }
    fn soa(ps: [(*mut T, &str); K], n: usize) -> Result<Self, Failure> {
        for (p, what) in ps {
            check_out(p, what)?;
        }
        check_len::<T>(n, 1)?;
        Ok(Self {
            ptr: ps.map(|(p, _)| p),
            stride: 1,
        })
    }
    /// Writes element i.
    ///
    /// # Safety
    /// i < n, and the caller's pointers are valid for n elements.
    #[inline]
    unsafe fn set(&self, i: usize, v: [f64; K]) {
        for (c, x) in v.iter().enumerate() {
            self.ptr[c].add(i * self.stride).write(T::from_f64(*x));
        }
    }
}

/// Points per chunk of a batch: the sampler's own batch path sees this many at a time.
const CHUNK: usize = 256;

/// Samples n points: directions into `dirs` and densities into `pdfs`. A point outside the unit
/// square (or NaN) stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`] naming its index (the
/// chunks before it are written).
///
/// # Safety
/// The views are valid for n elements.
unsafe fn sample_n<T: Real>(
    s: &dyn Sampler,
    n: usize,
    u: &In<T, 2>,
    dirs: &Out<T, 3>,
    pdfs: &Out<T, 1>,
) -> Result<(), Failure> {
    let mut pts = [[0.0; 2]; CHUNK];
    let mut out = [Sample::default(); CHUNK];
    let mut start = 0;
    while start < n {
        let m = CHUNK.min(n - start);
        for (k, p) in pts[..m].iter_mut().enumerate() {
            let i = start + k;
            *p = in_square(u.get(i))
                .map_err(|e| Failure::invalid(format!("point #{i}: {}", e.message)))?;
        }
        s.sample_batch(&pts[..m], &mut out[..m]);
        for (k, o) in out[..m].iter().enumerate() {
            dirs.set(start + k, o.direction);
            pdfs.set(start + k, [o.pdf]);
        }
        start += m;
    }
    Ok(())
}

/// Evaluates a batch function at n directions, a chunk of [`CHUNK`] at a time: the chunk's
/// directions are read and normalised (a zero or non-finite one stops with
/// [`GONIO_ERR_INVALID_ARGUMENT`] naming its index), `f` fills the chunk's results, which are then
/// written. Every input of a chunk is read before any of its outputs is written, so an output may
/// overwrite its own or an earlier element's input (in place).
///
/// # Safety
/// The views are valid for n elements.
unsafe fn eval_n<T: Real, const K: usize>(
    n: usize,
    dirs: &In<T, 3>,
    out: &Out<T, K>,
    mut f: impl FnMut(&[Vec3], &mut [[f64; K]]) -> Result<(), Failure>,
) -> Result<(), Failure> {
    let mut unit_dirs = [[0.0; 3]; CHUNK];
    let mut res = [[0.0; K]; CHUNK];
    let mut start = 0;
    while start < n {
        let m = CHUNK.min(n - start);
        for (k, d) in unit_dirs[..m].iter_mut().enumerate() {
            let i = start + k;
            *d = unit(dirs.get(i))
                .map_err(|e| Failure::invalid(format!("direction #{i}: {}", e.message)))?;
        }
        f(&unit_dirs[..m], &mut res[..m])?;
        for (k, r) in res[..m].iter().enumerate() {
            out.set(start + k, *r);
        }
        start += m;
    }
    Ok(())
}

/// `invert` of a chunk of unit directions through the sampler's batch path: a point, or NaN for a
/// direction outside the domain or of density 0 (no preimage).
fn invert_or_nan(s: &dyn Sampler, dirs: &[Vec3], out: &mut [[f64; 2]]) -> Result<(), Failure> {
    let mut res = [Ok([0.0; 2]); CHUNK];
    let res = &mut res[..dirs.len()];
    s.invert_batch(dirs, res);
    for (o, r) in out.iter_mut().zip(res.iter()) {
        *o = match *r {
            Ok(p) => p,
            Err(InvertError::OutsideDomain | InvertError::ZeroDensity) => [f64::NAN, f64::NAN],
            Err(e @ InvertError::Unsupported) => return Err(invert_error(e)),
        };
    }
    Ok(())
}

// The generic bodies of the batch functions; the exported functions below are one line each
// (written out, not generated by a macro, so that cbindgen sees them).

unsafe fn sample_aos<T: Real>(
    sampler: *const GonioSampler,
    u: *const T,
    n: usize,
    directions: *mut T,
    pdfs: *mut T,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let u = In::<T, 2>::aos(u, n, "u")?;
        let d = Out::<T, 3>::aos(directions, n, "directions")?;
        let p = Out::<T, 1>::aos(pdfs, n, "pdfs")?;
        sample_n(s.inner.as_ref(), n, &u, &d, &p)
    })
}

#[allow(clippy::too_many_arguments)]
unsafe fn sample_soa<T: Real>(
    sampler: *const GonioSampler,
    u: *const T,
    v: *const T,
    n: usize,
    x: *mut T,
    y: *mut T,
    z: *mut T,
    pdfs: *mut T,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let uv = In::<T, 2>::soa([(u, "u"), (v, "v")], n)?;
        let d = Out::<T, 3>::soa([(x, "x"), (y, "y"), (z, "z")], n)?;
        let p = Out::<T, 1>::soa([(pdfs, "pdfs")], n)?;
        sample_n(s.inner.as_ref(), n, &uv, &d, &p)
    })
}

/// A density of a sampler at a chunk of unit directions (pdf or target pdf).
type DensityFn = fn(&dyn Sampler, &[Vec3], &mut [[f64; 1]]);

/// The pdf through the sampler's batch path (the SIMD kernels of the HDS maps).
fn pdf_of(s: &dyn Sampler, dirs: &[Vec3], out: &mut [[f64; 1]]) {
    s.pdf_batch(dirs, out.as_flattened_mut());
}

/// The target density, one direction at a time (no sampler has a batch path for it).
fn target_of(s: &dyn Sampler, dirs: &[Vec3], out: &mut [[f64; 1]]) {
    for (o, d) in out.iter_mut().zip(dirs) {
        *o = [s.target_pdf(*d)];
    }
}

unsafe fn density_aos<T: Real>(
    sampler: *const GonioSampler,
    directions: *const T,
    n: usize,
    out: *mut T,
    f: DensityFn,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::aos(directions, n, "directions")?;
        let o = Out::<T, 1>::aos(out, n, "out")?;
        eval_n(n, &d, &o, |dirs, res| {
            f(s.inner.as_ref(), dirs, res);
            Ok(())
        })
    })
}

unsafe fn density_soa<T: Real>(
    sampler: *const GonioSampler,
    x: *const T,
    y: *const T,
    z: *const T,
    n: usize,
    out: *mut T,
    f: DensityFn,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::soa([(x, "x"), (y, "y"), (z, "z")], n)?;
        let o = Out::<T, 1>::soa([(out, "out")], n)?;
        eval_n(n, &d, &o, |dirs, res| {
            f(s.inner.as_ref(), dirs, res);
            Ok(())
        })
    })
}

unsafe fn invert_aos<T: Real>(
    sampler: *const GonioSampler,
    directions: *const T,
    n: usize,
    uv: *mut T,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::aos(directions, n, "directions")?;
        let o = Out::<T, 2>::aos(uv, n, "uv")?;
        // A method without inverse says so for every n, 0 included (issue 25).
        if s.inner.invert([0.0, 0.0, 1.0]) == Err(InvertError::Unsupported) {
            return Err(invert_error(InvertError::Unsupported));
        }
        eval_n(n, &d, &o, |dirs, res| {
            invert_or_nan(s.inner.as_ref(), dirs, res)
        })
    })
}

#[allow(clippy::too_many_arguments)]
unsafe fn invert_soa<T: Real>(
    sampler: *const GonioSampler,
    x: *const T,
    y: *const T,
    z: *const T,
    n: usize,
    u: *mut T,
    v: *mut T,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::soa([(x, "x"), (y, "y"), (z, "z")], n)?;
        let o = Out::<T, 2>::soa([(u, "u"), (v, "v")], n)?;
        // A method without inverse says so for every n, 0 included (issue 25).
        if s.inner.invert([0.0, 0.0, 1.0]) == Err(InvertError::Unsupported) {
            return Err(invert_error(InvertError::Unsupported));
        }
        eval_n(n, &d, &o, |dirs, res| {
            invert_or_nan(s.inner.as_ref(), dirs, res)
        })
    })
}

/// Samples `n` points of the square given as interleaved pairs `u[2i], u[2i+1]` (double):
/// directions into `directions[3i..3i+3]`, densities (per sr) into `pdfs[i]`.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_sample_batch(
    sampler: *const GonioSampler,
    u: *const f64,
    n: usize,
    directions: *mut f64,
    pdfs: *mut f64,
) -> GonioStatus {
    sample_aos::<f64>(sampler, u, n, directions, pdfs)
}

/// Samples `n` points of the square given as arrays `u[i]`, `v[i]` (double): directions
/// into `x[i]`, `y[i]`, `z[i]`, densities (per sr) into `pdfs[i]`.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gonio_sample_batch_soa(
    sampler: *const GonioSampler,
    u: *const f64,
    v: *const f64,
    n: usize,
    x: *mut f64,
    y: *mut f64,
    z: *mut f64,
    pdfs: *mut f64,
) -> GonioStatus {
    sample_soa::<f64>(sampler, u, v, n, x, y, z, pdfs)
}

/// The sampler's density (per sr) at `n` directions given as interleaved triples
/// `directions[3i..3i+3]` (double; normalised first), into `out[i]`. A zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf_batch(
    sampler: *const GonioSampler,
    directions: *const f64,
    n: usize,
    out: *mut f64,
) -> GonioStatus {
    density_aos::<f64>(sampler, directions, n, out, pdf_of)
}

/// The sampler's density (per sr) at `n` directions given as arrays `x[i]`, `y[i]`, `z[i]`
/// (double; normalised first), into `out[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf_batch_soa(
    sampler: *const GonioSampler,
    x: *const f64,
    y: *const f64,
    z: *const f64,
    n: usize,
    out: *mut f64,
) -> GonioStatus {
    density_soa::<f64>(sampler, x, y, z, n, out, pdf_of)
}

/// The target density (per sr) at `n` directions given as interleaved triples
/// `directions[3i..3i+3]` (double; normalised first), into `out[i]`. A zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf_batch(
    sampler: *const GonioSampler,
    directions: *const f64,
    n: usize,
    out: *mut f64,
) -> GonioStatus {
    density_aos::<f64>(sampler, directions, n, out, target_of)
}

/// The target density (per sr) at `n` directions given as arrays `x[i]`, `y[i]`, `z[i]`
/// (double; normalised first), into `out[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf_batch_soa(
    sampler: *const GonioSampler,
    x: *const f64,
    y: *const f64,
    z: *const f64,
    n: usize,
    out: *mut f64,
) -> GonioStatus {
    density_soa::<f64>(sampler, x, y, z, n, out, target_of)
}

/// Inverts `n` directions given as interleaved triples `directions[3i..3i+3]` (double)
/// into interleaved points `uv[2i], uv[2i+1]`. A direction outside the domain or of density 0 gives (NaN, NaN)
/// and the batch goes on; a method without inverse is [`GONIO_ERR_UNSUPPORTED`]; a zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_invert_batch(
    sampler: *const GonioSampler,
    directions: *const f64,
    n: usize,
    uv: *mut f64,
) -> GonioStatus {
    invert_aos::<f64>(sampler, directions, n, uv)
}

/// Inverts `n` directions given as arrays `x[i]`, `y[i]`, `z[i]` (double) into `u[i]`,
/// `v[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gonio_invert_batch_soa(
    sampler: *const GonioSampler,
    x: *const f64,
    y: *const f64,
    z: *const f64,
    n: usize,
    u: *mut f64,
    v: *mut f64,
) -> GonioStatus {
    invert_soa::<f64>(sampler, x, y, z, n, u, v)
}

/// Samples `n` points of the square given as interleaved pairs `u[2i], u[2i+1]` (float; computed in double, results rounded):
/// directions into `directions[3i..3i+3]`, densities (per sr) into `pdfs[i]`.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_sample_batch_f32(
    sampler: *const GonioSampler,
    u: *const f32,
    n: usize,
    directions: *mut f32,
    pdfs: *mut f32,
) -> GonioStatus {
    sample_aos::<f32>(sampler, u, n, directions, pdfs)
}

/// Samples `n` points of the square given as arrays `u[i]`, `v[i]` (float; computed in double, results rounded): directions
/// into `x[i]`, `y[i]`, `z[i]`, densities (per sr) into `pdfs[i]`.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gonio_sample_batch_soa_f32(
    sampler: *const GonioSampler,
    u: *const f32,
    v: *const f32,
    n: usize,
    x: *mut f32,
    y: *mut f32,
    z: *mut f32,
    pdfs: *mut f32,
) -> GonioStatus {
    sample_soa::<f32>(sampler, u, v, n, x, y, z, pdfs)
}

/// The sampler's density (per sr) at `n` directions given as interleaved triples
/// `directions[3i..3i+3]` (float; computed in double, results rounded; normalised first), into `out[i]`. A zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf_batch_f32(
    sampler: *const GonioSampler,
    directions: *const f32,
    n: usize,
    out: *mut f32,
) -> GonioStatus {
    density_aos::<f32>(sampler, directions, n, out, pdf_of)
}

/// The sampler's density (per sr) at `n` directions given as arrays `x[i]`, `y[i]`, `z[i]`
/// (float; computed in double, results rounded; normalised first), into `out[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf_batch_soa_f32(
    sampler: *const GonioSampler,
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
    out: *mut f32,
) -> GonioStatus {
    density_soa::<f32>(sampler, x, y, z, n, out, pdf_of)
}

/// The target density (per sr) at `n` directions given as interleaved triples
/// `directions[3i..3i+3]` (float; computed in double, results rounded; normalised first), into `out[i]`. A zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf_batch_f32(
    sampler: *const GonioSampler,
    directions: *const f32,
    n: usize,
    out: *mut f32,
) -> GonioStatus {
    density_aos::<f32>(sampler, directions, n, out, target_of)
}

/// The target density (per sr) at `n` directions given as arrays `x[i]`, `y[i]`, `z[i]`
/// (float; computed in double, results rounded; normalised first), into `out[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf_batch_soa_f32(
    sampler: *const GonioSampler,
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
    out: *mut f32,
) -> GonioStatus {
    density_soa::<f32>(sampler, x, y, z, n, out, target_of)
}

/// Inverts `n` directions given as interleaved triples `directions[3i..3i+3]` (float; computed in double, results rounded)
/// into interleaved points `uv[2i], uv[2i+1]`. A direction outside the domain or of density 0 gives (NaN, NaN)
/// and the batch goes on; a method without inverse is [`GONIO_ERR_UNSUPPORTED`]; a zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_invert_batch_f32(
    sampler: *const GonioSampler,
    directions: *const f32,
    n: usize,
    uv: *mut f32,
) -> GonioStatus {
    invert_aos::<f32>(sampler, directions, n, uv)
}

/// Inverts `n` directions given as arrays `x[i]`, `y[i]`, `z[i]` (float; computed in double, results rounded) into `u[i]`,
/// `v[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gonio_invert_batch_soa_f32(
    sampler: *const GonioSampler,
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
    u: *mut f32,
    v: *mut f32,
) -> GonioStatus {
    invert_soa::<f32>(sampler, x, y, z, n, u, v)
}
