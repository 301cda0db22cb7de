//! The float32 map: an HDS map of its own, with f32 tables and f32 arithmetic, for renderers
//! that work in float32 (issue 24, item 5).
//!
//! [`Float32Map`] is built from an f64 map ([`HemisphereMap::float32_map`],
//! [`SphereMap::float32_map`]). Its tables are the f64 map's tables rounded to f32, with the
//! tables derived from others recomputed from the rounded ones so that they stay consistent
//! (sector widths β_i = φ_{i+1} − φ_i, 1/(x_{j+1} − x_j), each meridian's total radial mass = the
//! last entry of its rounded cumulative row, the guide tables and their scales, the map's edge
//! radius); the split sphere's P_lower is rounded too. Its batch calls run the **same kernel
//! bodies** as the f64 maps (`mapping::simd::kernels`) over f32 vocabularies (portable, AVX2+FMA
//! on `__m256` with 32-bit indices, AVX-512 on `__m512`), with the precision-dependent constants
//! of `mapping::simd::math::Precision` for f32.
//!
//! **Contract** (tested in `tests/float32_map.rs`; the measured figures are in
//! `docs/API.md`, "Float32 maps"):
//!
//! - *Exact density of the float32 map.* The float32 map evaluated exactly is
//!   [`Float32Map::exact`]: the same tables widened to f64 (exactly) and run through the f64
//!   kernels. The pdf that [`Float32Map::sample_soa`] returns with a sample is that exact
//!   density at the returned (f32) direction to within 8 f32 ulps, plus, where the density is
//!   steep, the change of the density over the f32 round-off of the direction's disk position: a
//!   conditioning term |∂p/∂x|·δ with δ a few f32 ulps of the disk radius (and the same in
//!   azimuth).
//! - *pdf agrees with sample.* [`Float32Map::pdf_soa`] at a sample's direction agrees with the
//!   sample's pdf to the same bound.
//! - *Round trip.* [`Float32Map::invert_soa`] of a sample's direction gives its point of the
//!   square back to within 1e-5 (max norm) where the density is positive.
//! - *Bits do not depend on the backend*, the block size, the slice length or the number of
//!   threads: no fused multiply–add, the same operations in the same order on every backend.
//! - *Close to the f64 map.* The float32 map's pdf over the f64 map's target stays within the
//!   f64 map's guaranteed [`crate::MapRef::ratio_bound`] widened by a stated f32 margin where
//!   the target is not steep at the f32 scale (`docs/API.md`).
//!
//! Directions are f32 unit vectors as a renderer has them (unit only to f32 round-off): the
//! float32 map does not renormalise them; its edge test has an f32-sized slack
//! (`Precision::EDGE`).

use super::angular::wedge_guides;
use super::hds::{HdsCore, Tables};
use super::radial::{inverse_widths, radius_guides, Radial};
use super::simd::dispatch::TablesElem;
use super::simd::math::Precision;
use super::simd::Backend;
use super::soa_maps::{Shape, ViewKernel};
use super::sphere::CoresRef;
use super::split::SplitRule;
use super::{HemisphereMap, SphereMap};
use crate::batch::Soa;

// Points per chunk of the split sphere's partition into hemispheres, and per rayon task in the
// parallel calls: the crate's batch sizes.
use crate::batch::CHUNK;
/// The most meridians or parallels a float32 map takes: its guide tables (2M, 2N entries) must
/// index exactly through f32 (below 2²⁴).
pub const FLOAT32_MAX_NODES: usize = 1 << 22;

/// Why an f64 map has no float32 map.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Float32MapError {
    /// The grid is too large for the float32 kernels' 32-bit indices and f32 index conversions.
    #[error(
        "the map's grid ({meridians} meridians × {parallels} parallels) is too large for a \
         float32 map: at most {FLOAT32_MAX_NODES} of each and 2^31 table entries"
    )]
    TooLarge {
        /// Meridians of the completed grid.
        meridians: usize,
        /// Parallels of the completed grid.
        parallels: usize,
    },
}

/// An M × N table in f32 (its values are f32 values already: the conversion is exact).
fn to_f32(s: &[f64]) -> Vec<f32> {
    s.iter().map(|&x| x as f32).collect()
}

