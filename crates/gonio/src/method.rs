//! The one factory of the library: [`Method`] names a sampling method, [`Method::build`] builds its
//! [`Sampler`] for a [`Diagram`] on a [`Domain`], [`BuildOptions`] carries the few knobs some
//! methods take, and [`BuildError`] says why a sampler could not be built.
//!
//! Every consumer (the CLI, the benchmarks, the examples, the bindings) builds its samplers here and
//! then works with `&dyn Sampler` (a [`Built`] dereferences to one); what only the HDS map has
//! (ratio bound, refinement, completions, stages) is reached through [`Built::hds_map`], typed,
//! without a downcast.
//!
//! ```
//! use gonio::{BuildOptions, Diagram, Domain, Method, Sampler};
//! // A cosine-like lobe on 3 parallels × 1 meridian, values in candela.
//! let d = Diagram::from_degrees(&[0.0, 45.0, 90.0], &[0.0], &[vec![1.0, 0.7, 0.0]]).unwrap();
//! let domain = Domain::for_diagram(&d); // θ ≤ 90°: the hemisphere
//! for method in Method::ALL {
//!     let s = method.build(&d, domain).unwrap();
//!     assert_eq!(s.name(), method.as_str());
//!     let x = s.sample([0.3, 0.7]);
//!     assert!((s.pdf(x.direction) - x.pdf).abs() <= 1e-9 * x.pdf);
//! }
//! // Options that only some methods read; the others ignore them.
//! let opts = BuildOptions::default().resolution(64).seed(7);
//! let pc = Method::PiecewiseConstant.build_with(&d, domain, &opts).unwrap();
//! assert_eq!(pc.name(), "piecewise-constant");
//! ```

use crate::baselines::{Bilinear, PiecewiseConstant, Rejection, Uniform, DEFAULT_RESOLUTION};
use crate::diagram::Diagram;
pub use crate::error::BuildError;
use crate::mapping::{HemisphereMap, MapRef, SphereLayout, SphereMap};
use crate::sampler::{Domain, Sampler};
use std::borrow::Cow;
use std::f64::consts::FRAC_PI_2;
use std::fmt;
use std::str::FromStr;

/// The sampling methods the project compares, as the CLI's `--method` spells them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// `hds`: the Havran–Dmitriev–Seidel mapping, [`HemisphereMap`] or [`SphereMap`].
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

    /// Builds the sampler of this method for `diagram` on `domain`, with the default
    /// [`BuildOptions`].
    ///
    /// # Errors
    /// As [`Method::build_with`].
    pub fn build(self, diagram: &Diagram, domain: Domain) -> Result<Built<'static>, BuildError> {
        self.build_with(diagram, domain, &BuildOptions::default())
    }

    /// Builds the sampler of this method for `diagram` on `domain` with `options` (each method reads
    /// the options that apply to it and ignores the others).
    ///
    /// * [`Method::Hds`]: [`HemisphereMap`] on the hemisphere, [`SphereMap`] with
    ///   [`BuildOptions::sphere_layout`] on the sphere;
    /// * [`Method::PiecewiseConstant`]: [`PiecewiseConstant`] at [`BuildOptions::resolution`];
    /// * [`Method::Rejection`]: [`Rejection`] with [`BuildOptions::seed`];
    /// * [`Method::Bilinear`], [`Method::Uniform`]: no options.
    ///
    /// # Errors
    /// [`BuildError::NotHemisphere`] for [`Domain::Hemisphere`] and a diagram that passes θ = 90°
    /// (every method); [`BuildError::Tolerance`] for a tolerance outside (0, 1); otherwise what the
    /// method's constructor returns.
    pub fn build_with(
        self,
        diagram: &Diagram,
        domain: Domain,
        options: &BuildOptions,
    ) -> Result<Built<'static>, BuildError> {
        if let Some(t) = options.tolerance {
            if !crate::mapping::refine::valid_tolerance(t) {
                return Err(BuildError::Tolerance { tolerance: t });
            }
        }
        let theta_max = *diagram.theta().last().expect("a diagram has parallels");
        if domain == Domain::Hemisphere && theta_max > FRAC_PI_2 {
            return Err(BuildError::NotHemisphere {
                theta_max_deg: theta_max.to_degrees(),
            });
        }
        // One rule for every method (issue 25): a diagram whose power is not a positive finite
        // number (values near f64::MAX whose integral overflows) has no density to sample.
        let integral = diagram.integral();
        if !(integral.is_finite() && integral > 0.0) {
            return Err(BuildError::no_power(integral, diagram.max_value()));
        }
        let other = |s: Box<dyn Sampler>| Built::Other(s);
        Ok(match self {
            Method::Hds => match (domain, options.tolerance) {
                (Domain::Hemisphere, None) => HemisphereMap::new(diagram)?.into(),
                (Domain::Hemisphere, Some(t)) => HemisphereMap::with_tolerance(diagram, t)?.into(),
                (Domain::Sphere, None) => {
                    SphereMap::with_layout(diagram, options.sphere_layout)?.into()
                }
                (Domain::Sphere, Some(t)) => SphereMap::with_refinement(
                    diagram,
                    options.sphere_layout,
                    t,
                    &crate::mapping::RefineLimits::default(),
                )?
                .into(),
            },
            Method::PiecewiseConstant => other(Box::new(PiecewiseConstant::with_resolution(
                diagram,
                domain,
                options.resolution,
            )?)),
            Method::Bilinear => other(Box::new(Bilinear::new(diagram, domain)?)),
            Method::Rejection => other(Box::new(Rejection::with_seed(
                diagram,
                domain,
                options.seed,
            )?)),
            Method::Uniform => other(Box::new(Uniform::new(diagram, domain)?)),
        })
    }
}

