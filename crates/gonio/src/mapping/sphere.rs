//! [`SphereMap`]: the HDS mapping over the whole sphere, for luminaires that emit both down and up.
//!
//! Two layouts (docs/DERIVATION.md §10), measured against each other in `docs/SPHERE.md`:
//! * [`SphereLayout::Split`] (the default): one hemisphere map per side of the horizon, each built
//!   from its half of the diagram (the lower half mirrored), chosen by the first coordinate of the
//!   square in proportion to the hemispheres' power. Low distortion everywhere; the map is continuous
//!   except across the seam line u = P_lower of the square, where the sample jumps between
//!   hemispheres.
//! * [`SphereLayout::Lambert`]: a single map whose M_E is the whole-sphere Lambert lift, the disk of
//!   radius √2 (x_j = √(1 − cos θ_j) up to θ = π). Continuous on the whole square, but the far pole
//!   is the whole rim of the disk, so cells near θ = π are strongly stretched.
//!
//! In both, every sample's pdf is D/(2T) with T the total disk power of the map(s), so at every node
//! the pdf is the node value times one constant.

use super::complete::{complete, hemisphere_part_with_horizon, Completion};
use super::hds::HdsCore;
use super::refine::{refine, valid_tolerance, RefineLimits, Refinement};
use super::split::{mirror, Side, SplitRule};
use crate::diagram::{Diagram, DiagramError};
use crate::sampler::{spherical, Domain, InvertError, Point2, Sample, Sampler, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// How the sphere is laid out on the unit square (see [`SphereMap`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SphereLayout {
    /// Two hemisphere maps side by side on the square, split by power.
    Split,
    /// One map with the whole-sphere Lambert lift (disk of radius √2).
    Lambert,
}

/// The maps of a [`SphereMap`] and how the square is shared among them, resolved once at build
/// time: `sample`, `pdf` and `invert` branch on this one tag, not on the layout and on which
/// hemispheres carry light.
// One SphereMap exists per luminaire: the size of the enum does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
enum Layout {
    /// Split layout with light on both sides of the horizon: u < `p_lower` maps onto the lower
    /// hemisphere (mirrored), the rest onto the upper one.
    Split {
        upper: HdsCore,
        lower: HdsCore,
        /// Probability of the lower hemisphere, T_lower / (T_lower + T_upper).
        p_lower: f64,
    },
    /// Split layout with light above the horizon only: the whole square maps onto the upper
    /// hemisphere (P_lower = 0).
    Upper(HdsCore),
    /// Split layout with light below the horizon only: the whole square maps onto the lower
    /// hemisphere, mirrored (P_lower = 1).
    Lower(HdsCore),
    /// One map with the whole-sphere Lambert lift.
    Lambert(Box<HdsCore>),
}

/// Borrowed view of a [`SphereMap`]'s maps, for its scalar and batch paths alike: a split layout
/// is its maps and its [`SplitRule`].
pub(crate) enum CoresRef<'a> {
    Split {
        upper: Option<&'a HdsCore>,
        lower: Option<&'a HdsCore>,
        rule: SplitRule,
    },
    Lambert(&'a HdsCore),
}

/// A [`SphereMap`]'s maps, owned ([`SphereMap::into_cores`]).
// Made once per conversion, never in a collection: the split variant's size costs nothing.
#[allow(clippy::large_enum_variant)]
pub(crate) enum CoresOwned {
    Split {
        upper: Option<HdsCore>,
        lower: Option<HdsCore>,
        rule: SplitRule,
    },
    Lambert(HdsCore),
}

impl<'a> CoresRef<'a> {
    /// The map of a split layout's side (`None` where the layout has none there).
    #[inline]
    pub(crate) fn side(
        upper: Option<&'a HdsCore>,
        lower: Option<&'a HdsCore>,
        side: Side,
    ) -> Option<&'a HdsCore> {
        match side {
            Side::Lower => lower,
            Side::Upper => upper,
        }
    }
}

