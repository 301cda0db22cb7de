//! The one sampler contract every method of the project implements: the HDS mapping on the
//! hemisphere and on the sphere, and every baseline. The CLI, the checks, the benchmarks and the
//! plots take any `&dyn Sampler` without special cases (STYLE.md).
//!
//! Directions are unit vectors `[x, y, z]` in the sampler's frame; densities are **per steradian**
//! with respect to solid angle; points of the unit square are `[u, v]` with 0 ≤ u, v ≤ 1.

use crate::batch::{par, CHUNK};
pub use crate::batch::{Batch, Soa};

/// A unit direction `[x, y, z]`.
pub type Vec3 = [f64; 3];
/// A point `[u, v]` of the unit square [0, 1]².
pub type Point2 = [f64; 2];

/// One sample: a unit direction and the exact density (per steradian) of the map that produced it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sample {
    /// The sampled unit direction.
    pub direction: Vec3,
    /// Density of the sampler at `direction`, per steradian. Equal to [`Sampler::pdf`] there.
    pub pdf: f64,
}

/// The part of the sphere a sampler covers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    /// The upper hemisphere z ≥ 0 (2π sr).
    Hemisphere,
    /// The whole sphere (4π sr).
    Sphere,
}

impl Domain {
    /// Solid angle of the domain in steradians.
    pub fn solid_angle(self) -> f64 {
        match self {
            Domain::Hemisphere => 2.0 * std::f64::consts::PI,
            Domain::Sphere => 4.0 * std::f64::consts::PI,
        }
    }
    /// The domain policy of the library: [`Domain::Hemisphere`] when the diagram lies within
    /// θ ≤ 90° (its last parallel is at most π/2), [`Domain::Sphere`] otherwise.
    ///
    /// (Callers that know more may choose otherwise: the CLI gives photometric files the whole
    /// sphere always, since a luminaire's file covers the sphere even when it lists only its lower
    /// half.)
    ///
    /// ```
    /// use gonio::{Diagram, Domain};
    /// let hemi = Diagram::from_degrees(&[0.0, 90.0], &[0.0], &[vec![1.0, 0.0]]).unwrap();
    /// assert_eq!(Domain::for_diagram(&hemi), Domain::Hemisphere);
    /// let down = Diagram::from_degrees(&[90.0, 180.0], &[0.0], &[vec![0.0, 1.0]]).unwrap();
    /// assert_eq!(Domain::for_diagram(&down), Domain::Sphere);
    /// ```
    pub fn for_diagram(diagram: &crate::diagram::Diagram) -> Domain {
        match diagram.theta().last() {
            Some(&t) if t <= std::f64::consts::FRAC_PI_2 => Domain::Hemisphere,
            _ => Domain::Sphere,
        }
    }

    /// Whether the unit direction `d` lies in the domain.
    pub fn contains(self, d: Vec3) -> bool {
        match self {
            Domain::Hemisphere => d[2] >= 0.0,
            Domain::Sphere => true,
        }
    }
}

/// Why [`Sampler::invert`] gave no point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum InvertError {
    /// The method has no inverse (e.g. rejection sampling).
    #[error("this sampling method has no inverse")]
    Unsupported,
    /// The direction is not in the sampler's domain or is not a finite non-zero vector.
    #[error("the direction lies outside the sampler's domain")]
    OutsideDomain,
    /// The direction lies in the domain, but the density is 0 there and no point of the square
    /// maps to it (e.g. the lower hemisphere of a sphere map for a luminaire that emits no light
    /// downwards).
    #[error("no point of the square maps to the direction: the density is 0 there")]
    ZeroDensity,
}

