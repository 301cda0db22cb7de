//! Batches: every `*_batch*` function, array-of-structs and structure-of-arrays, f64 and f32.
//!
//! Every batch goes through the sampler's structure-of-arrays calls
//! ([`Batches::sample_batch_soa`], [`Batches::pdf_batch_soa`], [`Batches::invert_batch_soa`] and
//! their `_f32` twins; the HDS maps' vector kernels) on [`CHUNK`] elements at a time: the chunk's
//! inputs are read (and checked, directions normalised) into columns on the stack, the trait call
//! fills result columns on the stack, and these are written to the caller's arrays. A
//! structure-of-arrays call thus copies each column once in and once out (no transpose); an
//! array-of-structs call transposes once into the columns and once back. f32 calls reach the
//! `_f32` methods with f32 data (the sampler's float32 map where it has one).

// The chunk loops index several columns by the same element number on purpose.
#![allow(clippy::needless_range_loop)]

use super::*;
use gonio::batch::CHUNK;
use gonio::{Batches, InvertError, Sampler};

// ---------------------------------------------------------------------------------------------
// Batches.

/// The two float types of the batch functions: a sample call in either is
/// `sampler.batch(T::call(job))`; the pdf and the inverse take f64 unit directions (rounded once
/// to f32 for the f32 calls).
trait Real: Copy + Default + gonio::batch::Element {
    fn to_f64(self) -> f64;
    /// [`Batches::pdf_batch_soa`] or its `_f32` twin at unit f64 directions (at most [`CHUNK`]),
    /// rounded to f32 first for the twin.
    fn pdf(s: &dyn Sampler, dir: [&[f64]; 3], pdf: &mut [Self]);
    /// [`Batches::invert_batch_soa`] or its `_f32` twin, as [`Real::pdf`].
    fn invert(s: &dyn Sampler, dir: [&[f64]; 3], uv: [&mut [Self]; 2]);
    /// The target density at unit f64 directions, rounded to `Self` (no sampler has a batch path
    /// for it).
    fn target(s: &dyn Sampler, dir: [&[f64]; 3], out: &mut [Self]);
}

impl Real for f64 {
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    fn pdf(s: &dyn Sampler, dir: [&[f64]; 3], pdf: &mut [f64]) {
        s.pdf_batch_soa(dir, pdf)
    }
    fn invert(s: &dyn Sampler, dir: [&[f64]; 3], uv: [&mut [f64]; 2]) {
        s.invert_batch_soa(dir, uv)
    }
    fn target(s: &dyn Sampler, dir: [&[f64]; 3], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = s.target_pdf([dir[0][k], dir[1][k], dir[2][k]]);
        }
    }
}

/// f64 unit directions rounded to f32 columns on the stack.
fn round_dirs(dir: [&[f64]; 3]) -> [[f32; CHUNK]; 3] {
    let mut b = [[0.0f32; CHUNK]; 3];
    for (b, d) in b.iter_mut().zip(dir) {
        for (b, &x) in b.iter_mut().zip(d) {
            *b = x as f32;
        }
    }
    b
}

impl Real for f32 {
    #[inline]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn pdf(s: &dyn Sampler, dir: [&[f64]; 3], pdf: &mut [f32]) {
        let m = pdf.len();
        let b = round_dirs(dir);
        s.pdf_batch_soa_f32([&b[0][..m], &b[1][..m], &b[2][..m]], pdf)
    }
    fn invert(s: &dyn Sampler, dir: [&[f64]; 3], uv: [&mut [f32]; 2]) {
        let m = uv[0].len();
        let b = round_dirs(dir);
        s.invert_batch_soa_f32([&b[0][..m], &b[1][..m], &b[2][..m]], uv)
    }
    fn target(s: &dyn Sampler, dir: [&[f64]; 3], out: &mut [f32]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = s.target_pdf([dir[0][k], dir[1][k], dir[2][k]]) as f32;
        }
    }
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

/// A caller's pointer to elements: `*const T` for inputs, `*mut T` for outputs.
trait Ptr: Copy {
    /// The element type.
    type Elem;
    /// Non-null and aligned, else [`Failure::null`] naming `what`.
    fn check(self, what: &str) -> Result<(), Failure>;
    /// The pointer `c` elements on (not dereferenced).
    fn step(self, c: usize) -> Self;
}