/// `x` rounded to the nearest f32, kept in f64.
#[inline]
fn r32(x: f64) -> f64 {
    x as f32 as f64
}

impl Tables<f32> {
    /// Why `core` has no float32 tables (a grid beyond the float32 kernels' index limits).
    fn check_size(core: &HdsCore) -> Result<(), Float32MapError> {
        let v = core.view();
        let (a, r) = (v.angular, v.radial);
        let lim = 1usize << 31;
        if a.m >= FLOAT32_MAX_NODES
            || r.n >= FLOAT32_MAX_NODES
            || r.u.len() >= lim
            || r.radial_guide.len() >= lim
        {
            return Err(Float32MapError::TooLarge {
                meridians: a.m,
                parallels: r.n,
            });
        }
        Ok(())
    }

    /// [`Tables::table_bytes`] of `Tables::of(core)`, counted from the float64 tables' lengths
    /// without making the float32 tables (issue 40: counting them by building them cost 11 bytes
    /// a pixel of an environment map at the peak).
    pub(super) fn bytes_of(core: &HdsCore) -> Result<usize, Float32MapError> {
        Self::check_size(core)?;
        let v = core.view();
        let (a, r) = (v.angular, v.radial);
        let floats = a.phi.len()
            + a.phi.len().saturating_sub(1)
            + a.r2.len()
            + a.cum.len()
            + r.x.len()
            + r.d.len()
            + r.u.len()
            + a.m
            + r.x.len().saturating_sub(1);
        let guides = a.wedge_guide.len() + r.radius_guide.len() + r.radial_guide.len();
        Ok((floats + guides) * 4)
    }

    /// The float32 tables of `core` (see the module documentation), or why there are none.
    pub(super) fn of(core: &HdsCore) -> Result<Self, Float32MapError> {
        let small = Self::small_of(core)?;
        let r = core.view().radial;
        let d32 = to_f32(r.d);
        let u32_ = to_f32(r.u);
        Ok(Self::finish(small, d32, u32_))
    }

    /// [`Tables::of`] of a core given away: each M × N f64 table is dropped as soon as its f32
    /// twin is made, so that the conversion holds one f64 M × N table less at its peak (issue
    /// 40: the float32 environment map's peak memory). The same tables bit for bit.
    pub(super) fn of_owned(mut core: HdsCore) -> Result<Self, Float32MapError> {
        let small = Self::small_of(&core)?;
        let (d, u) = core.take_d_u();
        drop(core);
        let d32 = to_f32(&d);
        drop(d);
        let u32_ = to_f32(&u);
        drop(u);
        Ok(Self::finish(small, d32, u32_))
    }

    /// The tables but the M × N ones (`d`, `u`) and those made from `u` (`total`,
    /// `radial_guide`), which [`Tables::finish`] adds.
    fn small_of(core: &HdsCore) -> Result<Self, Float32MapError> {
        Self::check_size(core)?;
        let Tables {
            angular: a,
            radial: r,
        } = core.tables();
        // M_C: every table rounded, the sector widths and the guide table made again from the
        // rounded meridians and wedge angles.
        let mut angular = a.map(r32);
        angular.beta = angular.phi.windows(2).map(|w| r32(w[1] - w[0])).collect();
        let guide_scale = angular.guide_scale;
        angular.wedge_guide = wedge_guides(&angular.cum, a.wedge_guide.len(), |k| {
            k as f64 / guide_scale
        });
        // M_D. The M × N tables (one value a pixel of an environment map) go to f32 directly, in
        // `of` and `of_owned`: a rounded f64 copy of them beside the f64 map cost 19 bytes a
        // pixel at the peak of `into_float32` (issue 40). Every value is an f32 value, so this is
        // the same conversion.
        let n = r.n;
        let x: Vec<f64> = r.x.iter().map(|&v| r32(v)).collect();
        let radius_len = r.radius_guide.len();
        let radius_scale = r32(radius_len as f64 / x[n - 1]);
        let t = Tables {
            angular,
            radial: Radial {
                n,
                radius_guide: radius_guides(&x, radius_len, |k| k as f64 / radius_scale),
                radius_scale,
                inv_dx: inverse_widths(&x, r32),
                edge: r32(x[n - 1] * <f32 as Precision>::EDGE),
                x,
                d: Vec::new(),
                u: Vec::new(),
                total: Vec::new(),
                radial_guide: Vec::new(),
                radial_k: r.radial_k,
            },
        };
        // Every entry is an f32 value already: the conversion is exact.
        Ok(t.map(|x| x as f32))
    }

