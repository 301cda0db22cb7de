//! Baselines: the samplers a user would pick instead of the HDS mapping, behind the same trait.
//!
//! Every baseline is built from a [`Diagram`] and a [`Domain`] and implements [`Sampler`]:
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
//! outside it. Constructors validate and return a [`BaselineError`]; after construction, sampling
//! cannot fail or panic for any point of the closed unit square.
//!
//! The formulas, costs and weaknesses of each method are collected in `docs/BASELINES.md`.

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

use crate::diagram::{Diagram, DiagramError};
use crate::sampler::{normalize, spherical, Domain, Sampler, Vec3};
use std::f64::consts::FRAC_PI_2;
use std::fmt;
use std::str::FromStr;

/// Why a baseline sampler could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BaselineError {
    /// The diagram itself is invalid.
    #[error(transparent)]
    Diagram(#[from] DiagramError),
    /// A hemisphere sampler was given a diagram whose parallels pass θ = 90°.
    #[error("the hemisphere domain needs θ ≤ 90°, but the diagram's last parallel is at {theta_max_deg}°; use the sphere domain")]
    NotHemisphere {
        /// The diagram's last parallel, in degrees.
        theta_max_deg: f64,
    },
    /// The bilinear interpolant of the diagram integrates to zero (or to a non-finite number), e.g.
    /// a single parallel, so there is no density to sample.
    #[error("the interpolated diagram has no positive finite power to sample (integral = {integral} sr·unit)")]
    NoPower {
        /// [`Diagram::integral`] of the diagram.
        integral: f64,
    },
    /// The piecewise-constant image resolution is outside the accepted range.
    #[error("image resolution {resolution} is outside 1..={max}")]
    Resolution {
        /// The requested number of pixels per side.
        resolution: usize,
        /// The largest accepted resolution.
        max: usize,
    },
    /// Every pixel of the piecewise-constant image came out 0: the diagram's power lies between the
    /// pixel sample points. A higher resolution resolves it.
    #[error("every pixel of the {resolution}×{resolution} image is 0: the diagram is narrower than the pixels; raise the resolution")]
    EmptyImage {
        /// Pixels per side of the image.
        resolution: usize,
    },
    /// Rejection sampling would accept too rarely: mean target / max target is below
    /// [`MIN_ACCEPTANCE`].
    #[error(
        "rejection sampling would accept only a fraction {rate:e} of proposals (minimum {min:e})"
    )]
    AcceptanceTooLow {
        /// The exact acceptance rate.
        rate: f64,
        /// The smallest accepted rate, [`MIN_ACCEPTANCE`].
        min: f64,
    },
    /// [`Method::Hds`] is not a baseline; build it with [`crate::mapping`].
    #[error("method `{0}` is not a baseline")]
    NotABaseline(Method),
}

/// The sampling methods the project compares, as the CLI's `--method` spells them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// `hds`: the Havran–Dmitriev–Seidel mapping ([`crate::mapping`]), not built here.
    Hds,
    /// `piecewise-constant`: [`PiecewiseConstant`], a pixel image over an equal-area map.
    PiecewiseConstant,
    /// `bilinear`: [`Bilinear`], marginal–conditional inversion of the bilinear target.
    Bilinear,
    /// `rejection`: [`Rejection`], uniform proposals accepted against the maximum.
    Rejection,
    /// `uniform`: [`Uniform`], uniform directions that ignore the diagram.
    Uniform,
}

impl Method {
    /// Every method, in the order the CLI lists them.
    pub const ALL: [Method; 5] = [
        Method::Hds,
        Method::PiecewiseConstant,
        Method::Bilinear,
        Method::Rejection,
        Method::Uniform,
    ];

    /// The method's name as `--method` spells it (also what [`Sampler::name`] returns).
    pub fn as_str(self) -> &'static str {
        match self {
            Method::Hds => "hds",
            Method::PiecewiseConstant => "piecewise-constant",
            Method::Bilinear => "bilinear",
            Method::Rejection => "rejection",
            Method::Uniform => "uniform",
        }
    }

    /// Builds the baseline sampler of this method with its default options.
    ///
    /// [`Method::Hds`] gives [`BaselineError::NotABaseline`]: the caller builds the mapping.
    pub fn build_baseline(
        self,
        diagram: &Diagram,
        domain: Domain,
    ) -> Result<Box<dyn Sampler>, BaselineError> {
        Ok(match self {
            Method::Hds => return Err(BaselineError::NotABaseline(self)),
            Method::PiecewiseConstant => Box::new(PiecewiseConstant::new(diagram, domain)?),
            Method::Bilinear => Box::new(Bilinear::new(diagram, domain)?),
            Method::Rejection => Box::new(Rejection::new(diagram, domain)?),
            Method::Uniform => Box::new(Uniform::new(diagram, domain)?),
        })
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A method name that is none of `hds|piecewise-constant|bilinear|rejection|uniform`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown method `{0}`; expected one of hds, piecewise-constant, bilinear, rejection, uniform"
)]
pub struct ParseMethodError(pub String);

impl FromStr for Method {
    type Err = ParseMethodError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.as_str() == s)
            .ok_or_else(|| ParseMethodError(s.to_owned()))
    }
}

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
    pub(crate) fn new(diagram: &Diagram, domain: Domain) -> Result<Self, BaselineError> {
        let theta_max = *diagram.theta().last().expect("a diagram has parallels");
        if domain == Domain::Hemisphere && theta_max > FRAC_PI_2 {
            return Err(BaselineError::NotHemisphere {
                theta_max_deg: theta_max.to_degrees(),
            });
        }
        let integral = diagram.integral();
        if !(integral.is_finite() && integral > 0.0 && (1.0 / integral).is_finite()) {
            return Err(BaselineError::NoPower { integral });
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
    fn method_names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.to_string().parse::<Method>(), Ok(m));
        }
        assert!("HDS".parse::<Method>().is_err());
        assert_eq!(
            "piecewise-constant".parse::<Method>(),
            Ok(Method::PiecewiseConstant)
        );
    }

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