/// A built sampler: the HDS maps by their type (owned, or borrowed from what holds them, such as
/// an environment map), every other method behind the contract. It dereferences to
/// `dyn Sampler`, so it goes wherever a sampler does; [`Built::hds_map`] reaches what only the
/// HDS map has, typed, with no downcast.
// The maps are held inline (a Built is made once per sampler and moved rarely): a box per map
// would cost every sample call an indirection for nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub enum Built<'a> {
    /// The HDS map of the upper hemisphere.
    Hemisphere(Cow<'a, HemisphereMap>),
    /// The HDS map of the whole sphere.
    Sphere(Cow<'a, SphereMap>),
    /// Any other sampler.
    Other(Box<dyn Sampler + 'a>),
}

impl fmt::Debug for dyn Sampler + '_ {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Sampler({})", self.name())
    }
}

impl<'a> Built<'a> {
    /// The HDS map, for what only it has ([`MapRef::ratio_bound`], [`MapRef::refinement`],
    /// [`MapRef::completions`], [`MapRef::stages`], and the map itself); `None` for every other
    /// method.
    pub fn hds_map(&self) -> Option<MapRef<'_>> {
        match self {
            Built::Hemisphere(m) => Some(MapRef::Hemisphere(m)),
            Built::Sphere(m) => Some(MapRef::Sphere(m)),
            Built::Other(_) => None,
        }
    }

    /// The HDS map's guaranteed range of `pdf / target_pdf` ([`MapRef::ratio_bound`]); `None`
    /// for methods that promise no bound.
    pub fn ratio_bound(&self) -> Option<(f64, f64)> {
        self.hds_map().map(MapRef::ratio_bound)
    }

    /// What refinement to a tolerance asked, reached and cost ([`MapRef::refinement`]); `None`
    /// for a map built without one and for every other method.
    pub fn refinement(&self) -> Option<&crate::mapping::Refinement> {
        self.hds_map().and_then(MapRef::refinement)
    }

    /// The zones the HDS map completed with zero light ([`MapRef::completions`]); empty for
    /// every other method.
    pub fn completions(&self) -> &[crate::mapping::Completion] {
        self.hds_map().map_or(&[], MapRef::completions)
    }

    /// The intermediate points of the HDS map's forward map at `u` ([`MapRef::stages`]); `None`
    /// for every other method.
    pub fn stages(&self, u: crate::Point2) -> Option<crate::mapping::Stages> {
        self.hds_map().map(|m| m.stages(u))
    }

    /// The sampler as a boxed trait object (for a consumer that stores `Box<dyn Sampler>`).
    pub fn into_boxed(self) -> Box<dyn Sampler + 'a> {
        match self {
            Built::Hemisphere(Cow::Owned(m)) => Box::new(m),
            Built::Hemisphere(Cow::Borrowed(m)) => Box::new(m),
            Built::Sphere(Cow::Owned(m)) => Box::new(m),
            Built::Sphere(Cow::Borrowed(m)) => Box::new(m),
            Built::Other(s) => s,
        }
    }
}

