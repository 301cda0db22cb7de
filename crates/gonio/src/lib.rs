//! # gonio — goniometric diagram mapping
//!
//! Importance sampling of a tabulated directional distribution (a luminaire's goniometric diagram
//! from an IES LM-63 or EULUMDAT file, or any non-negative table on a (θ, φ) grid) through the
//! Havran–Dmitriev–Seidel mapping (Eurographics 2003): a bijective, continuous map from the unit
//! square to the hemisphere or sphere, with closed-form inverse and the exact pdf of every sample.
//!
//! The modules follow the data flow **file → diagram → mapping → samples → checks**:
//!
//! * [`photometry`] reads IES LM-63 and EULUMDAT files and expands their symmetry into a
//! * [`diagram::Diagram`], which [`mapping`] turns into a [`mapping::HemisphereMap`] or
//!   [`mapping::SphereMap`], both [`sampler::Sampler`]s, as are the [`baselines`];
//! * [`sequence`] provides the points of the unit square (Halton, Owen-scrambled Sobol', iid);
//! * [`check`] holds the statistical tests every sampler must pass.
//!
//! The mathematics and every formula's derivation are in `docs/DERIVATION.md`; section numbers
//! (§) in the documentation refer to it.
//!
//! ```
//! use gonio::{Diagram, HemisphereMap, Sampler};
//! // A cosine-like lobe on 3 parallels × 1 meridian (rotationally symmetric), values in candela.
//! let d = Diagram::from_degrees(&[0.0, 45.0, 90.0], &[0.0], &[vec![1.0, 0.7, 0.0]]).unwrap();
//! let map = HemisphereMap::new(&d).unwrap();
//! let s = map.sample([0.3, 0.7]);
//! assert!((map.pdf(s.direction) - s.pdf).abs() < 1e-12 * s.pdf);
//! let u = map.invert(s.direction).unwrap();
//! assert!((u[0] - 0.3).abs() < 1e-10 && (u[1] - 0.7).abs() < 1e-10);
//! ```
#![warn(missing_docs)]
// `!(x > 0.0)` is used on purpose throughout: it is true for NaN, which must take the safe branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod baselines;
pub mod batch;
pub mod brdf;
pub mod check;
pub mod clock;
pub mod decimal;
pub mod diagram;
pub mod envmap;
pub mod error;
pub mod image;
pub mod input;
pub mod mapping;
pub mod mesh;
pub mod method;
pub mod photometry;
pub mod sampler;
pub mod sequence;
pub mod synthetic;
pub mod vector;

/// The crate's README example, compiled and run as a doctest (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

pub use check::{run_battery, BatteryOptions, Report};
pub use diagram::{Diagram, DiagramError};
pub use error::Error;
pub use mapping::{HemisphereMap, MapRef, SphereLayout, SphereMap};
pub use method::{BuildError, BuildOptions, Built, Method};
pub use photometry::{FileFormat, Photometry};
pub use sampler::{Batches, Domain, InvertError, Point2, Sample, Sampler, Vec3};
pub use sequence::{Sequence, SequenceKind};
