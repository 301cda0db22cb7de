//! [`HemisphereMap`]: the HDS mapping of the upper hemisphere (ALGORITHM §1–§7, recommended variant
//! A6).

use super::complete::{complete, FarEnd};
use super::core::HdsCore;
use super::refine::{refine, valid_tolerance, RefineLimits, Refinement};
use crate::diagram::{Diagram, DiagramError};
use crate::sampler::{spherical, Domain, InvertError, Point2, Sample, Sampler, Vec3};
use std::f64::consts::FRAC_PI_2;

/// The Havran–Dmitriev–Seidel map from the unit square onto the upper hemisphere (z ≥ 0), built
/// once from a [`Diagram`], immutable and `Send + Sync`.
///
/// **Density.** The map is exact for the disk density D that interpolates the diagram's values
/// bilinearly in (x = √(1 − cos θ), φ): every sample carries `pdf = D(ω) / (2T)` per steradian,
/// where T = ∫_disk D dA (§7). [`Sampler::pdf`] returns the same number for any direction.
///
/// **Target.** [`Sampler::target_pdf`] is the diagram interpolated bilinearly in (θ, φ) and
/// normalised over the hemisphere. The two agree at every node up to one constant; in between they
/// differ within the guaranteed range [`HemisphereMap::ratio_bound`] computed at build time.
///
/// **Completion** (§10 A15). A diagram whose first parallel lies above the pole gets a pole parallel
/// holding the mean of that parallel over the meridians; one whose last parallel lies below the
/// horizon gets a horizon parallel of zeros; one whose first meridian is not at φ = 0 gets a meridian
/// there, interpolated across the wrap-around sector (which changes neither interpolant). The
/// completed diagram is [`HemisphereMap::diagram`].
///
/// **Seams.** The map is continuous on the whole square. Its inverse is discontinuous only where the
/// B-disk azimuth wraps from 2π to 0 (the half-line v = ½, u > ½ of the square, which maps to φ = 0);
/// a direction there inverts to either side of that seam.
///
/// Cost: O(log M + log N) per sample (O(1) sector lookup for uniform meridians in `pdf`/`invert`).
#[derive(Debug, Clone)]
pub struct HemisphereMap {
    core: HdsCore,
    inv_2t: f64,
    inv_target_total: f64,
    ratio_bound: (f64, f64),
    refinement: Option<Refinement>,
}

impl HemisphereMap {
    /// Builds the map. The diagram must lie within θ ∈ [0°, 90°].
    pub fn new(diagram: &Diagram) -> Result<Self, DiagramError> {
        let completed = complete(diagram, FRAC_PI_2, FarEnd::Zero)?;
        Ok(Self::from_core(HdsCore::build(completed)))
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
            return Err(DiagramError::Domain(format!(
                "the tolerance must be a finite number > 0, got {tolerance}"
            )));
        }
        let start = std::time::Instant::now();
        let completed = complete(diagram, FRAC_PI_2, FarEnd::Zero)?;
        let parallels_before = completed.n_parallels();
        let memory_before = HdsCore::table_bytes(&completed);
        let mut r = refine(&[&completed], tolerance, limits);
        let core = HdsCore::build_with_range(r.diagrams.remove(0), r.ranges[0]);
        let mut map = Self::from_core(core);
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

    /// 1/(2T): the pdf per unit of disk density.
    pub(crate) fn inv_2t(&self) -> f64 {
        self.inv_2t
    }

    pub(crate) fn from_core(core: HdsCore) -> Self {
        let inv_2t = 0.5 / core.total();
        let (lo, hi) = core.db_range();
        let scale = core.target_total() * inv_2t;
        HemisphereMap {
            inv_target_total: 1.0 / core.target_total(),
            ratio_bound: (lo * scale, hi * scale),
            inv_2t,
            core,
            refinement: None,
        }
    }

    /// What refinement to a tolerance asked, reached and cost; `None` for a map built without a
    /// tolerance ([`HemisphereMap::new`]).
    pub fn refinement(&self) -> Option<&Refinement> {
        self.refinement.as_ref()
    }

