//! The precomputed tables of §4 and the composed map F = M_E ∘ M_D ∘ M_C ∘ M_B on one disk.
//!
//! `HdsCore` works on a *completed* grid: θ_0 = 0 (the pole), φ_0 = 0, and θ_{N−1} anywhere up to
//! π/2 for a hemisphere (π for the whole-sphere Lambert lift): the map covers the zone
//! [0, θ_{N−1}], whose disk has radius x_{N−1} = √2 sin(θ_{N−1}/2). The public samplers in this module complete a user's
//! diagram first (ALGORITHM §10 A15) and then build a core.

use super::angular::{solve_wedge, wedge_angle};
use super::bound::density_ratio_range;
use super::concentric::{disk_to_square, square_to_disk};
use super::lift::{disk_to_sphere, parallel_radius, sphere_to_disk_radius};
use super::radial::{partial_mass, segment_mass, solve_radius};
use crate::diagram::{segment, Diagram, DiagramError};
use crate::sampler::Vec3;
use std::f64::consts::{PI, TAU};

mod lanes;

/// Azimuth φ ∈ [0, 2π) of a direction, as [`crate::sampler::spherical`] computes it, without the
/// polar angle: 0 at the poles (x = y = 0, any signs of zero).
#[inline]
fn azimuth(d: Vec3) -> f64 {
    if d[0] == 0.0 && d[1] == 0.0 {
        return 0.0;
    }
    let mut phi = d[1].atan2(d[0]);
    if phi < 0.0 {
        phi += TAU;
    }
    if phi >= TAU {
        phi = 0.0;
    }
    phi
}

/// Tables of one HDS map (ALGORITHM §4) plus the completed diagram it was built from.
#[derive(Debug, Clone)]
pub(crate) struct HdsCore {
    n: usize,
    m: usize,
    /// Parallel radii x_j = √(1 − cos θ_j) on the disk, N entries.
    x: Vec<f64>,
    /// Meridian azimuths, M + 1 entries with φ_M = 2π.
    phi: Vec<f64>,
    /// Sector widths β_i, M entries.
    beta: Vec<f64>,
    /// 1/β when the meridians are uniform (O(1) sector lookup), else 0.
    inv_uniform_beta: f64,
    /// Nodal disk densities d_{i,j} = p_{i,j}, row-major M × N.
    d: Vec<f64>,
    /// Cumulative radial masses U(i, j) = 2∫₀^{x_j} d_i(x) x dx, row-major M × N.
    u: Vec<f64>,
    /// Squared star radii R_i² = U(i, N−1)/s, M + 1 entries (R_M = R_0).
    r2: Vec<f64>,
    /// Cumulative wedge angles Γ_i, M + 1 entries, Γ_0 = 0, Γ_M = 2π exactly.
    cum: Vec<f64>,
    /// Γ_M / Σγ^i (1 up to round-off): keeps Γ exactly cumulative.
    kappa: f64,
    /// Guide table of the wedge search: entry k is the wedge that holds φ_B = 2πk/K (K = the
    /// table's length, 2M), so the search starts at most a step or two below its answer (O(1)
    /// for all but pathological Γ).
    wedge_guide: Vec<u32>,
    /// K / 2π for [`HdsCore::wedge_guide`].
    guide_scale: f64,
    /// Guide table of the parallel search: entry k is the segment of x that holds radius
    /// k·x_{N−1}/K (K = the table's length, 2N), for `pdf` and `invert`.
    radius_guide: Vec<u32>,
    /// K / x_{N−1} for [`HdsCore::radius_guide`].
    radius_scale: f64,
    /// 1 / (x_{j+1} − x_j), N − 1 entries (0 for an empty segment).
    inv_dx: Vec<f64>,
    /// Radial guide tables, row-major M × (K + 1) with K = [`HdsCore::radial_k`]: entry (i, k) is
    /// the largest j ≤ N − 2 with U(i, j) ≤ (k/K)·U(i, N−1), the segment of meridian i's own radial
    /// CDF at r_B² = k/K. They bracket the forward map's radial search.
    radial_guide: Vec<u32>,
    /// K = ⌈N/2⌉ cells per radial guide table.
    radial_k: usize,
    /// T = ∫_disk D dA (§4.3), in diagram units × disk area.
    total: f64,
    /// The completed diagram; the target density is its (θ, φ)-bilinear interpolant.
    diagram: Diagram,
    /// ∫ target dω over the domain (diagram units × sr).
    target_total: f64,
    /// Guaranteed range of D/B over directions where B > 0 (B: the (θ, φ)-bilinear interpolant).
    db_range: (f64, f64),
}