/// The HDS map from the unit square onto the whole sphere. Directions are in the diagram's frame
/// (θ from +z). A diagram that covers only θ ∈ [0°, 90°] or [90°, 180°] gives zero density on the
/// other hemisphere, which is never sampled.
///
/// Two layouts (docs/DERIVATION.md §10), measured against each other in `docs/SPHERE.md`:
/// * [`SphereLayout::Split`] (the default): one hemisphere map per side of the horizon, each built
///   from its half of the diagram (the lower half mirrored), chosen by the first coordinate of the
///   square in proportion to the hemispheres' power. Low distortion everywhere; the map is
///   continuous except across the seam line u = P_lower of the square
///   ([`SphereMap::lower_probability`]), where the sample jumps between hemispheres.
/// * [`SphereLayout::Lambert`]: a single map whose M_E is the whole-sphere Lambert lift, the disk of
///   radius √2 (x_j = √(1 − cos θ_j) up to θ = π). Continuous on the whole square, but the far pole
///   is the whole rim of the disk, so cells near θ = π are strongly stretched.
///
/// In both, every sample's pdf is D/(2T) with T the total disk power of the map(s), so at every
/// node the pdf is the node value times one constant.
///
/// ```
/// use gonio::{Diagram, Sampler, SphereLayout, SphereMap};
/// // Light both down (θ > 90°) and up, 5 parallels × 3 meridians.
/// let d = Diagram::from_degrees(
///     &[0.0, 40.0, 90.0, 130.0, 180.0],
///     &[0.0, 120.0, 240.0],
///     &vec![vec![1.0, 0.5, 0.3, 2.0, 4.0]; 3],
/// )
/// .unwrap();
/// for layout in [SphereLayout::Split, SphereLayout::Lambert] {
///     let map = SphereMap::with_layout(&d, layout).unwrap();
///     let s = map.sample([0.1, 0.4]);
///     assert!((map.pdf(s.direction) - s.pdf).abs() <= 1e-12 * s.pdf);
///     let u = map.invert(s.direction).unwrap();
///     assert!((u[0] - 0.1).abs() < 1e-9 && (u[1] - 0.4).abs() < 1e-9);
/// }
/// // Most of the power is below the horizon, so most of the square maps there.
/// assert!(SphereMap::new(&d).unwrap().lower_probability().unwrap() > 0.5);
/// ```
#[derive(Debug, Clone)]
pub struct SphereMap {
    layout: Layout,
    inv_2t: f64,
    inv_target_total: f64,
    /// target_total / (2T): the factor from the cores' D/B ranges to the ratio bound, which is
    /// computed on the first [`SphereMap::ratio_bound`] call (the cores keep their ranges).
    ratio_scale: f64,
    scale: f64,
    completions: Vec<Completion>,
    /// The measured θ range of the data (radians): the target's support.
    measured: (f64, f64),
    refinement: Option<Refinement>,
    /// The float32 map, built on the first float32 batch call ([`SphereMap::float32`]).
    float32: std::sync::OnceLock<Option<super::Float32Map>>,
}

/// The measured θ range of a diagram (radians).
fn measured(d: &Diagram) -> (f64, f64) {
    let t = d.theta();
    (t[0], t[t.len() - 1])
}

impl SphereMap {
    /// Builds the map with the default [`SphereLayout::Split`] layout.
    ///
    /// Each hemisphere that the diagram reaches into is completed as in
    /// [`crate::HemisphereMap`]: zero outside the measured θ range, with zero guard parallels (see
    /// [`SphereMap::completions`]); the horizon is the diagram's node at 90°, inserted by linear
    /// interpolation in θ if the diagram crosses 90° without one.
    pub fn new(diagram: &Diagram) -> Result<Self, DiagramError> {
        Self::with_layout(diagram, SphereLayout::Split)
    }

