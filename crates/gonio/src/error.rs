//! The errors of the library's front door: [`Error`], reading a diagram from its JSON text, and
//! [`BuildError`], building a sampler from a diagram (re-exported as `gonio::BuildError` and
//! `gonio::method::BuildError`). Every error from outside input says what is wrong and where.
//!
//! [`BuildError`] lives here, not beside the factory in `method.rs`, so that the samplers'
//! constructors (the baselines, the maps) and the factory that calls them share it without an
//! import circle.

use crate::diagram::DiagramError;

/// What [`crate::Diagram::from_json_str`] returns: the JSON text could not be read, or the diagram
/// it holds is not valid. (Photometric files have their own error,
/// [`crate::photometry::ParseError`]; building a sampler has [`crate::BuildError`].)
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The diagram is not valid (see [`DiagramError`]).
    #[error(transparent)]
    Diagram(#[from] DiagramError),
    /// The JSON text could not be read (1-based line and column).
    #[error("{line}:{column}: {message}")]
    Json {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What serde_json said.
        message: String,
    },
}

/// Why [`Method::build`](crate::Method::build) (or a sampler's own constructor) could not build a
/// sampler.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// The diagram does not fit the map (see [`DiagramError`]).
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
    #[error("the interpolated diagram has no positive finite power to sample (integral = {} sr·unit)", crate::decimal::shortest(*integral))]
    NoPower {
        /// [`Diagram::integral`](crate::Diagram::integral) of the diagram.
        integral: f64,
    },
    /// Every value is finite but the power (the integral over the domain) exceeds `f64::MAX`, so
    /// neither the power nor a pdf in the diagram's units can be stated: refused, naming the
    /// largest value (issue 40: all values 5e307 were "no positive finite power").
    #[error("the diagram's power overflows: its values reach {} and their integral over the domain exceeds the largest double (1.8e308); divide the values by a power of two (e.g. 2^16) first — the map itself does not depend on their scale", crate::decimal::shortest(*max_value))]
    PowerOverflow {
        /// [`Diagram::max_value`](crate::Diagram::max_value).
        max_value: f64,
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
    /// [`crate::baselines::MIN_ACCEPTANCE`].
    #[error(
        "rejection sampling would accept only a fraction {rate:e} of proposals (minimum {min:e})"
    )]
    AcceptanceTooLow {
        /// The exact acceptance rate.
        rate: f64,
        /// The smallest accepted rate, [`crate::baselines::MIN_ACCEPTANCE`].
        min: f64,
    },
    /// The requested tolerance is not a number in (0, 1)
    /// ([`crate::mapping::refine::valid_tolerance`]).
    #[error("tolerance {} is outside (0, 1)", crate::decimal::shortest(*tolerance))]
    Tolerance {
        /// The requested tolerance.
        tolerance: f64,
    },
}

impl BuildError {
    /// [`BuildError::PowerOverflow`] when a diagram of finite values has an infinite integral,
    /// else [`BuildError::NoPower`].
    pub(crate) fn no_power(integral: f64, max_value: f64) -> Self {
        if integral == f64::INFINITY && max_value.is_finite() {
            Self::PowerOverflow { max_value }
        } else {
            Self::NoPower { integral }
        }
    }
}
