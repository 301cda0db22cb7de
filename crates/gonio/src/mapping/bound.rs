//! The guaranteed range of the map's density over the target density ("guaranteed distance",
//! docs/DERIVATION.md §9), computed at build time.
//!
//! Both densities interpolate the same nodal values: the map's D is bilinear in (x, φ) with
//! x = √(1 − cos θ), the target B is bilinear in (θ, φ). In a cell between parallels j, j+1 and at
//! sector fraction ε, with a = a(ε), b = b(ε) the values interpolated along the two parallels,
//!
//! ```text
//! D/B = (a + s(θ)(b − a)) / (a + t(θ)(b − a)),   s = (x(θ) − x_j)/(x_{j+1} − x_j),  t = (θ − θ_j)/(θ_{j+1} − θ_j).
//! ```
//!
//! Three facts make the bound exact and cheap:
//! 1. For fixed θ, D/B is a monotone (Möbius) function of ρ = b/a, and ρ(ε) is monotone in ε, so
//!    the extremes over a sector lie on its two meridians: only the M·(N−1) meridian edges matter.
//! 2. x(θ) = √2 sin(θ/2) is concave, so s ≥ t: D/B ≥ 1 where the profile rises (ρ > 1) and ≤ 1
//!    where it falls; and sup_θ D/B grows with ρ. Per parallel segment only the largest and the smallest
//!    ρ among the meridians need to be examined; ρ = ∞ (a = 0) and ρ = 0 (b = 0) have closed-form limits
//!    x′(θ_j)·Δθ/Δx and x′(θ_{j+1})·Δθ/Δx (secant slopes of a concave function).
//! 3. For finite ρ the sup over θ is found by branch and bound: s, t, s′ = x′/Δx and t′ are monotone
//!    on any sub-interval [θ_a, θ_b], which bounds |∂(D/B)/∂θ| there by interval arithmetic, and the
//!    mean value theorem gives D/B ≤ (D/B)(mid) + max|∂(D/B)/∂θ|·(θ_b − θ_a)/2. The search refines
//!    until this bound is within 1e-10 of the best value seen (or a budget of 20,000 evaluations per
//!    segment is spent, which leaves a looser but still valid bound), and returns the bound itself,
//!    capped by the closed-form limits of fact 2, which hold for every ρ and are the tight ones when
//!    ρ is extreme (a cosine lobe falling from 1 to 1e-20 within one cell: the branch and bound would
//!    need ~log2 ρ levels there).
//!
//! The result is therefore an upper (lower) bound, not a sampled estimate, and tight to ~1e-10.
//! A relative margin of 1e-12 covers round-off in evaluating s and t.

use super::lift::parallel_radius;
use crate::diagram::Diagram;
use std::f64::consts::FRAC_1_SQRT_2;

const TOL: f64 = 1e-10;
pub(crate) const MARGIN: f64 = 1e-12;

/// Largest value of `f` on [a, b], given `slope(lo, hi)` ≥ |f′| on [lo, hi]. On an interval of
/// width w, f ≤ f(mid) + slope·w/2 (mean value theorem); intervals are split until that bound is
/// within a relative `TOL` of the best value seen, or an evaluation budget runs out. Either way the
/// returned number is an upper bound of the supremum.
///
/// `f` and `slope` read the point values that `at` computes (θ and what depends on it alone, the
/// trigonometry of s and s′): each point is evaluated once and handed to both halves of an
/// interval, instead of once by `f` and again by every `slope` that has it as an end.
fn supremum<P: Copy>(
    at: impl Fn(f64) -> P,
    f: impl Fn(&P) -> f64,
    slope: impl Fn(&P, &P) -> f64,
    a: f64,
    b: f64,
) -> f64 {
    let (pa, pb) = (at(a), at(b));
    let mut best = f(&pa).max(f(&pb));
    let mut bound = best;
    let mut stack = vec![(a, b, pa, pb)];
    let mut budget = 20_000u32;
    while let Some((lo, hi, plo, phi)) = stack.pop() {
        let mid = 0.5 * (lo + hi);
        let pm = at(mid);
        let fm = f(&pm);
        best = best.max(fm);
        let u = fm + slope(&plo, &phi) * 0.5 * (hi - lo);
        budget = budget.saturating_sub(1);
        if u <= best * (1.0 + TOL) || budget == 0 || hi - lo <= 1e-14 * hi.abs().max(1.0) {
            bound = bound.max(u);
            continue;
        }
        stack.push((lo, mid, plo, pm));
        stack.push((mid, hi, pm, phi));
    }
    bound.max(best)
}

