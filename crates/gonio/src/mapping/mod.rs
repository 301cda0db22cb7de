//! Diagram → mapping: the Havran–Dmitriev–Seidel map F = M_E ∘ M_D ∘ M_C ∘ M_B
//! (ALGORITHM §1–§7, recommended variant A6).
//!
//! | stage | module | from → to | area factor |
//! |---|---|---|---|
//! | M_B | [`concentric`] | unit square → unit disk (r_B, φ_B ∈ [0, 2π)) | π |
//! | M_C | [`angular`] | B-disk → star domain (marginal CDF in φ) | 1 |
//! | M_D | [`radial`] | star domain → unit disk (conditional CDF in r) | s/D |
//! | M_E | [`lift`] | disk → hemisphere (Lambert, equal-area) | 2 |
//!
//! The product of the area factors gives the exact density p(ω) = D(ω)/(2T) per steradian (§7).
//! [`HemisphereMap`] and [`SphereMap`] compose them over the tables of §4; `bound` computes the
//! guaranteed pdf/target range at build time.

pub mod angular;
pub mod batch;
mod bound;
mod complete;
pub mod concentric;
mod core;
mod hemisphere;
pub mod lift;
pub mod radial;
pub mod refine;
pub mod simd;
mod sphere;

pub use complete::Completion;
pub use hemisphere::HemisphereMap;
pub use refine::{RefineLimits, RefineStop, Refinement};
pub use sphere::{SphereLayout, SphereMap};

/// The intermediate points of one forward evaluation F(u) = M_E(M_D(M_C(M_B(u)))), in polar
/// coordinates (radius, azimuth in radians) on each disk. For pictures of the stages and for tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stages {
    /// The input point of the unit square.
    pub square: [f64; 2],
    /// After M_B: the unit disk (r_B, φ_B), φ_B ∈ [0, 2π).
    pub disk_b: (f64, f64),
    /// After M_C: the star domain (r_C, φ_C), r_C ≤ ρ(φ_C) (may exceed 1, §10 A9).
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
