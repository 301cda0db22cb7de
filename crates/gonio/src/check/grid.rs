//! Equal-solid-angle bins over a sampler's domain and per-bin quadrature.

use crate::sampler::{Domain, Vec3};
use rayon::prelude::*;
use std::f64::consts::TAU;

/// Tolerance on z below the horizon for a hemisphere direction still to count as inside (round-off
/// of maps that land exactly on the horizon).
pub(crate) const HORIZON_SLACK: f64 = 1e-12;

/// A grid of `z_bins × phi_bins` bins of equal solid angle: uniform in z = cos θ over [0, 1]
/// (hemisphere) or [−1, 1] (sphere) and uniform in the azimuth φ ∈ [0, 2π). Because dω = dz dφ,
/// every bin has solid angle Ω / (z_bins · phi_bins) with Ω the domain's solid angle.
///
/// Bin `(iz, iφ)` has flat index `iz · phi_bins + iφ`; `iz = 0` holds the lowest z.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BinGrid {
    domain: Domain,
    z_bins: usize,
    phi_bins: usize,
}

impl BinGrid {
    /// A grid of `z_bins × phi_bins` bins over `domain` (each count at least 1).
    pub fn new(domain: Domain, z_bins: usize, phi_bins: usize) -> Self {
        BinGrid {
            domain,
            z_bins: z_bins.max(1),
            phi_bins: phi_bins.max(1),
        }
    }

    /// The chi-square test's default grid: 16 × 32 on the hemisphere, 32 × 32 on the sphere.
    pub fn chi_square_default(domain: Domain) -> Self {
        match domain {
            Domain::Hemisphere => BinGrid::new(domain, 16, 32),
            Domain::Sphere => BinGrid::new(domain, 32, 32),
        }
    }

    /// The domain the grid covers.
    pub fn domain(&self) -> Domain {
        self.domain
    }
    /// Number of bins in z = cos θ.
    pub fn z_bins(&self) -> usize {
        self.z_bins
    }
    /// Number of bins in φ.
    pub fn phi_bins(&self) -> usize {
        self.phi_bins
    }
    /// Total number of bins.
    pub fn len(&self) -> usize {
        self.z_bins * self.phi_bins
    }
    /// Always false (a grid has at least one bin); present for clippy's `len_without_is_empty`.
    pub fn is_empty(&self) -> bool {
        false
    }
    /// Solid angle of one bin, in steradians.
    pub fn bin_solid_angle(&self) -> f64 {
        self.domain.solid_angle() / self.len() as f64
    }

    /// Lowest z of the domain (0 or −1).
    pub fn z_min(&self) -> f64 {
        match self.domain {
            Domain::Hemisphere => 0.0,
            Domain::Sphere => -1.0,
        }
    }

    /// `(iz, iφ)` of a flat bin index.
    pub fn bin_coords(&self, index: usize) -> [usize; 2] {
        [index / self.phi_bins, index % self.phi_bins]
    }

    /// The bin holding the unit direction `d`, or `None` if `d` is not finite or lies outside the
    /// domain (hemisphere directions down to z = −1e-12 count as on the horizon).
    pub fn bin_of(&self, d: Vec3) -> Option<usize> {
        if !d.iter().all(|c| c.is_finite()) {
            return None;
        }
        let z_min = self.z_min();
        if d[2] < z_min - HORIZON_SLACK {
            return None;
        }
        let t = (d[2] - z_min) / (1.0 - z_min);
        let iz = ((t * self.z_bins as f64) as usize).min(self.z_bins - 1);
        let (_, phi) = crate::sampler::spherical(d);
        let ip = ((phi / TAU * self.phi_bins as f64) as usize).min(self.phi_bins - 1);
        Some(iz * self.phi_bins + ip)
    }

    /// ∫ f dω over every bin (flat index order), adaptively: each bin is integrated in (θ, φ) with
    /// the sin θ factor (so that halving a cell halves its angular size, also at the poles) by a
    /// `nodes × nodes` Gauss–Legendre rule, on 2×2 sub-cells and on the cell itself; where the two
    /// differ by more than [`QUAD_REL_TOL`] of the cell's integral plus [`QUAD_TOL`] (absolute, the
    /// integral of a pdf over the domain being 1; divided by 4 per level) the sub-cells are refined
    /// in turn, down to 2⁻⁷ of the bin. Every bin is first split into 4×4 cells, so that features as
    /// narrow as 1/(16·nodes) of a bin are seen by some node. Kinks of a tabulated pdf (its
    /// parallels and meridians) are thereby localised, and beams a fraction of a degree wide are
    /// integrated to ~1e-3 relative (1e-7 absolute) — far below the chi-square's own resolution (an expected count
    /// E has noise √E, so a relative error δ matters only when δ·√E approaches 1).
    pub fn integrate<F>(&self, nodes: usize, f: F) -> Vec<f64>
    where
        F: Fn(Vec3) -> f64 + Sync,
    {
        let rule = gauss_legendre(nodes.max(1));
        let z_min = self.z_min();
        let dz = (1.0 - z_min) / self.z_bins as f64;
        let dphi = TAU / self.phi_bins as f64;
        let mut out = vec![0.0; self.len()];
        out.par_chunks_mut(self.phi_bins)
            .enumerate()
            .for_each(|(iz, row)| {
                let z0 = z_min + iz as f64 * dz;
                let z1 = (z0 + dz).min(1.0);
                // θ decreases as z increases
                let (t0, t1) = (z1.clamp(-1.0, 1.0).acos(), z0.clamp(-1.0, 1.0).acos());
                for (ip, cell) in row.iter_mut().enumerate() {
                    let p0 = ip as f64 * dphi;
                    let cell_rule = |ta: f64, tb: f64, pa: f64, pb: f64| -> f64 {
                        let mut sum = 0.0;
                        for &(xt, wt) in &rule {
                            let t = ta + xt * (tb - ta);
                            let (st, ct) = t.sin_cos();
                            for &(xp, wp) in &rule {
                                let (sp, cp) = (pa + xp * (pb - pa)).sin_cos();
                                sum += wt * wp * st * f([st * cp, st * sp, ct]);
                            }
                        }
                        sum * (tb - ta) * (pb - pa)
                    };
                    let mut total = 0.0;
                    let k = 4;
                    let (ht, hp) = ((t1 - t0) / k as f64, dphi / k as f64);
                    for a in 0..k {
                        for b in 0..k {
                            let (ta, pa) = (t0 + a as f64 * ht, p0 + b as f64 * hp);
                            total += adapt(&cell_rule, ta, ta + ht, pa, pa + hp, QUAD_TOL, 5);
                        }
                    }
                    *cell = total;
                }
            });
        out
    }
}