macro_rules! impl_ptr {
    ($($ptr:ty => $check:ident),*) => {$(
        impl<T> Ptr for $ptr {
            type Elem = T;
            fn check(self, what: &str) -> Result<(), Failure> {
                $check(self, what)
            }
            fn step(self, c: usize) -> Self {
                self.wrapping_add(c)
            }
        }
    )*};
}
impl_ptr!(*const T => check_in, *mut T => check_out);

/// K components of n elements through the caller's pointers `P`, array-of-structs (one pointer,
/// stride K) or structure-of-arrays (K pointers, stride 1).
struct Strided<P, const K: usize> {
    ptr: [P; K],
    stride: usize,
}

/// K input components.
type In<T, const K: usize> = Strided<*const T, K>;
/// K output components.
type Out<T, const K: usize> = Strided<*mut T, K>;

impl<P: Ptr, const K: usize> Strided<P, K> {
    fn aos(p: P, n: usize, what: &str) -> Result<Self, Failure> {
        p.check(what)?;
        check_len::<P::Elem>(n, K)?;
        let mut ptr = [p; K];
        for (c, q) in ptr.iter_mut().enumerate() {
            *q = p.step(c);
        }
        Ok(Self { ptr, stride: K })
    }
    fn soa(ps: [(P, &str); K], n: usize) -> Result<Self, Failure> {
        for (p, what) in ps {
            p.check(what)?;
        }
        check_len::<P::Elem>(n, 1)?;
        Ok(Self {
            ptr: ps.map(|(p, _)| p),
            stride: 1,
        })
    }
}

impl<T: Real, const K: usize> In<T, K> {
    /// Element i.
    ///
    /// # Safety
    /// i < n, and the caller's pointers are valid for n elements.
    #[inline]
    unsafe fn get(&self, i: usize) -> [T; K] {
        let mut v = [T::default(); K];
        for (c, x) in v.iter_mut().enumerate() {
            *x = self.ptr[c].add(i * self.stride).read();
        }
        v
    }
}

impl<T: Real, const K: usize> Out<T, K> {
    /// Writes elements `start..start + m` from the first m entries of K columns.
    ///
    /// # Safety
    /// start + m ≤ n, and the caller's pointers are valid for n elements.
    #[inline]
    unsafe fn put(&self, start: usize, cols: [&[T]; K]) {
        for (c, col) in cols.iter().enumerate() {
            let base = self.ptr[c];
            for (k, &x) in col.iter().enumerate() {
                base.add((start + k) * self.stride).write(x);
            }
        }
    }
}

/// Samples n points: directions into `dirs` and densities into `pdfs`, through
/// [`Real::sample`] a chunk at a time. A point outside the unit square (or NaN) stops the batch
/// with [`GONIO_ERR_INVALID_ARGUMENT`] naming its index (the chunks before it are written).
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
    let mut pts = [[T::default(); CHUNK]; 2];
    let mut out = [[T::default(); CHUNK]; 4];
    let mut start = 0;
    while start < n {
        let m = CHUNK.min(n - start);
        for k in 0..m {
            let i = start + k;
            let p = u.get(i);
            in_square(p.map(T::to_f64))
                .map_err(|e| Failure::invalid(format!("point #{i}: {}", e.message)))?;
            pts[0][k] = p[0];
            pts[1][k] = p[1];
        }
        let [x, y, z, p] = &mut out;
        s.batch(T::call(gonio::batch::Soa::Sample {
            u: &pts[0][..m],
            v: &pts[1][..m],
            dir: [&mut x[..m], &mut y[..m], &mut z[..m]],
            pdf: &mut p[..m],
        }));
        dirs.put(start, [&x[..m], &y[..m], &z[..m]]);
        pdfs.put(start, [&p[..m]]);
        start += m;
    }
    Ok(())
}