    /// Builds the map with the chosen layout. [`SphereLayout::Lambert`] needs a diagram that
    /// reaches into both hemispheres; outside the measured range it is completed with zero, as the
    /// split layout.
    pub fn with_layout(diagram: &Diagram, layout: SphereLayout) -> Result<Self, DiagramError> {
        Self::build(std::borrow::Cow::Borrowed(diagram), layout, None)
    }

    /// Builds the map with the default split layout, refined to `tolerance` (see
    /// [`crate::HemisphereMap::with_tolerance`] and [`super::refine`]): `ratio_bound` within
    /// [1 − tolerance, 1 + tolerance] wherever the target is positive, reached or not as
    /// [`SphereMap::refinement`] says. Both hemisphere maps are refined under one normalisation.
    pub fn with_tolerance(diagram: &Diagram, tolerance: f64) -> Result<Self, DiagramError> {
        Self::with_refinement(
            diagram,
            SphereLayout::Split,
            tolerance,
            &RefineLimits::default(),
        )
    }

    /// Builds the map with the chosen layout, refined to `tolerance` under `limits`. On the
    /// [`SphereLayout::Lambert`] layout a target that is zero at θ = 180° cannot be bounded from
    /// below ([`super::RefineStop::FarPoleZero`]); the split layout can always be refined.
    pub fn with_refinement(
        diagram: &Diagram,
        layout: SphereLayout,
        tolerance: f64,
        limits: &RefineLimits,
    ) -> Result<Self, DiagramError> {
        if !valid_tolerance(tolerance) {
            return Err(DiagramError::BadTolerance { tolerance });
        }
        Self::build(
            std::borrow::Cow::Borrowed(diagram),
            layout,
            Some((tolerance, limits)),
        )
    }

    /// [`SphereMap::new`] of a diagram the caller gives away: it is dropped as soon as the
    /// hemisphere parts are made, before the tables are built (an environment map's diagram is
    /// 8 bytes a pixel; issue 40).
    pub(crate) fn from_diagram(diagram: Diagram) -> Result<Self, DiagramError> {
        Self::build(std::borrow::Cow::Owned(diagram), SphereLayout::Split, None)
    }