    /// `small` with the M × N tables and those made from `u`.
    fn finish(mut small: Self, d32: Vec<f32>, u32_: Vec<f32>) -> Self {
        let (m, r) = (small.angular.m, &mut small.radial);
        let n = r.n;
        r.total = (0..m).map(|i| u32_[i * n + n - 1]).collect();
        r.radial_guide = super::radial::radial_guides(&u32_, n, r.radial_k);
        r.d = d32;
        r.u = u32_;
        small
    }
}

/// The layout of a float32 map (as the f64 map's), over tables in `T`.
// One per map, never in a collection: the split variant's size costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub(super) enum Layout<T> {
    /// One hemisphere map (z ≥ 0).
    Hemisphere(Tables<T>),
    /// The Lambert sphere: one map over the whole sphere.
    Lambert(Tables<T>),
    /// The split sphere: an upper and/or a lower map and the rule between them.
    Split {
        upper: Option<Tables<T>>,
        lower: Option<Tables<T>>,
        rule: SplitRule,
    },
}

/// A float32 map's layout and pdf scale in element type `T`, with the batch calls.
#[derive(Debug, Clone)]
pub(super) struct Maps<T> {
    pub(super) layout: Layout<T>,
    /// 1/(2T): the pdf per unit of disk density (the f64 map's, rounded to f32).
    pub(super) inv_2t: T,
}

impl<T> Maps<T> {
    /// The hemisphere map of `tables` with 1/(2T) = `inv_2t`.
    pub(super) fn hemisphere(tables: Tables<T>, inv_2t: T) -> Self {
        Maps {
            layout: Layout::Hemisphere(tables),
            inv_2t,
        }
    }
}

impl<T: TablesElem> Maps<T> {
    /// The layout as a [`Shape`] over its tables' views on backend `b` (or the fastest below it
    /// that the CPU has): the one layout driver of every map (`soa_maps.rs`).
    fn shape(&self, b: Backend) -> Shape<ViewKernel<'_, T>> {
        let backend = b.usable();
        fn k<T: Copy>(backend: Backend, t: &Tables<T>) -> ViewKernel<'_, T> {
            ViewKernel {
                backend,
                tables: t.view(),
            }
        }
        match &self.layout {
            Layout::Hemisphere(t) => Shape::Hemisphere(k(backend, t)),
            Layout::Lambert(t) => Shape::Lambert(k(backend, t)),
            Layout::Split { upper, lower, rule } => Shape::Split {
                upper: upper.as_ref().map(|t| k(backend, t)),
                lower: lower.as_ref().map(|t| k(backend, t)),
                rule: *rule,
            },
        }
    }

    fn sample(&self, b: Backend, u: &[T], v: &[T], dir: [&mut [T]; 3], pdf: &mut [T]) {
        self.shape(b).sample(self.inv_2t, u, v, dir, pdf)
    }

    fn pdf(&self, b: Backend, dir: [&[T]; 3], pdf: &mut [T]) {
        self.shape(b).pdf(self.inv_2t, dir, pdf)
    }

    fn invert(&self, b: Backend, dir: [&[T]; 3], uv: [&mut [T]; 2]) {
        self.shape(b).invert(dir, uv)
    }

    fn table_bytes(&self) -> usize {
        match &self.layout {
            Layout::Hemisphere(t) | Layout::Lambert(t) => t.table_bytes(),
            Layout::Split { upper, lower, .. } => {
                upper.as_ref().map_or(0, Tables::table_bytes)
                    + lower.as_ref().map_or(0, Tables::table_bytes)
            }
        }
    }
}

fn check_len(what: &str, n: usize, lens: &[usize]) {
    assert!(
        lens.iter().all(|&l| l == n),
        "{what}: slices differ in length"
    );
}