/// A map from the unit square to directions with its exact density and (where it exists) its inverse.
///
/// Contract, for every implementation:
/// * `sample(u)` is defined for every `u` in the closed square [0, 1]² and returns a finite unit
///   direction in [`Sampler::domain`] with `pdf == self.pdf(direction)` (up to round-off);
/// * `pdf(d)` is the density of `sample` per steradian, 0 outside the domain and where the target is 0;
/// * `invert(sample(u)) == u` wherever the pdf is positive (away from measure-zero seams that the
///   implementation documents).
///
/// The trait is narrow on purpose: the seven methods a sampler must have, the power of its
/// target, and one batch entry ([`Sampler::batch`]) that a sampler with vector kernels
/// overrides. Every other batch form (arrays of structures, split outputs, float32, parallel) is
/// an adapter over that entry ([`Batches`], [`sample_batch_par`]); what only the HDS map has
/// (ratio bound, refinement, completions, stages) is a method of the map
/// ([`crate::mapping::MapRef`], reached through [`crate::method::Built::hds_map`]).
pub trait Sampler: Send + Sync {
    /// Short name of the method, as the CLI's `--method` spells it.
    fn name(&self) -> &'static str;
    /// The domain the samples lie in.
    fn domain(&self) -> Domain;
    /// Maps a point of the unit square to a direction and its density.
    fn sample(&self, u: Point2) -> Sample;
    /// Density of [`Sampler::sample`] at a unit direction, per steradian.
    fn pdf(&self, direction: Vec3) -> f64;
    /// The point of the unit square that `sample` maps to `direction`.
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError>;
    /// The target density the sampler approximates (the diagram interpolated bilinearly in (θ, φ),
    /// normalised to integrate to 1 over the domain), per steradian.
    fn target_pdf(&self, direction: Vec3) -> f64;
    /// Bytes held by the sampler's precomputed tables.
    fn memory_bytes(&self) -> usize;

    /// The power of the target: the integral over the domain of the un-normalised density that
    /// [`Sampler::target_pdf`] normalises (the diagram interpolated bilinearly in (θ, φ)), in the
    /// diagram's units × sr (lumens for a diagram in candela). `target_pdf` = that density / this.
    ///
    /// Every sampler of the library returns it; the default, for samplers that do not know it, is
    /// NaN. (The HDS map integrates the diagram as completed for its tables, see
    /// [`crate::HemisphereMap`]; it equals [`crate::Diagram::integral`] of the raw diagram when the
    /// completion adds nothing.)
    fn target_power(&self) -> f64 {
        f64::NAN
    }

    /// Runs one structure-of-arrays batch call ([`Batch`]): the one batch entry of the contract,
    /// through which every batch form of [`Batches`] and every parallel batch goes. Allocates
    /// nothing.
    ///
    /// The default ([`scalar_batch`]) calls [`Sampler::sample`], [`Sampler::pdf`] and
    /// [`Sampler::invert`] point by point (so batches equal the scalar calls bit for bit), and
    /// evaluates a float32 call in f64 ([`CHUNK`] points at a time on the stack, through this
    /// method's f64 form) rounding each result once. The HDS maps override it with their vector
    /// kernels and their float32 map.
    ///
    /// # Panics
    /// If the call's slices differ in length (a programming error, not an input error).
    fn batch(&self, job: Batch<'_>) {
        scalar_batch(self, job)
    }
}

/// A shared reference to a sampler is the sampler: every call forwards, so that a borrowed map
/// (an environment map's own sphere map, say) goes wherever a `Box<dyn Sampler + '_>` does.
impl<T: Sampler + ?Sized> Sampler for &T {
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn domain(&self) -> Domain {
        (**self).domain()
    }
    fn sample(&self, u: Point2) -> Sample {
        (**self).sample(u)
    }
    fn pdf(&self, direction: Vec3) -> f64 {
        (**self).pdf(direction)
    }
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        (**self).invert(direction)
    }
    fn target_pdf(&self, direction: Vec3) -> f64 {
        (**self).target_pdf(direction)
    }
    fn memory_bytes(&self) -> usize {
        (**self).memory_bytes()
    }
    fn target_power(&self) -> f64 {
        (**self).target_power()
    }
    fn batch(&self, job: Batch<'_>) {
        (**self).batch(job)
    }
}

