//! Batch paths of the HDS mapping over structure-of-arrays slices, in f64 and f32, on AVX-512 or
//! AVX2+FMA (chosen at run time) or the portable instruction set: [`SoaSampler`] (implemented for
//! [`crate::HemisphereMap`] and [`crate::SphereMap`] in `soa_maps.rs`), and the parallel versions [`sample_soa_par`],
//! [`pdf_soa_par`], [`invert_soa_par`].
//!
//! The scalar [`Sampler`] methods stay the reference. In f64 the batch results equal them bit for
//! bit except through sin/cos (directions) and atan2 (pdf and invert), whose lane versions are
//! within 2 ulp of libm ([`crate::mapping::simd::math`]); the resulting end-to-end differences are
//! bounded by the tests in `tests/batch.rs` and reported in `docs/PERFORMANCE.md`. Results never
//! depend on the backend, the block size or the number of threads (tested bit for bit).
//!
//! **f32** calls are evaluated by the f64 kernels and rounded once: points of the square are
//! widened, directions are widened and renormalised in f64 (an f32 unit vector is unit only to
//! ~1e-7, which at the map's rim would read as "beyond the map"), and every result is the f64
//! result rounded to f32. So an f32 result is within ½ ulp of the f64 batch result for the same
//! (widened) input, the f32 pdf of a sample is the exact density of its f64 direction rounded
//! once, and f32 costs what f64 does (the f64 kernels are the fast ones; `docs/PERFORMANCE.md`).
//!
//! Conventions, as in [`Sampler`]: directions are unit vectors in the map's frame, densities per
//! steradian, points of the square in [0, 1]². Where the scalar `invert` returns an error (a
//! direction outside the domain or not finite), the batch inverse writes NaN to both coordinates.
//!
//! ```
//! use gonio::mapping::batch::SoaSampler;
//! use gonio::{Diagram, HemisphereMap, Sampler};
//! let d = Diagram::from_degrees(&[0.0, 45.0, 90.0], &[0.0], &[vec![1.0, 0.7, 0.0]]).unwrap();
//! let map = HemisphereMap::new(&d).unwrap();
//! let (u, v) = (vec![0.3f32, 0.9], vec![0.7f32, 0.1]);
//! let (mut x, mut y, mut z, mut pdf) = (vec![0.0f32; 2], vec![0.0; 2], vec![0.0; 2], vec![0.0; 2]);
//! map.sample_soa(&u, &v, [&mut x, &mut y, &mut z], &mut pdf);
//! let (mut uu, mut vv) = (vec![0.0f32; 2], vec![0.0; 2]);
//! map.invert_soa([&x, &y, &z], [&mut uu, &mut vv]);
//! assert!((uu[0] - 0.3).abs() < 1e-5 && (vv[1] - 0.1).abs() < 1e-5);
//! ```

// Lane loops index several arrays by the same lane number on purpose (they vectorise).
#![allow(clippy::needless_range_loop)]

use super::core::HdsCore;
use super::simd::{Backend, BatchFloat, Lane};
use crate::sampler::{InvertError, Point2, Sample, Sampler, Vec3};
use rayon::prelude::*;