    /// The map's own intensity at `direction`: the disk density D(ω), i.e. `pdf(ω) ·`
    /// [`HemisphereMap::map_power`], in the diagram's units (candela for a diagram in candela).
    ///
    /// It equals the diagram's value at every node of the map's grid (the input's nodes and those
    /// refinement added) and lies within [`HemisphereMap::ratio_bound`] (up to the normalisation
    /// `map_power / target_power`) of the (θ, φ)-interpolated diagram elsewhere. A renderer that
    /// emits this intensity and samples with this map gets the constant weight
    /// `map_intensity / pdf = map_power` for every sample: no variance from the emission at all.
    /// See `docs/MAPPING.md` for when to prefer it to the interpolated diagram.
    pub fn map_intensity(&self, direction: Vec3) -> f64 {
        self.pdf(direction) * self.map_power()
    }

    /// The map's own flux: ∫ [`HemisphereMap::map_intensity`] dω = 2T, in diagram units × sr (lumens
    /// for candela). It differs from [`HemisphereMap::target_power`] by a factor within the bound.
    pub fn map_power(&self) -> f64 {
        1.0 / self.inv_2t
    }

    /// The completed diagram the map was built from (see the type's documentation), with the
    /// parallels refinement added, if any: the grid of the map's tables. Its (θ, φ)-bilinear
    /// interpolant, the target, is the same as the input's.
    pub fn diagram(&self) -> &Diagram {
        self.core.diagram()
    }

    /// Guaranteed (min, max) of `pdf / target_pdf` over every direction where the target is positive,
    /// computed at build time (see `mapping::bound`): a true bound, tight to about 1e-10.
    pub fn ratio_bound(&self) -> (f64, f64) {
        self.ratio_bound
    }

    /// T = ∫_disk D dA: the total power of the disk density, in diagram units × (disk area).
    pub fn disk_power(&self) -> f64 {
        self.core.total()
    }

    /// ∫ over the hemisphere of the diagram interpolated bilinearly in (θ, φ), in diagram units × sr
    /// (lumens for a diagram in candela).
    pub fn target_power(&self) -> f64 {
        self.core.target_total()
    }

    /// The intermediate points of the forward map at `u` (see [`super::Stages`]).
    pub fn stages(&self, u: Point2) -> super::Stages {
        self.core.stages(u)
    }

    /// The slide's count of additional precomputed floats, M·N + 2M + 2 (§4, A10), for this grid.
    pub fn paper_table_floats(&self) -> usize {
        let d = self.diagram();
        d.n_meridians() * d.n_parallels() + 2 * d.n_meridians() + 2
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
        Ok(self.core.invert(direction))
    }
    fn target_pdf(&self, direction: Vec3) -> f64 {
        if !(direction[2] >= 0.0) {
            return 0.0;
        }
        let (t, p) = spherical(direction);
        self.core.diagram().interpolate(t, p) * self.inv_target_total
    }
    fn target_power(&self) -> f64 {
        HemisphereMap::target_power(self)
    }
    fn ratio_bound(&self) -> Option<(f64, f64)> {
        Some(HemisphereMap::ratio_bound(self))
    }
    fn refinement(&self) -> Option<&Refinement> {
        HemisphereMap::refinement(self)
    }
    fn stages(&self, u: Point2) -> Option<super::Stages> {
        Some(HemisphereMap::stages(self, u))
    }
    fn memory_bytes(&self) -> usize {
        self.core.memory_bytes()
    }
    fn sample_batch(&self, u: &[Point2], out: &mut [Sample]) {
        super::batch::sample_batch_aos(self, u, out)
    }
    fn pdf_batch(&self, dirs: &[Vec3], out: &mut [f64]) {
        super::batch::pdf_batch_aos(self, dirs, out)
    }
    fn invert_batch(&self, dirs: &[Vec3], out: &mut [Result<Point2, InvertError>]) {
        super::batch::invert_batch_aos(self, dirs, out)
    }
}