/// The values at one θ of a segment that the branch and bound needs: s(θ), t(θ) and s′(θ).
#[derive(Debug, Clone, Copy)]
struct Point {
    s: f64,
    t: f64,
    ds: f64,
}

/// Guaranteed (min, max) of D/B over all directions where the target B is positive.
/// `x` are the disk radii of the diagram's parallels.
///
/// The same numbers as combining [`segment_ratio_range`] over every parallel segment, computed
/// without the branch and bound of the segments that cannot move the result: a segment's upper
/// end never exceeds max(1, x′(θ_j)Δθ/Δx)·(1 + its round-off widening) and its lower end is never
/// below min(1, x′(θ_{j+1})Δθ/Δx)·(1 − widening) (the closed-form caps of fact 2), so the
/// segments are visited by decreasing (increasing) cap and the walk stops at the first whose cap
/// is within the range found so far. Max and min are exact and order-free, so the result is
/// bit-identical to the plain loop; on a fine grid (a 2048 × 1024 environment map) the caps fall
/// off with the distance from the horizon and only a few segments need the branch and bound.
pub(crate) fn density_ratio_range(diagram: &Diagram, x: &[f64]) -> (f64, f64) {
    density_ratio_range_grid(diagram.theta(), diagram.values(), x)
}

/// [`density_ratio_range`] of the diagram with parallels `theta` (N entries) and row-major
/// M × N `values` (value (i, j) at `values[i * N + j]`, as [`Diagram::value`]): the same
/// computation on a grid held as parts (a sphere map's core keeps only the grid and its tables).
pub(crate) fn density_ratio_range_grid(theta: &[f64], values: &[f64], x: &[f64]) -> (f64, f64) {
    let n = theta.len();
    let m = values.len() / n;
    let value = |i: usize, j: usize| values[i * n + j];
    let (mut lo, mut hi) = (1.0f64, 1.0f64);
    // The segments that carry a ratio at all, with their caps (see `SegmentGeometry`).
    let segs: Vec<(usize, SegmentGeometry)> = (0..n - 1)
        .filter_map(|j| {
            SegmentGeometry::new(theta[j], theta[j + 1], x[j], x[j + 1]).map(|g| (j, g))
        })
        .collect();
    let mut scans: Vec<Option<RowScan>> = vec![None; n - 1];
    let mut scan = |j: usize| -> RowScan {
        *scans[j]
            .get_or_insert_with(|| RowScan::new((0..m).map(|i| (value(i, j), value(i, j + 1)))))
    };
    let mut order: Vec<usize> = (0..segs.len()).collect();
    order.sort_by(|&a, &b| segs[b].1.hi_cap().total_cmp(&segs[a].1.hi_cap()));
    for &k in &order {
        let (j, g) = &segs[k];
        if g.hi_cap() <= hi {
            // Every later segment's cap is at most this one's: none can raise `hi`.
            break;
        }
        hi = hi.max(g.hi(&scan(*j)));
    }
    order.sort_by(|&a, &b| segs[a].1.lo_cap().total_cmp(&segs[b].1.lo_cap()));
    for &k in &order {
        let (j, g) = &segs[k];
        if g.lo_cap() >= lo {
            break;
        }
        lo = lo.min(g.lo(&scan(*j)));
    }
    (lo * (1.0 - MARGIN), hi * (1.0 + MARGIN))
}

