//! [`HemisphereMap`]: the HDS mapping of the upper hemisphere (ALGORITHM §1–§7, recommended variant
//! A6).

use super::complete::{complete, FarEnd};
use super::core::HdsCore;
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
}

impl HemisphereMap {
    /// Builds the map. The diagram must lie within θ ∈ [0°, 90°].
    pub fn new(diagram: &Diagram) -> Result<Self, DiagramError> {
        let completed = complete(diagram, FRAC_PI_2, FarEnd::Zero)?;
        Ok(Self::from_core(HdsCore::build(completed)))
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
        }
    }

    /// The completed diagram the map was built from (see the type's documentation).
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
    fn stages(&self, u: Point2) -> Option<super::Stages> {
        Some(HemisphereMap::stages(self, u))
    }
    fn memory_bytes(&self) -> usize {
        self.core.memory_bytes()
    }
}
