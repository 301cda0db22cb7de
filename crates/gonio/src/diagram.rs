//! The goniometric diagram: non-negative values on a latitude–longitude grid of directions.
//!
//! Frame (docs/DERIVATION.md §1): θ is the polar angle measured from +z, φ the azimuth measured
//! from +x toward +y, so the direction of (θ, φ) is `(sin θ cos φ, sin θ sin φ, cos θ)`. Angles are
//! stored in **radians**; the JSON format and [`Diagram::from_degrees`] speak degrees.
//!
//! * Parallels θ_j, j = 0..N−1: strictly increasing, within [0, π]. A hemisphere diagram lies in
//!   [0, π/2]; photometric files converted by [`crate::photometry`] may cover the whole sphere.
//! * Meridians φ_i, i = 0..M−1: strictly increasing, within [0, 2π); non-uniform spacing allowed;
//!   M = 1 means rotationally symmetric. The last meridian wraps around to the first one.
//! * Values p_{i,j} ≥ 0, finite, in any scale (candela, relative intensity, pdf…). Stored
//!   row-major: `values[i * N + j]` is the value on meridian i at parallel j.
//!
//! **Pole values.** Meridians may disagree at θ = 0 (or θ = π): the values are kept as given, so the
//! interpolated density is direction-dependent in an arbitrarily small neighbourhood of the pole and
//! takes the value of meridian 0 exactly at the pole (where φ = atan2(0, 0) = 0). The pole is a single
//! direction of measure zero, so no probability is changed by this, and no measured value is altered.
//! See docs/DERIVATION.md §8.1, A12.

use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Largest number of grid nodes (M·N) a diagram may hold: 2²⁸ ≈ 268 million values (2 GiB of f64).
///
/// A 0.1° × 0.1° full-sphere grid has 6.5 million nodes; the largest diagrams are those of
/// environment maps, one node per pixel: a 16384 × 8192 sky (the largest image
/// [`crate::image::MAX_PIXELS`] admits by default) has 16384 × 8194 nodes. The cap exists so that no
/// input can make the library allocate without bound; every reader also checks its counts against
/// the bytes present.
pub const MAX_NODES: usize = 1 << 28;

/// Angles within this many **degrees** of 0°, 90° or 180° (θ), or of 0° and 360° (φ), *are* those
/// angles: [`Diagram::new`] and every reader snap them there before any domain or range is decided,
/// so that `90.00000000000001` (a cumulative sum, a radians → degrees round trip) or an IES
/// `90.0000001` ends a hemisphere diagram exactly at the horizon. Values are never changed by the
/// snap; an angle moves by at most this much. A θ is snapped only when it stays strictly between
/// its neighbours (otherwise it is kept as given).
pub const ANGLE_TOLERANCE_DEG: f64 = 1e-6;

