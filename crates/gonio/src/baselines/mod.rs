//! Baselines: the samplers a user would pick instead of the HDS mapping, behind the same trait.
//!
//! Every baseline is built from a [`Diagram`] and a [`Domain`] and implements [`crate::Sampler`]:
//!
//! * [`Uniform`] — uniform directions on the domain, ignoring the diagram (pdf 1/2π or 1/4π sr⁻¹);
//! * [`Rejection`] — uniform proposals accepted with probability target / max target; pdf = target;
//! * [`PiecewiseConstant`] — a piecewise-constant image over an equal-area square↔sphere
//!   (or square↔hemisphere) map, sampled by marginal–conditional CDF inversion (as pbrt-v4's
//!   goniometric light);
//! * [`Bilinear`] — marginal–conditional inversion of the bilinear-in-(θ, φ) target itself (the
//!   continuous analogue of Mitsuba 3's `Marginal2D`); pdf = target exactly.
//!
//! All of them share the *target density*: the diagram interpolated bilinearly in (θ, φ)
//! ([`Diagram::interpolate`]) divided by its integral over the sphere ([`Diagram::integral`]),
//! per steradian, and 0 outside the domain. On [`Domain::Hemisphere`] the diagram must lie within
//! θ ≤ 90° (its parallels may not pass π/2); on [`Domain::Sphere`] it may cover any θ range and is 0
//! outside it. Constructors validate and return a [`BuildError`]; after construction, sampling
//! cannot fail or panic for any point of the closed unit square.
//!
//! The formulas, costs and weaknesses of each method are collected in `docs/BASELINES.md`.

/// The [`crate::Sampler`] methods every baseline answers from its `target` field ([`Target`]):
/// the name given, the domain, the target density and its power.
macro_rules! target_methods {
    ($name:literal) => {
        fn name(&self) -> &'static str {
            $name
        }
        fn domain(&self) -> crate::sampler::Domain {
            self.target.domain
        }
        fn target_pdf(&self, direction: crate::sampler::Vec3) -> f64 {
            self.target.pdf(direction)
        }
        fn target_power(&self) -> f64 {
            self.target.integral
        }
    };
}

mod bilinear;
pub mod equal_area;
mod piecewise_constant;
mod rejection;
mod uniform;

pub use bilinear::Bilinear;
pub use piecewise_constant::{
    PiecewiseConstant, DEFAULT_RESOLUTION, MAX_RESOLUTION, SUPERSAMPLING,
};
pub use rejection::{Rejection, MAX_TV_ERROR, MIN_ACCEPTANCE};
pub use uniform::Uniform;

use crate::diagram::Diagram;
use crate::error::BuildError;
use crate::sampler::{normalize, spherical, Domain, Vec3};
use std::f64::consts::FRAC_PI_2;

/// The normalised target density shared by every baseline: the diagram interpolated bilinearly in
/// (θ, φ), divided by its integral, per steradian, 0 outside the domain.
#[derive(Debug, Clone)]
pub(crate) struct Target {
    pub(crate) diagram: Diagram,
    pub(crate) domain: Domain,
    /// [`Diagram::integral`], in the diagram's unit × sr.
    pub(crate) integral: f64,
    /// 1 / integral.
    pub(crate) inv_integral: f64,
}

impl Target {
    /// Validates the diagram against the domain and that it has power to sample.
    pub(crate) fn new(diagram: &Diagram, domain: Domain) -> Result<Self, BuildError> {
        let theta_max = *diagram.theta().last().expect("a diagram has parallels");
        if domain == Domain::Hemisphere && theta_max > FRAC_PI_2 {
            return Err(BuildError::NotHemisphere {
                theta_max_deg: theta_max.to_degrees(),
            });
        }
        let integral = diagram.integral();
        if !(integral.is_finite() && integral > 0.0 && (1.0 / integral).is_finite()) {
            return Err(BuildError::no_power(integral, diagram.max_value()));
        }
        Ok(Self {
            diagram: diagram.clone(),
            domain,
            integral,
            inv_integral: 1.0 / integral,
        })
    }

    /// Target density at polar angle θ and azimuth φ (radians), per steradian. The caller has
    /// checked the domain (a hemisphere diagram is 0 below the equator anyway).
    #[inline]
    pub(crate) fn at(&self, theta: f64, phi: f64) -> f64 {
        self.diagram.interpolate(theta, phi) * self.inv_integral
    }

    /// Target density at a direction (normalised first), per steradian; 0 outside the domain or for
    /// a zero or non-finite vector.
    pub(crate) fn pdf(&self, d: Vec3) -> f64 {
        match normalize(d) {
            Some(d) if self.domain.contains(d) => {
                let (t, p) = spherical(d);
                self.at(t, p)
            }
            _ => 0.0,
        }
    }

    /// Bytes of the diagram's angle and value tables.
    pub(crate) fn diagram_bytes(&self) -> usize {
        let d = &self.diagram;
        std::mem::size_of::<f64>() * (d.theta().len() + d.phi().len() + d.values().len())
    }
}