impl HdsCore {
    /// Builds the tables from a completed diagram (θ_0 = 0, φ_0 = 0, N ≥ 2), values normalised
    /// (largest 1, see `complete`). Refuses a diagram whose light the disk cannot resolve (every
    /// cell with light thinner than an ulp of x): [`DiagramError::UnresolvedLight`].
    pub(crate) fn build(diagram: Diagram) -> Result<Self, DiagramError> {
        let x = parallel_radii(diagram.theta());
        let db_range = density_ratio_range(&diagram, &x);
        Self::build_with_range(diagram, db_range)
    }

    /// As [`HdsCore::build`], with the guaranteed range of D/B already known (refinement computes
    /// it cell by cell on the way).
    pub(crate) fn build_with_range(
        diagram: Diagram,
        db_range: (f64, f64),
    ) -> Result<Self, DiagramError> {
        let n = diagram.n_parallels();
        let m = diagram.n_meridians();
        debug_assert!(n >= 2 && diagram.theta()[0] == 0.0 && diagram.phi()[0] == 0.0);
        let x = parallel_radii(diagram.theta());
        let mut phi = diagram.phi().to_vec();
        phi.push(TAU);
        let beta: Vec<f64> = (0..m).map(|i| phi[i + 1] - phi[i]).collect();
        let uniform = beta.iter().all(|b| (b - TAU / m as f64).abs() <= 1e-12);
        let d = diagram.values().to_vec();
        let mut u = vec![0.0; m * n];
        for i in 0..m {
            let (row, dr) = (&mut u[i * n..(i + 1) * n], &d[i * n..(i + 1) * n]);
            for j in 0..n - 1 {
                row[j + 1] = row[j] + segment_mass(x[j], x[j + 1], dr[j], dr[j + 1]);
            }
        }
        let last = |i: usize| u[(i % m) * n + n - 1];
        let total: f64 = (0..m)
            .map(|i| beta[i] * (last(i) + last(i + 1)) / 4.0)
            .sum();
        if !(total > 0.0 && total.is_finite()) {
            return Err(DiagramError::UnresolvedLight);
        }
        let s = total / PI;
        let mut r2: Vec<f64> = (0..=m).map(|i| last(i) / s).collect();
        r2[m] = r2[0];
        let mut cum = vec![0.0; m + 1];
        for i in 0..m {
            cum[i + 1] = cum[i] + beta[i] * (r2[i] + r2[i + 1]) / 2.0;
        }
        let kappa = TAU / cum[m];
        for c in cum.iter_mut() {
            *c *= kappa;
        }
        cum[m] = TAU;
        let guide_len = 2 * m;
        let wedge_guide: Vec<u32> = (0..guide_len)
            .map(|k| {
                let p = k as f64 * TAU / guide_len as f64;
                (cum.partition_point(|&g| g <= p).clamp(1, m) - 1) as u32
            })
            .collect();
        let radius_len = 2 * n;
        let x_max = x[n - 1];
        let radius_guide: Vec<u32> = (0..radius_len)
            .map(|k| segment(&x, k as f64 * x_max / radius_len as f64) as u32)
            .collect();
        let inv_dx: Vec<f64> = x
            .windows(2)
            .map(|w| {
                if w[1] > w[0] {
                    1.0 / (w[1] - w[0])
                } else {
                    0.0
                }
            })
            .collect();
        let radial_k = n.div_ceil(2).max(1);
        let mut radial_guide = Vec::with_capacity(m * (radial_k + 1));
        for i in 0..m {
            let row = &u[i * n..(i + 1) * n];
            for k in 0..=radial_k {
                let level = k as f64 / radial_k as f64 * row[n - 1];
                let j = row.partition_point(|&v| v <= level).max(1) - 1;
                radial_guide.push(j.min(n - 2) as u32);
            }
        }
        let target_total = diagram.integral();
        Ok(HdsCore {
            n,
            m,
            x,
            phi,
            beta,
            inv_uniform_beta: if uniform { m as f64 / TAU } else { 0.0 },
            d,
            u,
            r2,
            cum,
            kappa,
            wedge_guide,
            guide_scale: guide_len as f64 / TAU,
            radius_guide,
            radius_scale: radius_len as f64 / x_max,
            inv_dx,
            radial_guide,
            radial_k,
            total,
            diagram,
            target_total,
            db_range,
        })
    }