/// Why a diagram was refused. Indices are zero-based: `meridian` i indexes φ, `parallel` j indexes θ.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DiagramError {
    /// No parallels or no meridians were given.
    #[error("the diagram needs at least one parallel (θ) and one meridian (φ); got {parallels} parallels and {meridians} meridians")]
    Empty {
        /// Number of parallels given.
        parallels: usize,
        /// Number of meridians given.
        meridians: usize,
    },
    /// M·N exceeds [`MAX_NODES`] (or overflows).
    #[error("the diagram has {meridians} × {parallels} nodes, more than the limit of {MAX_NODES}")]
    TooLarge {
        /// Number of parallels given.
        parallels: usize,
        /// Number of meridians given.
        meridians: usize,
    },
    /// An angle is NaN or infinite.
    #[error("{axis} angle #{index} is not finite ({value})")]
    NonFiniteAngle {
        /// `"theta"` or `"phi"`.
        axis: &'static str,
        /// Index of the angle.
        index: usize,
        /// The offending value, in the unit it was given.
        value: f64,
    },
    /// An angle lies outside its range (θ in [0°, 180°], φ in [0°, 360°)).
    #[error("{axis} angle #{index} = {}° is outside {range}", crate::decimal::shortest(*value_deg))]
    AngleOutOfRange {
        /// `"theta"` or `"phi"`.
        axis: &'static str,
        /// Index of the angle.
        index: usize,
        /// The angle in degrees.
        value_deg: f64,
        /// The allowed range, in words.
        range: &'static str,
    },
    /// Angles are not strictly increasing (unsorted or duplicated).
    #[error(
        "{axis} angles must be strictly increasing (also in radians, as stored), but #{index} = {}° follows {}°",
        crate::decimal::shortest(*value_deg),
        crate::decimal::shortest(*previous_deg)
    )]
    NotIncreasing {
        /// `"theta"` or `"phi"`.
        axis: &'static str,
        /// Index of the angle that is not larger than its predecessor.
        index: usize,
        /// That angle, in degrees.
        value_deg: f64,
        /// Its predecessor, in degrees.
        previous_deg: f64,
    },
    /// The value table does not have M rows of N values.
    #[error("values: expected {expected} entries in {what}, found {found}")]
    Shape {
        /// What was counted, e.g. `"values"` or `"values[3]"`.
        what: String,
        /// The expected count.
        expected: usize,
        /// The count found.
        found: usize,
    },
    /// A value is NaN, infinite or negative.
    #[error(
        "values[{meridian}][{parallel}] = {} is not a finite non-negative number",
        crate::decimal::shortest(*value)
    )]
    BadValue {
        /// Meridian index i.
        meridian: usize,
        /// Parallel index j.
        parallel: usize,
        /// The offending value.
        value: f64,
    },
    /// The diagram carries no light in its measured range: every value is 0.
    #[error("the diagram carries no light in its measured range: every value is 0")]
    ZeroPower,
    /// The diagram reaches beyond the polar range the map covers (e.g. past θ = 90° for a
    /// hemisphere map).
    #[error("the diagram reaches θ = {theta_deg}°, beyond the {limit_deg}° this map covers")]
    BeyondDomain {
        /// The diagram's last parallel, in degrees.
        theta_deg: f64,
        /// The largest θ the map covers, in degrees.
        limit_deg: f64,
    },
    /// A map was asked for a tolerance that is not a number in (0, 1)
    /// ([`crate::mapping::refine::valid_tolerance`]).
    #[error("the tolerance must be a number in (0, 1), got {}", crate::decimal::shortest(*tolerance))]
    BadTolerance {
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// The Lambert sphere layout was asked for a diagram that lies on one side of the horizon.
    #[error("the Lambert sphere layout needs a diagram that spans the horizon")]
    NotSpanningHorizon,
    /// The diagram has a single parallel: a line of directions of zero solid angle carries no power,
    /// and there is no range of θ to sample.
    #[error("the diagram has a single parallel (θ = {theta_deg}°): it covers no solid angle, so it carries no light to sample; give at least two parallels")]
    SingleParallel {
        /// The parallel, in degrees.
        theta_deg: f64,
    },
    /// The last meridian lies at 360° (within [`ANGLE_TOLERANCE_DEG`]), the same meridian as the
    /// first one at 0°, but holds different values.
    #[error("phi angle #{index} = {value_deg}° is the meridian φ = 0° again (360°), but its values differ from those of φ = 0°")]
    ClosingMeridian {
        /// Index of the meridian at 360°.
        index: usize,
        /// The angle as given, in degrees.
        value_deg: f64,
    },
    /// The diagram's light lies in cells thinner than double precision resolves on the map's disk
    /// (e.g. between θ = 89.99999999999999° and 90°): no map can place it.
    #[error("the diagram's light lies only in cells too thin for double precision to resolve (parallels closer than about 1e-15 rad); nothing can be sampled")]
    UnresolvedLight,
}

/// A validated goniometric diagram. See the [module documentation](self) for the frame and layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagram {
    theta: Vec<f64>,
    phi: Vec<f64>,
    values: Vec<f64>,
    /// The largest value, found by `new` in its validation pass (the values never change after).
    max: f64,
}

/// The native JSON form: `{"theta_deg": [...], "phi_deg": [...], "values": [[...], ...]}`, where
/// `values[i][j]` is the value at (`phi_deg[i]`, `theta_deg[j]`). Unknown keys are refused.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiagramJson {
    /// Parallels θ_j in degrees from +z, strictly increasing.
    pub theta_deg: Vec<f64>,
    /// Meridians φ_i in degrees from +x toward +y, strictly increasing in [0, 360).
    pub phi_deg: Vec<f64>,
    /// `values[i][j]`: the value on meridian i at parallel j.
    pub values: Vec<Vec<f64>>,
}

