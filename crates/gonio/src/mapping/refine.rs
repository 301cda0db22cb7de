//! Refinement to a tolerance: extra parallels until the guaranteed range of pdf / target lies within
//! [1 − tol, 1 + tol] (issue 14; the bound is `mapping::bound`, docs/DERIVATION.md §9).
//!
//! **Why only parallels.** The map's density D is bilinear in (x = √(1 − cos θ), φ); the target B is
//! bilinear in (θ, φ). Both are linear in φ between two meridians at every fixed θ, with the same
//! nodal values, so they differ only along θ. A meridian inserted with values taken from B changes
//! neither D nor B (each stays the same linear function of φ within the old sector), and the bound's
//! extremes lie on the meridians anyway (`bound`, fact 1). So the φ-direction never needs
//! refinement: the number of meridians added is always 0, reported as such.
//!
//! **What a new parallel holds.** A parallel inserted at θ inside the input segment [θ_j, θ_{j+1}]
//! takes, on every meridian, the target's own value (1 − t)·p_{i,j} + t·p_{i,j+1},
//! t = (θ − θ_j)/(θ_{j+1} − θ_j), always computed from the input's two rows (no accumulation). B is
//! therefore unchanged (to round-off), every input node keeps its value exactly, and a segment that
//! is zero on a meridian stays zero there. D moves towards B: on a sub-segment of width h the ratio
//! D/B − 1 = (s − t)(b − a)/B is bounded by a multiple of h (below).
//!
//! **The algorithm.** Every input segment is cut into sub-segments; each carries its guaranteed
//! (min, max) of D/B (`segment_ratio_range`) and its contributions to ∫D dω and ∫B dω. The
//! normalised bound is that range divided by the mean m = ∫D dω / ∫B dω (pdf = D/∫D, target = B/∫B).
//! Each round splits, at its θ midpoint, every sub-segment whose range divided by the current m is
//! not within [1 − tol, 1 + tol], then recomputes m. The refinement is adaptive: cells already within
//! the tolerance are never touched.
//!
//! **Convergence, and where it fails.** On a sub-segment of width h starting at θ_a the worst ratio
//! (at a zero of the target, ρ = b/a = ∞) is x′(θ_a)·h/(x(θ_a + h) − x(θ_a)) ≈ 1 + h·tan(θ_a/2)/4, and
//! at a zero at its end the least is x′(θ_b)·h/Δx ≈ 1 − h·tan(θ_b/2)/4; for finite ρ the deviation is
//! smaller still. So a target that goes linearly to zero is boundable: near such a zero the cells
//! need width h ≲ 4·tol / tan(θ/2), i.e. about 2.3° at 90° for tol = 1 %, and refinement ends in
//! finitely many steps, on the hemisphere and on both halves of the split sphere, whatever the
//! values. The exception is a zero of the target at θ = π on the whole-sphere Lambert layout:
//! x′(π) = 0, so in the last cell D/B = (1 − s)/(1 − t) → 0 as θ → π, in every cell however narrow.
//! There the guaranteed minimum is 0 and no refinement helps ([`RefineStop::FarPoleZero`]; the split
//! layout has no such point). A cell narrower than [`RefineLimits::min_width`], or a grid that
//! would exceed [`RefineLimits::max_parallels`], also stops the refinement; the map is still built,
//! exact and bijective, and [`Refinement::reached`] says that the tolerance was not reached, with the
//! bound that was.

use super::bound::{segment_ratio_range, MARGIN};
use super::hds::parallel_radii;
use super::lift::parallel_radius;
use super::radial::segment_mass;
use crate::diagram::{cell_weights, Diagram};
use std::f64::consts::PI;

/// Limits that guard refinement against runaway growth. When one is hit, the map is built with the
/// parallels added so far and [`Refinement::reached`] is false.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct RefineLimits {
    /// Largest number of parallels of one refined map (input parallels included). Default 4096.
    pub max_parallels: usize,
    /// Narrowest sub-segment that is still split, in radians. Default 1e-6 rad (0.2 arc seconds),
    /// far below any tolerance ≥ 1e-6 needs away from the Lambert far pole.
    pub min_width: f64,
}