/// Evaluates a batch function at n directions, a chunk of [`CHUNK`] at a time: the chunk's
/// directions are read and normalised in f64 into columns (a zero or non-finite one stops with
/// [`GONIO_ERR_INVALID_ARGUMENT`] naming its index), `f` fills the chunk's K result columns,
/// which are then written. Every input of a chunk is read before any of its outputs is written,
/// so an output may overwrite its own or an earlier element's input (in place).
///
/// # Safety
/// The views are valid for n elements.
unsafe fn eval_n<T: Real, const K: usize>(
    n: usize,
    dirs: &In<T, 3>,
    out: &Out<T, K>,
    mut f: impl FnMut([&[f64]; 3], [&mut [T]; K]),
) -> Result<(), Failure> {
    let mut unit_dirs = [[0.0f64; CHUNK]; 3];
    let mut res = [[T::default(); CHUNK]; K];
    let mut start = 0;
    while start < n {
        let m = CHUNK.min(n - start);
        for k in 0..m {
            let i = start + k;
            let d = unit(dirs.get(i).map(T::to_f64))
                .map_err(|e| Failure::invalid(format!("direction #{i}: {}", e.message)))?;
            for (c, x) in d.into_iter().enumerate() {
                unit_dirs[c][k] = x;
            }
        }
        let [x, y, z] = &unit_dirs;
        let mut cols = res.iter_mut().map(|c| &mut c[..m]);
        f(
            [&x[..m], &y[..m], &z[..m]],
            std::array::from_fn(|_| cols.next().expect("K columns")),
        );
        out.put(start, std::array::from_fn(|c| &res[c][..m]));
        start += m;
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
type DensityFn<T> = fn(&dyn Sampler, [&[f64]; 3], &mut [T]);

unsafe fn density_aos<T: Real>(
    sampler: *const GonioSampler,
    directions: *const T,
    n: usize,
    out: *mut T,
    f: DensityFn<T>,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::aos(directions, n, "directions")?;
        let o = Out::<T, 1>::aos(out, n, "out")?;
        eval_n(n, &d, &o, |dirs, [res]| f(s.inner.as_ref(), dirs, res))
    })
}

unsafe fn density_soa<T: Real>(
    sampler: *const GonioSampler,
    x: *const T,
    y: *const T,
    z: *const T,
    n: usize,
    out: *mut T,
    f: DensityFn<T>,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::soa([(x, "x"), (y, "y"), (z, "z")], n)?;
        let o = Out::<T, 1>::soa([(out, "out")], n)?;
        eval_n(n, &d, &o, |dirs, [res]| f(s.inner.as_ref(), dirs, res))
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
        eval_n(n, &d, &o, |dirs, uv| T::invert(s.inner.as_ref(), dirs, uv))
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
        eval_n(n, &d, &o, |dirs, uv| T::invert(s.inner.as_ref(), dirs, uv))
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
    density_aos::<f64>(sampler, directions, n, out, f64::pdf)
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
    density_soa::<f64>(sampler, x, y, z, n, out, f64::pdf)
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
    density_aos::<f64>(sampler, directions, n, out, f64::target)
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
    density_soa::<f64>(sampler, x, y, z, n, out, f64::target)
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

/// Samples `n` points of the square given as interleaved pairs `u[2i], u[2i+1]` (float; the sampler's float32 batch call: its float32 map where it has one, else computed in double and rounded once):
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

/// Samples `n` points of the square given as arrays `u[i]`, `v[i]` (float; the sampler's float32 batch call: its float32 map where it has one, else computed in double and rounded once): directions
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
/// `directions[3i..3i+3]` (float; normalised in double and rounded to float, then the sampler's float32 batch call: its float32 map where it has one, else computed in double and rounded once), into `out[i]`. A zero or
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
    density_aos::<f32>(sampler, directions, n, out, f32::pdf)
}

/// The sampler's density (per sr) at `n` directions given as arrays `x[i]`, `y[i]`, `z[i]`
/// (float; normalised in double and rounded to float, then the sampler's float32 batch call: its float32 map where it has one, else computed in double and rounded once), into `out[i]`; as the interleaved variant.
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
    density_soa::<f32>(sampler, x, y, z, n, out, f32::pdf)
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
    density_aos::<f32>(sampler, directions, n, out, f32::target)
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
    density_soa::<f32>(sampler, x, y, z, n, out, f32::target)
}

/// Inverts `n` directions given as interleaved triples `directions[3i..3i+3]` (float; normalised in double and rounded to float, then the sampler's float32 batch call: its float32 map where it has one, else computed in double and rounded once)
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

/// Inverts `n` directions given as arrays `x[i]`, `y[i]`, `z[i]` (float; normalised in double and rounded to float, then the sampler's float32 batch call: its float32 map where it has one, else computed in double and rounded once) into `u[i]`,
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