fn check_axis(
    axis: &'static str,
    angles: &[f64],
    max: f64,
    max_inclusive: bool,
    range: &'static str,
) -> Result<(), DiagramError> {
    for (index, &a) in angles.iter().enumerate() {
        if !a.is_finite() {
            return Err(DiagramError::NonFiniteAngle {
                axis,
                index,
                value: a,
            });
        }
        let above = if max_inclusive { a > max } else { a >= max };
        if a < 0.0 || above {
            return Err(DiagramError::AngleOutOfRange {
                axis,
                index,
                value_deg: a.to_degrees(),
                range,
            });
        }
        if index > 0 && a <= angles[index - 1] {
            return Err(DiagramError::NotIncreasing {
                axis,
                index,
                value_deg: a.to_degrees(),
                previous_deg: angles[index - 1].to_degrees(),
            });
        }
    }
    Ok(())
}

impl Diagram {
    /// Builds a diagram from angles in **radians** and a row-major value table
    /// (`values[i * theta.len() + j]` on meridian i, parallel j).
    ///
    /// θ must be strictly increasing in [0, π], φ strictly increasing in [0, 2π), values finite
    /// and ≥ 0, not all zero.
    ///
    /// Angles within [`ANGLE_TOLERANCE_DEG`] of 0, π/2 and π (θ) or 0 and 2π (φ) are those angles
    /// (see there); a last meridian at 2π is the first one again: dropped when φ_0 = 0 and its values
    /// are the same (refused with [`DiagramError::ClosingMeridian`] when they differ), moved to φ = 0
    /// otherwise. A single parallel is refused ([`DiagramError::SingleParallel`]).
    pub fn new(
        mut theta: Vec<f64>,
        mut phi: Vec<f64>,
        mut values: Vec<f64>,
    ) -> Result<Self, DiagramError> {
        let (n, m) = (theta.len(), phi.len());
        if n == 0 || m == 0 {
            return Err(DiagramError::Empty {
                parallels: n,
                meridians: m,
            });
        }
        match n.checked_mul(m) {
            Some(c) if c <= MAX_NODES => {}
            _ => {
                return Err(DiagramError::TooLarge {
                    parallels: n,
                    meridians: m,
                })
            }
        }
        if values.len() != n * m {
            return Err(DiagramError::Shape {
                what: "values".into(),
                expected: n * m,
                found: values.len(),
            });
        }
        snap_theta(&mut theta);
        snap_phi(&mut phi, &mut values, n)?;
        check_axis("theta", &theta, PI, true, "[0°, 180°]")?;
        check_axis("phi", &phi, TAU, false, "[0°, 360°)")?;
        if n == 1 {
            return Err(DiagramError::SingleParallel {
                theta_deg: theta[0].to_degrees(),
            });
        }
        // finite and ≥ 0 ⇔ 0 ≤ v ≤ MAX (NaN fails both): a branch-free count (it vectorises);
        // the first bad value is then located. The same pass keeps four running maxima (a plain
        // comparison is `f64::max` once every value is finite and ≥ 0, and the maximum does not
        // depend on the order).
        let invalid = |v: f64| !(0.0..=f64::MAX).contains(&v);
        let (mut bad, mut lanes) = (0usize, [0.0f64; 4]);
        let mut blocks = values.chunks_exact(4);
        for b in &mut blocks {
            for (l, &v) in lanes.iter_mut().zip(b) {
                bad += usize::from(invalid(v));
                *l = if v > *l { v } else { *l };
            }
        }
        for &v in blocks.remainder() {
            bad += usize::from(invalid(v));
            lanes[0] = if v > lanes[0] { v } else { lanes[0] };
        }
        let max = lanes.iter().fold(0.0f64, |a, &b| a.max(b));
        if bad > 0 {
            let k = values.iter().position(|&v| invalid(v)).unwrap_or(0);
            return Err(DiagramError::BadValue {
                meridian: k / n,
                parallel: k % n,
                value: values[k],
            });
        }
        let Some(first_positive) = values.iter().position(|&v| v > 0.0) else {
            return Err(DiagramError::ZeroPower);
        };
        let d = Self {
            theta,
            phi,
            values,
            max,
        };
        // Light on nodes only between parallels closer than an ulp cannot integrate to anything.
        if !d.positive_integral(first_positive / n, first_positive % n) {
            return Err(DiagramError::UnresolvedLight);
        }
        Ok(d)
    }