/// The default [`Sampler::batch`]: the scalar calls point by point in f64; a float32 call widened
/// [`CHUNK`] points at a time into stack buffers, run through `s.batch` in f64 (so a sampler that
/// overrides only the f64 calls gets its float32 calls from them), each result rounded once.
/// Float32 directions are scaled to unit length in f64 first (an f32 unit vector is unit only to
/// ~1e-7, which at the rim of a map would read as beyond it).
///
/// # Panics
/// If the call's slices differ in length.
pub fn scalar_batch<S: Sampler + ?Sized>(s: &S, job: Batch<'_>) {
    match job {
        Batch::F64(job) => scalar_f64(s, job),
        Batch::F32(job) => widened(s, job),
    }
}

/// The f64 calls of [`scalar_batch`].
fn scalar_f64<S: Sampler + ?Sized>(s: &S, job: Soa<'_, f64>) {
    let n = job.len();
    match job {
        Soa::Sample { u, v, dir, pdf } => {
            let [x, y, z] = dir;
            for k in 0..n {
                let o = s.sample([u[k], v[k]]);
                [x[k], y[k], z[k]] = o.direction;
                pdf[k] = o.pdf;
            }
        }
        Soa::Pdf { dir, pdf } => {
            for (k, p) in pdf.iter_mut().enumerate() {
                *p = s.pdf([dir[0][k], dir[1][k], dir[2][k]]);
            }
        }
        Soa::Invert { dir, uv } => {
            let [u, v] = uv;
            for k in 0..n {
                let p = s
                    .invert([dir[0][k], dir[1][k], dir[2][k]])
                    .unwrap_or([f64::NAN; 2]);
                (u[k], v[k]) = (p[0], p[1]);
            }
        }
    }
}

/// The f32 calls of [`scalar_batch`]: widened, run through the sampler's f64 batch, rounded.
fn widened<S: Sampler + ?Sized>(s: &S, job: Soa<'_, f32>) {
    let n = job.len();
    let mut bi = [[0.0f64; CHUNK]; 3];
    let mut bo = [[0.0f64; CHUNK]; 4];
    let [o0, o1, o2, o3] = &mut bo;
    match job {
        Soa::Sample {
            u,
            v,
            dir: [x, y, z],
            pdf,
        } => {
            for r in chunks(n) {
                let m = r.len();
                let [bu, bv, _] = &mut bi;
                widen(&u[r.clone()], bu);
                widen(&v[r.clone()], bv);
                s.batch(Batch::F64(Soa::Sample {
                    u: &bu[..m],
                    v: &bv[..m],
                    dir: [&mut o0[..m], &mut o1[..m], &mut o2[..m]],
                    pdf: &mut o3[..m],
                }));
                narrow(&o0[..m], &mut x[r.clone()]);
                narrow(&o1[..m], &mut y[r.clone()]);
                narrow(&o2[..m], &mut z[r.clone()]);
                narrow(&o3[..m], &mut pdf[r]);
            }
        }
        Soa::Pdf { dir, pdf } => {
            for r in chunks(n) {
                let m = r.len();
                let dir = widen_unit(dir, r.clone(), &mut bi);
                s.batch(Batch::F64(Soa::Pdf {
                    dir,
                    pdf: &mut o0[..m],
                }));
                narrow(&o0[..m], &mut pdf[r]);
            }
        }
        Soa::Invert { dir, uv: [u, v] } => {
            for r in chunks(n) {
                let m = r.len();
                let dir = widen_unit(dir, r.clone(), &mut bi);
                s.batch(Batch::F64(Soa::Invert {
                    dir,
                    uv: [&mut o0[..m], &mut o1[..m]],
                }));
                narrow(&o0[..m], &mut u[r.clone()]);
                narrow(&o1[..m], &mut v[r]);
            }
        }
    }
}