/// A float32 map: f32 tables, f32 arithmetic, its own exact density (see the module
/// documentation for how it is made and its tested contract). Built by
/// [`HemisphereMap::float32_map`] or [`SphereMap::float32_map`].
///
/// ```
/// use gonio::{Diagram, HemisphereMap};
/// let d = Diagram::from_degrees(&[0.0, 45.0, 90.0], &[0.0], &[vec![1.0, 0.7, 0.0]]).unwrap();
/// let map = HemisphereMap::new(&d).unwrap().float32_map().unwrap();
/// let (u, v) = (vec![0.3f32, 0.9], vec![0.7f32, 0.1]);
/// let (mut x, mut y, mut z, mut pdf) = (vec![0.0f32; 2], vec![0.0; 2], vec![0.0; 2], vec![0.0; 2]);
/// map.sample_soa(&u, &v, [&mut x, &mut y, &mut z], &mut pdf);
/// let mut p2 = vec![0.0f32; 2];
/// map.pdf_soa([&x, &y, &z], &mut p2);
/// assert!((p2[0] - pdf[0]).abs() <= 8.0 * f32::EPSILON * pdf[0]);
/// let (mut uu, mut vv) = (vec![0.0f32; 2], vec![0.0; 2]);
/// map.invert_soa([&x, &y, &z], [&mut uu, &mut vv]);
/// assert!((uu[0] - 0.3).abs() < 1e-5 && (vv[1] - 0.1).abs() < 1e-5);
/// ```
#[derive(Debug, Clone)]
pub struct Float32Map {
    pub(super) maps: Maps<f32>,
}

/// The float32 map evaluated exactly: its tables widened to f64 (exactly) and run through the f64
/// kernels, with its split rule evaluated in f64. The reference of the float32 map's contract
/// (its "exact density"); [`Float32Map::exact`] makes one.
#[derive(Debug, Clone)]
pub struct Float32Exact {
    maps: Maps<f64>,
}

/// The f64 map's tables alone: what a float64 table blob ([`crate::mapping::blob`]) reads back into.
/// Its batch calls run the same f64 kernels over the same tables as the map that wrote them, so
/// they give the bits of that map's structure-of-arrays batches
/// ([`crate::Batches::sample_batch_soa`], [`crate::Batches::pdf_batch_soa`],
/// [`crate::Batches::invert_batch_soa`]); tested in `tests/tables.rs`. It keeps no diagram and no
/// bound: the target, the ratio bound and the refinement stay with the map that wrote it.
#[derive(Debug, Clone)]
pub struct Float64Map {
    pub(super) maps: Maps<f64>,
}

impl Float64Map {
    /// Maps the points `(u[k], v[k])` of the unit square to directions and densities (per
    /// steradian) on the detected backend.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn sample_soa(&self, u: &[f64], v: &[f64], dir: [&mut [f64]; 3], pdf: &mut [f64]) {
        self.maps.sample(Backend::detect(), u, v, dir, pdf)
    }
    /// The density (per steradian) at each direction; 0 outside the domain.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn pdf_soa(&self, dir: [&[f64]; 3], pdf: &mut [f64]) {
        self.maps.pdf(Backend::detect(), dir, pdf)
    }
    /// The point of the unit square of each direction; NaN outside the domain or for a
    /// non-finite direction.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn invert_soa(&self, dir: [&[f64]; 3], uv: [&mut [f64]; 2]) {
        self.maps.invert(Backend::detect(), dir, uv)
    }
    /// One structure-of-arrays call ([`Soa`]) on the detected backend, the inverse as it comes
    /// from the kernels (NaN only outside the domain).
    ///
    /// # Panics
    /// If the call's slices differ in length.
    pub fn batch(&self, job: Soa<'_, f64>) {
        match job {
            Soa::Sample { u, v, dir, pdf } => self.sample_soa(u, v, dir, pdf),
            Soa::Pdf { dir, pdf } => self.pdf_soa(dir, pdf),
            Soa::Invert { dir, uv } => self.invert_soa(dir, uv),
        }
    }
    /// Bytes of the tables' contents and the map itself.
    pub fn memory_bytes(&self) -> usize {
        self.maps.table_bytes() + std::mem::size_of::<Self>()
    }
}

impl HemisphereMap {
    /// This map's tables alone in f64 ([`Float64Map`]).
    pub fn float64_map(&self) -> Float64Map {
        Float64Map {
            maps: Maps::hemisphere(self.core().tables().clone(), self.inv_2t()),
        }
    }