/// Absolute tolerance of [`BinGrid::integrate`] per cell of the first split.
pub const QUAD_TOL: f64 = 1e-7;
/// Relative tolerance of [`BinGrid::integrate`] per cell.
pub const QUAD_REL_TOL: f64 = 1e-3;

/// Adaptive 2×2 refinement of `rule` over [ta, tb] × [pa, pb] (see [`BinGrid::integrate`]).
fn adapt(
    rule: &dyn Fn(f64, f64, f64, f64) -> f64,
    ta: f64,
    tb: f64,
    pa: f64,
    pb: f64,
    tol: f64,
    depth: u32,
) -> f64 {
    let coarse = rule(ta, tb, pa, pb);
    let (tm, pm) = (0.5 * (ta + tb), 0.5 * (pa + pb));
    let parts = [
        (ta, tm, pa, pm),
        (tm, tb, pa, pm),
        (ta, tm, pm, pb),
        (tm, tb, pm, pb),
    ];
    let fine: f64 = parts.iter().map(|&(a, b, c, d)| rule(a, b, c, d)).sum();
    if depth == 0 || (fine - coarse).abs() <= tol + QUAD_REL_TOL * fine.abs() || !fine.is_finite() {
        return fine;
    }
    parts
        .iter()
        .map(|&(a, b, c, d)| adapt(rule, a, b, c, d, 0.25 * tol, depth - 1))
        .sum()
}

/// Gauss–Legendre nodes and weights on [0, 1] (weights sum to 1), by Newton's method on the
/// Legendre polynomial Pₙ from the usual cosine first guesses.
pub(crate) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut rule = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // Three-term recurrence for P_n(x) and P_{n-1}(x).
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let (pn, pn1) = if n == 1 { (x, 1.0) } else { (p1, p0) };
            dp = n as f64 * (x * pn - pn1) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        rule.push((0.5 * (1.0 + x), 0.5 * w));
    }
    rule
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_is_exact_for_polynomials() {
        for n in 1..=10 {
            let rule = gauss_legendre(n);
            for deg in 0..2 * n {
                let q: f64 = rule.iter().map(|&(x, w)| w * x.powi(deg as i32)).sum();
                let exact = 1.0 / (deg + 1) as f64;
                assert!((q - exact).abs() < 1e-14, "n {n} deg {deg}: {q} vs {exact}");
            }
        }
    }

    #[test]
    fn bins_cover_the_domain() {
        let g = BinGrid::new(Domain::Sphere, 4, 8);
        assert_eq!(g.bin_of([0.0, 0.0, 1.0]), Some(3 * 8));
        assert_eq!(g.bin_of([0.0, 0.0, -1.0]), Some(0));
        assert_eq!(g.bin_of([0.0, -1.0, 0.0]), Some(2 * 8 + 6));
        assert_eq!(g.bin_of([f64::NAN, 0.0, 1.0]), None);
        let h = BinGrid::chi_square_default(Domain::Hemisphere);
        assert_eq!(h.bin_of([0.0, 0.0, -0.5]), None);
        assert_eq!(h.bin_of([1.0, 0.0, -1e-14]), Some(0));
        assert_eq!(h.bin_coords(33), [1, 1]);
        // The adaptive rule is accurate to QUAD_TOL per bin.
        let areas = h.integrate(3, |_| 1.0);
        for a in areas {
            assert!((a - h.bin_solid_angle()).abs() < QUAD_TOL);
        }
        // ∫ cos θ dω over the hemisphere = π.
        let cos: f64 = h.integrate(2, |d| d[2]).iter().sum();
        assert!((cos - std::f64::consts::PI).abs() < QUAD_TOL * h.len() as f64);
        // A tent-shaped beam max(0, 1 − θ/a) of half-width a = 0.3° at the pole (a kink at θ = a,
        // like a tabulated pdf) is integrated to its tolerance, although a bin spans 29° in θ:
        // 2π ∫₀^a (1 − θ/a) sin θ dθ = 2π[(1 − cos a) − (sin a − a cos a)/a].
        let a = 0.3f64.to_radians();
        let tent: f64 = h
            .integrate(6, |d| (1.0 - d[2].clamp(-1.0, 1.0).acos() / a).max(0.0))
            .iter()
            .sum();
        let want = std::f64::consts::TAU * ((1.0 - a.cos()) - (a.sin() - a * a.cos()) / a);
        assert!(
            // the refinement's error estimate is per cell; allow a few cells' worth
            (tent - want).abs() < 10.0 * QUAD_TOL + 5.0 * QUAD_REL_TOL * want,
            "{tent} vs {want}"
        );
    }
}