impl RefineLimits {
    /// These limits with [`RefineLimits::max_parallels`] set to `n`.
    pub fn with_max_parallels(mut self, n: usize) -> Self {
        self.max_parallels = n;
        self
    }

    /// These limits with [`RefineLimits::min_width`] set to `radians`.
    pub fn with_min_width(mut self, radians: f64) -> Self {
        self.min_width = radians;
        self
    }
}

impl Default for RefineLimits {
    fn default() -> Self {
        RefineLimits {
            max_parallels: 4096,
            min_width: 1e-6,
        }
    }
}

/// Why refinement stopped before the tolerance was reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RefineStop {
    /// Splitting further would exceed [`RefineLimits::max_parallels`].
    MaxParallels,
    /// A sub-segment outside the tolerance is narrower than [`RefineLimits::min_width`].
    MinWidth,
    /// The target vanishes at θ = π on the whole-sphere Lambert layout, where the map's density
    /// falls to zero faster than the target's in every cell (see the module documentation).
    FarPoleZero,
}

impl std::fmt::Display for RefineStop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RefineStop::MaxParallels => "the limit on parallels was reached",
            RefineStop::MinWidth => "a cell reached the smallest width",
            RefineStop::FarPoleZero => {
                "the target is zero at θ = 180° on the Lambert layout (use the split layout)"
            }
        })
    }
}

/// What refinement to a tolerance asked, reached and cost. Returned by the maps' `refinement()`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Refinement {
    /// The tolerance asked: pdf / target within [1 − tol, 1 + tol] wherever the target is positive.
    pub tolerance: f64,
    /// The guaranteed (min, max) of pdf / target reached (the map's `ratio_bound`).
    pub bound: (f64, f64),
    /// Whether `bound` lies within [1 − tolerance, 1 + tolerance].
    pub reached: bool,
    /// Why refinement stopped early (`None` when the tolerance was reached).
    pub stop: Option<RefineStop>,
    /// Parallels of the completed diagram(s) before refinement (summed over the two maps of a split
    /// sphere).
    pub parallels_before: usize,
    /// Parallels after refinement.
    pub parallels_after: usize,
    /// Meridians added: always 0 (see the module documentation).
    pub meridians_added: usize,
    /// Bytes of the map's tables before refinement (`Sampler::memory_bytes` of the unrefined map).
    pub memory_before: usize,
    /// Bytes of the map's tables after refinement.
    pub memory_after: usize,
    /// Wall-clock seconds of the whole build, refinement included.
    pub build_seconds: f64,
}

impl Refinement {
    /// Parallels added by refinement.
    pub fn parallels_added(&self) -> usize {
        self.parallels_after - self.parallels_before
    }

    /// A warning for the user when the tolerance was not reached (what was asked, what was reached,
    /// why), `None` when it was.
    pub fn warning(&self) -> Option<String> {
        if self.reached {
            return None;
        }
        Some(format!(
            "tolerance {} not reached: pdf/target is guaranteed within [{:.6}, {:.6}] only ({}; {} parallels)",
            self.tolerance,
            self.bound.0,
            self.bound.1,
            self.stop
                .map_or_else(|| "round-off".to_string(), |s| s.to_string()),
            self.parallels_after
        ))
    }
}

/// The one rule for a tolerance asked by a caller, wherever it is asked
/// ([`crate::BuildOptions::tolerance`], [`crate::HemisphereMap::with_tolerance`],
/// [`crate::SphereMap::with_tolerance`] and `with_refinement`, the CLI's `--tolerance`, the
/// bindings): a number in the open interval (0, 1). A tolerance is a relative accuracy, the
/// guaranteed pdf / target lying within [1 − tol, 1 + tol]; at tol ≥ 1 the lower end is ≤ 0 and
/// bounds nothing. 0, negative numbers, NaN and ±∞ are refused too.
///
/// ```
/// use gonio::mapping::refine::valid_tolerance;
/// assert!(valid_tolerance(0.01) && valid_tolerance(0.999));
/// for t in [0.0, 1.0, 1.5, -0.1, f64::NAN, f64::INFINITY] {
///     assert!(!valid_tolerance(t));
/// }
/// ```
pub fn valid_tolerance(tol: f64) -> bool {
    tol > 0.0 && tol < 1.0
}

