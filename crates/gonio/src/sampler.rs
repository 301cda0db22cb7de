//! The one sampler contract every method of the project implements: the HDS mapping on the
//! hemisphere and on the sphere, and every baseline. The CLI, the checks, the benchmarks and the
//! plots take any `&dyn Sampler` without special cases (STYLE.md).
//!
//! Directions are unit vectors `[x, y, z]` in the sampler's frame; densities are **per steradian**
//! with respect to solid angle; points of the unit square are `[u, v]` with 0 ≤ u, v ≤ 1.

use crate::batch::{check_len, CHUNK, PAR_CHUNK};
use rayon::prelude::*;

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

/// A borrowed HDS map, as [`Sampler::hds_map`] returns it: what only the map has is reached
/// through its variant, with no downcast.
///
/// ```
/// use gonio::{Diagram, Domain, MapRef, Method};
/// let d = Diagram::from_degrees(&[0.0, 90.0, 180.0], &[0.0], &[vec![1.0, 0.5, 2.0]]).unwrap();
/// let s = Method::Hds.build(&d, Domain::Sphere).unwrap();
/// match s.hds_map() {
///     Some(MapRef::Sphere(m)) => assert!(m.lower_probability().unwrap() > 0.5),
///     _ => unreachable!("the HDS method on the sphere is a sphere map"),
/// }
/// assert!(Method::Uniform.build(&d, Domain::Sphere).unwrap().hds_map().is_none());
/// ```
#[derive(Debug, Clone, Copy)]
pub enum MapRef<'a> {
    /// The map of the upper hemisphere.
    Hemisphere(&'a crate::HemisphereMap),
    /// The map of the whole sphere (either layout).
    Sphere(&'a crate::SphereMap),
}

/// A map from the unit square to directions with its exact density and (where it exists) its inverse.
///
/// Contract, for every implementation:
/// * `sample(u)` is defined for every `u` in the closed square [0, 1]² and returns a finite unit
///   direction in [`Sampler::domain`] with `pdf == self.pdf(direction)` (up to round-off);
/// * `pdf(d)` is the density of `sample` per steradian, 0 outside the domain and where the target is 0;
/// * `invert(sample(u)) == u` wherever the pdf is positive (away from measure-zero seams that the
///   implementation documents).
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

    /// A guaranteed range (min, max) of `pdf / target_pdf` over every direction where the target
    /// is positive, computed at build time, for methods that have one (the HDS map); `None` (the
    /// default) where the method promises no bound.
    fn ratio_bound(&self) -> Option<(f64, f64)> {
        None
    }

    /// What refinement to a tolerance asked, reached and cost, for a map built with one
    /// ([`crate::mapping::Refinement`]); `None` (the default) otherwise.
    fn refinement(&self) -> Option<&crate::mapping::Refinement> {
        None
    }

    /// The zones without data that the sampler completed with zero light (the HDS maps, issue 9),
    /// each a warning for the user; empty (the default) for samplers that complete nothing.
    fn completions(&self) -> &[crate::mapping::Completion] {
        &[]
    }

    /// The intermediate points of the forward map at `u` (for the warp plot and tests), for
    /// methods built from stages (the HDS map); `None` (the default) otherwise.
    fn stages(&self, u: Point2) -> Option<crate::mapping::Stages> {
        let _ = u;
        None
    }

    /// The HDS map behind the sampler, for what only the map has (e.g.
    /// [`crate::SphereMap::lower_probability`] or the completed grid for `gonio info`, the stages
    /// of both layouts for the warp plot). `None` (the default) for every other method; the
    /// library's [`crate::HemisphereMap`] and [`crate::SphereMap`] return themselves. This is the
    /// one typed accessor to concrete maps: no consumer downcasts.
    fn hds_map(&self) -> Option<MapRef<'_>> {
        None
    }

    /// Samples every point of `u` into the same position of `out`; allocates nothing.
    ///
    /// # Panics
    /// If the two slices differ in length (a programming error, not an input error).
    fn sample_batch(&self, u: &[Point2], out: &mut [Sample]) {
        assert_eq!(u.len(), out.len(), "sample_batch: slices differ in length");
        for (o, &p) in out.iter_mut().zip(u) {
            *o = self.sample(p);
        }
    }

    /// [`Sampler::sample_batch`] with the directions and the densities in separate slices (the
    /// layout of the Python package's and the C API's outputs): sample k goes to `dirs[k]` and
    /// `pdf[k]`, the same values as `sample_batch`. Allocates nothing. The default goes through
    /// `sample_batch` [`CHUNK`] points at a time; the HDS maps write their SIMD batch path's results
    /// directly.
    ///
    /// # Panics
    /// If the slices differ in length.
    fn sample_batch_split(&self, u: &[Point2], dirs: &mut [Vec3], pdf: &mut [f64]) {
        assert!(
            u.len() == dirs.len() && u.len() == pdf.len(),
            "sample_batch_split: slices differ in length"
        );
        let mut buf = [Sample::default(); CHUNK];
        for ((u, d), p) in u
            .chunks(CHUNK)
            .zip(dirs.chunks_mut(CHUNK))
            .zip(pdf.chunks_mut(CHUNK))
        {
            let b = &mut buf[..u.len()];
            self.sample_batch(u, b);
            for ((d, p), b) in d.iter_mut().zip(p.iter_mut()).zip(b.iter()) {
                *d = b.direction;
                *p = b.pdf;
            }
        }
    }

    /// [`Sampler::pdf`] of every direction of `dirs` into the same position of `out`; allocates
    /// nothing. The HDS maps override it with their SIMD batch path ([`crate::mapping::batch`]).
    ///
    /// # Panics
    /// If the two slices differ in length.
    fn pdf_batch(&self, dirs: &[Vec3], out: &mut [f64]) {
        assert_eq!(dirs.len(), out.len(), "pdf_batch: slices differ in length");
        for (o, &d) in out.iter_mut().zip(dirs) {
            *o = self.pdf(d);
        }
    }

    /// [`Sampler::invert`] of every direction of `dirs` into the same position of `out`;
    /// allocates nothing. The HDS maps override it with their SIMD batch path.
    ///
    /// # Panics
    /// If the two slices differ in length.
    fn invert_batch(&self, dirs: &[Vec3], out: &mut [Result<Point2, InvertError>]) {
        assert_eq!(
            dirs.len(),
            out.len(),
            "invert_batch: slices differ in length"
        );
        for (o, &d) in out.iter_mut().zip(dirs) {
            *o = self.invert(d);
        }
    }

    // Structure-of-arrays batches: the calls the C ABI and the Python package make. Every
    // default below runs the methods above on at most [`CHUNK`] points at a time in buffers on
    // the stack; the HDS maps override all six with their vector kernels
    // ([`crate::mapping::batch::SoaSampler`]), with no transposes.

    /// Maps the points `(u[k], v[k])` of the unit square to directions
    /// `(dir[0][k], dir[1][k], dir[2][k])` and their densities `pdf[k]` (per steradian): the
    /// values of [`Sampler::sample_batch`]. Allocates nothing.
    ///
    /// The default transposes [`CHUNK`] points at a time through stack buffers into
    /// `sample_batch` (so it equals the scalar [`Sampler::sample`] bit for bit unless
    /// `sample_batch` is overridden). The HDS maps run their vector kernels on the slices
    /// directly ([`crate::mapping::batch::SoaSampler::sample_soa`], bit for bit).
    ///
    /// # Panics
    /// If the slices differ in length (a programming error, not an input error).
    fn sample_batch_soa(&self, u: &[f64], v: &[f64], dir: [&mut [f64]; 3], pdf: &mut [f64]) {
        let [x, y, z] = dir;
        let n = u.len();
        check_len(
            "sample_batch_soa",
            n,
            &[v.len(), x.len(), y.len(), z.len(), pdf.len()],
        );
        let mut pts = [[0.0f64; 2]; CHUNK];
        let mut out = [Sample::default(); CHUNK];
        for start in (0..n).step_by(CHUNK) {
            let m = CHUNK.min(n - start);
            for (k, p) in pts[..m].iter_mut().enumerate() {
                *p = [u[start + k], v[start + k]];
            }
            self.sample_batch(&pts[..m], &mut out[..m]);
            for (k, o) in out[..m].iter().enumerate() {
                let i = start + k;
                [x[i], y[i], z[i]] = o.direction;
                pdf[i] = o.pdf;
            }
        }
    }

    /// The density (per steradian) of [`Sampler::sample`] at each unit direction
    /// `(dir[0][k], dir[1][k], dir[2][k])` into `pdf[k]`: the values of [`Sampler::pdf_batch`].
    /// Allocates nothing. The default transposes [`CHUNK`] directions at a time into `pdf_batch`;
    /// the HDS maps call [`crate::mapping::batch::SoaSampler::pdf_soa`] (bit for bit).
    ///
    /// # Panics
    /// If the slices differ in length.
    fn pdf_batch_soa(&self, dir: [&[f64]; 3], pdf: &mut [f64]) {
        let n = pdf.len();
        check_len(
            "pdf_batch_soa",
            n,
            &[dir[0].len(), dir[1].len(), dir[2].len()],
        );
        let mut d = [[0.0f64; 3]; CHUNK];
        for start in (0..n).step_by(CHUNK) {
            let m = CHUNK.min(n - start);
            for (k, d) in d[..m].iter_mut().enumerate() {
                let i = start + k;
                *d = [dir[0][i], dir[1][i], dir[2][i]];
            }
            self.pdf_batch(&d[..m], &mut pdf[start..start + m]);
        }
    }

    /// The point `(uv[0][k], uv[1][k])` of the unit square that [`Sampler::sample`] maps to each
    /// unit direction `(dir[0][k], dir[1][k], dir[2][k])`: the values of
    /// [`Sampler::invert_batch`], with NaN in both coordinates where it gives an error (outside
    /// the domain, density 0, or no inverse at all). Allocates nothing.
    ///
    /// The default transposes [`CHUNK`] directions at a time into `invert_batch`; the HDS maps
    /// call [`crate::mapping::batch::SoaSampler::invert_soa`] and write NaN where
    /// [`crate::mapping::batch::SoaSampler::pdf_soa`] is 0 (the rule of every sampler: no
    /// preimage where the density is 0).
    ///
    /// # Panics
    /// If the slices differ in length.
    fn invert_batch_soa(&self, dir: [&[f64]; 3], uv: [&mut [f64]; 2]) {
        let [u, v] = uv;
        let n = u.len();
        check_len(
            "invert_batch_soa",
            n,
            &[v.len(), dir[0].len(), dir[1].len(), dir[2].len()],
        );
        let mut d = [[0.0f64; 3]; CHUNK];
        let mut res = [Ok([0.0f64; 2]); CHUNK];
        for start in (0..n).step_by(CHUNK) {
            let m = CHUNK.min(n - start);
            for (k, d) in d[..m].iter_mut().enumerate() {
                let i = start + k;
                *d = [dir[0][i], dir[1][i], dir[2][i]];
            }
            self.invert_batch(&d[..m], &mut res[..m]);
            for (k, r) in res[..m].iter().enumerate() {
                let p = r.unwrap_or([f64::NAN; 2]);
                u[start + k] = p[0];
                v[start + k] = p[1];
            }
        }
    }

    /// [`Sampler::sample_batch_soa`] in float32: the sampler's float32 map where it has one,
    /// else the f64 map rounded once.
    ///
    /// The default widens [`CHUNK`] points at a time to f64, runs the f64 map and rounds every
    /// result once to f32. The HDS maps override it with their float32 map
    /// ([`crate::mapping::Float32Map`]: f32 tables and arithmetic, its own exact density; built
    /// on the first call, [`crate::HemisphereMap::float32`]).
    ///
    /// # Panics
    /// If the slices differ in length.
    fn sample_batch_soa_f32(&self, u: &[f32], v: &[f32], dir: [&mut [f32]; 3], pdf: &mut [f32]) {
        let [x, y, z] = dir;
        let n = u.len();
        check_len(
            "sample_batch_soa_f32",
            n,
            &[v.len(), x.len(), y.len(), z.len(), pdf.len()],
        );
        let (mut bu, mut bv) = ([0.0f64; CHUNK], [0.0f64; CHUNK]);
        let mut bo = [[0.0f64; CHUNK]; 4];
        for start in (0..n).step_by(CHUNK) {
            let m = CHUNK.min(n - start);
            let r = start..start + m;
            widen(&u[r.clone()], &mut bu);
            widen(&v[r.clone()], &mut bv);
            let [bx, by, bz, bp] = &mut bo;
            self.sample_batch_soa(
                &bu[..m],
                &bv[..m],
                [&mut bx[..m], &mut by[..m], &mut bz[..m]],
                &mut bp[..m],
            );
            narrow(&bx[..m], &mut x[r.clone()]);
            narrow(&by[..m], &mut y[r.clone()]);
            narrow(&bz[..m], &mut z[r.clone()]);
            narrow(&bp[..m], &mut pdf[r]);
        }
    }

    /// [`Sampler::pdf_batch_soa`] in float32 at f32 unit directions (unit to within f32
    /// rounding): the sampler's float32 map where it has one, else the f64 map rounded once.
    ///
    /// The default widens [`CHUNK`] directions at a time to f64, scales each to unit length in
    /// f64 (an f32 unit vector is unit only to ~1e-7, which at the rim of a map would read as
    /// beyond it), runs the f64 call and rounds each density once. The HDS maps run their
    /// float32 map (which takes f32 directions as they are; its edge test has f32-sized slack).
    ///
    /// # Panics
    /// If the slices differ in length.
    fn pdf_batch_soa_f32(&self, dir: [&[f32]; 3], pdf: &mut [f32]) {
        let n = pdf.len();
        check_len(
            "pdf_batch_soa_f32",
            n,
            &[dir[0].len(), dir[1].len(), dir[2].len()],
        );
        let mut bd = [[0.0f64; CHUNK]; 3];
        let mut bp = [0.0f64; CHUNK];
        for start in (0..n).step_by(CHUNK) {
            let m = CHUNK.min(n - start);
            let r = start..start + m;
            for (b, d) in bd.iter_mut().zip(dir) {
                widen(&d[r.clone()], b);
            }
            let [bx, by, bz] = &mut bd;
            crate::batch::renormalise([&mut bx[..], &mut by[..], &mut bz[..]], m);
            self.pdf_batch_soa([&bx[..m], &by[..m], &bz[..m]], &mut bp[..m]);
            narrow(&bp[..m], &mut pdf[r]);
        }
    }

    /// [`Sampler::invert_batch_soa`] in float32 (NaN where `invert` fails): the sampler's float32
    /// map where it has one, else the f64 map rounded once. The default widens and renormalises
    /// the directions as [`Sampler::pdf_batch_soa_f32`] does and rounds each coordinate once; the
    /// HDS maps run their float32 map (NaN where its density is 0).
    ///
    /// # Panics
    /// If the slices differ in length.
    fn invert_batch_soa_f32(&self, dir: [&[f32]; 3], uv: [&mut [f32]; 2]) {
        let [u, v] = uv;
        let n = u.len();
        check_len(
            "invert_batch_soa_f32",
            n,
            &[v.len(), dir[0].len(), dir[1].len(), dir[2].len()],
        );
        let mut bd = [[0.0f64; CHUNK]; 3];
        let (mut bu, mut bv) = ([0.0f64; CHUNK], [0.0f64; CHUNK]);
        for start in (0..n).step_by(CHUNK) {
            let m = CHUNK.min(n - start);
            let r = start..start + m;
            for (b, d) in bd.iter_mut().zip(dir) {
                widen(&d[r.clone()], b);
            }
            let [bx, by, bz] = &mut bd;
            crate::batch::renormalise([&mut bx[..], &mut by[..], &mut bz[..]], m);
            self.invert_batch_soa([&bx[..m], &by[..m], &bz[..m]], [&mut bu[..m], &mut bv[..m]]);
            narrow(&bu[..m], &mut u[r.clone()]);
            narrow(&bv[..m], &mut v[r]);
        }
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
    fn ratio_bound(&self) -> Option<(f64, f64)> {
        (**self).ratio_bound()
    }
    fn refinement(&self) -> Option<&crate::mapping::Refinement> {
        (**self).refinement()
    }
    fn completions(&self) -> &[crate::mapping::Completion] {
        (**self).completions()
    }
    fn stages(&self, u: Point2) -> Option<crate::mapping::Stages> {
        (**self).stages(u)
    }
    fn hds_map(&self) -> Option<MapRef<'_>> {
        (**self).hds_map()
    }
    fn sample_batch(&self, u: &[Point2], out: &mut [Sample]) {
        (**self).sample_batch(u, out)
    }
    fn sample_batch_split(&self, u: &[Point2], dirs: &mut [Vec3], pdf: &mut [f64]) {
        (**self).sample_batch_split(u, dirs, pdf)
    }
    fn pdf_batch(&self, dirs: &[Vec3], out: &mut [f64]) {
        (**self).pdf_batch(dirs, out)
    }
    fn invert_batch(&self, dirs: &[Vec3], out: &mut [Result<Point2, InvertError>]) {
        (**self).invert_batch(dirs, out)
    }
    fn sample_batch_soa(&self, u: &[f64], v: &[f64], dir: [&mut [f64]; 3], pdf: &mut [f64]) {
        (**self).sample_batch_soa(u, v, dir, pdf)
    }
    fn pdf_batch_soa(&self, dir: [&[f64]; 3], pdf: &mut [f64]) {
        (**self).pdf_batch_soa(dir, pdf)
    }
    fn invert_batch_soa(&self, dir: [&[f64]; 3], uv: [&mut [f64]; 2]) {
        (**self).invert_batch_soa(dir, uv)
    }
    fn sample_batch_soa_f32(&self, u: &[f32], v: &[f32], dir: [&mut [f32]; 3], pdf: &mut [f32]) {
        (**self).sample_batch_soa_f32(u, v, dir, pdf)
    }
    fn pdf_batch_soa_f32(&self, dir: [&[f32]; 3], pdf: &mut [f32]) {
        (**self).pdf_batch_soa_f32(dir, pdf)
    }
    fn invert_batch_soa_f32(&self, dir: [&[f32]; 3], uv: [&mut [f32]; 2]) {
        (**self).invert_batch_soa_f32(dir, uv)
    }
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

