//! Uniform directions on the domain: the baseline that ignores the diagram.

use super::{clamp_unit, BuildError, Target};
use crate::diagram::Diagram;
use crate::sampler::{normalize, Domain, InvertError, Point2, Sample, Sampler, Vec3};
use std::f64::consts::TAU;

/// Uniform sampling of the hemisphere (pdf 1/2π sr⁻¹) or the sphere (pdf 1/4π sr⁻¹) through the
/// equal-area cylindrical map (Archimedes):
///
/// * hemisphere: z = 1 − u, φ = 2πv;
/// * sphere: z = 1 − 2u, φ = 2πv;
///
/// with (x, y) = √(1 − z²)(cos φ, sin φ). The inverse is u = 1 − z (or (1 − z)/2), v = φ/2π with
/// φ ∈ [0, 2π); the seam v = 1 inverts to v = 0 and the poles to v = 0.
///
/// The diagram is used only for [`Sampler::target_pdf`], which lets the checks measure how far a
/// uniform density is from the target.
///
/// ```
/// use gonio::baselines::Uniform;
/// use gonio::{Diagram, Domain, Sampler};
/// let d = Diagram::from_degrees(&[0.0, 90.0], &[0.0], &[vec![1.0, 0.0]]).unwrap();
/// let u = Uniform::new(&d, Domain::Hemisphere).unwrap();
/// let s = u.sample([0.5, 0.25]);
/// assert_eq!(s.pdf, 1.0 / Domain::Hemisphere.solid_angle());
/// let back = u.invert(s.direction).unwrap();
/// assert!((back[0] - 0.5).abs() < 1e-12 && (back[1] - 0.25).abs() < 1e-12);
/// ```
#[derive(Debug, Clone)]
pub struct Uniform {
    target: Target,
    pdf: f64,
}

impl Uniform {
    /// A uniform sampler over `domain` for the target of `diagram`.
    ///
    /// # Errors
    /// [`BuildError::NotHemisphere`] if `domain` is the hemisphere and the diagram passes θ = 90°;
    /// [`BuildError::NoPower`] if the interpolated diagram integrates to 0.
    pub fn new(diagram: &Diagram, domain: Domain) -> Result<Self, BuildError> {
        Ok(Self {
            target: Target::new(diagram, domain)?,
            pdf: 1.0 / domain.solid_angle(),
        })
    }
}

/// The uniform direction of the point `p` of the square on `domain`, no allocation.
#[inline]
pub(crate) fn square_to_uniform(domain: Domain, p: Point2) -> Vec3 {
    let (u, v) = (clamp_unit(p[0]), clamp_unit(p[1]));
    // 1 − z² factored so that it has no cancellation near the poles.
    let (z, one_minus_z2) = match domain {
        Domain::Hemisphere => (1.0 - u, u * (2.0 - u)),
        Domain::Sphere => (1.0 - 2.0 * u, 4.0 * u * (1.0 - u)),
    };
    let s = one_minus_z2.max(0.0).sqrt();
    let (sp, cp) = (TAU * v).sin_cos();
    [s * cp, s * sp, z]
}

impl Sampler for Uniform {
    target_methods!("uniform");
    fn sample(&self, u: Point2) -> Sample {
        Sample {
            direction: square_to_uniform(self.target.domain, u),
            pdf: self.pdf,
        }
    }
    fn pdf(&self, direction: Vec3) -> f64 {
        match normalize(direction) {
            Some(d) if self.target.domain.contains(d) => self.pdf,
            _ => 0.0,
        }
    }
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        let d = normalize(direction).ok_or(InvertError::OutsideDomain)?;
        if !self.target.domain.contains(d) {
            return Err(InvertError::OutsideDomain);
        }
        let u = match self.target.domain {
            Domain::Hemisphere => 1.0 - d[2],
            Domain::Sphere => 0.5 * (1.0 - d[2]),
        };
        let mut v = d[1].atan2(d[0]) / TAU;
        if v < 0.0 {
            v += 1.0;
        }
        if v >= 1.0 {
            v = 0.0;
        }
        Ok([u.clamp(0.0, 1.0), v])
    }
    fn memory_bytes(&self) -> usize {
        0
    }
}
