//! [`HemisphereMap`]: the HDS mapping of the upper hemisphere (docs/DERIVATION.md §1–§7,
//! recommended variant A6).

use super::complete::{complete, Completion};
use super::hds::HdsCore;
use super::refine::{refine, valid_tolerance, RefineLimits, Refinement};
use crate::diagram::{Diagram, DiagramError};
use crate::sampler::{spherical, Domain, InvertError, Point2, Sample, Sampler, Vec3};
use std::f64::consts::FRAC_PI_2;

/// The Havran–Dmitriev–Seidel map from the unit square onto the upper hemisphere (z ≥ 0), built
/// once from a [`Diagram`], immutable and `Send + Sync`.
///
/// **Density.** The map is exact for the disk density D that interpolates the diagram's values
/// bilinearly in (x = √(1 − cos θ), φ): every sample carries `pdf = D(ω) / (2T)` per steradian,
/// where T = ∫_disk D dA (docs/DERIVATION.md §7). [`Sampler::pdf`] returns the same number for any
/// direction.
///
/// **Target.** [`Sampler::target_pdf`] is the **data**: the diagram as given, interpolated
/// bilinearly in (θ, φ), zero outside its measured θ range, normalised by its integral. The two agree at every node up to one constant; in between they
/// differ within the guaranteed range [`HemisphereMap::ratio_bound`] computed at build time.
///
/// **Completion** (docs/DERIVATION.md §8.1 A15, docs/MAPPING.md "Completion"). The support of the
/// map is the measured range: a diagram whose first parallel lies below the pole, or whose last
/// parallel ends above the horizon, is completed with **zero** there (a zero pole or horizon
/// parallel, and a zero guard parallel within 1e-7 of the adjacent cell's width outside the
/// measured edge, so at most ~2e-7 of the probability lies outside the measured range); each such
/// zone is a [`Completion`], listed by [`HemisphereMap::completions`]. One whose first meridian is
/// not at φ = 0 gets a meridian there, interpolated across the wrap-around sector (which changes
/// neither interpolant). The completed diagram, divided by the data's largest value, is
/// [`HemisphereMap::diagram`].
///
/// **Seams.** The map is continuous on the whole square. Its inverse is discontinuous only where the
/// B-disk azimuth wraps from 2π to 0 (the half-line v = ½, u > ½ of the square, which maps to φ = 0);
/// a direction there inverts to either side of that seam.
///
/// Cost: O(log M + log N) per sample (O(1) sector lookup for uniform meridians in `pdf`/`invert`).
///
/// ```
/// use gonio::{Diagram, HemisphereMap, Sampler};
/// // A lobe on 4 parallels × 4 meridians in candela (completed at the pole and at φ = 0 as above).
/// let d = Diagram::from_degrees(
///     &[10.0, 30.0, 60.0, 90.0],
///     &[20.0, 110.0, 200.0, 290.0],
///     &vec![vec![5.0, 3.0, 1.0, 0.0]; 4],
/// )
/// .unwrap();
/// let map = HemisphereMap::new(&d).unwrap();
/// let s = map.sample([0.25, 0.8]);
/// assert!(s.direction[2] >= 0.0);
/// assert!((map.pdf(s.direction) - s.pdf).abs() <= 1e-12 * s.pdf);
/// let u = map.invert(s.direction).unwrap();
/// assert!((u[0] - 0.25).abs() < 1e-10 && (u[1] - 0.8).abs() < 1e-10);
/// let (lo, hi) = map.ratio_bound(); // guaranteed range of pdf / target_pdf
/// let r = map.pdf(s.direction) / map.target_pdf(s.direction);
/// assert!(lo * (1.0 - 1e-9) <= r && r <= hi * (1.0 + 1e-9));
/// ```
#[derive(Debug, Clone)]
pub struct HemisphereMap {
    core: HdsCore,
    inv_2t: f64,
    inv_target_total: f64,
    ratio_bound: (f64, f64),
    scale: f64,
    completions: Vec<Completion>,
    /// The measured θ range [θ_0, θ_{N−1}] of the data (radians): the target's support.
    measured: (f64, f64),
    /// The data's integral in units of its largest value.
    data_total: f64,
    refinement: Option<Refinement>,
    /// The float32 map, built on the first float32 batch call ([`HemisphereMap::float32`]).
    float32: std::sync::OnceLock<Option<super::Float32Map>>,
}