    /// Builds a diagram from angles in **degrees** and nested rows, `values[i][j]` at (φ_i, θ_j).
    pub fn from_degrees(
        theta_deg: &[f64],
        phi_deg: &[f64],
        values: &[Vec<f64>],
    ) -> Result<Self, DiagramError> {
        if values.len() != phi_deg.len() {
            return Err(DiagramError::Shape {
                what: "values (one row per phi_deg entry)".into(),
                expected: phi_deg.len(),
                found: values.len(),
            });
        }
        for (i, row) in values.iter().enumerate() {
            if row.len() != theta_deg.len() {
                return Err(DiagramError::Shape {
                    what: format!("values[{i}] (one entry per theta_deg entry)"),
                    expected: theta_deg.len(),
                    found: row.len(),
                });
            }
        }
        // Angles are checked in degrees first so that 360° is refused even if rounding in the
        // conversion would bring it just below 2π.
        let beyond =
            |axis: &'static str, values: &[f64], max: f64, range: &'static str| match values
                .iter()
                .position(|&a| a.is_finite() && a > max + ANGLE_TOLERANCE_DEG)
            {
                Some(index) => Err(DiagramError::AngleOutOfRange {
                    axis,
                    index,
                    value_deg: values[index],
                    range,
                }),
                None => Ok(()),
            };
        beyond("phi", phi_deg, 360.0, "[0°, 360°)")?;
        beyond("theta", theta_deg, 180.0, "[0°, 180°]")?;
        // φ ≈ 360° is 2π (the closing meridian, resolved by `new`).
        // θ is snapped by `new` (which keeps the order strict); 180° + round-off is π.
        // (`min` would turn NaN into π.)
        let theta = theta_deg
            .iter()
            .map(|&t| if deg(t) > PI { PI } else { deg(t) })
            .collect();
        let phi = phi_deg
            .iter()
            .map(|&p| {
                let s = snap_deg(p, &[0.0, 360.0]);
                if s == 360.0 {
                    TAU
                } else {
                    deg(s)
                }
            })
            .collect();
        // Messages name the angles as given (5e-324° and 0° differ in degrees but not in
        // radians). `new` moves a lone closing meridian (360°) to the front, shifting φ's indices
        // by one.
        let moved = phi_deg.len() > 1
            && snap_deg(phi_deg[0], &[0.0]) != 0.0
            && snap_deg(phi_deg[phi_deg.len() - 1], &[360.0]) == 360.0;
        Self::new(theta, phi, values.concat()).map_err(|e| match e {
            DiagramError::NotIncreasing { axis, index, .. }
                if index > 0 && !(axis == "phi" && moved) =>
            {
                let given = if axis == "theta" { theta_deg } else { phi_deg };
                DiagramError::NotIncreasing {
                    axis,
                    index,
                    value_deg: given[index],
                    previous_deg: given[index - 1],
                }
            }
            other => other,
        })
    }

    /// Parses the native JSON form (see [`DiagramJson`]).
    pub fn from_json_str(text: &str) -> Result<Self, crate::Error> {
        let j: DiagramJson = serde_json::from_str(text).map_err(|e| crate::Error::Json {
            line: e.line(),
            column: e.column(),
            message: e.to_string(),
        })?;
        Ok(Self::from_degrees(&j.theta_deg, &j.phi_deg, &j.values)?)
    }

    /// The native JSON form (angles in degrees).
    pub fn to_json(&self) -> DiagramJson {
        DiagramJson {
            // The shortest degrees that read back to the stored radians (55, not 54.99…986).
            theta_deg: self
                .theta
                .iter()
                .map(|&t| crate::decimal::degrees(t))
                .collect(),
            phi_deg: self
                .phi
                .iter()
                .map(|&p| crate::decimal::degrees(p))
                .collect(),
            values: self
                .values
                .chunks(self.theta.len())
                .map(<[f64]>::to_vec)
                .collect(),
        }
    }

    /// Parallels θ_j in radians from +z, strictly increasing.
    pub fn theta(&self) -> &[f64] {
        &self.theta
    }
    /// Meridians φ_i in radians from +x toward +y, strictly increasing in [0, 2π).
    pub fn phi(&self) -> &[f64] {
        &self.phi
    }
    /// Row-major values: `values()[i * n_parallels() + j]` on meridian i at parallel j.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
    /// Number of parallels N.
    pub fn n_parallels(&self) -> usize {
        self.theta.len()
    }
    /// Number of meridians M.
    pub fn n_meridians(&self) -> usize {
        self.phi.len()
    }
    /// The value on meridian `i` at parallel `j`.
    pub fn value(&self, i: usize, j: usize) -> f64 {
        self.values[i * self.theta.len() + j]
    }
    /// The largest value.
    pub fn max_value(&self) -> f64 {
        self.max
    }