impl<'a> std::ops::Deref for Built<'a> {
    type Target = dyn Sampler + 'a;
    fn deref(&self) -> &Self::Target {
        match self {
            Built::Hemisphere(m) => &**m,
            Built::Sphere(m) => &**m,
            Built::Other(s) => &**s,
        }
    }
}

impl<'a> AsRef<dyn Sampler + 'a> for Built<'a> {
    fn as_ref(&self) -> &(dyn Sampler + 'a) {
        &**self
    }
}

impl From<HemisphereMap> for Built<'_> {
    fn from(m: HemisphereMap) -> Self {
        Built::Hemisphere(Cow::Owned(m))
    }
}

impl From<SphereMap> for Built<'_> {
    fn from(m: SphereMap) -> Self {
        Built::Sphere(Cow::Owned(m))
    }
}

impl<'a> From<&'a SphereMap> for Built<'a> {
    fn from(m: &'a SphereMap) -> Self {
        Built::Sphere(Cow::Borrowed(m))
    }
}

impl<'a> From<&'a HemisphereMap> for Built<'a> {
    fn from(m: &'a HemisphereMap) -> Self {
        Built::Hemisphere(Cow::Borrowed(m))
    }
}

impl<'a> From<Box<dyn Sampler + 'a>> for Built<'a> {
    fn from(s: Box<dyn Sampler + 'a>) -> Self {
        Built::Other(s)
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
        crate::input::find_by_name(Method::ALL, Method::as_str, s)
            .ok_or_else(|| ParseMethodError(s.to_owned()))
    }
}

/// The options of [`Method::build_with`]. Construct with [`BuildOptions::default`] and the
/// builder-style setters (the struct is `#[non_exhaustive]`, so new options can be added without
/// breaking callers):
///
/// ```
/// use gonio::{BuildOptions, SphereLayout};
/// let o = BuildOptions::default()
///     .tolerance(Some(0.01))
///     .resolution(128)
///     .seed(42)
///     .sphere_layout(SphereLayout::Lambert);
/// assert_eq!(o.resolution, 128);
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct BuildOptions {
    /// Requested relative accuracy of the HDS map: refine it (`crate::mapping::refine`) until the
    /// guaranteed bound of pdf / target lies within [1 − tol, 1 + tol] wherever the target is
    /// positive. Must lie in (0, 1) when given (the one rule,
    /// [`crate::mapping::refine::valid_tolerance`]). Whether it was reached, the bound reached and the
    /// cost: [`MapRef::refinement`] (a growth limit can stop it early; the map is still exact).
    /// Default `None`: the paper's map on the diagram's own grid.
    pub tolerance: Option<f64>,
    /// Pixels per side of the [`PiecewiseConstant`] image, 1..=[`MAX_RESOLUTION`](crate::baselines::MAX_RESOLUTION). Default
    /// [`DEFAULT_RESOLUTION`].
    pub resolution: usize,
    /// Seed of the [`Rejection`] sampler's proposal stream ([`Rejection::with_seed`]). Default 0.
    pub seed: u64,
    /// Layout of the HDS map on [`Domain::Sphere`]. Default [`SphereLayout::Split`].
    pub sphere_layout: SphereLayout,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            tolerance: None,
            resolution: DEFAULT_RESOLUTION,
            seed: 0,
            sphere_layout: SphereLayout::Split,
        }
    }
}