    fn build(
        diagram: std::borrow::Cow<'_, Diagram>,
        layout: SphereLayout,
        tolerance: Option<(f64, &RefineLimits)>,
    ) -> Result<Self, DiagramError> {
        let start = std::time::Instant::now();
        // The target is the data (zero outside its measured range), normalised by the data's
        // integral; the cores' own (completed) totals include the guard bands.
        let target_total = diagram.normalised_integral();
        let measured_theta = measured(&diagram);
        // The completed diagram(s); refined when a tolerance is asked.
        let scale = diagram.max_value();
        let mut completions = Vec::new();
        let completed: Vec<Option<Diagram>> = match layout {
            SphereLayout::Split => {
                let mut part = |upper: bool| -> Result<Option<Diagram>, DiagramError> {
                    // No part: the data does not reach into this hemisphere (it ends at the
                    // horizon) or measures only zeros there; nothing is completed.
                    let Some(p) = hemisphere_part_with_horizon(&diagram, upper)? else {
                        return Ok(None);
                    };
                    let c = complete(&p, FRAC_PI_2, !upper, scale)?;
                    completions.extend(c.completions);
                    Ok(Some(c.diagram))
                };
                vec![part(true)?, part(false)?]
            }
            SphereLayout::Lambert => {
                let theta = diagram.theta();
                if !(theta[0] < FRAC_PI_2 && theta[theta.len() - 1] > FRAC_PI_2) {
                    return Err(DiagramError::NotSpanningHorizon);
                }
                let c = complete(&diagram, PI, false, scale)?;
                completions.extend(c.completions);
                vec![Some(c.diagram)]
            }
        };
        // The parts are made: an owned diagram is not needed any more.
        drop(diagram);
        completions.sort_by(|a, b| a.theta_from_deg.total_cmp(&b.theta_from_deg));
        // Light below double precision's resolution on one side only (< 1e-15 of the total) is
        // dropped there; the other side carries the power.
        let split = layout == SphereLayout::Split;
        let keep = |r: Result<HdsCore, DiagramError>| -> Result<Option<HdsCore>, DiagramError> {
            match r {
                Ok(c) => Ok(Some(c)),
                Err(DiagramError::UnresolvedLight) if split => Ok(None),
                Err(e) => Err(e),
            }
        };
        let mut cores: Vec<Option<HdsCore>> = Vec::with_capacity(2);
        let mut info = None;
        match tolerance {
            None => {
                for c in completed {
                    cores.push(match c {
                        Some(d) => keep(HdsCore::build_lean(d))?,
                        None => None,
                    });
                }
            }
            Some((tol, limits)) => {
                let present: Vec<&Diagram> = completed.iter().flatten().collect();
                let parallels_before = present.iter().map(|d| d.n_parallels()).sum::<usize>();
                let memory_before = present.iter().map(|d| HdsCore::table_bytes(d)).sum();
                let r = refine(&present, tol, limits);
                let mut refined = r.diagrams.into_iter().zip(r.ranges);
                for c in &completed {
                    cores.push(match c {
                        Some(_) => {
                            let (d, range) = refined.next().expect("one refined diagram per part");
                            keep(HdsCore::build_lean_with_range(d, range))?
                        }
                        None => None,
                    });
                }
                info = Some((tol, r.stop, parallels_before, memory_before));
            }
        }
        let mut map = match layout {
            SphereLayout::Split => {
                let lower = cores.pop().flatten();
                let upper = cores.pop().flatten();
                let t = |c: &Option<HdsCore>| c.as_ref().map_or(0.0, |c| c.total());
                let (tu, tl) = (t(&upper), t(&lower));
                if !(tu + tl > 0.0) {
                    return Err(DiagramError::UnresolvedLight);
                }
                let total = tu + tl;
                let ratio_scale = target_total / (2.0 * total);
                let layout = match (upper, lower) {
                    (Some(upper), Some(lower)) => Layout::Split {
                        upper,
                        lower,
                        p_lower: tl / total,
                    },
                    (Some(upper), None) => Layout::Upper(upper),
                    (None, Some(lower)) => Layout::Lower(lower),
                    (None, None) => return Err(DiagramError::UnresolvedLight),
                };
                SphereMap {
                    layout,
                    inv_2t: 0.5 / total,
                    inv_target_total: 1.0 / target_total,
                    ratio_scale,
                    scale,
                    completions,
                    measured: measured_theta,
                    refinement: None,
                    float32: std::sync::OnceLock::new(),
                }
            }
            SphereLayout::Lambert => {
                let core = cores
                    .pop()
                    .flatten()
                    .expect("the Lambert layout has one map");
                let ratio_scale = target_total / (2.0 * core.total());
                SphereMap {
                    inv_2t: 0.5 / core.total(),
                    inv_target_total: 1.0 / target_total,
                    ratio_scale,
                    layout: Layout::Lambert(Box::new(core)),
                    scale,
                    completions,
                    measured: measured_theta,
                    refinement: None,
                    float32: std::sync::OnceLock::new(),
                }
            }
        };
        if let Some((tolerance, stop, parallels_before, memory_before)) = info {
            let bound = map.ratio_bound();
            let reached = bound.0 >= 1.0 - tolerance && bound.1 <= 1.0 + tolerance;
            map.refinement = Some(Refinement {
                tolerance,
                bound,
                reached,
                stop: if reached { None } else { stop },
                parallels_before,
                parallels_after: map.map_cores().map(|c| c.n_parallels()).sum(),
                meridians_added: 0,
                memory_before,
                memory_after: map.memory_bytes(),
                build_seconds: start.elapsed().as_secs_f64(),
            });
        }
        Ok(map)
    }