    /// The diagram interpolated **bilinearly in (θ, φ)** at polar angle `theta` and azimuth `phi`
    /// (radians; φ taken modulo 2π), in the diagram's own units, not normalised.
    ///
    /// Between the last and the first meridian the interpolation wraps around through 2π; with
    /// one meridian the value does not depend on φ. Outside [θ_0, θ_{N−1}] the value is 0 (a
    /// direction the diagram does not cover carries no power).
    pub fn interpolate(&self, theta: f64, phi: f64) -> f64 {
        interpolate_grid(&self.theta, &self.phi, &self.values, theta, phi)
    }

    /// The grid and the values, taken apart (θ, φ, row-major values) without a copy.
    pub(crate) fn into_parts(self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        (self.theta, self.phi, self.values)
    }

    /// Sector widths β_i = φ_{i+1} − φ_i in radians, the last one wrapping to φ_0 + 2π
    /// (one sector of width 2π when M = 1).
    pub fn sector_widths(&self) -> Vec<f64> {
        let m = self.phi.len();
        (0..m)
            .map(|i| {
                if i + 1 < m {
                    self.phi[i + 1] - self.phi[i]
                } else {
                    self.phi[0] + TAU - self.phi[i]
                }
            })
            .collect()
    }

    /// ∫ over the sphere of the diagram interpolated bilinearly in (θ, φ) (see
    /// [`Diagram::interpolate`]), dω in steradians, in closed form. For a diagram in candela this is the
    /// luminous flux in lumens.
    ///
    /// Computed on the values divided by their maximum and scaled back, so it is exact in relative
    /// terms for any scale of values; it is `+inf` only when the power itself exceeds `f64::MAX`
    /// (values near `f64::MAX` over a large solid angle) — use [`Diagram::normalised_integral`] there.
    pub fn integral(&self) -> f64 {
        self.normalised_integral() * self.max_value()
    }

    /// [`Diagram::integral`] of the values divided by [`Diagram::max_value`]: finite and positive for
    /// every valid diagram, whatever the scale of its values (1e-320 … `f64::MAX`).
    pub fn normalised_integral(&self) -> f64 {
        let max = self.max_value();
        let (n, m) = (self.theta.len(), self.phi.len());
        let beta = self.sector_widths();
        // The sum Σ_j Σ_i ½β_i (P_{i,j} w0_j + P_{i,j+1} w1_j), P_{i,j} = v_{i,j}/max + v_{i+1,j}/max
        // (meridians wrapping), in this order: each parallel's pair sums are made once and used by
        // the cells on both sides of it.
        // The scaled values of BLOCK parallels at a time, meridian-major (BLOCK per meridian, read
        // and divided as contiguous runs): a walk along one parallel of `values` reads one cache
        // line per value, N × 8 bytes apart. The same quotients as one parallel at a time.
        const BLOCK: usize = 16;
        let mut block = vec![0.0; BLOCK * m];
        let mut block_start = usize::MAX;
        let mut pairs = |j: usize, out: &mut Vec<f64>| {
            if !(block_start..block_start.saturating_add(BLOCK)).contains(&j) {
                block_start = j;
                let len = BLOCK.min(n - j);
                for (dst, meridian) in block
                    .chunks_exact_mut(BLOCK)
                    .zip(self.values.chunks_exact(n))
                {
                    for (d, v) in dst[..len].iter_mut().zip(&meridian[j..j + len]) {
                        *d = v / max;
                    }
                }
            }
            let o = j - block_start;
            let scaled = |i: usize| block[i * BLOCK + o];
            out.clear();
            out.extend((0..m - 1).map(|i| scaled(i) + scaled(i + 1)));
            out.push(scaled(m - 1) + scaled(0));
        };
        let (mut below, mut above) = (Vec::with_capacity(m), Vec::with_capacity(m));
        if n >= 2 {
            pairs(0, &mut below);
        }
        let mut total = 0.0;
        for j in 0..n.saturating_sub(1) {
            let (w0, w1) = cell_weights(self.theta[j], self.theta[j + 1]);
            pairs(j + 1, &mut above);
            for ((b, a), c) in beta.iter().zip(&below).zip(&above) {
                total += 0.5 * b * (a * w0 + c * w1);
            }
            std::mem::swap(&mut below, &mut above);
        }
        total
    }

