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
mod bound;
mod complete;
pub mod concentric;
mod core;
mod hemisphere;
pub mod lift;
pub mod radial;
mod sphere;

pub use hemisphere::HemisphereMap;
pub use sphere::{SphereLayout, SphereMap};