/// One sub-segment [θ_a, θ_b] of an input segment.
#[derive(Debug, Clone, Copy)]
struct Sub {
    ta: f64,
    tb: f64,
    /// Guaranteed (min, max) of D/B on it (with the round-off margin).
    range: (f64, f64),
    /// Its part of ∫D dω (= 2 ∫D dA) and of ∫B dω, in diagram units × sr.
    d_power: f64,
    b_power: f64,
    /// Not to be split again (narrower than the limit, or the Lambert far-pole case).
    stuck: Option<RefineStop>,
}

/// One completed diagram being refined: its segments, each a list of sub-segments in θ order.
struct Part<'a> {
    diagram: &'a Diagram,
    /// The disk radii of the input parallels, as the map's tables will have them.
    x: Vec<f64>,
    /// Per-meridian weight (β_{i−1} + β_i)/2 of a radial mass in ∫D dω and of a value in ∫B dω.
    w: Vec<f64>,
    segments: Vec<Vec<Sub>>,
}

impl Part<'_> {
    /// The values of every meridian at θ inside input segment j (input nodes exactly).
    fn row(&self, j: usize, theta: f64) -> impl Iterator<Item = f64> + '_ {
        let th = self.diagram.theta();
        let t = if theta == th[j] {
            0.0
        } else if theta == th[j + 1] {
            1.0
        } else {
            (theta - th[j]) / (th[j + 1] - th[j])
        };
        let d = self.diagram;
        (0..d.n_meridians()).map(move |i| {
            let (a, b) = (d.value(i, j), d.value(i, j + 1));
            if t == 0.0 {
                a
            } else if t == 1.0 {
                b
            } else {
                (1.0 - t) * a + t * b
            }
        })
    }

    fn radius(&self, j: usize, theta: f64) -> f64 {
        let th = self.diagram.theta();
        if theta == th[j] {
            self.x[j]
        } else if theta == th[j + 1] {
            self.x[j + 1]
        } else {
            parallel_radius(theta)
        }
    }

    fn sub(&self, j: usize, ta: f64, tb: f64, limits: &RefineLimits) -> Sub {
        let (xa, xb) = (self.radius(j, ta), self.radius(j, tb));
        let ra: Vec<f64> = self.row(j, ta).collect();
        let rb: Vec<f64> = self.row(j, tb).collect();
        let (lo, hi) =
            segment_ratio_range(ta, tb, xa, xb, ra.iter().copied().zip(rb.iter().copied()));
        let (w0, w1) = cell_weights(ta, tb);
        let (mut d_power, mut b_power) = (0.0, 0.0);
        for (i, w) in self.w.iter().enumerate() {
            d_power += 2.0 * w * segment_mass(xa, xb, ra[i], rb[i]);
            b_power += 2.0 * w * (ra[i] * w0 + rb[i] * w1);
        }
        let far_pole_zero = tb >= PI && ra.iter().zip(&rb).any(|(&a, &b)| a > 0.0 && !(b > 0.0));
        let stuck = if far_pole_zero {
            Some(RefineStop::FarPoleZero)
        } else if tb - ta < 2.0 * limits.min_width {
            Some(RefineStop::MinWidth)
        } else {
            None
        };
        Sub {
            ta,
            tb,
            range: (lo * (1.0 - MARGIN), hi * (1.0 + MARGIN)),
            d_power: 0.5 * d_power,
            b_power: 0.5 * b_power,
            stuck,
        }
    }
}

/// The outcome of [`refine`]: the refined diagrams (one per input), the guaranteed range of D/B of
/// each (the unnormalised bound the maps' tables need), and why refinement stopped early, if it did.
pub(crate) struct Refined {
    pub(crate) diagrams: Vec<Diagram>,
    pub(crate) ranges: Vec<(f64, f64)>,
    pub(crate) stop: Option<RefineStop>,
}

