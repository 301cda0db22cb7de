//! Diagram → mapping: the Havran–Dmitriev–Seidel map F = M_E ∘ M_D ∘ M_C ∘ M_B
//! (docs/DERIVATION.md §1–§7, recommended variant A6).
//!
//! | stage | module | from → to | area factor |
//! |---|---|---|---|
//! | M_B | [`concentric`] | unit square → unit disk (r_B, φ_B ∈ [0, 2π)) | π |
//! | M_C | [`angular`] | B-disk → star domain (marginal CDF in φ) | 1 |
//! | M_D | [`radial`] | star domain → unit disk (conditional CDF in r) | s/D |
//! | M_E | [`lift`] | disk → hemisphere (Lambert, equal-area) | 2 |
//!
//! Each stage is one room: its module holds the forward map, the inverse and the area factor, and
//! for the two stages with tables (M_C, M_D) the tables themselves (`angular::Angular`,
//! `radial::Radial`). The private `hds` module composes them: `sample` is
//! M_E(M_D(M_C(M_B(u)))), `invert` runs the four inverses back, and the density is the radial
//! room's D over the constant 2T. The product of the area factors, π · 1 · (s/D) · 2 = 2T/D, gives
//! the exact density p(ω) = D(ω)/(2T) per steradian (docs/DERIVATION.md §7), with T = πs.
//! [`HemisphereMap`] and [`SphereMap`] are built on that core; `bound` computes the guaranteed
//! pdf/target range at build time. The equal-area baseline's hemisphere map
//! ([`crate::baselines::equal_area`]) reuses M_B and M_E.

pub mod angular;
pub mod batch;
pub mod blend;
pub mod blob;
mod bound;
mod complete;
pub mod concentric;
mod float32;
mod hds;
mod hemisphere;
pub mod lift;
pub mod radial;
pub mod refine;
pub mod simd;
mod soa_maps;
mod sphere;
mod split;

pub use blend::{BlendError, BlendedMap};
pub use complete::Completion;
pub use float32::{Float32Exact, Float32Map, Float32MapError, Float64Map, FLOAT32_MAX_NODES};
pub use hemisphere::HemisphereMap;
pub use refine::{RefineLimits, RefineStop, Refinement};
pub use sphere::{SphereLayout, SphereMap};

/// The accessors [`HemisphereMap`] and [`SphereMap`] share, written once over their common
/// fields (`refinement`, `completions`, `scale`, `inv_2t`, `measured`, `float32`).
macro_rules! shared_accessors {
    ($map:ident) => {
        impl $map {
            /// What refinement to a tolerance asked, reached and cost; `None` for a map built
            /// without a tolerance.
            pub fn refinement(&self) -> Option<&$crate::mapping::Refinement> {
                self.refinement.as_ref()
            }

            /// The zones the data does not cover, completed with zero light (each is a warning
            /// for the user), in θ order; empty when the data covers the map's whole domain.
            pub fn completions(&self) -> &[$crate::mapping::Completion] {
                &self.completions
            }

            /// The map's own flux: ∫ `map_intensity` dω = 2T, in diagram units × sr (lumens for
            /// candela). It differs from `target_power` by a factor within the ratio bound.
            pub fn map_power(&self) -> f64 {
                self.scale / self.inv_2t
            }

            /// The map's own intensity at `direction`: `pdf(ω) · map_power`, the disk density D
            /// of the map that serves ω, in the diagram's units (candela for a diagram in
            /// candela). It equals the diagram's value at every node of the map's grid (the
            /// input's nodes and those refinement added) and lies within the ratio bound (up to
            /// the normalisation `map_power / target_power`) of the (θ, φ)-interpolated diagram
            /// elsewhere. A renderer that emits this intensity and samples with this map gets the
            /// constant weight `map_intensity / pdf = map_power` for every sample: no variance
            /// from the emission at all. See `docs/MAPPING.md` for when to prefer it to the
            /// interpolated diagram.
            pub fn map_intensity(&self, direction: $crate::Vec3) -> f64 {
                $crate::Sampler::pdf(self, direction) * self.map_power()
            }

            /// The measured θ range [θ_0, θ_{N−1}] of the data (radians): the target's support.
            pub fn measured_theta(&self) -> (f64, f64) {
                self.measured
            }

            /// The factor by which the map's tables were scaled (the data's largest value): the
            /// map is built on the data divided by it.
            pub fn value_scale(&self) -> f64 {
                self.scale
            }

            /// This map's float32 map ([`crate::mapping::Float32Map`]), built on the first call and
            /// kept (one f32 copy of the tables, `Float32Map::memory_bytes`, not counted in
            /// [`crate::Sampler::memory_bytes`]); `None` for a grid beyond the float32 kernels'
            /// limits. The float32 batch calls (`Batches::sample_batch_soa_f32` and its twins,
            /// which the C ABI's and Python's float32 batches call) run it.
            pub fn float32(&self) -> Option<&$crate::mapping::Float32Map> {
                self.float32
                    .get_or_init(|| self.float32_map().ok())
                    .as_ref()
            }

            /// 1/(2T): the pdf per unit of disk density.
            pub(crate) fn inv_2t(&self) -> f64 {
                self.inv_2t
            }
        }
    };
}
pub(crate) use shared_accessors;