    /// This map's float32 map (see [`Float32Map`]).
    ///
    /// # Errors
    /// [`Float32MapError::TooLarge`] for a grid beyond the float32 kernels' index limits.
    pub fn float32_map(&self) -> Result<Float32Map, Float32MapError> {
        Ok(Float32Map {
            maps: Maps::hemisphere(Tables::of(self.core())?, self.inv_2t() as f32),
        })
    }
}

impl SphereMap {
    /// This map's tables alone in f64 ([`Float64Map`]).
    pub fn float64_map(&self) -> Float64Map {
        let layout = match self.cores() {
            CoresRef::Lambert(c) => Layout::Lambert(c.tables().clone()),
            CoresRef::Split { upper, lower, rule } => Layout::Split {
                upper: upper.map(|c| c.tables().clone()),
                lower: lower.map(|c| c.tables().clone()),
                rule,
            },
        };
        Float64Map {
            maps: Maps {
                layout,
                inv_2t: self.inv_2t(),
            },
        }
    }

    /// This map's float32 map (see [`Float32Map`]): the same layout, the split layout's rule
    /// evaluated in f32 with P_lower rounded to f32.
    ///
    /// # Errors
    /// [`Float32MapError::TooLarge`] for a grid beyond the float32 kernels' index limits.
    pub fn float32_map(&self) -> Result<Float32Map, Float32MapError> {
        let of = |c: Option<&HdsCore>| c.map(Tables::of).transpose();
        let layout = match self.cores() {
            CoresRef::Lambert(c) => Layout::Lambert(Tables::of(c)?),
            CoresRef::Split { upper, lower, rule } => Layout::Split {
                upper: of(upper)?,
                lower: of(lower)?,
                rule: rule.rounded_f32(),
            },
        };
        Ok(Float32Map {
            maps: Maps {
                layout,
                inv_2t: self.inv_2t() as f32,
            },
        })
    }
}

impl SphereMap {
    /// [`Float32Map::memory_bytes`] of [`SphereMap::float32_map`], counted without making it.
    ///
    /// [`SphereMap::into_float32_map`], the same map made from a map given away, drops each
    /// hemisphere map as soon as its float32 tables are made, so the float64 and float32 tables of
    /// one hemisphere, not of both, are held at once (issue 40: the peak of
    /// `EnvironmentMap::into_float32`).
    ///
    /// # Errors
    /// As [`SphereMap::float32_map`].
    pub(crate) fn float32_map_bytes(&self) -> Result<usize, Float32MapError> {
        let of = |c: Option<&HdsCore>| c.map_or(Ok(0), Tables::bytes_of);
        let tables = match self.cores() {
            CoresRef::Lambert(c) => Tables::bytes_of(c)?,
            CoresRef::Split { upper, lower, .. } => of(upper)? + of(lower)?,
        };
        Ok(tables + std::mem::size_of::<Float32Map>())
    }

    /// [`SphereMap::float32_map`] of a map given away: each hemisphere map is dropped as soon as
    /// its float32 tables are made (see above).
    pub(crate) fn into_float32_map(self) -> Result<Float32Map, Float32MapError> {
        let inv_2t = self.inv_2t() as f32;
        // `c` is dropped at the end of each closure, right after its conversion.
        let of = |c: Option<HdsCore>| c.map(Tables::of_owned).transpose();
        // The f64 radial guides go first (the float32 tables get their own from the f32 masses):
        // the core converted second does not hold them while the first is converted.
        let guides_dropped = |mut c: HdsCore| {
            c.drop_radial_guide();
            c
        };
        let layout = match self.into_cores() {
            super::sphere::CoresOwned::Lambert(c) => {
                Layout::Lambert(Tables::of_owned(guides_dropped(c))?)
            }
            super::sphere::CoresOwned::Split { upper, lower, rule } => {
                let (upper, lower) = (upper.map(guides_dropped), lower.map(guides_dropped));
                let upper = of(upper)?;
                let lower = of(lower)?;
                Layout::Split {
                    upper,
                    lower,
                    rule: rule.rounded_f32(),
                }
            }
        };
        Ok(Float32Map {
            maps: Maps { layout, inv_2t },
        })
    }
}

