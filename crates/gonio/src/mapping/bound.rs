//! The guaranteed range of the map's density over the target density ("guaranteed distance",
//! ALGORITHM §9, §13), computed at build time.
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
fn supremum(f: impl Fn(f64) -> f64, slope: impl Fn(f64, f64) -> f64, a: f64, b: f64) -> f64 {
    let mut best = f(a).max(f(b));
    let mut bound = best;
    let mut stack = vec![(a, b)];
    let mut budget = 20_000u32;
    while let Some((lo, hi)) = stack.pop() {
        let mid = 0.5 * (lo + hi);
        let fm = f(mid);
        best = best.max(fm);
        let u = fm + slope(lo, hi) * 0.5 * (hi - lo);
        budget = budget.saturating_sub(1);
        if u <= best * (1.0 + TOL) || budget == 0 || hi - lo <= 1e-14 * hi.abs().max(1.0) {
            bound = bound.max(u);
            continue;
        }
        stack.push((lo, mid));
        stack.push((mid, hi));
    }
    bound.max(best)
}

/// Guaranteed (min, max) of D/B over all directions where the target B is positive.
/// `x` are the disk radii of the diagram's parallels.
pub(crate) fn density_ratio_range(diagram: &Diagram, x: &[f64]) -> (f64, f64) {
    let (n, m) = (diagram.n_parallels(), diagram.n_meridians());
    let theta = diagram.theta();
    let (mut lo, mut hi) = (1.0f64, 1.0f64);
    for j in 0..n - 1 {
        let rows = (0..m).map(|i| (diagram.value(i, j), diagram.value(i, j + 1)));
        let (a, b) = segment_ratio_range(theta[j], theta[j + 1], x[j], x[j + 1], rows);
        lo = lo.min(a);
        hi = hi.max(b);
    }
    (lo * (1.0 - MARGIN), hi * (1.0 + MARGIN))
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
    let (mut lo, mut hi) = (1.0f64, 1.0f64);
    let (h, dx) = (t1 - t0, x1 - x0);
    if !(dx > 0.0 && h > 0.0) {
        // A segment thinner than double precision resolves on the disk carries no map mass (its
        // probability is below 1e-15): no ratio to bound there (issue 9).
        return (lo, hi);
    }
    let s = |t: f64| ((parallel_radius(t) - x0) / dx).clamp(0.0, 1.0);
    let tt = |t: f64| ((t - t0) / h).clamp(0.0, 1.0);
    let slope_cap = |t: f64| FRAC_1_SQRT_2 * (0.5 * t).cos() * h / dx;
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
    if a_zero {
        hi = hi.max(slope_cap(t0));
    }
    if b_zero {
        lo = lo.min(slope_cap(t1));
    }
    // s′ = x′(θ)/Δx is decreasing (x concave); t′ = 1/h.
    let ds = |t: f64| FRAC_1_SQRT_2 * (0.5 * t).cos() / dx;
    let dt = 1.0 / h;
    if rho_max > 1.0 {
        // g = N/Dn with N = 1 + s c, Dn = 1 + t c (both increasing); g′ = c (s′Dn − t′N)/Dn².
        let c = rho_max - 1.0;
        let g = |t: f64| (1.0 + s(t) * c) / (1.0 + tt(t) * c);
        let slope = |a: f64, b: f64| {
            let (n_lo, n_hi) = (1.0 + s(a) * c, 1.0 + s(b) * c);
            let (d_lo, d_hi) = (1.0 + tt(a) * c, 1.0 + tt(b) * c);
            let lo_num = ds(b) * d_lo - dt * n_hi;
            let hi_num = ds(a) * d_hi - dt * n_lo;
            c * lo_num.abs().max(hi_num.abs()) / (d_lo * d_lo)
        };
        // g(θ; ρ) ≤ g(θ; ∞) = s/t ≤ x′(θ_j)Δθ/Δx (fact 2): a closed-form cap that keeps the
        // bound tight where the branch and bound would need ~log2(ρ) levels (ρ up to 1e20+).
        hi = hi.max(supremum(g, slope, t0, t1).min(slope_cap(t0)));
    }
    if rho_min < 1.0 {
        // minimise (1 − s c)/(1 − t c): maximise g = N/Dn, N = 1 − t c, Dn = 1 − s c (both
        // decreasing, Dn ≥ ρ > 0); g′ = c (s′N − t′Dn)/Dn².
        let c = 1.0 - rho_min;
        let g = |t: f64| (1.0 - tt(t) * c) / (1.0 - s(t) * c);
        let slope = |a: f64, b: f64| {
            let (n_hi, n_lo) = (1.0 - tt(a) * c, 1.0 - tt(b) * c);
            let (d_hi, d_lo) = (1.0 - s(a) * c, 1.0 - s(b) * c);
            let lo_num = ds(b) * n_lo - dt * d_hi;
            let hi_num = ds(a) * n_hi - dt * d_lo;
            c * lo_num.abs().max(hi_num.abs()) / (d_lo * d_lo)
        };
        // likewise g(θ; ρ) ≥ g(θ; 0) = (1 − s)/(1 − t) ≥ x′(θ_{j+1})Δθ/Δx.
        lo = lo.min((1.0 / supremum(g, slope, t0, t1)).max(slope_cap(t1)));
    }
    // s and t lose digits to cancellation in cells much narrower than their radius (refined cells):
    // widen by a few units of round-off relative to the cell.
    let eps = 4.0 * f64::EPSILON * (x1.abs() / dx + t1.abs() / h);
    (lo * (1.0 - eps), hi * (1.0 + eps))
}