/// A borrowed HDS map, as [`crate::method::Built::hds_map`] returns it: what only the HDS map
/// has (ratio bound, refinement, completions, stages) is a method here, and the map itself is
/// reached through its variant, with no downcast.
///
/// ```
/// use gonio::{Diagram, Domain, MapRef, Method};
/// let d = Diagram::from_degrees(&[0.0, 90.0, 180.0], &[0.0], &[vec![1.0, 0.5, 2.0]]).unwrap();
/// let s = Method::Hds.build(&d, Domain::Sphere).unwrap();
/// match s.hds_map() {
///     Some(MapRef::Sphere(m)) => assert!(m.lower_probability().unwrap() > 0.5),
///     _ => unreachable!("the HDS method on the sphere is a sphere map"),
/// }
/// let (lo, hi) = s.hds_map().unwrap().ratio_bound();
/// assert!(0.0 < lo && lo <= 1.0 && 1.0 <= hi);
/// assert!(Method::Uniform.build(&d, Domain::Sphere).unwrap().hds_map().is_none());
/// ```
#[derive(Debug, Clone, Copy)]
pub enum MapRef<'a> {
    /// The map of the upper hemisphere.
    Hemisphere(&'a HemisphereMap),
    /// The map of the whole sphere (either layout).
    Sphere(&'a SphereMap),
}

impl<'a> From<&'a HemisphereMap> for MapRef<'a> {
    fn from(m: &'a HemisphereMap) -> Self {
        MapRef::Hemisphere(m)
    }
}

impl<'a> From<&'a SphereMap> for MapRef<'a> {
    fn from(m: &'a SphereMap) -> Self {
        MapRef::Sphere(m)
    }
}

impl<'a> MapRef<'a> {
    /// The map behind the sampler contract.
    pub fn sampler(self) -> &'a dyn crate::Sampler {
        match self {
            MapRef::Hemisphere(m) => m,
            MapRef::Sphere(m) => m,
        }
    }

    /// A guaranteed range (min, max) of `pdf / target_pdf` over every direction where the target
    /// is positive, computed at build time ([`HemisphereMap::ratio_bound`],
    /// [`SphereMap::ratio_bound`]).
    pub fn ratio_bound(self) -> (f64, f64) {
        match self {
            MapRef::Hemisphere(m) => m.ratio_bound(),
            MapRef::Sphere(m) => m.ratio_bound(),
        }
    }

    /// What refinement to a tolerance asked, reached and cost, for a map built with one.
    pub fn refinement(self) -> Option<&'a Refinement> {
        match self {
            MapRef::Hemisphere(m) => m.refinement(),
            MapRef::Sphere(m) => m.refinement(),
        }
    }

    /// The zones without data the map completed with zero light (issue 9), each a warning for
    /// the user.
    pub fn completions(self) -> &'a [Completion] {
        match self {
            MapRef::Hemisphere(m) => m.completions(),
            MapRef::Sphere(m) => m.completions(),
        }
    }

    /// The intermediate points of the forward map at `u` (for the warp plot and tests).
    pub fn stages(self, u: crate::Point2) -> Stages {
        match self {
            MapRef::Hemisphere(m) => m.stages(u),
            MapRef::Sphere(m) => m.stages(u),
        }
    }
}

/// The intermediate points of one forward evaluation F(u) = M_E(M_D(M_C(M_B(u)))), in polar
/// coordinates (radius, azimuth in radians) on each disk. For pictures of the stages and for tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stages {
    /// The input point of the unit square.
    pub square: [f64; 2],
    /// After M_B: the unit disk (r_B, φ_B), φ_B ∈ [0, 2π).
    pub disk_b: (f64, f64),
    /// After M_C: the star domain (r_C, φ_C), r_C ≤ ρ(φ_C) (may exceed 1,
    /// docs/DERIVATION.md §8.1 A9).
    pub star_c: (f64, f64),
    /// After M_D: the disk (r_D, φ_D), r_D ≤ 1 for a hemisphere (≤ √2 for the Lambert sphere).
    pub disk_d: (f64, f64),
    /// After M_E: the unit direction, in the sampler's frame (for the lower map of a split sphere
    /// layout, mirrored to z ≤ 0 as the sample is).
    pub direction: [f64; 3],
    /// Whether the point went through the lower-hemisphere map of a split sphere layout (the disk
    /// coordinates are then those of that map, whose pole is the nadir).
    pub lower: bool,
}

/// The paper's count of additional precomputed floats for a grid of M meridians × N parallels,
/// M·N + 2M + 2 (docs/DERIVATION.md §4.6, A10), the one place the formula is written. (This crate's
/// tables hold more, e.g. guide tables and the nodal densities: see
/// [`crate::Sampler::memory_bytes`].)
///
/// ```
/// let d = gonio::Diagram::from_degrees(&[0.0, 90.0], &[0.0, 180.0], &vec![vec![1.0, 0.0]; 2]).unwrap();
/// assert_eq!(gonio::mapping::paper_table_floats(&d), 2 * 2 + 2 * 2 + 2);
/// ```
pub fn paper_table_floats(diagram: &crate::Diagram) -> usize {
    let (m, n) = (diagram.n_meridians(), diagram.n_parallels());
    m * n + 2 * m + 2
}

/// The largest i ≤ `last` with a_i ≤ x (0 if none), for non-decreasing `a`, starting from the guess
/// of a guide table whose cell k covers [k, k + 1)/`scale`. The guess may round to either side of x:
/// step back, then forward; on a well-built guide both loops run at most a step or two. Shared by
/// the searches of M_C (wedges) and M_D (parallels).
#[inline]
pub(crate) fn guided_search(a: &[f64], guide: &[u32], scale: f64, x: f64, last: usize) -> usize {
    let k = ((x * scale) as usize).min(guide.len() - 1);
    let mut i = (guide[k] as usize).min(last);
    while i > 0 && a[i] > x {
        i -= 1;
    }
    while i < last && a[i + 1] <= x {
        i += 1;
    }
    i
}