/// [`Sampler::sample_batch`] on all rayon threads. Each output depends only on its own input point,
/// so the result is identical for any number of threads.
///
/// # Panics
/// If the two slices differ in length.
pub fn sample_batch_par<S: Sampler + ?Sized>(sampler: &S, u: &[Point2], out: &mut [Sample]) {
    assert_eq!(
        u.len(),
        out.len(),
        "sample_batch_par: slices differ in length"
    );
    out.par_chunks_mut(PAR_CHUNK)
        .zip(u.par_chunks(PAR_CHUNK))
        .for_each(|(o, p)| sampler.sample_batch(p, o));
}

/// [`Sampler::pdf_batch`] for every direction, on all rayon threads.
///
/// # Panics
/// If the two slices differ in length.
pub fn pdf_batch_par<S: Sampler + ?Sized>(sampler: &S, dirs: &[Vec3], out: &mut [f64]) {
    assert_eq!(
        dirs.len(),
        out.len(),
        "pdf_batch_par: slices differ in length"
    );
    out.par_chunks_mut(PAR_CHUNK)
        .zip(dirs.par_chunks(PAR_CHUNK))
        .for_each(|(o, d)| sampler.pdf_batch(d, o));
}

/// [`Sampler::invert_batch`] on all rayon threads (the result does not depend on their number).
///
/// # Panics
/// If the two slices differ in length.
pub fn invert_batch_par<S: Sampler + ?Sized>(
    sampler: &S,
    dirs: &[Vec3],
    out: &mut [Result<Point2, InvertError>],
) {
    assert_eq!(
        dirs.len(),
        out.len(),
        "invert_batch_par: slices differ in length"
    );
    out.par_chunks_mut(PAR_CHUNK)
        .zip(dirs.par_chunks(PAR_CHUNK))
        .for_each(|(o, d)| sampler.invert_batch(d, o));
}