    /// Bytes of the completed grids' angles the maps keep beside their tables (counted by
    /// [`crate::envmap::EnvironmentMap::memory_bytes_beyond_image`], not by
    /// [`Sampler::memory_bytes`], which counts the tables).
    pub(crate) fn grid_bytes(&self) -> usize {
        self.map_cores().map(|c| c.diagram_bytes()).sum()
    }

    /// The hemisphere maps (split layout) or the one Lambert map.
    fn map_cores(&self) -> impl Iterator<Item = &HdsCore> {
        let (a, b): (Option<&HdsCore>, Option<&HdsCore>) = match &self.layout {
            Layout::Split { upper, lower, .. } => (Some(upper), Some(lower)),
            Layout::Upper(c) | Layout::Lower(c) => (Some(c), None),
            Layout::Lambert(c) => (Some(c), None),
        };
        a.into_iter().chain(b)
    }

    /// [`SphereMap::target_power`] divided by [`SphereMap::value_scale`]: always finite.
    pub fn normalised_target_power(&self) -> f64 {
        1.0 / self.inv_target_total
    }

    /// The intermediate points of the forward map at `u` (see [`super::Stages`]): those of the
    /// hemisphere map that serves `u` in the split layout (with `square` the original point and the
    /// direction as sampled), or of the single Lambert map.
    pub fn stages(&self, u: Point2) -> super::Stages {
        let (core, w, is_lower) = match self.cores() {
            CoresRef::Split { upper, lower, rule } => {
                let (side, w) = rule.split_u(u[0]);
                match CoresRef::side(upper, lower, side) {
                    Some(c) => (c, [w, u[1]], side == Side::Lower),
                    None => unreachable!("a split layout has a map on every side it samples"),
                }
            }
            CoresRef::Lambert(c) => return c.stages(u),
        };
        let mut st = core.stages(w);
        st.square = u;
        if is_lower {
            st.direction = mirror(st.direction);
            st.lower = true;
        }
        st
    }