/// The ranges of at most [`CHUNK`] points that cover `0..n`.
fn chunks(n: usize) -> impl Iterator<Item = std::ops::Range<usize>> {
    (0..n).step_by(CHUNK).map(move |s| s..(s + CHUNK).min(n))
}

/// The f32 directions `dir[·][r]` widened into `buf` and scaled to unit length in f64
/// ([`crate::batch::renormalise`]).
fn widen_unit<'b>(
    dir: [&[f32]; 3],
    r: std::ops::Range<usize>,
    buf: &'b mut [[f64; CHUNK]; 3],
) -> [&'b [f64]; 3] {
    let m = r.len();
    for (b, d) in buf.iter_mut().zip(dir) {
        widen(&d[r.clone()], b);
    }
    let [x, y, z] = buf;
    crate::batch::renormalise([&mut x[..], &mut y[..], &mut z[..]], m);
    [&x[..m], &y[..m], &z[..m]]
}

/// f32 values widened into the first entries of an f64 buffer.
fn widen(src: &[f32], buf: &mut [f64; CHUNK]) {
    for (b, &x) in buf.iter_mut().zip(src) {
        *b = f64::from(x);
    }
}

/// f64 values rounded (to nearest) into f32.
fn narrow(src: &[f64], dst: &mut [f32]) {
    for (d, &x) in dst.iter_mut().zip(src) {
        *d = x as f32;
    }
}