/// Points per chunk of the sphere's partition into hemispheres and of the AoS adapters.
pub(super) const CHUNK: usize = 256;
/// Points per rayon task in the parallel batch functions.
const PAR_CHUNK: usize = 4096;

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::HdsCore;
    use crate::mapping::simd::Lane;
    use std::any::TypeId;

    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn sample<T: Lane>(c: &HdsCore, u: &[T], v: &[T], out: [&mut [T]; 4]) {
        if let (Some(u), Some(v)) = (as_f64(u), as_f64(v)) {
            if c.explicit_indexable() {
                let [x, y, z, d] = out.map(|o| as_f64_mut(o).expect("T is f64"));
                return crate::mapping::core::avx2::sample_slices(c, u, v, [x, y, z, d]);
            }
        }
        c.sample_slices(u, v, out)
    }

    /// `s` as an f64 slice when `T` is f64 (the explicit f64 kernels), else `None`.
    pub(super) fn as_f64<T: Lane>(s: &[T]) -> Option<&[f64]> {
        (TypeId::of::<T>() == TypeId::of::<f64>())
            // SAFETY: T is f64: same layout, same length.
            .then(|| unsafe { std::slice::from_raw_parts(s.as_ptr().cast::<f64>(), s.len()) })
    }

    /// [`as_f64`] for a mutable slice.
    pub(super) fn as_f64_mut<T: Lane>(s: &mut [T]) -> Option<&mut [f64]> {
        (TypeId::of::<T>() == TypeId::of::<f64>()).then(|| {
            // SAFETY: T is f64: same layout, same length; `s` is borrowed mutably for the result.
            unsafe { std::slice::from_raw_parts_mut(s.as_mut_ptr().cast::<f64>(), s.len()) }
        })
    }
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn density<T: Lane>(c: &HdsCore, dir: [&[T]; 3], out: &mut [T]) {
        if let (Some(x), Some(y), Some(z)) = (as_f64(dir[0]), as_f64(dir[1]), as_f64(dir[2])) {
            if c.explicit_indexable() {
                let out = as_f64_mut(out).expect("T is f64");
                return crate::mapping::core::avx2::density_slices(c, [x, y, z], out);
            }
        }
        c.density_slices(dir, out)
    }
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn invert<T: Lane>(c: &HdsCore, dir: [&[T]; 3], out: [&mut [T]; 2]) {
        if let (Some(x), Some(y), Some(z)) = (as_f64(dir[0]), as_f64(dir[1]), as_f64(dir[2])) {
            if c.explicit_indexable() {
                let [u, v] = out.map(|o| as_f64_mut(o).expect("T is f64"));
                return crate::mapping::core::avx2::invert_slices(c, [x, y, z], [u, v]);
            }
        }
        c.invert_slices(dir, out)
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::avx2::{as_f64, as_f64_mut};
    use super::HdsCore;
    use crate::mapping::core::avx512 as k;
    use crate::mapping::simd::Lane;

    /// # Safety
    /// The CPU must support AVX-512 F and DQ, AVX2 and FMA.
    #[target_feature(enable = "avx512f,avx512dq,avx2,fma")]
    pub(super) unsafe fn sample<T: Lane>(c: &HdsCore, u: &[T], v: &[T], out: [&mut [T]; 4]) {
        if let (Some(u), Some(v)) = (as_f64(u), as_f64(v)) {
            if c.explicit_indexable() {
                let [x, y, z, d] = out.map(|o| as_f64_mut(o).expect("T is f64"));
                return k::k2::sample_slices(c, u, v, [x, y, z, d]);
            }
        }
        // SAFETY: the caller guarantees AVX2 and FMA.
        unsafe { super::avx2::sample(c, u, v, out) }
    }
    /// # Safety
    /// As [`sample`].
    #[target_feature(enable = "avx512f,avx512dq,avx2,fma")]
    pub(super) unsafe fn density<T: Lane>(c: &HdsCore, dir: [&[T]; 3], out: &mut [T]) {
        if let (Some(x), Some(y), Some(z)) = (as_f64(dir[0]), as_f64(dir[1]), as_f64(dir[2])) {
            if c.explicit_indexable() {
                let out = as_f64_mut(out).expect("T is f64");
                return k::k4::density_slices(c, [x, y, z], out);
            }
        }
        // SAFETY: the caller guarantees AVX2 and FMA.
        unsafe { super::avx2::density(c, dir, out) }
    }
    /// # Safety
    /// As [`sample`].
    #[target_feature(enable = "avx512f,avx512dq,avx2,fma")]
    pub(super) unsafe fn invert<T: Lane>(c: &HdsCore, dir: [&[T]; 3], out: [&mut [T]; 2]) {
        if let (Some(x), Some(y), Some(z)) = (as_f64(dir[0]), as_f64(dir[1]), as_f64(dir[2])) {
            if c.explicit_indexable() {
                let [u, v] = out.map(|o| as_f64_mut(o).expect("T is f64"));
                return k::k4::invert_slices(c, [x, y, z], [u, v]);
            }
        }
        // SAFETY: the caller guarantees AVX2 and FMA.
        unsafe { super::avx2::invert(c, dir, out) }
    }
}