/// What the meridians of one parallel segment say about the ratio: the largest and the smallest
/// b/a among meridians with light at both ends, and whether some meridian has light only at the
/// far end (a = 0) or only at the near end (b = 0).
#[derive(Debug, Clone, Copy)]
struct RowScan {
    rho_max: f64,
    rho_min: f64,
    a_zero: bool,
    b_zero: bool,
}

impl RowScan {
    fn new(rows: impl Iterator<Item = (f64, f64)>) -> Self {
        let (mut rho_max, mut rho_min) = (1.0f64, 1.0f64);
        let (mut a_zero, mut b_zero) = (false, false);
        for (a, b) in rows {
            match (a > 0.0, b > 0.0) {
                (false, false) => {}
                (false, true) => a_zero = true,
                (true, false) => b_zero = true,
                (true, true) => {
                    rho_max = rho_max.max(b / a);
                    rho_min = rho_min.min(b / a);
                }
            }
        }
        RowScan {
            rho_max,
            rho_min,
            a_zero,
            b_zero,
        }
    }
}

/// The geometry of one parallel segment [θ0, θ1] with disk radii x0 < x1 (Δθ, Δx > 0).
#[derive(Debug, Clone, Copy)]
struct SegmentGeometry {
    t0: f64,
    t1: f64,
    x0: f64,
    dx: f64,
    h: f64,
    /// The round-off widening of the segment's range (see the end of [`segment_ratio_range`]).
    eps: f64,
}

impl SegmentGeometry {
    /// `None` for a segment thinner than double precision resolves on the disk: it carries no
    /// map mass (its probability is below 1e-15) and no ratio to bound (issue 9).
    fn new(t0: f64, t1: f64, x0: f64, x1: f64) -> Option<Self> {
        let (h, dx) = (t1 - t0, x1 - x0);
        if !(dx > 0.0 && h > 0.0) {
            return None;
        }
        // s and t lose digits to cancellation in cells much narrower than their radius (refined
        // cells): widen by a few units of round-off relative to the cell.
        let eps = 4.0 * f64::EPSILON * (x1.abs() / dx + t1.abs() / h);
        Some(SegmentGeometry {
            t0,
            t1,
            x0,
            dx,
            h,
            eps,
        })
    }

    /// x′(θ)·Δθ/Δx: the closed-form limits of fact 2 at θ0 (ρ = ∞) and θ1 (ρ = 0).
    fn slope_cap(&self, t: f64) -> f64 {
        FRAC_1_SQRT_2 * (0.5 * t).cos() * self.h / self.dx
    }

    /// An upper bound of [`SegmentGeometry::hi`] whatever the meridians hold.
    fn hi_cap(&self) -> f64 {
        1.0f64.max(self.slope_cap(self.t0)) * (1.0 + self.eps)
    }

    /// A lower bound of [`SegmentGeometry::lo`] whatever the meridians hold (−∞ when the
    /// widening reaches 1, where the product's order is not kept).
    fn lo_cap(&self) -> f64 {
        let f = 1.0 - self.eps;
        if f > 0.0 {
            1.0f64.min(self.slope_cap(self.t1)) * f
        } else {
            f64::NEG_INFINITY
        }
    }