/// The batch forms of every sampler, adapters over its one entry [`Sampler::batch`]: arrays of
/// structures, split outputs, structure-of-arrays slices in f64 and f32. Implemented for every
/// [`Sampler`] (and `dyn Sampler`); nothing to implement. None allocates: the arrays of
/// structures are transposed [`CHUNK`] points at a time through stack buffers.
///
/// # Panics
/// Every method panics if its slices differ in length (a programming error, not an input error).
pub trait Batches: Sampler {
    /// Samples every point of `u` into the same position of `out`.
    fn sample_batch(&self, u: &[Point2], out: &mut [Sample]) {
        assert_eq!(u.len(), out.len(), "sample_batch: slices differ in length");
        for (u, out) in u.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
            let n = u.len();
            let [bu, bv] = split_points(u);
            let mut o = [[0.0f64; CHUNK]; 4];
            let [ox, oy, oz, op] = &mut o;
            self.batch(Batch::F64(Soa::Sample {
                u: &bu[..n],
                v: &bv[..n],
                dir: [&mut ox[..n], &mut oy[..n], &mut oz[..n]],
                pdf: &mut op[..n],
            }));
            for (k, o) in out.iter_mut().enumerate() {
                *o = Sample {
                    direction: [ox[k], oy[k], oz[k]],
                    pdf: op[k],
                };
            }
        }
    }

    /// [`Batches::sample_batch`] with the directions and the densities in separate slices (the
    /// layout of the Python package's and the C API's outputs): sample k goes to `dirs[k]` and
    /// `pdf[k]`, the same values.
    fn sample_batch_split(&self, u: &[Point2], dirs: &mut [Vec3], pdf: &mut [f64]) {
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
            self.batch(Batch::F64(Soa::Sample {
                u: &bu[..n],
                v: &bv[..n],
                dir: [&mut ox[..n], &mut oy[..n], &mut oz[..n]],
                pdf,
            }));
            for (k, d) in dirs.iter_mut().enumerate() {
                *d = [ox[k], oy[k], oz[k]];
            }
        }
    }

    /// [`Sampler::pdf`] of every direction of `dirs` into the same position of `out`.
    fn pdf_batch(&self, dirs: &[Vec3], out: &mut [f64]) {
        assert_eq!(dirs.len(), out.len(), "pdf_batch: slices differ in length");
        for (d, out) in dirs.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
            let n = d.len();
            let b = split_dirs(d);
            self.batch(Batch::F64(Soa::Pdf {
                dir: [&b[0][..n], &b[1][..n], &b[2][..n]],
                pdf: out,
            }));
        }
    }

    /// [`Sampler::invert`] of every direction of `dirs` into the same position of `out`: the
    /// batch inverse, and where it has no point, the scalar `invert`'s reason
    /// ([`InvertError::ZeroDensity`] where the batch's density is 0 and the scalar call maps).
    fn invert_batch(&self, dirs: &[Vec3], out: &mut [Result<Point2, InvertError>]) {
        assert_eq!(
            dirs.len(),
            out.len(),
            "invert_batch: slices differ in length"
        );
        for (d, out) in dirs.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
            let n = d.len();
            let b = split_dirs(d);
            let (mut u, mut v) = ([0.0f64; CHUNK], [0.0f64; CHUNK]);
            self.batch(Batch::F64(Soa::Invert {
                dir: [&b[0][..n], &b[1][..n], &b[2][..n]],
                uv: [&mut u[..n], &mut v[..n]],
            }));
            for (k, o) in out.iter_mut().enumerate() {
                // One store per branch: a `Result` built first and then copied was stored with
                // unaligned moves that stalled on store forwarding (30 % of the inverse's time).
                if u[k].is_nan() || v[k].is_nan() {
                    *o = Err(no_preimage(self, d[k]));
                } else {
                    *o = Ok([u[k], v[k]]);
                }
            }
        }
    }

    /// Maps the points `(u[k], v[k])` of the unit square to directions
    /// `(dir[0][k], dir[1][k], dir[2][k])` and their densities `pdf[k]` (per steradian).
    fn sample_batch_soa(&self, u: &[f64], v: &[f64], dir: [&mut [f64]; 3], pdf: &mut [f64]) {
        self.batch(Batch::F64(Soa::Sample { u, v, dir, pdf }))
    }

    /// The density (per steradian) at each unit direction `(dir[0][k], dir[1][k], dir[2][k])`
    /// into `pdf[k]`.
    fn pdf_batch_soa(&self, dir: [&[f64]; 3], pdf: &mut [f64]) {
        self.batch(Batch::F64(Soa::Pdf { dir, pdf }))
    }

    /// The point `(uv[0][k], uv[1][k])` of the unit square of each unit direction, NaN in both
    /// coordinates where [`Sampler::invert`] gives an error.
    fn invert_batch_soa(&self, dir: [&[f64]; 3], uv: [&mut [f64]; 2]) {
        self.batch(Batch::F64(Soa::Invert { dir, uv }))
    }

    /// [`Batches::sample_batch_soa`] in float32: the sampler's float32 map where it has one (the
    /// HDS maps' [`crate::mapping::Float32Map`]: f32 tables and arithmetic, its own exact
    /// density), else the f64 map rounded once ([`scalar_batch`]).
    fn sample_batch_soa_f32(&self, u: &[f32], v: &[f32], dir: [&mut [f32]; 3], pdf: &mut [f32]) {
        self.batch(Batch::F32(Soa::Sample { u, v, dir, pdf }))
    }

    /// [`Batches::pdf_batch_soa`] in float32 at f32 unit directions (unit to within f32
    /// rounding).
    fn pdf_batch_soa_f32(&self, dir: [&[f32]; 3], pdf: &mut [f32]) {
        self.batch(Batch::F32(Soa::Pdf { dir, pdf }))
    }

    /// [`Batches::invert_batch_soa`] in float32 (NaN where there is no preimage).
    fn invert_batch_soa_f32(&self, dir: [&[f32]; 3], uv: [&mut [f32]; 2]) {
        self.batch(Batch::F32(Soa::Invert { dir, uv }))
    }
}

impl<S: Sampler + ?Sized> Batches for S {}