#[inline(never)]
fn sample_portable<T: Lane>(c: &HdsCore, u: &[T], v: &[T], out: [&mut [T]; 4]) {
    c.sample_slices(u, v, out)
}
#[inline(never)]
fn density_portable<T: Lane>(c: &HdsCore, dir: [&[T]; 3], out: &mut [T]) {
    c.density_slices(dir, out)
}
#[inline(never)]
fn invert_portable<T: Lane>(c: &HdsCore, dir: [&[T]; 3], out: [&mut [T]; 2]) {
    c.invert_slices(dir, out)
}

/// Points per chunk when an f32 call runs through the f64 kernels.
const F32_CHUNK: usize = 256;

/// Whether the lane type is f32 (which the batch paths evaluate in f64, rounded once).
fn is_f32<T: Lane>() -> bool {
    std::any::TypeId::of::<T>() == std::any::TypeId::of::<f32>()
}

/// `T` values widened into the first `cnt` entries of an f64 buffer.
fn widen<T: Lane>(src: &[T], buf: &mut [f64; F32_CHUNK]) {
    for (b, &x) in buf.iter_mut().zip(src) {
        *b = x.to_f64();
    }
}

/// f32 directions widened to f64 are unit vectors only to within f32 rounding (~1e-7); the f64
/// kernels expect them unit to within f64 rounding (a horizon direction rounded to f32 can lie
/// "beyond the map's edge" by 1e-7 otherwise). Renormalises the first `cnt` widened directions
/// (those of positive finite length; others pass unchanged).
fn renormalise(d: &mut [[f64; F32_CHUNK]; 3], cnt: usize) {
    for k in 0..cnt {
        let n = (d[0][k] * d[0][k] + d[1][k] * d[1][k] + d[2][k] * d[2][k]).sqrt();
        // One division per direction (the f32 results do not see the last bits of the scale).
        let s = if n > 0.0 && n.is_finite() {
            1.0 / n
        } else {
            1.0
        };
        for c in d.iter_mut() {
            c[k] *= s;
        }
    }
}

/// f64 values rounded into `T`.
fn narrow<T: Lane>(src: &[f64], dst: &mut [T]) {
    for (d, &x) in dst.iter_mut().zip(src) {
        *d = T::from_f64(x);
    }
}