    /// ∫ D dA over the cells of the completed grid that lie outside θ ∈ [`lo`, `hi`] (radians,
    /// the measured range; completion puts nodes exactly at its ends): the map's power there,
    /// exactly, in the units of [`HdsCore::total`].
    pub(crate) fn power_outside(&self, lo: f64, hi: f64) -> f64 {
        let (n, m) = (self.n, self.m);
        let theta = self.diagram.theta();
        let mut p = 0.0;
        for j in 0..n - 1 {
            if theta[j] >= lo && theta[j + 1] <= hi {
                continue;
            }
            for i in 0..m {
                let i1 = self.next(i);
                let du = |r: usize| self.u[r * n + j + 1] - self.u[r * n + j];
                p += self.beta[i] * (du(i) + du(i1)) / 4.0;
            }
        }
        p
    }

    /// T = ∫_disk D dA.
    pub(crate) fn total(&self) -> f64 {
        self.total
    }
    /// ∫ target dω over the domain, in diagram units × sr.
    pub(crate) fn target_total(&self) -> f64 {
        self.target_total
    }
    /// The completed diagram.
    pub(crate) fn diagram(&self) -> &Diagram {
        &self.diagram
    }
    /// Guaranteed (min, max) of D/B over directions where the target is positive.
    pub(crate) fn db_range(&self) -> (f64, f64) {
        self.db_range
    }
    /// Γ_i, M + 1 entries.
    #[cfg(test)]
    pub(crate) fn wedge_cumulative(&self) -> &[f64] {
        &self.cum
    }

    /// Bytes of the precomputed tables (the vectors' lengths, not their capacities), including the
    /// nodal densities and angles that the run time needs, excluding the diagram kept for the target.
    pub(crate) fn memory_bytes(&self) -> usize {
        8 * (self.x.len()
            + self.phi.len()
            + self.beta.len()
            + self.d.len()
            + self.u.len()
            + self.r2.len()
            + self.cum.len())
            + 8 * self.inv_dx.len()
            + 4 * (self.wedge_guide.len() + self.radius_guide.len() + self.radial_guide.len())
            + std::mem::size_of::<Self>()
    }

    /// [`HdsCore::memory_bytes`] of the core that [`HdsCore::build`] would make from `diagram`.
    pub(crate) fn table_bytes(diagram: &Diagram) -> usize {
        let (n, m) = (diagram.n_parallels(), diagram.n_meridians());
        let radial_k = n.div_ceil(2).max(1);
        8 * (n + (m + 1) + m + 2 * m * n + 2 * (m + 1))
            + 8 * (n - 1)
            + 4 * (2 * m + 2 * n + m * (radial_k + 1))
            + std::mem::size_of::<Self>()
    }

    /// Sector of azimuth `p` ∈ [0, 2π) and the fraction ε within it.
    #[inline]
    fn sector(&self, p: f64) -> (usize, f64) {
        let i = if self.inv_uniform_beta > 0.0 {
            let mut i = ((p * self.inv_uniform_beta) as usize).min(self.m - 1);
            if p < self.phi[i] {
                i -= 1;
            } else if p >= self.phi[i + 1] && i + 1 < self.m {
                i += 1;
            }
            i
        } else {
            segment(&self.phi, p)
        };
        let eps = ((p - self.phi[i]) / self.beta[i]).clamp(0.0, 1.0);
        (i, eps)
    }