/// Why a direction has no preimage (the batch gave NaN): the scalar call's reason, or
/// [`InvertError::ZeroDensity`] where the scalar call maps but the batch's density is 0.
#[cold]
#[inline(never)]
fn no_preimage<S: Sampler + ?Sized>(s: &S, d: Vec3) -> InvertError {
    match s.invert(d) {
        Err(e) => e,
        Ok(_) => InvertError::ZeroDensity,
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

/// [`Sampler::batch`] on all rayon threads, [`crate::batch::PAR_CHUNK`] points a task
/// ([`crate::batch::par`]). Each output depends only on its own input point, so the result is
/// identical for any number of threads.
///
/// # Panics
/// If the call's slices differ in length.
pub fn batch_par<S: Sampler + ?Sized>(sampler: &S, job: Batch<'_>) {
    par(job, &|j| sampler.batch(j))
}

/// [`Batches::sample_batch`] on all rayon threads (see [`batch_par`]).
///
/// # Panics
/// If the two slices differ in length.
pub fn sample_batch_par<S: Sampler + ?Sized>(sampler: &S, u: &[Point2], out: &mut [Sample]) {
    par((u, out), &|(u, o)| sampler.sample_batch(u, o))
}

/// [`Batches::pdf_batch`] for every direction, on all rayon threads (see [`batch_par`]).
///
/// # Panics
/// If the two slices differ in length.
pub fn pdf_batch_par<S: Sampler + ?Sized>(sampler: &S, dirs: &[Vec3], out: &mut [f64]) {
    par((dirs, out), &|(d, o)| sampler.pdf_batch(d, o))
}

/// [`Batches::invert_batch`] on all rayon threads (see [`batch_par`]).
///
/// # Panics
/// If the two slices differ in length.
pub fn invert_batch_par<S: Sampler + ?Sized>(
    sampler: &S,
    dirs: &[Vec3],
    out: &mut [Result<Point2, InvertError>],
) {
    par((dirs, out), &|(d, o)| sampler.invert_batch(d, o))
}

/// Polar angle θ (radians from +z) and azimuth φ in [0, 2π) (radians from +x toward +y) of a unit
/// direction. At the poles (x = y = 0, either sign of zero) φ = 0: the azimuth of every pole
/// direction is meridian 0's, so (±0, ±0, ±1) all get the same values (`atan2(0, −0)` would be π).
///
/// θ = atan2(√(x² + y²), z), accurate to a few ulps everywhere; acos(z) would lose half the digits
/// near the poles (θ = 1e-4 came back with a relative error of 1e-8, θ = 1e-7 with 2e-2).
pub fn spherical(d: Vec3) -> (f64, f64) {
    let theta = d[0].hypot(d[1]).atan2(d[2]);
    if d[0] == 0.0 && d[1] == 0.0 {
        return (theta, 0.0);
    }
    let mut phi = d[1].atan2(d[0]);
    if phi < 0.0 {
        phi += std::f64::consts::TAU;
    }
    if phi >= std::f64::consts::TAU {
        phi = 0.0;
    }
    (theta, phi)
}

/// The unit direction of polar angle θ and azimuth φ (radians).
pub fn direction(theta: f64, phi: f64) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * cp, st * sp, ct]
}

/// `d` scaled to unit length, or `None` if it is zero or not finite. Any finite non-zero vector is
/// normalised, however long or short (1e-300 … 1e300 components). Where the sum of squares is far
/// from overflow and underflow (between 1e-290 and 1e290), `d` is multiplied by the reciprocal of
/// its length (one division; within 3 ulp of unit length); otherwise it is first divided by its
/// largest component magnitude, so the sum of squares neither overflows nor underflows.
pub fn normalize(d: Vec3) -> Option<Vec3> {
    if !d.iter().all(|c| c.is_finite()) {
        return None;
    }
    let ss = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (1e-290..=1e290).contains(&ss) {
        let inv = 1.0 / ss.sqrt();
        return Some([d[0] * inv, d[1] * inv, d[2] * inv]);
    }
    let big = d.iter().fold(0.0f64, |a, c| a.max(c.abs()));
    if !(big > 0.0) {
        return None;
    }
    let s = [d[0] / big, d[1] / big, d[2] / big];
    let l = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    Some([s[0] / l, s[1] / l, s[2] / l])
}