/// [`Sampler::sample_batch_soa`] on all rayon threads, [`PAR_CHUNK`] points a task. Each output
/// depends only on its own input point, so the result is identical for any number of threads.
///
/// # Panics
/// If the slices differ in length.
pub fn sample_batch_soa_par<S: Sampler + ?Sized>(
    sampler: &S,
    u: &[f64],
    v: &[f64],
    dir: [&mut [f64]; 3],
    pdf: &mut [f64],
) {
    let [x, y, z] = dir;
    check_len(
        "sample_batch_soa_par",
        u.len(),
        &[v.len(), x.len(), y.len(), z.len(), pdf.len()],
    );
    x.par_chunks_mut(PAR_CHUNK)
        .zip(y.par_chunks_mut(PAR_CHUNK))
        .zip(z.par_chunks_mut(PAR_CHUNK))
        .zip(pdf.par_chunks_mut(PAR_CHUNK))
        .zip(u.par_chunks(PAR_CHUNK).zip(v.par_chunks(PAR_CHUNK)))
        .for_each(|((((x, y), z), p), (u, v))| sampler.sample_batch_soa(u, v, [x, y, z], p));
}

/// [`Sampler::pdf_batch_soa`] on all rayon threads (see [`sample_batch_soa_par`]).
///
/// # Panics
/// If the slices differ in length.
pub fn pdf_batch_soa_par<S: Sampler + ?Sized>(sampler: &S, dir: [&[f64]; 3], pdf: &mut [f64]) {
    check_len(
        "pdf_batch_soa_par",
        pdf.len(),
        &[dir[0].len(), dir[1].len(), dir[2].len()],
    );
    pdf.par_chunks_mut(PAR_CHUNK)
        .zip(dir[0].par_chunks(PAR_CHUNK))
        .zip(
            dir[1]
                .par_chunks(PAR_CHUNK)
                .zip(dir[2].par_chunks(PAR_CHUNK)),
        )
        .for_each(|((p, x), (y, z))| sampler.pdf_batch_soa([x, y, z], p));
}

/// [`Sampler::invert_batch_soa`] on all rayon threads (see [`sample_batch_soa_par`]).
///
/// # Panics
/// If the slices differ in length.
pub fn invert_batch_soa_par<S: Sampler + ?Sized>(
    sampler: &S,
    dir: [&[f64]; 3],
    uv: [&mut [f64]; 2],
) {
    let [u, v] = uv;
    check_len(
        "invert_batch_soa_par",
        u.len(),
        &[v.len(), dir[0].len(), dir[1].len(), dir[2].len()],
    );
    u.par_chunks_mut(PAR_CHUNK)
        .zip(v.par_chunks_mut(PAR_CHUNK))
        .zip(dir[0].par_chunks(PAR_CHUNK))
        .zip(
            dir[1]
                .par_chunks(PAR_CHUNK)
                .zip(dir[2].par_chunks(PAR_CHUNK)),
        )
        .for_each(|(((u, v), x), (y, z))| sampler.invert_batch_soa([x, y, z], [u, v]));
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
