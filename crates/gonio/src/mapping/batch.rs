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

use super::simd::{Backend, BatchFloat};
use crate::sampler::{InvertError, Point2, Sample, Sampler, Vec3};
use rayon::prelude::*;

pub(super) use crate::batch::{check_len, CHUNK, PAR_CHUNK};

pub(super) use super::simd::dispatch::{core_density, core_invert, core_sample};

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

/// [`SoaSampler::sample_soa`] on all rayon threads, in chunks of [`PAR_CHUNK`] points. Each output depends
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

/// The HDS maps' [`Sampler::invert_batch_soa`] and [`Sampler::invert_batch_soa_f32`]:
/// [`SoaSampler::invert_soa`], then NaN in both coordinates wherever [`SoaSampler::pdf_soa`] is 0
/// (the rule of every sampler, issue 25: no preimage where the density is 0; the map's inverse
/// there is a boundary point that samples another direction). [`CHUNK`] directions at a time.
///
/// # Panics
/// If the slices differ in length.
pub(crate) fn invert_soa_nonzero<S: SoaSampler, T: BatchFloat>(
    s: &S,
    dir: [&[T]; 3],
    uv: [&mut [T]; 2],
) {
    let [u, v] = uv;
    let n = u.len();
    check_len(
        "invert_batch_soa",
        n,
        &[v.len(), dir[0].len(), dir[1].len(), dir[2].len()],
    );
    let b = Backend::detect();
    let mut p = [T::ZERO; CHUNK];
    for start in (0..n).step_by(CHUNK) {
        let r = start..(start + CHUNK).min(n);
        let m = r.len();
        let d = [&dir[0][r.clone()], &dir[1][r.clone()], &dir[2][r.clone()]];
        let (u, v) = (&mut u[r.clone()], &mut v[r]);
        s.invert_soa_with(b, d, [&mut *u, &mut *v]);
        s.pdf_soa_with(b, d, &mut p[..m]);
        for ((u, v), &p) in u.iter_mut().zip(v.iter_mut()).zip(&p[..m]) {
            if p == T::ZERO {
                *u = T::NAN;
                *v = T::NAN;
            }
        }
    }
}

/// The six structure-of-arrays methods of [`Sampler`] for a map that implements [`SoaSampler`]
/// (the HDS maps): each runs the map's vector kernels on the slices directly, with no transposes.
/// The `_f32` ones are the single override point of the float32 path: they run the map's
/// [`crate::mapping::Float32Map`].
macro_rules! soa_sampler_methods {
    () => {
        fn sample_batch_soa(&self, u: &[f64], v: &[f64], dir: [&mut [f64]; 3], pdf: &mut [f64]) {
            $crate::mapping::batch::SoaSampler::sample_soa(self, u, v, dir, pdf)
        }
        fn pdf_batch_soa(&self, dir: [&[f64]; 3], pdf: &mut [f64]) {
            $crate::mapping::batch::SoaSampler::pdf_soa(self, dir, pdf)
        }
        fn invert_batch_soa(&self, dir: [&[f64]; 3], uv: [&mut [f64]; 2]) {
            $crate::mapping::batch::invert_soa_nonzero(self, dir, uv)
        }
        // The float32 map's override point: the map's float32 map (`float32()`, built on the
        // first call), else (a grid beyond its limits) the f64 map rounded once.
        fn sample_batch_soa_f32(
            &self,
            u: &[f32],
            v: &[f32],
            dir: [&mut [f32]; 3],
            pdf: &mut [f32],
        ) {
            match self.float32() {
                Some(f) => f.sample_soa(u, v, dir, pdf),
                None => $crate::mapping::batch::SoaSampler::sample_soa(self, u, v, dir, pdf),
            }
        }
        fn pdf_batch_soa_f32(&self, dir: [&[f32]; 3], pdf: &mut [f32]) {
            match self.float32() {
                Some(f) => f.pdf_soa(dir, pdf),
                None => $crate::mapping::batch::SoaSampler::pdf_soa(self, dir, pdf),
            }
        }
        fn invert_batch_soa_f32(&self, dir: [&[f32]; 3], uv: [&mut [f32]; 2]) {
            match self.float32() {
                Some(f) => f.invert_soa_nonzero(dir, uv),
                None => $crate::mapping::batch::invert_soa_nonzero(self, dir, uv),
            }
        }
    };
}
pub(crate) use soa_sampler_methods;