    /// The wedge of B-disk azimuth `phib`: the largest i ≤ M − 1 with Γ_i ≤ φ_B (empty wedges are
    /// skipped by taking the last such i), found from the guide table.
    #[inline]
    fn wedge(&self, phib: f64) -> usize {
        guided_search(
            &self.cum,
            &self.wedge_guide,
            self.guide_scale,
            phib,
            self.m - 1,
        )
    }

    /// The segment of the parallel radii that holds disk radius `xr` (as `diagram::segment`: the
    /// largest j ≤ N − 2 with x_j ≤ xr), found from the guide table.
    #[inline]
    fn radial_segment(&self, xr: f64) -> usize {
        guided_search(
            &self.x,
            &self.radius_guide,
            self.radius_scale,
            xr,
            self.n - 2,
        )
    }

    #[inline]
    fn next(&self, i: usize) -> usize {
        if i + 1 == self.m {
            0
        } else {
            i + 1
        }
    }

    /// M_C: the wedge i with Γ_i ≤ φ_B < Γ_{i+1} (empty wedges are skipped by taking the last such
    /// i), the fraction ε of sector i that has the wedge's area, and φ_C = φ_i + εβ_i.
    #[inline]
    fn angular(&self, phib: f64) -> (usize, f64, f64) {
        let i = self.wedge(phib);
        let eps = solve_wedge(
            self.beta[i],
            self.r2[i],
            self.r2[i + 1],
            (phib - self.cum[i]) / self.kappa,
        );
        (i, eps, self.phi[i] + eps * self.beta[i])
    }

    /// The intermediate points of the forward map (for pictures and tests).
    pub(crate) fn stages(&self, uv: [f64; 2]) -> super::Stages {
        let (rb, phib) = square_to_disk(uv);
        let (i, eps, phi) = self.angular(phib);
        let rho2 = (1.0 - eps) * self.r2[i] + eps * self.r2[i + 1];
        let (direction, _) = self.sample(uv);
        super::Stages {
            square: uv,
            disk_b: (rb, phib),
            star_c: (rb * rho2.max(0.0).sqrt(), phi),
            disk_d: (sphere_to_disk_radius(direction), phi),
            direction,
            lower: false,
        }
    }

    /// The forward map: a point of the unit square to (direction, D at the sample).
    #[inline]
    pub(crate) fn sample(&self, uv: [f64; 2]) -> (Vec3, f64) {
        let n = self.n;
        // M_B
        let (rb, phib) = square_to_disk(uv);
        // M_C
        let (i, eps, phi) = self.angular(phib);
        let i1 = self.next(i);
        // M_D on the interpolated tables Ũ_j, d̃_j (§6, A6).
        let (ua, ub) = (&self.u[i * n..i * n + n], &self.u[i1 * n..i1 * n + n]);
        let (da, db) = (&self.d[i * n..i * n + n], &self.d[i1 * n..i1 * n + n]);
        let ut = |j: usize| (1.0 - eps) * ua[j] + eps * ub[j];
        let w = rb * rb * ut(n - 1);
        // Largest j ≤ N−2 with Ũ_j ≤ w. Ũ/Ũ_{N−1} is a convex combination of the two rows'
        // normalised cumulatives, so the answer lies between the rows' own answers for r_B², which
        // the radial guide tables bracket: j ∈ [min(g_a[k], g_b[k]), max(g_a[k+1], g_b[k+1])].
        let kg = self.radial_k;
        let k = ((rb * rb * kg as f64) as usize).min(kg - 1);
        let (ga, gb) = (
            &self.radial_guide[i * (kg + 1)..(i + 1) * (kg + 1)],
            &self.radial_guide[i1 * (kg + 1)..(i1 + 1) * (kg + 1)],
        );
        let (mut lo, mut hi) = (ga[k].min(gb[k]) as usize, ga[k + 1].max(gb[k + 1]) as usize);
        while hi > lo {
            let mid = (lo + hi).div_ceil(2);
            if ut(mid) <= w {
                lo = mid;
            } else {
                hi = mid - 1;
            }
        }
        let mut j = lo;
        // Round-off may move the answer just outside the bracket: settle it exactly.
        while j > 0 && ut(j) > w {
            j -= 1;
        }
        while j + 2 < n && ut(j + 1) <= w {
            j += 1;
        }
        let d0 = (1.0 - eps) * da[j] + eps * db[j];
        let d1 = (1.0 - eps) * da[j + 1] + eps * db[j + 1];
        let (x0, x1) = (self.x[j], self.x[j + 1]);
        let xr = solve_radius(x0, x1, d0, d1, w - ut(j)).min(x1);
        // M_E
        let dir = disk_to_sphere(xr, phi);
        // The density at the radius the returned direction has (what `density` reads), not at xr:
        // they differ by the lift's round-off, which a steep segment (a zero guard band) would
        // turn into a visible disagreement between sample() and pdf().
        let t = ((sphere_to_disk_radius(dir) - x0) * self.inv_dx[j]).clamp(0.0, 1.0);
        let dens = d0 + (d1 - d0) * t;
        if dir[0] == 0.0 && dir[1] == 0.0 {
            // The pole: every meridian meets there, and `density` reads meridian 0 (φ = 0);
            // the sample carries that same value, so sample() and pdf() agree at (±0, ±0, 1).
            return (dir, self.density(dir));
        }
        (dir, dens.max(0.0))
    }