    /// Whether [`Diagram::normalised_integral`] is > 0, usually without the whole sum: when no
    /// cell weight is negative every term of the sum is ≥ 0, and then one positive term of a
    /// cell next to the positive node (`i`, `j`) makes the sum positive (a floating-point sum of
    /// terms ≥ 0 is at least its largest term). Otherwise the sum itself decides.
    fn positive_integral(&self, i: usize, j: usize) -> bool {
        let (n, m) = (self.theta.len(), self.phi.len());
        let weights: Vec<(f64, f64)> = (0..n - 1)
            .map(|k| cell_weights(self.theta[k], self.theta[k + 1]))
            .collect();
        if weights.iter().all(|&(w0, w1)| w0 >= 0.0 && w1 >= 0.0) {
            let max = self.max_value();
            let beta = self.sector_widths();
            // The term of the cell between meridians k, k + 1 and parallels l, l + 1, computed as
            // in `normalised_integral`.
            let term = |k: usize, l: usize| {
                let k1 = if k + 1 == m { 0 } else { k + 1 };
                let a = self.value(k, l) / max + self.value(k1, l) / max;
                let c = self.value(k, l + 1) / max + self.value(k1, l + 1) / max;
                let (w0, w1) = weights[l];
                0.5 * beta[k] * (a * w0 + c * w1)
            };
            let sectors = [i, if i == 0 { m - 1 } else { i - 1 }];
            let cells = [j.min(n - 2), j.saturating_sub(1)];
            if sectors
                .iter()
                .any(|&k| cells.iter().any(|&l| term(k, l) > 0.0))
            {
                return true;
            }
        }
        self.normalised_integral() > 0.0
    }

    /// The two meridians that bracket azimuth `phi` (radians) and the weight of the second:
    /// `(i0, i1, e)` with value = (1−e)·row(i0) + e·row(i1), wrapping around 2π.
    pub fn meridian_weights(&self, phi: f64) -> (usize, usize, f64) {
        meridian_weights(&self.phi, phi)
    }
}

/// [`Diagram::meridian_weights`] on the meridians `phis` of a valid diagram.
fn meridian_weights(phis: &[f64], phi: f64) -> (usize, usize, f64) {
    let m = phis.len();
    let p = phi.rem_euclid(TAU);
    if m == 1 {
        return (0, 0, 0.0);
    }
    let (first, last) = (phis[0], phis[m - 1]);
    if p >= last || p < first {
        // Wrap sector from the last meridian to the first one (+2π).
        let width = first + TAU - last;
        let off = if p >= last { p - last } else { p + TAU - last };
        return (m - 1, 0, (off / width).clamp(0.0, 1.0));
    }
    let i = segment(phis, p);
    let e = (p - phis[i]) / (phis[i + 1] - phis[i]);
    (i, i + 1, e.clamp(0.0, 1.0))
}

/// [`Diagram::interpolate`] on the parts of a valid diagram (`values` row-major, one row of
/// `thetas.len()` values per meridian of `phis`): for the maps that keep the grid and the values
/// apart.
pub(crate) fn interpolate_grid(
    thetas: &[f64],
    phis: &[f64],
    values: &[f64],
    theta: f64,
    phi: f64,
) -> f64 {
    let n = thetas.len();
    let (t0, t1) = (thetas[0], thetas[n - 1]);
    if !(theta >= t0 && theta <= t1) {
        return 0.0;
    }
    let (j, t) = if n == 1 {
        (0, 0.0)
    } else {
        let j = segment(thetas, theta);
        let t = (theta - thetas[j]) / (thetas[j + 1] - thetas[j]);
        (j, t.clamp(0.0, 1.0))
    };
    let (i0, i1, e) = meridian_weights(phis, phi);
    let jn = (j + 1).min(n - 1);
    let value = |i: usize, j: usize| values[i * n + j];
    let row = |i: usize| (1.0 - t) * value(i, j) + t * value(i, jn);
    (1.0 - e) * row(i0) + e * row(i1)
}

/// (∫(1−t) sin θ dθ, ∫ t sin θ dθ) over [a, b] with t = (θ − a)/(b − a): the weights of the two
/// end values of a linear-in-θ profile in the solid-angle integral of one cell.
pub(crate) fn cell_weights(a: f64, b: f64) -> (f64, f64) {
    let h = b - a;
    // (sin b − sin a)/h written without cancellation.
    let mean_cos = 2.0 * (0.5 * (a + b)).cos() * (0.5 * h).sin() / h;
    let w1 = mean_cos - b.cos();
    let w0 = (a.cos() - b.cos()) - w1;
    (w0, w1)
}

