//! The Rust structs of the Python classes that several modules use (the diagram), and the domain
//! names: below both `diagram.rs` (the class's methods and readers) and `sampler.rs` (which builds
//! from a diagram), so that neither imports the other both ways.

use crate::InputError;
use gonio::photometry::Photometry;
use gonio::{Diagram, Domain};
use pyo3::prelude::*;
use std::path::Path;

/// Where a diagram came from (the library's one kind enum); photometric sources are in candela
/// and always sampled on the sphere.
pub(crate) use gonio::input::InputKind as Source;

/// A goniometric diagram: values on a (θ, φ) grid, from a file or from arrays.
///
/// Frame (README "The frame"): θ is the polar angle from +z, φ the azimuth from +x toward +y, both
/// in degrees here; the direction of (θ, φ) is (sin θ cos φ, sin θ sin φ, cos θ). Photometric
/// files are brought into this frame with θ = 180° − γ (nadir γ = 0° is −z) and φ = C; their
/// values are candela.
#[pyclass(name = "Diagram", module = "gonio", frozen)]
pub(crate) struct PyDiagram {
    pub(crate) diagram: Diagram,
    pub(crate) source: Source,
    pub(crate) name: String,
    pub(crate) photometry: Option<Box<Photometry>>,
}

impl PyDiagram {
    /// The domain every sampler gets by default: the whole sphere for photometric input (IES,
    /// EULUMDAT, the example), else the upper hemisphere when the diagram lies in θ ≤ 90°.
    pub(crate) fn default_domain(&self) -> Domain {
        let theta_max = *self
            .diagram
            .theta()
            .last()
            .expect("a diagram has parallels");
        if self.source.is_photometric() || theta_max > std::f64::consts::FRAC_PI_2 {
            Domain::Sphere
        } else {
            Domain::Hemisphere
        }
    }
}

pub(crate) fn domain_name(d: Domain) -> &'static str {
    match d {
        Domain::Hemisphere => "hemisphere",
        Domain::Sphere => "sphere",
    }
}

pub(crate) fn parse_domain(s: &str) -> PyResult<Domain> {
    // Names are matched as everywhere in gonio: ASCII letter case and blanks do not matter.
    match s.trim().to_ascii_lowercase().as_str() {
        "hemisphere" => Ok(Domain::Hemisphere),
        "sphere" => Ok(Domain::Sphere),
        _ => Err(InputError::new_err(format!(
            "unknown domain `{s}`; expected \"hemisphere\" or \"sphere\""
        ))),
    }
}

impl PyDiagram {
    /// The file stem of the name, for headers written from this diagram.
    pub(crate) fn stem(&self) -> String {
        Path::new(&self.name)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| self.name.clone())
    }
}