    /// The disk density D at a direction (bilinear in (x, φ)), the numerator of the pdf.
    #[inline]
    pub(crate) fn density(&self, dir: Vec3) -> f64 {
        let n = self.n;
        let xr = sphere_to_disk_radius(dir);
        if xr > self.x[n - 1] * (1.0 + 1e-12) {
            // Beyond the zone the map covers (a diagram ending before θ_max): no light.
            return 0.0;
        }
        let p = azimuth(dir);
        let (i, eps) = self.sector(p);
        let i1 = self.next(i);
        let j = self.radial_segment(xr);
        let t = ((xr - self.x[j]) * self.inv_dx[j]).clamp(0.0, 1.0);
        let row = |r: usize| {
            let a = &self.d[r * n..r * n + n];
            a[j] + t * (a[j + 1] - a[j])
        };
        ((1.0 - eps) * row(i) + eps * row(i1)).max(0.0)
    }

    /// The inverse map: a direction to its point of the unit square (closed form, §6–§7a).
    #[inline]
    pub(crate) fn invert(&self, dir: Vec3) -> [f64; 2] {
        let n = self.n;
        let xr = sphere_to_disk_radius(dir);
        let p = azimuth(dir);
        let (i, eps) = self.sector(p);
        let i1 = self.next(i);
        let (ua, ub) = (&self.u[i * n..i * n + n], &self.u[i1 * n..i1 * n + n]);
        let (da, db) = (&self.d[i * n..i * n + n], &self.d[i1 * n..i1 * n + n]);
        let j = self.radial_segment(xr);
        let (x0, x1) = (self.x[j], self.x[j + 1]);
        let d0 = (1.0 - eps) * da[j] + eps * db[j];
        let d1 = (1.0 - eps) * da[j + 1] + eps * db[j + 1];
        let k = (d1 - d0) * self.inv_dx[j];
        let tau = (xr - x0).clamp(0.0, x1 - x0);
        let w = (1.0 - eps) * ua[j] + eps * ub[j] + partial_mass(x0, d0, k, tau);
        let wn = (1.0 - eps) * ua[n - 1] + eps * ub[n - 1];
        let rb = if wn > 0.0 {
            (w / wn).clamp(0.0, 1.0).sqrt()
        } else {
            0.0
        };
        let phib = (self.cum[i]
            + self.kappa * wedge_angle(self.beta[i], self.r2[i], self.r2[i + 1], eps))
        .min(self.cum[i + 1]);
        disk_to_square(rb, phib)
    }

    /// ρ² of the star domain at azimuth `p` (for tests of the angular stage).
    #[cfg(test)]
    pub(crate) fn star_radius2_at(&self, p: f64) -> f64 {
        let (i, eps) = self.sector(p);
        super::angular::star_radius2(self.r2[i], self.r2[i + 1], eps)
    }
}