pub(super) fn core_sample<T: Lane>(b: Backend, c: &HdsCore, u: &[T], v: &[T], out: [&mut [T]; 4]) {
    if is_f32::<T>() {
        let mut o = out;
        let (mut bu, mut bv) = ([0.0; F32_CHUNK], [0.0; F32_CHUNK]);
        let mut bo = [[0.0; F32_CHUNK]; 4];
        let mut start = 0;
        while start < u.len() {
            let cnt = (u.len() - start).min(F32_CHUNK);
            widen(&u[start..start + cnt], &mut bu);
            widen(&v[start..start + cnt], &mut bv);
            let [bx, by, bz, bd] = &mut bo;
            core_sample::<f64>(
                b,
                c,
                &bu[..cnt],
                &bv[..cnt],
                [
                    &mut bx[..cnt],
                    &mut by[..cnt],
                    &mut bz[..cnt],
                    &mut bd[..cnt],
                ],
            );
            for (col, bcol) in o.iter_mut().zip(&bo) {
                narrow(&bcol[..cnt], &mut col[start..start + cnt]);
            }
            start += cnt;
        }
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if b.usable() == Backend::Avx512 {
        // SAFETY: `usable` returns Avx512 only when the CPU has AVX-512 F/DQ, AVX2 and FMA.
        return unsafe { avx512::sample(c, u, v, out) };
    }
    #[cfg(target_arch = "x86_64")]
    if b.usable() == Backend::Avx2Fma {
        // SAFETY: `usable` returns Avx2Fma only when the CPU has AVX2 and FMA.
        return unsafe { avx2::sample(c, u, v, out) };
    }
    let _ = b;
    sample_portable(c, u, v, out)
}

pub(super) fn core_density<T: Lane>(b: Backend, c: &HdsCore, dir: [&[T]; 3], out: &mut [T]) {
    if is_f32::<T>() {
        let mut bd = [[0.0; F32_CHUNK]; 3];
        let mut bo = [0.0; F32_CHUNK];
        let mut start = 0;
        while start < out.len() {
            let cnt = (out.len() - start).min(F32_CHUNK);
            for (k, b) in bd.iter_mut().enumerate() {
                widen(&dir[k][start..start + cnt], b);
            }
            renormalise(&mut bd, cnt);
            let [x, y, z] = &bd;
            core_density::<f64>(b, c, [&x[..cnt], &y[..cnt], &z[..cnt]], &mut bo[..cnt]);
            narrow(&bo[..cnt], &mut out[start..start + cnt]);
            start += cnt;
        }
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if b.usable() == Backend::Avx512 {
        // SAFETY: as in `core_sample`.
        return unsafe { avx512::density(c, dir, out) };
    }
    #[cfg(target_arch = "x86_64")]
    if b.usable() == Backend::Avx2Fma {
        // SAFETY: as in `core_sample`.
        return unsafe { avx2::density(c, dir, out) };
    }
    let _ = b;
    density_portable(c, dir, out)
}

pub(super) fn core_invert<T: Lane>(b: Backend, c: &HdsCore, dir: [&[T]; 3], out: [&mut [T]; 2]) {
    if is_f32::<T>() {
        let [u, v] = out;
        let mut bd = [[0.0; F32_CHUNK]; 3];
        let (mut bu, mut bv) = ([0.0; F32_CHUNK], [0.0; F32_CHUNK]);
        let mut start = 0;
        while start < u.len() {
            let cnt = (u.len() - start).min(F32_CHUNK);
            for (k, b) in bd.iter_mut().enumerate() {
                widen(&dir[k][start..start + cnt], b);
            }
            renormalise(&mut bd, cnt);
            let [x, y, z] = &bd;
            core_invert::<f64>(
                b,
                c,
                [&x[..cnt], &y[..cnt], &z[..cnt]],
                [&mut bu[..cnt], &mut bv[..cnt]],
            );
            narrow(&bu[..cnt], &mut u[start..start + cnt]);
            narrow(&bv[..cnt], &mut v[start..start + cnt]);
            start += cnt;
        }
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if b.usable() == Backend::Avx512 {
        // SAFETY: as in `core_sample`.
        return unsafe { avx512::invert(c, dir, out) };
    }
    #[cfg(target_arch = "x86_64")]
    if b.usable() == Backend::Avx2Fma {
        // SAFETY: as in `core_sample`.
        return unsafe { avx2::invert(c, dir, out) };
    }
    let _ = b;
    invert_portable(c, dir, out)
}

/// Batch sample / pdf / invert over structure-of-arrays slices (see the module documentation).
///
/// Every method panics if its slices differ in length (a programming error, not an input error).
/// The `_with` methods take the [`Backend`] explicitly (one the CPU lacks falls back to
/// [`Backend::Portable`]); the others use [`Backend::detect`].
pub trait SoaSampler: Sampler {
    /// Maps the points `(u[k], v[k])` of the unit square to directions `dir[·][k]` and their exact
    /// densities `pdf[k]` (per steradian).
    fn sample_soa_with<T: BatchFloat>(
        &self,
        backend: Backend,
        u: &[T],
        v: &[T],
        dir: [&mut [T]; 3],
        pdf: &mut [T],
    );
    /// The density (per steradian) at each direction `(dir[0][k], dir[1][k], dir[2][k])`; 0 outside
    /// the domain.
    fn pdf_soa_with<T: BatchFloat>(&self, backend: Backend, dir: [&[T]; 3], pdf: &mut [T]);
    /// The point of the unit square of each direction, NaN where the scalar `invert` fails.
    fn invert_soa_with<T: BatchFloat>(&self, backend: Backend, dir: [&[T]; 3], uv: [&mut [T]; 2]);

    /// [`SoaSampler::sample_soa_with`] on the detected backend.
    fn sample_soa<T: BatchFloat>(&self, u: &[T], v: &[T], dir: [&mut [T]; 3], pdf: &mut [T]) {
        self.sample_soa_with(Backend::detect(), u, v, dir, pdf)
    }
    /// [`SoaSampler::pdf_soa_with`] on the detected backend.
    fn pdf_soa<T: BatchFloat>(&self, dir: [&[T]; 3], pdf: &mut [T]) {
        self.pdf_soa_with(Backend::detect(), dir, pdf)
    }
    /// [`SoaSampler::invert_soa_with`] on the detected backend.
    fn invert_soa<T: BatchFloat>(&self, dir: [&[T]; 3], uv: [&mut [T]; 2]) {
        self.invert_soa_with(Backend::detect(), dir, uv)
    }
}

pub(super) fn check_len(what: &str, n: usize, lens: &[usize]) {
    assert!(
        lens.iter().all(|&l| l == n),
        "{what}: slices differ in length"
    );
}

/// [`SoaSampler::sample_soa`] on all rayon threads, in chunks of 4096 points. Each output depends
/// only on its own input, so the result is the same for any number of threads.
///
/// # Panics
/// If the slices differ in length.
pub fn sample_soa_par<S: SoaSampler, T: BatchFloat>(
    s: &S,
    u: &[T],
    v: &[T],
    dir: [&mut [T]; 3],
    pdf: &mut [T],
) {
    let [x, y, z] = dir;
    check_len(
        "sample_soa_par",
        u.len(),
        &[v.len(), x.len(), y.len(), z.len(), pdf.len()],
    );
    let b = Backend::detect();
    x.par_chunks_mut(PAR_CHUNK)
        .zip(y.par_chunks_mut(PAR_CHUNK))
        .zip(z.par_chunks_mut(PAR_CHUNK))
        .zip(pdf.par_chunks_mut(PAR_CHUNK))
        .zip(u.par_chunks(PAR_CHUNK).zip(v.par_chunks(PAR_CHUNK)))
        .for_each(|((((x, y), z), p), (u, v))| s.sample_soa_with(b, u, v, [x, y, z], p));
}

/// [`SoaSampler::pdf_soa`] on all rayon threads (see [`sample_soa_par`]).
///
/// # Panics
/// If the slices differ in length.
pub fn pdf_soa_par<S: SoaSampler, T: BatchFloat>(s: &S, dir: [&[T]; 3], pdf: &mut [T]) {
    check_len(
        "pdf_soa_par",
        pdf.len(),
        &[dir[0].len(), dir[1].len(), dir[2].len()],
    );
    let b = Backend::detect();
    pdf.par_chunks_mut(PAR_CHUNK)
        .zip(dir[0].par_chunks(PAR_CHUNK))
        .zip(
            dir[1]
                .par_chunks(PAR_CHUNK)
                .zip(dir[2].par_chunks(PAR_CHUNK)),
        )
        .for_each(|((p, x), (y, z))| s.pdf_soa_with(b, [x, y, z], p));
}

/// [`SoaSampler::invert_soa`] on all rayon threads (see [`sample_soa_par`]).
///
/// # Panics
/// If the slices differ in length.
pub fn invert_soa_par<S: SoaSampler, T: BatchFloat>(s: &S, dir: [&[T]; 3], uv: [&mut [T]; 2]) {
    let [u, v] = uv;
    check_len(
        "invert_soa_par",
        u.len(),
        &[v.len(), dir[0].len(), dir[1].len(), dir[2].len()],
    );
    let b = Backend::detect();
    u.par_chunks_mut(PAR_CHUNK)
        .zip(v.par_chunks_mut(PAR_CHUNK))
        .zip(dir[0].par_chunks(PAR_CHUNK))
        .zip(
            dir[1]
                .par_chunks(PAR_CHUNK)
                .zip(dir[2].par_chunks(PAR_CHUNK)),
        )
        .for_each(|(((u, v), x), (y, z))| s.invert_soa_with(b, [x, y, z], [u, v]));
}

/// The AoS `Sampler::sample_batch` of the HDS maps through the SoA path, [`CHUNK`] points at a
/// time on the stack.
pub(crate) fn sample_batch_aos<S: SoaSampler>(s: &S, u: &[Point2], out: &mut [Sample]) {
    assert_eq!(u.len(), out.len(), "sample_batch: slices differ in length");
    for (u, out) in u.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
        let n = u.len();
        let [bu, bv] = split_points(u);
        let mut o = [[0.0f64; CHUNK]; 4];
        let [ox, oy, oz, op] = &mut o;
        s.sample_soa(
            &bu[..n],
            &bv[..n],
            [&mut ox[..n], &mut oy[..n], &mut oz[..n]],
            &mut op[..n],
        );
        for (k, o) in out.iter_mut().enumerate() {
            *o = Sample {
                direction: [ox[k], oy[k], oz[k]],
                pdf: op[k],
            };
        }
    }
}

/// The AoS `Sampler::sample_batch_split` of the HDS maps through the SoA path: the kernels'
/// columns are written straight into the direction rows and the densities.
pub(crate) fn sample_batch_split_aos<S: SoaSampler>(
    s: &S,
    u: &[Point2],
    dirs: &mut [Vec3],
    pdf: &mut [f64],
) {
    assert!(
        u.len() == dirs.len() && u.len() == pdf.len(),
        "sample_batch_split: slices differ in length"
    );
    for ((u, dirs), pdf) in u
        .chunks(CHUNK)
        .zip(dirs.chunks_mut(CHUNK))
        .zip(pdf.chunks_mut(CHUNK))
    {
        let n = u.len();
        let [bu, bv] = split_points(u);
        let mut o = [[0.0f64; CHUNK]; 3];
        let [ox, oy, oz] = &mut o;
        s.sample_soa(
            &bu[..n],
            &bv[..n],
            [&mut ox[..n], &mut oy[..n], &mut oz[..n]],
            pdf,
        );
        for (k, d) in dirs.iter_mut().enumerate() {
            *d = [ox[k], oy[k], oz[k]];
        }
    }
}

/// Transposes points into two stack arrays.
fn split_points(u: &[Point2]) -> [[f64; CHUNK]; 2] {
    let mut b = [[0.0f64; CHUNK]; 2];
    for (k, p) in u.iter().enumerate() {
        b[0][k] = p[0];
        b[1][k] = p[1];
    }
    b
}

/// Transposes directions into three stack arrays.
fn split_dirs(d: &[Vec3]) -> [[f64; CHUNK]; 3] {
    let mut b = [[0.0f64; CHUNK]; 3];
    for (k, d) in d.iter().enumerate() {
        b[0][k] = d[0];
        b[1][k] = d[1];
        b[2][k] = d[2];
    }
    b
}

/// The AoS `Sampler::pdf_batch` of the HDS maps through the SoA path.
pub(crate) fn pdf_batch_aos<S: SoaSampler>(s: &S, dirs: &[Vec3], out: &mut [f64]) {
    assert_eq!(dirs.len(), out.len(), "pdf_batch: slices differ in length");
    for (d, out) in dirs.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
        let n = d.len();
        let b = split_dirs(d);
        s.pdf_soa([&b[0][..n], &b[1][..n], &b[2][..n]], out);
    }
}

/// The AoS `Sampler::invert_batch` of the HDS maps through the SoA path.
pub(crate) fn invert_batch_aos<S: SoaSampler>(
    s: &S,
    dirs: &[Vec3],
    out: &mut [Result<Point2, InvertError>],
) {
    assert_eq!(
        dirs.len(),
        out.len(),
        "invert_batch: slices differ in length"
    );
    for (d, out) in dirs.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
        let n = d.len();
        let b = split_dirs(d);
        let (mut u, mut v) = ([0.0f64; CHUNK], [0.0f64; CHUNK]);
        s.invert_soa(
            [&b[0][..n], &b[1][..n], &b[2][..n]],
            [&mut u[..n], &mut v[..n]],
        );
        // The rule of every sampler (issue 25): no preimage where the density is 0.
        let mut p = [0.0f64; CHUNK];
        pdf_batch_aos(s, d, &mut p[..n]);
        for (k, o) in out.iter_mut().enumerate() {
            // One store per branch: a `Result` built first and then copied was stored with
            // unaligned moves that stalled on store forwarding (30 % of the inverse's time).
            if u[k].is_nan() || v[k].is_nan() {
                *o = Err(no_preimage(s, d[k]));
            } else if p[k] == 0.0 {
                *o = Err(InvertError::ZeroDensity);
            } else {
                *o = Ok([u[k], v[k]]);
            }
        }
    }
}

/// Why a direction has no preimage (the batch path gave NaN): the scalar path says whether it is
/// outside the domain or of density 0.
#[cold]
#[inline(never)]
fn no_preimage<S: SoaSampler>(s: &S, d: Vec3) -> InvertError {
    match s.invert(d) {
        Err(e) => e,
        Ok(_) => InvertError::OutsideDomain,
    }
}