impl Float32Map {
    /// Maps the points `(u[k], v[k])` of the unit square to directions `dir[·][k]` and their
    /// densities `pdf[k]` (per steradian), on `backend` (or the fastest below it that the CPU
    /// has).
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn sample_soa_with(
        &self,
        backend: Backend,
        u: &[f32],
        v: &[f32],
        dir: [&mut [f32]; 3],
        pdf: &mut [f32],
    ) {
        self.maps.sample(backend, u, v, dir, pdf)
    }
    /// The density (per steradian) at each direction; 0 outside the domain.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn pdf_soa_with(&self, backend: Backend, dir: [&[f32]; 3], pdf: &mut [f32]) {
        self.maps.pdf(backend, dir, pdf)
    }
    /// The point of the unit square of each direction; NaN outside the domain or for a
    /// non-finite direction.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn invert_soa_with(&self, backend: Backend, dir: [&[f32]; 3], uv: [&mut [f32]; 2]) {
        self.maps.invert(backend, dir, uv)
    }
    /// [`Float32Map::sample_soa_with`] on the detected backend.
    pub fn sample_soa(&self, u: &[f32], v: &[f32], dir: [&mut [f32]; 3], pdf: &mut [f32]) {
        self.sample_soa_with(Backend::detect(), u, v, dir, pdf)
    }
    /// [`Float32Map::pdf_soa_with`] on the detected backend.
    pub fn pdf_soa(&self, dir: [&[f32]; 3], pdf: &mut [f32]) {
        self.pdf_soa_with(Backend::detect(), dir, pdf)
    }
    /// [`Float32Map::invert_soa_with`] on the detected backend.
    pub fn invert_soa(&self, dir: [&[f32]; 3], uv: [&mut [f32]; 2]) {
        self.invert_soa_with(Backend::detect(), dir, uv)
    }

    /// One structure-of-arrays call ([`Soa`]) on the detected backend: the float32 path of the
    /// HDS maps' [`crate::Sampler::batch`]. The inverse writes NaN where there is no preimage
    /// ([`Float32Map::invert_soa_nonzero`]).
    ///
    /// # Panics
    /// If the call's slices differ in length.
    pub fn batch(&self, job: Soa<'_, f32>) {
        match job {
            Soa::Sample { u, v, dir, pdf } => self.sample_soa(u, v, dir, pdf),
            Soa::Pdf { dir, pdf } => self.pdf_soa(dir, pdf),
            Soa::Invert { dir, uv } => self.invert_soa_nonzero(dir, uv),
        }
    }

    /// [`Float32Map::batch`] on all rayon threads ([`crate::batch::par`]); the same bits for any
    /// number of threads.
    ///
    /// # Panics
    /// If the call's slices differ in length.
    pub fn batch_par(&self, job: Soa<'_, f32>) {
        crate::batch::par(job, &|j| self.batch(j))
    }

    /// [`Float32Map::invert_soa`], then NaN in both coordinates wherever [`Float32Map::pdf_soa`]
    /// is 0 (the rule of every sampler's `invert_batch_soa`, issue 25: no preimage where the
    /// density is 0), on the detected backend, [`CHUNK`] directions at a time: the HDS maps'
    /// [`crate::Batches::invert_batch_soa_f32`].
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn invert_soa_nonzero(&self, dir: [&[f32]; 3], uv: [&mut [f32]; 2]) {
        let [u, v] = uv;
        let n = u.len();
        check_len(
            "invert_batch_soa_f32",
            n,
            &[v.len(), dir[0].len(), dir[1].len(), dir[2].len()],
        );
        let b = Backend::detect();
        let mut p = [0f32; CHUNK];
        for start in (0..n).step_by(CHUNK) {
            let r = start..(start + CHUNK).min(n);
            let m = r.len();
            let d = [&dir[0][r.clone()], &dir[1][r.clone()], &dir[2][r.clone()]];
            let (u, v) = (&mut u[r.clone()], &mut v[r]);
            self.invert_soa_with(b, d, [&mut *u, &mut *v]);
            self.pdf_soa_with(b, d, &mut p[..m]);
            for ((u, v), &p) in u.iter_mut().zip(v.iter_mut()).zip(&p[..m]) {
                if p == 0.0 {
                    *u = f32::NAN;
                    *v = f32::NAN;
                }
            }
        }
    }

    /// Bytes of the float32 map: its tables' contents (f32 entries and u32 guide entries) and
    /// the map itself.
    pub fn memory_bytes(&self) -> usize {
        self.maps.table_bytes() + std::mem::size_of::<Self>()
    }

    /// This float32 map evaluated exactly ([`Float32Exact`]).
    pub fn exact(&self) -> Float32Exact {
        let widen = |t: &Tables<f32>| t.map(f64::from);
        let layout = match &self.maps.layout {
            Layout::Hemisphere(t) => Layout::Hemisphere(widen(t)),
            Layout::Lambert(t) => Layout::Lambert(widen(t)),
            Layout::Split { upper, lower, rule } => Layout::Split {
                upper: upper.as_ref().map(widen),
                lower: lower.as_ref().map(widen),
                rule: *rule,
            },
        };
        Float32Exact {
            maps: Maps {
                layout,
                inv_2t: f64::from(self.maps.inv_2t),
            },
        }
    }
}