/// A point of the unit square with NaN sent to 0 and every coordinate clamped to [0, 1], so that
/// no input can push a table lookup out of range.
#[inline]
pub(crate) fn clamp_unit(x: f64) -> f64 {
    if x > 0.0 {
        x.min(1.0)
    } else {
        0.0
    }
}

/// Inverts a normalised discrete CDF `cdf[0] = 0 ≤ … ≤ cdf[n] = 1` (n = `cdf.len() − 1` cells) at
/// `x` ∈ [0, 1]: the cell k with cdf[k] ≤ x < cdf[k+1] and the offset (x − cdf[k]) / (cdf[k+1] − cdf[k])
/// ∈ [0, 1] within it. Cells of zero probability are never returned (`last_positive` is the last
/// cell of positive probability, used when x reaches the top of the CDF). O(log n), no allocation.
#[inline]
pub(crate) fn invert_cdf(cdf: &[f64], last_positive: usize, x: f64) -> (usize, f64) {
    let n = cdf.len() - 1;
    // Number of interior breakpoints cdf[1..n] that are ≤ x.
    let k = cdf[1..n].partition_point(|&c| c <= x).min(last_positive);
    let (lo, hi) = (cdf[k], cdf[k + 1]);
    let w = hi - lo;
    let t = if w > 0.0 {
        ((x - lo) / w).clamp(0.0, 1.0)
    } else {
        1.0
    };
    (k, t)
}

/// The CDFs of a piecewise-constant `w` × `h` image (row-major, non-negative): each row's
/// conditional CDF over its columns and the marginal CDF over the rows' sums, as
/// [`build_cdf`] makes them.
#[derive(Debug, Clone)]
pub(crate) struct ImageCdfs {
    /// The rows' CDF, h + 1 entries.
    pub(crate) marginal: Vec<f64>,
    /// The last row of positive sum.
    pub(crate) marginal_last: usize,
    /// h rows of w + 1 CDF entries.
    pub(crate) conditional: Vec<f64>,
    /// Each row's last column of positive value.
    pub(crate) conditional_last: Vec<u32>,
}

impl ImageCdfs {
    /// The CDFs of `image` (`w` × `h`, row-major) and the sum of its pixels.
    pub(crate) fn build(image: &[f64], w: usize, h: usize) -> (Self, f64) {
        let mut conditional = vec![0.0; h * (w + 1)];
        let mut conditional_last = vec![0u32; h];
        let mut rows = vec![0.0; h];
        for r in 0..h {
            let (sum, last) = build_cdf(
                &image[r * w..(r + 1) * w],
                &mut conditional[r * (w + 1)..(r + 1) * (w + 1)],
            );
            rows[r] = sum;
            conditional_last[r] = last as u32;
        }
        let mut marginal = vec![0.0; h + 1];
        let (total, marginal_last) = build_cdf(&rows, &mut marginal);
        let cdfs = ImageCdfs {
            marginal,
            marginal_last,
            conditional,
            conditional_last,
        };
        (cdfs, total)
    }

    /// Bytes of the CDFs' contents.
    pub(crate) fn bytes(&self) -> usize {
        8 * (self.marginal.len() + self.conditional.len()) + 4 * self.conditional_last.len()
    }
}

/// Builds the normalised CDF of non-negative `weights` into `cdf` (length `weights.len() + 1`) and
/// returns (total, index of the last positive weight).
pub(crate) fn build_cdf(weights: &[f64], cdf: &mut [f64]) -> (f64, usize) {
    debug_assert_eq!(cdf.len(), weights.len() + 1);
    let mut sum = 0.0;
    let mut last = 0;
    cdf[0] = 0.0;
    for (k, &w) in weights.iter().enumerate() {
        sum += w;
        cdf[k + 1] = sum;
        if w > 0.0 {
            last = k;
        }
    }
    if sum > 0.0 {
        for c in cdf.iter_mut() {
            *c /= sum;
        }
        // The prefix sums are monotone and their last one is `sum` itself, so this only removes
        // nothing but makes the top exact.
        *cdf.last_mut().expect("non-empty") = 1.0;
    }
    (sum, last)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdf_inversion_skips_empty_cells() {
        let w = [0.0, 1.0, 0.0, 0.0, 3.0, 0.0];
        let mut cdf = [0.0; 7];
        let (sum, last) = build_cdf(&w, &mut cdf);
        assert_eq!((sum, last), (4.0, 4));
        assert_eq!(invert_cdf(&cdf, last, 0.0), (1, 0.0));
        assert_eq!(invert_cdf(&cdf, last, 1.0), (4, 1.0));
        assert_eq!(invert_cdf(&cdf, last, 0.25), (4, 0.0));
        let (k, t) = invert_cdf(&cdf, last, 0.125);
        assert_eq!(k, 1);
        assert!((t - 0.5).abs() < 1e-15);
    }
}
