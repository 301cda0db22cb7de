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

    /// ∫ f dω over every bin (flat index order), by a `nodes × nodes` Gauss–Legendre rule in
    /// (z, φ) per bin. The rule is exact for polynomials of degree 2·nodes − 1 in each variable;
    /// for an f that is smooth inside a bin the error falls as h^(2·nodes), across a kink of f
    /// (a table node inside the bin) it is O(h²) times the jump of the derivative there.
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
                for (ip, cell) in row.iter_mut().enumerate() {
                    let phi0 = ip as f64 * dphi;
                    let mut sum = 0.0;
                    for &(tz, wz) in &rule {
                        let z = z0 + tz * dz;
                        let s = (1.0 - z * z).max(0.0).sqrt();
                        for &(tp, wp) in &rule {
                            let (sp, cp) = (phi0 + tp * dphi).sin_cos();
                            sum += wz * wp * f([s * cp, s * sp, z]);
                        }
                    }
                    *cell = sum * dz * dphi;
                }
            });
        out
    }
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
        let areas = h.integrate(3, |_| 1.0);
        for a in areas {
            assert!((a - h.bin_solid_angle()).abs() < 1e-14);
        }
        // ∫ cos θ dω over the hemisphere = π.
        let cos: f64 = h.integrate(2, |d| d[2]).iter().sum();
        assert!((cos - std::f64::consts::PI).abs() < 1e-13);
    }
}