impl HemisphereMap {
    /// Builds the map. The diagram must lie within θ ∈ [0°, 90°].
    pub fn new(diagram: &Diagram) -> Result<Self, DiagramError> {
        let completed = complete(diagram, FRAC_PI_2, false, diagram.max_value())?;
        let core = HdsCore::build(completed.diagram)?;
        Ok(Self::assemble(
            diagram,
            core,
            completed.scale,
            completed.completions,
        ))
    }

    /// The map of `core`, built from the completion of `diagram` (the data).
    fn assemble(
        diagram: &Diagram,
        core: HdsCore,
        scale: f64,
        completions: Vec<Completion>,
    ) -> Self {
        let theta = diagram.theta();
        let measured = (theta[0], theta[theta.len() - 1]);
        // The target is the data: normalised by the data's integral (in units of its largest
        // value), zero outside the measured range (the zero guard bands included).
        let data_total = diagram.normalised_integral();
        let inv_2t = 0.5 / core.total();
        let (lo, hi) = core.db_range();
        let ratio_scale = data_total * inv_2t;
        HemisphereMap {
            inv_target_total: 1.0 / data_total,
            ratio_bound: (lo * ratio_scale, hi * ratio_scale),
            inv_2t,
            core,
            scale,
            completions,
            measured,
            data_total,
            refinement: None,
            float32: std::sync::OnceLock::new(),
        }
    }

    /// Builds the map refined to `tolerance` (issue 14, [`super::refine`]): parallels whose values
    /// come from the target's own (θ, φ)-bilinear interpolant are inserted where needed, until
    /// [`HemisphereMap::ratio_bound`] lies within [1 − tolerance, 1 + tolerance] wherever the target
    /// is positive. Input nodes keep their values, zero regions stay zero, the target is unchanged,
    /// and the map is still exact and bijective with a closed-form inverse.
    ///
    /// With the default [`RefineLimits`] every hemisphere diagram reaches any tolerance ≥ 1e-4;
    /// whether it was reached, the bound reached and the cost are in
    /// [`HemisphereMap::refinement`] (check [`Refinement::reached`], or show
    /// [`Refinement::warning`]). `tolerance` must be finite and > 0.
    pub fn with_tolerance(diagram: &Diagram, tolerance: f64) -> Result<Self, DiagramError> {
        Self::with_refinement(diagram, tolerance, &RefineLimits::default())
    }

    /// As [`HemisphereMap::with_tolerance`], with explicit limits on the refinement's growth.
    pub fn with_refinement(
        diagram: &Diagram,
        tolerance: f64,
        limits: &RefineLimits,
    ) -> Result<Self, DiagramError> {
        if !valid_tolerance(tolerance) {
            return Err(DiagramError::BadTolerance { tolerance });
        }
        let start = std::time::Instant::now();
        let c = complete(diagram, FRAC_PI_2, false, diagram.max_value())?;
        let completed = c.diagram;
        let parallels_before = completed.n_parallels();
        let memory_before = HdsCore::table_bytes(&completed);
        let mut r = refine(&[&completed], tolerance, limits);
        let core = HdsCore::build_with_range(r.diagrams.remove(0), r.ranges[0])?;
        let mut map = Self::assemble(diagram, core, c.scale, c.completions);
        let bound = map.ratio_bound;
        let reached = bound.0 >= 1.0 - tolerance && bound.1 <= 1.0 + tolerance;
        map.refinement = Some(Refinement {
            tolerance,
            bound,
            reached,
            stop: if reached { None } else { r.stop },
            parallels_before,
            parallels_after: map.diagram().n_parallels(),
            meridians_added: 0,
            memory_before,
            memory_after: map.memory_bytes(),
            build_seconds: start.elapsed().as_secs_f64(),
        });
        Ok(map)
    }

    /// The map's tables (for the batch paths).
    pub(crate) fn core(&self) -> &HdsCore {
        &self.core
    }

    /// The completed diagram the map was built from, its values divided by the data's largest value
    /// ([`HemisphereMap::value_scale`]); see the type's documentation.
    pub fn diagram(&self) -> &Diagram {
        self.core.diagram()
    }

