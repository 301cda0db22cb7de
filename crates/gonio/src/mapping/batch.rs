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
use crate::batch::Soa;
use crate::sampler::Sampler;

pub(super) use crate::batch::{check_len, CHUNK};

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

/// One structure-of-arrays call on `backend` through the map's kernels ([`SoaSampler`]'s `_with`
/// methods; the inverse as the kernels give it, NaN only where the scalar `invert` fails).
///
/// # Panics
/// If the call's slices differ in length.
pub fn run_with<S: SoaSampler, T: BatchFloat>(s: &S, backend: Backend, job: Soa<'_, T>) {
    match job {
        Soa::Sample { u, v, dir, pdf } => s.sample_soa_with(backend, u, v, dir, pdf),
        Soa::Pdf { dir, pdf } => s.pdf_soa_with(backend, dir, pdf),
        Soa::Invert { dir, uv } => s.invert_soa_with(backend, dir, uv),
    }
}

/// [`run_with`] on the detected backend on all rayon threads, through the project's one parallel
/// driver ([`crate::batch::par`], [`crate::batch::PAR_CHUNK`] points a task). Each output depends only on its own
/// input, so the result is the same for any number of threads.
///
/// # Panics
/// If the call's slices differ in length.
pub fn run_par<S: SoaSampler, T: BatchFloat>(s: &S, job: Soa<'_, T>) {
    let b = Backend::detect();
    crate::batch::par(job, &|j| run_with(s, b, j))
}

/// [`SoaSampler::sample_soa`] on all rayon threads ([`run_par`]).
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
    run_par(s, Soa::Sample { u, v, dir, pdf })
}

/// [`SoaSampler::pdf_soa`] on all rayon threads ([`run_par`]).
///
/// # Panics
/// If the slices differ in length.
pub fn pdf_soa_par<S: SoaSampler, T: BatchFloat>(s: &S, dir: [&[T]; 3], pdf: &mut [T]) {
    run_par(s, Soa::Pdf { dir, pdf })
}

/// [`SoaSampler::invert_soa`] on all rayon threads ([`run_par`]).
///
/// # Panics
/// If the slices differ in length.
pub fn invert_soa_par<S: SoaSampler, T: BatchFloat>(s: &S, dir: [&[T]; 3], uv: [&mut [T]; 2]) {
    run_par(s, Soa::Invert { dir, uv })
}

/// The HDS maps' batch inverse ([`Sampler::batch`] with [`Soa::Invert`], both precisions):
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

/// The one [`Sampler::batch`] of a map that implements [`SoaSampler`] (the HDS maps): f64 calls
/// run the map's vector kernels on the slices directly, with no transposes; f32 calls are the
/// single override point of the float32 path: the map's float32 map (`float32()`, built on the
/// first call), else (a grid beyond its limits) the f64 kernels rounded once.
macro_rules! soa_sampler_methods {
    () => {
        fn batch(&self, job: $crate::batch::Batch<'_>) {
            use $crate::batch::{Batch, Soa};
            use $crate::mapping::batch::{invert_soa_nonzero, SoaSampler};
            match (job, self.float32()) {
                (Batch::F64(Soa::Sample { u, v, dir, pdf }), _) => self.sample_soa(u, v, dir, pdf),
                (Batch::F64(Soa::Pdf { dir, pdf }), _) => self.pdf_soa(dir, pdf),
                (Batch::F64(Soa::Invert { dir, uv }), _) => invert_soa_nonzero(self, dir, uv),
                (Batch::F32(job), Some(f)) => f.batch(job),
                (Batch::F32(Soa::Sample { u, v, dir, pdf }), None) => {
                    self.sample_soa(u, v, dir, pdf)
                }
                (Batch::F32(Soa::Pdf { dir, pdf }), None) => self.pdf_soa(dir, pdf),
                (Batch::F32(Soa::Invert { dir, uv }), None) => invert_soa_nonzero(self, dir, uv),
            }
        }
    };
}
pub(crate) use soa_sampler_methods;