/// The disk radii x_j = √(1 − cos θ_j) of a completed grid's parallels, with the pole at exactly 0
/// and a horizon at π/2 at exactly 1.
pub(crate) fn parallel_radii(theta: &[f64]) -> Vec<f64> {
    let n = theta.len();
    let mut x: Vec<f64> = theta.iter().map(|&t| parallel_radius(t)).collect();
    x[0] = 0.0;
    if (theta[n - 1] - PI / 2.0).abs() < 1e-15 {
        x[n - 1] = 1.0;
    }
    x
}

/// The largest i ≤ `last` with a_i ≤ x (0 if none), for non-decreasing `a`, starting from the guess
/// of a guide table whose cell k covers [k, k + 1)/`scale`. The guess may round to either side of x:
/// step back, then forward; on a well-built guide both loops run at most a step or two.
#[inline]
fn guided_search(a: &[f64], guide: &[u32], scale: f64, x: f64, last: usize) -> usize {
    let k = ((x * scale) as usize).min(guide.len() - 1);
    let mut i = (guide[k] as usize).min(last);
    while i > 0 && a[i] > x {
        i -= 1;
    }
    while i < last && a[i + 1] <= x {
        i += 1;
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mapping::complete::complete;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn random_core(seed: u64, n: usize, m: usize, zeros: bool) -> HdsCore {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut theta: Vec<f64> = (0..n).map(|_| rng.gen_range(0.0..90.0)).collect();
        theta[0] = 0.0;
        theta[n - 1] = 90.0;
        theta.sort_by(f64::total_cmp);
        theta.dedup();
        let mut phi: Vec<f64> = (0..m).map(|_| rng.gen_range(0.0..360.0)).collect();
        phi[0] = 0.0;
        phi.sort_by(f64::total_cmp);
        phi.dedup();
        let values: Vec<Vec<f64>> = phi
            .iter()
            .map(|_| {
                theta
                    .iter()
                    .map(|_| {
                        let v: f64 = rng.gen();
                        if zeros && v < 0.4 {
                            0.0
                        } else {
                            v
                        }
                    })
                    .collect()
            })
            .collect();
        let mut values = values;
        values[0][0] += 1.0;
        let d = Diagram::from_degrees(&theta, &phi, &values).unwrap();
        HdsCore::build(
            complete(&d, PI / 2.0, false, d.max_value())
                .unwrap()
                .diagram,
        )
        .unwrap()
    }

    /// §4.4 and §12: Σγ^i = 2π and the star domain has the area π of the B-disk.
    #[test]
    fn wedges_cover_the_circle_and_the_star_has_area_pi() {
        for seed in 0..50 {
            let c = random_core(
                seed,
                2 + seed as usize % 20,
                1 + seed as usize % 40,
                seed % 2 == 0,
            );
            let cum = c.wedge_cumulative();
            assert_eq!(cum[0], 0.0);
            assert_eq!(*cum.last().unwrap(), TAU);
            assert!((c.kappa - 1.0).abs() < 1e-14, "Σγ = 2π/{}", c.kappa);
            assert!(cum.windows(2).all(|w| w[0] <= w[1]));
            let area: f64 = (0..c.m)
                .map(|i| c.beta[i] * (c.r2[i] + c.r2[i + 1]) / 4.0)
                .sum();
            assert!((area - PI).abs() < 1e-13);
        }
    }

    /// M_C preserves area pointwise: dφ_C/dφ_B = 1/ρ(φ_C)² (with r_C = r_B ρ, the area ratio is 1).
    #[test]
    fn angular_stage_preserves_area() {
        let c = random_core(3, 8, 9, false);
        let phi_c = |phib: f64| {
            let i = c.cum.partition_point(|&g| g <= phib).clamp(1, c.m) - 1;
            let e = solve_wedge(c.beta[i], c.r2[i], c.r2[i + 1], (phib - c.cum[i]) / c.kappa);
            c.phi[i] + e * c.beta[i]
        };
        for k in 1..200 {
            let pb = TAU * (k as f64 + 0.37) / 200.0;
            let h = 1e-7;
            let fd = (phi_c(pb + h) - phi_c(pb - h)) / (2.0 * h);
            let rho2 = c.star_radius2_at(phi_c(pb));
            assert!((fd * rho2 - 1.0).abs() < 1e-5, "{fd} {rho2}");
        }
    }
}