impl BuildOptions {
    /// Sets [`BuildOptions::tolerance`].
    pub fn tolerance(mut self, tolerance: Option<f64>) -> Self {
        self.tolerance = tolerance;
        self
    }
    /// Sets [`BuildOptions::resolution`].
    pub fn resolution(mut self, resolution: usize) -> Self {
        self.resolution = resolution;
        self
    }
    /// Sets [`BuildOptions::seed`].
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
    /// Sets [`BuildOptions::sphere_layout`].
    pub fn sphere_layout(mut self, layout: SphereLayout) -> Self {
        self.sphere_layout = layout;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baselines::MAX_RESOLUTION;

    #[test]
    fn method_names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.to_string().parse::<Method>(), Ok(m));
        }
        // Issue 25: one rule for names, as for sequences: letter case and blanks do not matter.
        assert_eq!("HDS".parse::<Method>(), Ok(Method::Hds));
        assert_eq!(" Bilinear ".parse::<Method>(), Ok(Method::Bilinear));
        assert!("hds2".parse::<Method>().is_err());
        assert_eq!(
            "piecewise-constant".parse::<Method>(),
            Ok(Method::PiecewiseConstant)
        );
    }

    fn sphere_diagram() -> Diagram {
        Diagram::from_degrees(
            &[0.0, 60.0, 120.0, 180.0],
            &[0.0, 90.0, 180.0, 270.0],
            &vec![vec![1.0, 0.5, 0.8, 0.2]; 4],
        )
        .unwrap()
    }

    #[test]
    fn every_method_builds_on_both_domains_and_names_itself() {
        let hemi =
            Diagram::from_degrees(&[0.0, 45.0, 90.0], &[0.0], &[vec![1.0, 0.7, 0.0]]).unwrap();
        for m in Method::ALL {
            let s = m.build(&hemi, Domain::Hemisphere).unwrap();
            assert_eq!((s.name(), s.domain()), (m.as_str(), Domain::Hemisphere));
            let s = m.build(&sphere_diagram(), Domain::Sphere).unwrap();
            assert_eq!((s.name(), s.domain()), (m.as_str(), Domain::Sphere));
        }
    }

    #[test]
    fn a_sphere_diagram_is_refused_on_the_hemisphere_by_every_method() {
        for m in Method::ALL {
            let e = m.build(&sphere_diagram(), Domain::Hemisphere).err();
            assert_eq!(
                e,
                Some(BuildError::NotHemisphere {
                    theta_max_deg: 180.0
                }),
                "{m}"
            );
        }
    }

    #[test]
    fn options_reach_the_methods() {
        let d = sphere_diagram();
        let bad = BuildOptions::default().resolution(0);
        assert_eq!(
            Method::PiecewiseConstant
                .build_with(&d, Domain::Sphere, &bad)
                .err(),
            Some(BuildError::Resolution {
                resolution: 0,
                max: MAX_RESOLUTION
            })
        );
        let tol = BuildOptions::default().tolerance(Some(1.5));
        assert_eq!(
            Method::Hds.build_with(&d, Domain::Sphere, &tol).err(),
            Some(BuildError::Tolerance { tolerance: 1.5 })
        );
        let (a, b) = (
            Method::Rejection.build(&d, Domain::Sphere).unwrap(),
            Method::Rejection
                .build_with(&d, Domain::Sphere, &BuildOptions::default().seed(9))
                .unwrap(),
        );
        let differ = (0..16).any(|k| {
            let u = [(k as f64 + 0.5) / 16.0, 0.3];
            a.sample(u).direction != b.sample(u).direction
        });
        assert!(differ, "the seed must change the rejection stream");
        let lambert = BuildOptions::default().sphere_layout(SphereLayout::Lambert);
        let l = Method::Hds
            .build_with(&d, Domain::Sphere, &lambert)
            .unwrap();
        let s = Method::Hds.build(&d, Domain::Sphere).unwrap();
        assert_ne!(l.sample([0.2, 0.9]), s.sample([0.2, 0.9]));
    }

    #[test]
    fn target_power_is_the_integral_of_the_same_diagram_for_every_method() {
        // A diagram the mapping needs no completion for (pole, 180° and φ = 0 present).
        let d = sphere_diagram();
        for m in Method::ALL {
            let s = m.build(&d, Domain::Sphere).unwrap();
            let p = s.target_power();
            assert!((p - d.integral()).abs() <= 1e-12 * p, "{m}: {p}");
        }
    }
}