    /// Guaranteed (min, max) of `pdf / target_pdf` over every direction where the target is positive,
    /// computed at build time (see `mapping::bound`): a true bound, tight to about 1e-10.
    pub fn ratio_bound(&self) -> (f64, f64) {
        self.ratio_bound
    }

    /// T = ∫_disk D dA: the total power of the disk density, in units of the data's largest value ×
    /// (disk area).
    pub fn disk_power(&self) -> f64 {
        self.core.total()
    }

    /// The data's integral: ∫ over the hemisphere of the diagram as given, interpolated bilinearly in
    /// (θ, φ) and zero outside its measured θ range, in diagram units × sr (lumens for a diagram in
    /// candela). The completed diagram's power ([`HemisphereMap::completed_power`])
    /// equals it to ~2e-7 relative. `+inf` only if the power exceeds `f64::MAX` (see
    /// [`HemisphereMap::normalised_target_power`]).
    pub fn target_power(&self) -> f64 {
        self.data_total * self.scale
    }

    /// [`HemisphereMap::target_power`] divided by [`HemisphereMap::value_scale`]: always finite.
    pub fn normalised_target_power(&self) -> f64 {
        self.data_total
    }

    /// The power of the completed diagram the map samples (data plus the zero guard bands), in
    /// diagram units × sr: [`HemisphereMap::target_power`] × (1 + at most ~2e-7).
    pub fn completed_power(&self) -> f64 {
        self.core.target_total() * self.scale
    }

    /// The probability that a sample lies outside the measured θ range (in the zero guard bands),
    /// computed exactly from the tables; at most ~2e-7 by construction (docs/MAPPING.md).
    pub fn probability_outside_measured(&self) -> f64 {
        self.core.power_outside(self.measured.0, self.measured.1) / self.core.total()
    }

    /// [`HemisphereMap::completed_power`] / [`HemisphereMap::target_power`], computed without overflow:
    /// 1 + (the guard bands' share), within 1e-6 of 1.
    pub fn power_ratio(&self) -> f64 {
        self.core.target_total() / self.data_total
    }

    /// The intermediate points of the forward map at `u` (see [`super::Stages`]).
    pub fn stages(&self, u: Point2) -> super::Stages {
        self.core.stages(u)
    }

    /// The slide's count of additional precomputed floats, M·N + 2M + 2 (docs/DERIVATION.md §4.6,
    /// A10), for this grid.
    pub fn paper_table_floats(&self) -> usize {
        super::paper_table_floats(self.diagram())
    }
}

impl Sampler for HemisphereMap {
    fn name(&self) -> &'static str {
        "hds"
    }
    fn domain(&self) -> Domain {
        Domain::Hemisphere
    }
    #[inline]
    fn sample(&self, u: Point2) -> Sample {
        let (direction, d) = self.core.sample(u);
        Sample {
            direction,
            pdf: d * self.inv_2t,
        }
    }
    #[inline]
    fn pdf(&self, direction: Vec3) -> f64 {
        if !(direction[2] >= 0.0) {
            return 0.0;
        }
        self.core.density(direction) * self.inv_2t
    }
    #[inline]
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        if !(direction[2] >= 0.0) || !direction.iter().all(|c| c.is_finite()) {
            return Err(InvertError::OutsideDomain);
        }
        // The rule of every sampler (issue 25): no point maps where the density is 0 (e.g.
        // outside the measured range of θ); the map's inverse there is a boundary point that
        // samples another direction.
        if self.pdf(direction) == 0.0 {
            return Err(InvertError::ZeroDensity);
        }
        Ok(self.core.invert(direction))
    }
    fn target_pdf(&self, direction: Vec3) -> f64 {
        if !(direction[2] >= 0.0) {
            return 0.0;
        }
        let (t, p) = spherical(direction);
        if !(t >= self.measured.0 && t <= self.measured.1) {
            return 0.0;
        }
        self.core.diagram().interpolate(t, p) * self.inv_target_total
    }
    fn target_power(&self) -> f64 {
        HemisphereMap::target_power(self)
    }
    fn memory_bytes(&self) -> usize {
        self.core.memory_bytes()
    }
    super::batch::soa_sampler_methods!();
}

super::shared_accessors!(HemisphereMap);