impl Float32Exact {
    /// As [`Float32Map::sample_soa_with`], evaluated exactly (f64 arithmetic on the float32
    /// map's tables).
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn sample_soa_with(
        &self,
        backend: Backend,
        u: &[f64],
        v: &[f64],
        dir: [&mut [f64]; 3],
        pdf: &mut [f64],
    ) {
        self.maps.sample(backend, u, v, dir, pdf)
    }
    /// As [`Float32Map::pdf_soa_with`], evaluated exactly: the float32 map's exact density.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn pdf_soa_with(&self, backend: Backend, dir: [&[f64]; 3], pdf: &mut [f64]) {
        self.maps.pdf(backend, dir, pdf)
    }
    /// As [`Float32Map::invert_soa_with`], evaluated exactly.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn invert_soa_with(&self, backend: Backend, dir: [&[f64]; 3], uv: [&mut [f64]; 2]) {
        self.maps.invert(backend, dir, uv)
    }
}

#[cfg(test)]
mod memory_tests {
    use crate::diagram::Diagram;
    use crate::mapping::{SphereLayout, SphereMap};

    /// Issue 40: the float32 map's bytes counted without making it, and the map made from a map
    /// given away (each hemisphere's float64 tables dropped once converted), are those of
    /// `float32_map`, on both layouts and on one-sided split maps.
    #[test]
    fn counted_and_consumed_float32_maps_equal_the_made_one() {
        let theta: Vec<f64> = (0..9)
            .map(|j| std::f64::consts::PI * j as f64 / 8.0)
            .collect();
        let phi: Vec<f64> = (0..7)
            .map(|i| std::f64::consts::TAU * i as f64 / 7.0)
            .collect();
        let both: Vec<f64> = (0..63).map(|k| 0.2 + ((k * 13) % 7) as f64).collect();
        let upper: Vec<f64> = (0..63)
            .map(|k| {
                if k % 9 <= 4 {
                    1.0 + (k % 5) as f64
                } else {
                    0.0
                }
            })
            .collect();
        let lower: Vec<f64> = (0..63)
            .map(|k| {
                if k % 9 >= 4 {
                    1.0 + (k % 3) as f64
                } else {
                    0.0
                }
            })
            .collect();
        for values in [both, upper, lower] {
            let d = Diagram::new(theta.clone(), phi.clone(), values).unwrap();
            for layout in [SphereLayout::Split, SphereLayout::Lambert] {
                let Ok(map) = SphereMap::with_layout(&d, layout) else {
                    continue;
                };
                let made = map.float32_map().unwrap();
                assert_eq!(map.float32_map_bytes().unwrap(), made.memory_bytes());
                let consumed = map.into_float32_map().unwrap();
                let (u, v) = ([0.1f32, 0.5, 0.93], [0.7f32, 0.5, 0.02]);
                let run = |m: &super::Float32Map| {
                    let (mut x, mut y, mut z, mut p) = ([0f32; 3], [0f32; 3], [0f32; 3], [0f32; 3]);
                    m.sample_soa(&u, &v, [&mut x, &mut y, &mut z], &mut p);
                    [x, y, z, p].map(|a| a.map(f32::to_bits))
                };
                assert_eq!(run(&made), run(&consumed));
                assert_eq!(made.memory_bytes(), consumed.memory_bytes());
            }
        }
    }
}