    /// The maps of the layout and, for a split one, its rule.
    #[inline]
    pub(crate) fn cores(&self) -> CoresRef<'_> {
        match &self.layout {
            Layout::Split {
                upper,
                lower,
                p_lower,
            } => CoresRef::Split {
                upper: Some(upper),
                lower: Some(lower),
                rule: SplitRule::both(*p_lower),
            },
            Layout::Upper(c) => CoresRef::Split {
                upper: Some(c),
                lower: None,
                rule: SplitRule::upper_only(),
            },
            Layout::Lower(c) => CoresRef::Split {
                upper: None,
                lower: Some(c),
                rule: SplitRule::lower_only(),
            },
            Layout::Lambert(c) => CoresRef::Lambert(c),
        }
    }

    /// The maps taken apart (as [`SphereMap::cores`], owned), for a conversion that drops each
    /// map as soon as it is converted ([`SphereMap::into_float32_map`]).
    pub(crate) fn into_cores(self) -> CoresOwned {
        match self.layout {
            Layout::Split {
                upper,
                lower,
                p_lower,
            } => CoresOwned::Split {
                upper: Some(upper),
                lower: Some(lower),
                rule: SplitRule::both(p_lower),
            },
            Layout::Upper(c) => CoresOwned::Split {
                upper: Some(c),
                lower: None,
                rule: SplitRule::upper_only(),
            },
            Layout::Lower(c) => CoresOwned::Split {
                upper: None,
                lower: Some(c),
                rule: SplitRule::lower_only(),
            },
            Layout::Lambert(c) => CoresOwned::Lambert(*c),
        }
    }

    /// The layout in use.
    pub fn layout(&self) -> SphereLayout {
        match self.layout {
            Layout::Split { .. } | Layout::Upper(_) | Layout::Lower(_) => SphereLayout::Split,
            Layout::Lambert(_) => SphereLayout::Lambert,
        }
    }

    /// Guaranteed (min, max) of `pdf / target_pdf` wherever the target is positive (see
    /// [`crate::HemisphereMap::ratio_bound`]).
    ///
    /// Computed on the first call and kept (sampling never needs it): the cores' guaranteed ranges
    /// of D/B (a branch and bound over the grid, tens of milliseconds on a 2048 × 1024
    /// environment map) times target_total / (2T). A map refined to a tolerance has it from the
    /// build.
    pub fn ratio_bound(&self) -> (f64, f64) {
        let (lo, hi) = match &self.layout {
            Layout::Split { upper, lower, .. } => {
                let (a, b) = (upper.db_range(), lower.db_range());
                (a.0.min(b.0), a.1.max(b.1))
            }
            Layout::Upper(c) | Layout::Lower(c) => c.db_range(),
            Layout::Lambert(c) => c.db_range(),
        };
        (lo * self.ratio_scale, hi * self.ratio_scale)
    }

    /// The ratio bound computed now from the cores' grids (the build-time computation of before
    /// the bound was lazy), cached or not; and whether it is cached yet. For the tests.
    #[cfg(test)]
    pub(crate) fn ratio_bound_eager(&self) -> ((f64, f64), bool) {
        let cores: Vec<&HdsCore> = self.map_cores().collect();
        let cached = cores.iter().all(|c| c.db_range_cached());
        let (mut lo, mut hi) = cores[0].db_range_eager();
        if let Some(c) = cores.get(1) {
            let b = c.db_range_eager();
            (lo, hi) = (lo.min(b.0), hi.max(b.1));
        }
        ((lo * self.ratio_scale, hi * self.ratio_scale), cached)
    }

    /// Probability that a sample lies in the lower hemisphere (z < 0) for the split layout, which
    /// is also where the seam of the square lies (u = this value); `None` for the Lambert layout.
    pub fn lower_probability(&self) -> Option<f64> {
        match &self.layout {
            Layout::Split { p_lower, .. } => Some(*p_lower),
            Layout::Upper(_) => Some(0.0),
            Layout::Lower(_) => Some(1.0),
            Layout::Lambert(_) => None,
        }
    }

    /// The data's integral: ∫ over the sphere of the diagram as given, interpolated bilinearly in
    /// (θ, φ) and zero outside its measured θ range, in diagram units × sr (lumens for a diagram in
    /// candela). The completed diagram's power ([`SphereMap::completed_power`]) equals it
    /// to ~2e-7 relative (zero guard bands, docs/MAPPING.md "Completion"). `+inf` only if the power
    /// exceeds `f64::MAX`.
    pub fn target_power(&self) -> f64 {
        self.scale / self.inv_target_total
    }

    /// The power of the completed diagram(s) the map samples (data plus the zero guard bands), in
    /// diagram units × sr.
    pub fn completed_power(&self) -> f64 {
        self.scale * self.normalised_map_power()
    }

    fn normalised_map_power(&self) -> f64 {
        match &self.layout {
            Layout::Split { upper, lower, .. } => upper.target_total() + lower.target_total(),
            Layout::Upper(c) => c.target_total() + 0.0,
            Layout::Lower(c) => 0.0 + c.target_total(),
            Layout::Lambert(c) => c.target_total(),
        }
    }

    /// [`SphereMap::completed_power`] / [`SphereMap::target_power`], computed without overflow:
    /// 1 + (the guard bands' share), within 1e-6 of 1.
    pub fn power_ratio(&self) -> f64 {
        self.normalised_map_power() * self.inv_target_total
    }

    /// The probability that a sample lies outside the measured θ range (in the zero guard bands),
    /// computed exactly from the tables; at most ~2e-7 by construction (docs/MAPPING.md).
    pub fn probability_outside_measured(&self) -> f64 {
        let (lo, hi) = self.measured;
        let half = FRAC_PI_2;
        let above = |c: &HdsCore| c.power_outside(lo, hi.min(half));
        let below = |c: &HdsCore| c.power_outside((PI - hi).max(0.0), (PI - lo.max(half)).max(0.0));
        let outside = match &self.layout {
            Layout::Split { upper, lower, .. } => above(upper) + below(lower),
            Layout::Upper(c) => above(c) + 0.0,
            Layout::Lower(c) => 0.0 + below(c),
            Layout::Lambert(c) => c.power_outside(lo, hi),
        };
        outside * 2.0 * self.inv_2t
    }

    fn target_value(&self, d: Vec3) -> f64 {
        let (t, _) = spherical(d);
        if !(t >= self.measured.0 && t <= self.measured.1) {
            return 0.0;
        }
        let (core, dir) = match self.serving(d) {
            Some(served) => served,
            None => return 0.0,
        };
        let (t, p) = spherical(dir);
        core.target_value(t, p)
    }

    /// The map that serves direction `d` and the direction in its frame (mirrored for the lower
    /// hemisphere of a split layout); `None` where no map does (the side without light).
    #[inline]
    fn serving(&self, d: Vec3) -> Option<(&HdsCore, Vec3)> {
        match self.cores() {
            CoresRef::Split { upper, lower, rule } => {
                let side = rule.side_of(d[2]);
                let dir = if side == Side::Lower { mirror(d) } else { d };
                CoresRef::side(upper, lower, side).map(|c| (c, dir))
            }
            CoresRef::Lambert(c) => Some((c, d)),
        }
    }
}