/// Refines the completed diagrams `parts` (the one map of a hemisphere or a Lambert sphere, or the
/// two halves of a split sphere, which share one normalisation) until pdf / target is guaranteed
/// within [1 − tol, 1 + tol] (see the module documentation), or a limit stops it.
pub(crate) fn refine(parts: &[&Diagram], tol: f64, limits: &RefineLimits) -> Refined {
    let mut ps: Vec<Part> = parts
        .iter()
        .map(|d| {
            let m = d.n_meridians();
            let beta = d.sector_widths();
            let w = (0..m)
                .map(|i| 0.5 * (beta[i] + beta[(i + m - 1) % m]))
                .collect();
            Part {
                diagram: d,
                x: parallel_radii(d.theta()),
                w,
                segments: Vec::new(),
            }
        })
        .collect();
    for p in ps.iter_mut() {
        let th = p.diagram.theta();
        let segs = (0..th.len() - 1)
            .map(|j| vec![p.sub(j, th[j], th[j + 1], limits)])
            .collect();
        p.segments = segs;
    }
    // The tolerance is compared with a hair of room for the round-off between these sums and the
    // maps' own (differently ordered) power sums.
    let (lo_ok, hi_ok) = (1.0 - tol * (1.0 - 1e-9), 1.0 + tol * (1.0 - 1e-9));
    let stop;
    loop {
        let (mut dp, mut bp) = (0.0, 0.0);
        for s in ps.iter().flat_map(|p| p.segments.iter().flatten()) {
            dp += s.d_power;
            bp += s.b_power;
        }
        let mean = dp / bp;
        let outside = |s: &Sub| s.range.0 / mean < lo_ok || s.range.1 / mean > hi_ok;
        let mut splits = 0usize;
        let mut stuck = None;
        for s in ps.iter().flat_map(|p| p.segments.iter().flatten()) {
            if outside(s) {
                match s.stuck {
                    None => splits += 1,
                    Some(r) => stuck = stuck.or(Some(r)),
                }
            }
        }
        if splits == 0 {
            stop = stuck;
            break;
        }
        let too_many = ps.iter().any(|p| {
            let n: usize = p.segments.iter().map(|s| s.len()).sum::<usize>() + 1;
            let add: usize = p
                .segments
                .iter()
                .flatten()
                .filter(|s| outside(s) && s.stuck.is_none())
                .count();
            n + add > limits.max_parallels
        });
        if too_many {
            stop = Some(RefineStop::MaxParallels);
            break;
        }
        for p in ps.iter_mut() {
            let mut segments = std::mem::take(&mut p.segments);
            for (j, seg) in segments.iter_mut().enumerate() {
                if !seg.iter().any(|s| outside(s) && s.stuck.is_none()) {
                    continue;
                }
                let mut next = Vec::with_capacity(seg.len() + 4);
                for s in seg.iter() {
                    if outside(s) && s.stuck.is_none() {
                        let mid = 0.5 * (s.ta + s.tb);
                        next.push(p.sub(j, s.ta, mid, limits));
                        next.push(p.sub(j, mid, s.tb, limits));
                    } else {
                        next.push(*s);
                    }
                }
                *seg = next;
            }
            p.segments = segments;
        }
    }
    let mut diagrams = Vec::with_capacity(ps.len());
    let mut ranges = Vec::with_capacity(ps.len());
    for p in &ps {
        let d = p.diagram;
        let mut theta = vec![d.theta()[0]];
        let mut seg_of = Vec::new();
        for (j, seg) in p.segments.iter().enumerate() {
            for s in seg {
                theta.push(s.tb);
                seg_of.push(j);
            }
        }
        let n = theta.len();
        let m = d.n_meridians();
        let mut values = vec![0.0; m * n];
        for k in 0..n {
            // Node k lies at the start of sub-segment k (segment seg_of[k]), or is the last node.
            let (j, t) = if k + 1 < n {
                (seg_of[k], theta[k])
            } else {
                (seg_of[k - 1], theta[k])
            };
            for (i, v) in p.row(j, t).enumerate() {
                values[i * n + k] = v;
            }
        }
        let (mut lo, mut hi) = (1.0f64, 1.0f64);
        for s in p.segments.iter().flatten() {
            lo = lo.min(s.range.0);
            hi = hi.max(s.range.1);
        }
        diagrams.push(
            Diagram::new(theta, d.phi().to_vec(), values)
                .expect("inserting interpolated parallels keeps a valid diagram valid"),
        );
        ranges.push((lo, hi));
    }
    Refined {
        diagrams,
        ranges,
        stop,
    }
}