/// `a` replaced by the first of `targets` within [`ANGLE_TOLERANCE_DEG`] of it (degrees).
pub(crate) fn snap_deg(a: f64, targets: &[f64]) -> f64 {
    targets
        .iter()
        .copied()
        .find(|t| (a - t).abs() <= ANGLE_TOLERANCE_DEG)
        .unwrap_or(a)
}

/// The tolerance of [`ANGLE_TOLERANCE_DEG`] in radians.
fn tol_rad() -> f64 {
    ANGLE_TOLERANCE_DEG.to_radians()
}

/// Snaps parallels within the tolerance of 0, π/2, π to those angles when the order stays strict.
fn snap_theta(theta: &mut [f64]) {
    let n = theta.len();
    for j in 0..n {
        let t = theta[j];
        let Some(&s) = [0.0, FRAC_PI_2, PI]
            .iter()
            .find(|&&s| (t - s).abs() <= tol_rad())
        else {
            continue;
        };
        let after_prev = j == 0 || theta[j - 1] < s;
        let before_next = j + 1 == n || s < theta[j + 1];
        if after_prev && before_next {
            theta[j] = s;
        }
    }
}

/// Snaps meridians within the tolerance of 0 to 0, and resolves a last meridian within the
/// tolerance of 2π (it is φ = 0 again): dropped when it repeats meridian 0 at φ = 0 exactly,
/// refused when its values differ there, moved to the front at φ = 0 when there is no meridian at 0.
fn snap_phi(phi: &mut Vec<f64>, values: &mut Vec<f64>, n: usize) -> Result<(), DiagramError> {
    let m = phi.len();
    if phi[0].abs() <= tol_rad() {
        phi[0] = 0.0;
    }
    let last = phi[m - 1];
    if !((last - TAU).abs() <= tol_rad()) {
        return Ok(());
    }
    if m == 1 {
        phi[0] = 0.0;
        return Ok(());
    }
    if phi[0] == 0.0 {
        if values[..n] == values[(m - 1) * n..] {
            phi.pop();
            values.truncate((m - 1) * n);
            return Ok(());
        }
        return Err(DiagramError::ClosingMeridian {
            index: m - 1,
            value_deg: last.to_degrees(),
        });
    }
    phi.pop();
    phi.insert(0, 0.0);
    let row: Vec<f64> = values.drain((m - 1) * n..).collect();
    values.splice(0..0, row);
    Ok(())
}

/// Degrees to radians.
fn deg(d: f64) -> f64 {
    d.to_radians()
}