    /// The guaranteed maximum of D/B on the segment, widened.
    fn hi(&self, r: &RowScan) -> f64 {
        let (t0, t1, x0, dx, h) = (self.t0, self.t1, self.x0, self.dx, self.h);
        let mut hi = 1.0f64;
        if r.a_zero {
            hi = hi.max(self.slope_cap(t0));
        }
        if r.rho_max > 1.0 {
            // s′ = x′(θ)/Δx is decreasing (x concave); t′ = 1/h.
            let at = |t: f64| Point {
                s: ((parallel_radius(t) - x0) / dx).clamp(0.0, 1.0),
                t: ((t - t0) / h).clamp(0.0, 1.0),
                ds: FRAC_1_SQRT_2 * (0.5 * t).cos() / dx,
            };
            let dt = 1.0 / h;
            // g = N/Dn with N = 1 + s c, Dn = 1 + t c (both increasing); g′ = c (s′Dn − t′N)/Dn².
            let c = r.rho_max - 1.0;
            let g = |p: &Point| (1.0 + p.s * c) / (1.0 + p.t * c);
            let slope = |a: &Point, b: &Point| {
                let (n_lo, n_hi) = (1.0 + a.s * c, 1.0 + b.s * c);
                let (d_lo, d_hi) = (1.0 + a.t * c, 1.0 + b.t * c);
                let lo_num = b.ds * d_lo - dt * n_hi;
                let hi_num = a.ds * d_hi - dt * n_lo;
                c * lo_num.abs().max(hi_num.abs()) / (d_lo * d_lo)
            };
            // g(θ; ρ) ≤ g(θ; ∞) = s/t ≤ x′(θ_j)Δθ/Δx (fact 2): a closed-form cap that keeps the
            // bound tight where the branch and bound would need ~log2(ρ) levels (ρ up to 1e20+).
            hi = hi.max(supremum(at, g, slope, t0, t1).min(self.slope_cap(t0)));
        }
        hi * (1.0 + self.eps)
    }

    /// The guaranteed minimum of D/B on the segment, widened.
    fn lo(&self, r: &RowScan) -> f64 {
        let (t0, t1, x0, dx, h) = (self.t0, self.t1, self.x0, self.dx, self.h);
        let mut lo = 1.0f64;
        if r.b_zero {
            lo = lo.min(self.slope_cap(t1));
        }
        if r.rho_min < 1.0 {
            let at = |t: f64| Point {
                s: ((parallel_radius(t) - x0) / dx).clamp(0.0, 1.0),
                t: ((t - t0) / h).clamp(0.0, 1.0),
                ds: FRAC_1_SQRT_2 * (0.5 * t).cos() / dx,
            };
            let dt = 1.0 / h;
            // minimise (1 − s c)/(1 − t c): maximise g = N/Dn, N = 1 − t c, Dn = 1 − s c (both
            // decreasing, Dn ≥ ρ > 0); g′ = c (s′N − t′Dn)/Dn².
            let c = 1.0 - r.rho_min;
            let g = |p: &Point| (1.0 - p.t * c) / (1.0 - p.s * c);
            let slope = |a: &Point, b: &Point| {
                let (n_hi, n_lo) = (1.0 - a.t * c, 1.0 - b.t * c);
                let (d_hi, d_lo) = (1.0 - a.s * c, 1.0 - b.s * c);
                let lo_num = b.ds * n_lo - dt * d_hi;
                let hi_num = a.ds * n_hi - dt * d_lo;
                c * lo_num.abs().max(hi_num.abs()) / (d_lo * d_lo)
            };
            // likewise g(θ; ρ) ≥ g(θ; 0) = (1 − s)/(1 − t) ≥ x′(θ_{j+1})Δθ/Δx.
            lo = lo.min((1.0 / supremum(at, g, slope, t0, t1)).max(self.slope_cap(t1)));
        }
        lo * (1.0 - self.eps)
    }
}

/// Guaranteed (min, max) of D/B over one parallel segment [θ0, θ1] (disk radii x0 < x1) and every
/// meridian, given each meridian's (value at θ0, value at θ1); (1, 1) when the target is zero on
/// the whole segment. Without the round-off margin (see [`MARGIN`]): the caller applies it once.
pub(crate) fn segment_ratio_range(
    t0: f64,
    t1: f64,
    x0: f64,
    x1: f64,
    rows: impl Iterator<Item = (f64, f64)>,
) -> (f64, f64) {
    let Some(g) = SegmentGeometry::new(t0, t1, x0, x1) else {
        return (1.0, 1.0);
    };
    let r = RowScan::new(rows);
    (g.lo(&r), g.hi(&r))
}