impl Sampler for SphereMap {
    fn name(&self) -> &'static str {
        "hds"
    }
    fn domain(&self) -> Domain {
        Domain::Sphere
    }
    #[inline]
    fn sample(&self, u: Point2) -> Sample {
        let (direction, d) = match self.cores() {
            CoresRef::Split { upper, lower, rule } => {
                let (side, w) = rule.split_u(u[0]);
                match CoresRef::side(upper, lower, side) {
                    Some(c) => {
                        let (dir, d) = c.sample([w, u[1]]);
                        (
                            if side == Side::Lower {
                                mirror(dir)
                            } else {
                                dir
                            },
                            d,
                        )
                    }
                    // Refused at build time (zero power).
                    None => ([0.0, 0.0, 1.0], 0.0),
                }
            }
            CoresRef::Lambert(c) => c.sample(u),
        };
        Sample {
            direction,
            pdf: d * self.inv_2t,
        }
    }
    #[inline]
    fn pdf(&self, d: Vec3) -> f64 {
        let dens = match self.serving(d) {
            Some((c, dir)) => c.density(dir),
            None => 0.0,
        };
        dens * self.inv_2t
    }
    fn invert(&self, d: Vec3) -> Result<Point2, InvertError> {
        if !d.iter().all(|c| c.is_finite()) {
            return Err(InvertError::OutsideDomain);
        }
        // The rule of every sampler (issue 25): no point maps where the density is 0.
        if self.pdf(d) == 0.0 {
            return Err(InvertError::ZeroDensity);
        }
        match self.cores() {
            CoresRef::Split { upper, lower, rule } => {
                let side = rule.side_of(d[2]);
                match CoresRef::side(upper, lower, side) {
                    Some(c) => {
                        let w = c.invert(if side == Side::Lower { mirror(d) } else { d });
                        Ok([rule.join_u(side, w[0]), w[1]])
                    }
                    // No light on the other side: no preimage there.
                    None => Err(InvertError::ZeroDensity),
                }
            }
            CoresRef::Lambert(c) => Ok(c.invert(d)),
        }
    }
    fn target_pdf(&self, d: Vec3) -> f64 {
        self.target_value(d) * self.inv_target_total
    }
    fn target_power(&self) -> f64 {
        SphereMap::target_power(self)
    }
    fn memory_bytes(&self) -> usize {
        self.map_cores().map(|c| c.memory_bytes()).sum()
    }
    super::batch::soa_sampler_methods!();
}

super::shared_accessors!(SphereMap);