/// Index k of the segment [a_k, a_{k+1}] that holds `x`, for strictly increasing `a` with at least two
/// entries: the largest k ≤ len−2 with a_k ≤ x (k = 0 when x < a_0).
pub(crate) fn segment<T: Copy + PartialOrd>(a: &[T], x: T) -> usize {
    let k = a.partition_point(|&v| v <= x);
    k.saturating_sub(1).min(a.len() - 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn simple() -> Diagram {
        Diagram::from_degrees(
            &[0.0, 45.0, 90.0],
            &[0.0, 90.0, 180.0, 270.0],
            &[
                vec![1.0, 2.0, 3.0],
                vec![1.0, 4.0, 0.0],
                vec![1.0, 2.0, 3.0],
                vec![1.0, 0.0, 0.0],
            ],
        )
        .unwrap()
    }

    #[test]
    fn interpolation_hits_nodes_and_wraps() {
        let d = simple();
        for i in 0..4 {
            for j in 0..3 {
                let v = d.interpolate(d.theta()[j], d.phi()[i]);
                assert!((v - d.value(i, j)).abs() < 1e-12, "node ({i},{j})");
            }
        }
        // halfway between meridian 3 (270°) and meridian 0 (360°) at θ = 45°: (0 + 2)/2
        let v = d.interpolate(45f64.to_radians(), 315f64.to_radians());
        assert!((v - 1.0).abs() < 1e-12);
        // outside the θ range
        let h = Diagram::from_degrees(&[10.0, 20.0], &[0.0], &[vec![1.0, 1.0]]).unwrap();
        assert_eq!(h.interpolate(5f64.to_radians(), 0.0), 0.0);
    }

    #[test]
    fn integral_of_constant_is_solid_angle() {
        let d = Diagram::from_degrees(
            &[0.0, 30.0, 90.0],
            &[0.0, 10.0, 200.0],
            &vec![vec![2.0; 3]; 3],
        )
        .unwrap();
        let want = 2.0 * 2.0 * PI;
        assert!((d.integral() - want).abs() < 1e-12 * want);
        // cos θ on the upper hemisphere, sampled finely: ∫ cos θ dω = π
        let t: Vec<f64> = (0..=900).map(|k| k as f64 * 0.1).collect();
        let row: Vec<f64> = t.iter().map(|x| x.to_radians().cos()).collect();
        let d = Diagram::from_degrees(&t, &[0.0], &[row]).unwrap();
        assert!((d.integral() - PI).abs() < 1e-5);
    }

    #[test]
    fn refuses_bad_input() {
        let r = |t: &[f64], p: &[f64], v: &[Vec<f64>]| Diagram::from_degrees(t, p, v).unwrap_err();
        assert!(matches!(
            r(&[0.0, 0.0], &[0.0], &[vec![1.0, 1.0]]),
            DiagramError::NotIncreasing { .. }
        ));
        assert!(matches!(
            r(&[0.0, 90.0], &[360.001], &[vec![1.0, 1.0]]),
            DiagramError::AngleOutOfRange { .. }
        ));
        // 360° is φ = 0 again: a differing closing meridian is refused, an equal one dropped, a
        // lone one moved to the front.
        assert!(matches!(
            r(
                &[0.0, 90.0],
                &[0.0, 360.0],
                &[vec![1.0, 1.0], vec![2.0, 1.0]]
            ),
            DiagramError::ClosingMeridian { index: 1, .. }
        ));
        let d = Diagram::from_degrees(
            &[0.0, 90.0],
            &[0.0, 180.0, 359.9999999999],
            &[vec![1.0, 1.0], vec![2.0, 2.0], vec![1.0, 1.0]],
        )
        .unwrap();
        assert_eq!(d.n_meridians(), 2);
        let d = Diagram::from_degrees(
            &[0.0, 90.0],
            &[90.0, 360.0000000001],
            &[vec![1.0, 1.0], vec![2.0, 2.0]],
        )
        .unwrap();
        assert_eq!(d.phi(), &[0.0, FRAC_PI_2]);
        assert_eq!(d.values(), &[2.0, 2.0, 1.0, 1.0]);
        // θ within the tolerance of 0°, 90°, 180° is there, when the order allows
        let d = Diagram::from_degrees(
            &[1e-9, 90.00000000000001, 179.9999999],
            &[0.0],
            &[vec![1.0; 3]],
        )
        .unwrap();
        assert_eq!(d.theta(), &[0.0, FRAC_PI_2, PI]);
        assert!(matches!(
            r(&[45.0], &[0.0], &[vec![1.0]]),
            DiagramError::SingleParallel { .. }
        ));
        assert!(matches!(
            r(&[0.0, 90.0], &[0.0], &[vec![1.0, -1.0]]),
            DiagramError::BadValue { .. }
        ));
        assert!(matches!(
            r(&[0.0, 90.0], &[0.0], &[vec![0.0, 0.0]]),
            DiagramError::ZeroPower
        ));
        assert!(matches!(
            r(&[0.0, 90.0], &[0.0], &[vec![1.0]]),
            DiagramError::Shape { .. }
        ));
        assert!(matches!(
            r(&[0.0, f64::NAN], &[0.0], &[vec![1.0, 1.0]]),
            DiagramError::NonFiniteAngle { .. }
        ));
        assert!(matches!(
            r(&[], &[0.0], &[vec![]]),
            DiagramError::Empty { .. }
        ));
    }

    #[test]
    fn json_round_trip_and_unknown_keys() {
        let d = simple();
        let text = serde_json::to_string(&d.to_json()).unwrap();
        let back = Diagram::from_json_str(&text).unwrap();
        assert_eq!(back.n_meridians(), 4);
        for (a, b) in back.values().iter().zip(d.values()) {
            assert_eq!(a, b);
        }
        let bad = r#"{"theta_deg":[0,90],"phi_deg":[0],"values":[[1,1]],"extra":1}"#;
        assert!(matches!(
            Diagram::from_json_str(bad),
            Err(crate::Error::Json { .. })
        ));
    }
}
