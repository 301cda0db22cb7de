//! The HDS map of a **convex combination of normalised diagrams**, read from the tables of its
//! parts without building new ones (issue 26: a tabulated BRDF's slice for an incident direction
//! between the tabulated ones).
//!
//! Let maps k = 1..K share one grid (the same parallels and meridians after completion) and let
//! p_k = D_k / (2T_k) be their exact densities. For weights w_k ≥ 0 with Σ w_k = 1 the mixture
//! p = Σ w_k p_k is, up to the factor 2, the disk density D = Σ c_k D_k with c_k = w_k / T_k, whose
//! total is T = Σ c_k T_k = 1. Every table of docs/DERIVATION.md §4 is linear in the diagram values
//! once the total is fixed:
//!
//! * the radial masses U(i, j) = Σ c_k U_k(i, j) and nodal densities d(i, j) = Σ c_k d_k(i, j);
//! * the squared star radii R_i² = U(i, N−1)/s with s = T/π = 1/π, so R_i² = Σ w_k R²_{k,i};
//! * the cumulative wedge angles Γ_i = Σ w_k Γ_{k,i} (each Γ_k ends at 2π, so Γ does too).
//!
//! So the map of the mixture is the HDS map of the diagram Σ c_k d_k **exactly** (the tests build
//! [`HemisphereMap::new`] of that diagram and compare to round-off). This file keeps the blending
//! weights and nothing else of the map: the stages' own forward and inverse run over the blended
//! entries read on the fly (issue 36, as Mitsuba's `Marginal2D` blends its slices inside one
//! lookup): M_C over the blended wedges (`angular::Wedges`, `angular::forward_on`,
//! `angular::inverse_on`), M_D over a row of 2K table rows (`radial::RadialRow`,
//! `radial::forward_on`, `radial::inverse_on`), M_B and M_E as for one map. The searches
//! are bracketed by the parts' own guide tables: a blended cumulative is a convex combination of
//! the parts' normalised cumulatives, so its answer lies between theirs. The pdf is Σ w_k p_k, the
//! exact density of the map; the map is continuous in the weights, so a family of weights that is
//! continuous in a parameter gives maps continuous in that parameter.

use super::angular::{forward_on, inverse_on, Angular, Wedges};
use super::concentric::{disk_to_square, square_to_disk};
use super::hds::HdsCore;
use super::lift::{disk_to_sphere, sphere_to_disk_azimuth, sphere_to_disk_radius};
use super::radial::{self, Radial, RadialRow, RadialView};
use super::HemisphereMap;
use crate::sampler::{Point2, Sample, Vec3};

/// The most maps a [`BlendedMap`] combines (bilinear interpolation between four slices).
pub const MAX_PARTS: usize = 4;

/// Why a set of maps cannot be blended.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BlendError {
    /// No part with a positive weight, or more than [`MAX_PARTS`] parts.
    #[error("a blend needs 1 to {MAX_PARTS} parts with positive weights, got {parts}")]
    PartCount {
        /// Number of parts with positive weight given.
        parts: usize,
    },
    /// A weight is negative or not finite, or the weights do not sum to 1 (within 1e-12).
    #[error("blend weights must be finite, ≥ 0 and sum to 1; got sum {sum}")]
    Weights {
        /// Their sum.
        sum: f64,
    },
    /// The parts' completed grids differ.
    #[error("part #{part} has a different grid (parallels or meridians) from part #0")]
    Grid {
        /// The index of the first part whose grid differs.
        part: usize,
    },
}

/// The HDS map of the mixture Σ w_k p_k of maps that share a grid (see the module
/// documentation). Cheap to make (no allocation, no table built): one per incident direction.
#[derive(Debug, Clone, Copy)]
pub struct BlendedMap<'a> {
    cores: [&'a HdsCore; MAX_PARTS],
    /// Mixture weights w_k.
    w: [f64; MAX_PARTS],
    /// c_k = w_k / T_k: the weights of the un-normalised tables U_k and d_k.
    c: [f64; MAX_PARTS],
    len: usize,
    /// Σ w_k κ_k: the blended Γ_M / Σγ (1 up to round-off).
    kappa: f64,
    /// 1 / (2 Σ c_k T_k): the pdf per unit of blended disk density.
    inv_2t: f64,
}

impl<'a> BlendedMap<'a> {
    /// The blend of `parts` (map, weight): weights ≥ 0 summing to 1, parts of weight 0 dropped,
    /// at most [`MAX_PARTS`] left, all on the same completed grid.
    pub fn new(parts: &[(&'a HemisphereMap, f64)]) -> Result<Self, BlendError> {
        let sum: f64 = parts.iter().map(|p| p.1).sum();
        if parts.iter().any(|p| !(p.1 >= 0.0 && p.1.is_finite())) || !((sum - 1.0).abs() <= 1e-12) {
            return Err(BlendError::Weights { sum });
        }
        let kept: Vec<_> = parts.iter().filter(|p| p.1 > 0.0).collect();
        if kept.is_empty() || kept.len() > MAX_PARTS {
            return Err(BlendError::PartCount { parts: kept.len() });
        }
        let g0 = kept[0].0.diagram();
        for (k, p) in kept.iter().enumerate().skip(1) {
            let g = p.0.diagram();
            if g.theta() != g0.theta() || g.phi() != g0.phi() {
                return Err(BlendError::Grid { part: k });
            }
        }
        let mut cores = [kept[0].0.core(); MAX_PARTS];
        let mut w = [0.0; MAX_PARTS];
        for (k, p) in kept.iter().enumerate() {
            cores[k] = p.0.core();
            w[k] = p.1;
        }
        Ok(Self::from_cores(cores, w, kept.len()))
    }

    /// The blend of the first `len` cores with weights `w` (positive, summing to 1), whose grids
    /// the caller has checked to be equal.
    pub(crate) fn from_cores(
        cores: [&'a HdsCore; MAX_PARTS],
        w: [f64; MAX_PARTS],
        len: usize,
    ) -> Self {
        let mut totals = [0.0; MAX_PARTS];
        let mut kappas = [0.0; MAX_PARTS];
        for k in 0..len {
            totals[k] = cores[k].total();
            kappas[k] = cores[k].tables().angular.kappa;
        }
        Self::from_parts(cores, w, totals, kappas, len)
    }

    /// [`BlendedMap::from_cores`] with each core's total T_k and κ_k given by the caller (read
    /// from a contiguous array instead of each core's tables); the same arithmetic, so the same
    /// bits.
    pub(crate) fn from_parts(
        cores: [&'a HdsCore; MAX_PARTS],
        w: [f64; MAX_PARTS],
        totals: [f64; MAX_PARTS],
        kappas: [f64; MAX_PARTS],
        len: usize,
    ) -> Self {
        let mut c = [0.0; MAX_PARTS];
        let (mut kappa, mut t) = (0.0, 0.0);
        for k in 0..len {
            let total = totals[k];
            c[k] = w[k] / total;
            t += c[k] * total;
            kappa += w[k] * kappas[k];
        }
        BlendedMap {
            cores,
            w,
            c,
            len,
            kappa,
            inv_2t: 0.5 / t,
        }
    }

    #[inline]
    fn angular(&self, k: usize) -> &'a Angular {
        &self.cores[k].tables().angular
    }
    #[inline]
    fn radial(&self, k: usize) -> &'a Radial {
        &self.cores[k].tables().radial
    }

    /// The coefficients of the rows (k, meridian) that the radial stage of sector (i, i1) at
    /// fraction `eps` combines: (core, meridian, coefficient), 2·len entries.
    #[inline]
    fn rows(&self, i: usize, i1: usize, eps: f64) -> BlendRow<'_, 'a> {
        let mut rows = [(0, 0, 0.0); 2 * MAX_PARTS];
        for k in 0..self.len {
            rows[2 * k] = (k, i, self.c[k] * (1.0 - eps));
            rows[2 * k + 1] = (k, i1, self.c[k] * eps);
        }
        BlendRow {
            map: self,
            rows,
            len: 2 * self.len,
        }
    }

    /// The forward map: a point of the unit square to (direction, blended disk density there):
    /// the stages' own M_C and M_D ([`forward_on`], [`radial::forward_on`]) over the blended
    /// wedges and rows.
    fn forward(&self, uv: Point2) -> (Vec3, f64) {
        let (rb, phib) = square_to_disk(uv);
        let a0 = self.angular(0);
        let (i, eps, phi) = forward_on(self, a0.view().beta, a0.view().phi, phib);
        let r0 = self.radial(0);
        let row = self.rows(i, a0.next(i), eps);
        let (xr, seg) = radial::forward_on(r0.view().x, r0.view().radial_k, &row, rb);
        let dir = disk_to_sphere(xr, phi);
        if dir[0] == 0.0 && dir[1] == 0.0 {
            return (dir, self.density(dir));
        }
        (dir, r0.density_on(seg, sphere_to_disk_radius(dir)))
    }

    /// The blended disk density D at a direction of the upper hemisphere.
    #[inline]
    fn density(&self, dir: Vec3) -> f64 {
        let xr = sphere_to_disk_radius(dir);
        let a0 = self.angular(0);
        let (i, eps) = a0.sector(sphere_to_disk_azimuth(dir));
        let i1 = a0.next(i);
        (0..self.len)
            .map(|k| self.c[k] * self.radial(k).density(xr, i, i1, eps))
            .sum()
    }

    /// The map at a point of the unit square: the direction and its exact density (per sr).
    pub fn sample(&self, u: Point2) -> Sample {
        let (direction, d) = self.forward(u);
        Sample {
            direction,
            pdf: d * self.inv_2t,
        }
    }

    /// The exact density of [`BlendedMap::sample`] per steradian: Σ w_k pdf_k(ω); 0 below the
    /// horizon.
    pub fn pdf(&self, dir: Vec3) -> f64 {
        if !(dir[2] >= 0.0) {
            return 0.0;
        }
        self.density(dir) * self.inv_2t
    }

    /// The inverse map (closed form), `None` below the horizon or for a non-finite direction.
    pub fn invert(&self, dir: Vec3) -> Option<Point2> {
        if !(dir[2] >= 0.0) || !dir.iter().all(|c| c.is_finite()) {
            return None;
        }
        let xr = sphere_to_disk_radius(dir);
        let a0 = self.angular(0);
        let (i, eps) = a0.sector(sphere_to_disk_azimuth(dir));
        let row = self.rows(i, a0.next(i), eps);
        let r0 = self.radial(0);
        let j = r0.segment_of(xr);
        let rb = radial::inverse_on(r0.view().x, r0.view().inv_dx, j, &row, xr);
        let phib = inverse_on(self, a0.view().beta, i, eps);
        Some(disk_to_square(rb, phib))
    }

    /// The mixture weights of the parts kept (positive, summing to 1).
    pub fn weights(&self) -> &[f64] {
        &self.w[..self.len]
    }
}

/// The blended wedges: Γ_i = Σ w_k Γ_{k,i}, R_i² = Σ w_k R²_{k,i}, κ = Σ w_k κ_k; the wedge
/// search is bracketed by the parts' own (each part's Γ_lo ≤ φ_B, so the blend's is too).
impl Wedges for BlendedMap<'_> {
    #[inline]
    fn gamma(&self, i: usize) -> f64 {
        (0..self.len)
            .map(|k| self.w[k] * self.angular(k).view().cum[i])
            .sum()
    }
    #[inline]
    fn rho2(&self, i: usize) -> f64 {
        (0..self.len)
            .map(|k| self.w[k] * self.angular(k).view().r2[i])
            .sum()
    }
    #[inline]
    fn scale(&self) -> f64 {
        self.kappa
    }
    #[inline]
    fn find(&self, phib: f64) -> usize {
        let (mut lo, mut hi) = (usize::MAX, 0);
        for k in 0..self.len {
            let i = self.angular(k).wedge(phib);
            lo = lo.min(i);
            hi = hi.max(i);
        }
        // Largest i in [lo, hi] with Γ_i ≤ φ_B (Γ_lo ≤ φ_B holds: every part's Γ_lo is).
        while hi > lo {
            let mid = (lo + hi).div_ceil(2);
            if self.gamma(mid) <= phib {
                lo = mid;
            } else {
                hi = mid - 1;
            }
        }
        lo
    }
}

/// The radial row of a blend at one azimuth: 2K rows of the parts' tables, each with its
/// coefficient c_k·(1 − ε) or c_k·ε.
struct BlendRow<'m, 'a> {
    map: &'m BlendedMap<'a>,
    rows: [(usize, usize, f64); 2 * MAX_PARTS],
    len: usize,
}

impl BlendRow<'_, '_> {
    /// Entry j of the blended row of one table (u or d): Σ a · table[r][j] over the 2K rows.
    #[inline]
    fn mix(&self, j: usize, table: impl Fn(RadialView<'_, f64>) -> &[f64]) -> f64 {
        self.rows[..self.len]
            .iter()
            .map(|&(k, r, a)| {
                let v = self.map.radial(k).view();
                a * table(v)[r * v.n + j]
            })
            .sum()
    }
}

impl RadialRow for BlendRow<'_, '_> {
    #[inline]
    fn u(&self, j: usize) -> f64 {
        self.mix(j, |v| v.u)
    }
    #[inline]
    fn d(&self, j: usize) -> f64 {
        self.mix(j, |v| v.d)
    }
    /// Every row's own radial guide bracket, united (a convex combination, as in M_D).
    #[inline]
    fn bracket(&self, k: usize) -> (usize, usize) {
        let (mut lo, mut hi) = (usize::MAX, 0usize);
        for &(p, r, _) in &self.rows[..self.len] {
            let v = self.map.radial(p).view();
            let kg = v.radial_k;
            let g = &v.radial_guide[r * (kg + 1)..(r + 1) * (kg + 1)];
            lo = lo.min(g[k] as usize);
            hi = hi.max(g[k + 1] as usize);
        }
        (lo, hi)
    }
}

/// The exact density of a mixture, written independently of the tables (for tests).
#[cfg(test)]
pub(crate) fn mixture_pdf(parts: &[(&HemisphereMap, f64)], dir: Vec3) -> f64 {
    use crate::Sampler;
    parts.iter().map(|(m, w)| w * m.pdf(dir)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Diagram, Sampler};
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn random_map(
        rng: &mut Xoshiro256PlusPlus,
        theta: &[f64],
        phi: &[f64],
        zeros: bool,
    ) -> HemisphereMap {
        let values = crate::synthetic::grid_values(phi.len(), theta.len(), |_, _| {
            let v: f64 = rng.gen();
            if zeros && v < 0.3 {
                0.0
            } else {
                v * 10.0
            }
        });
        let mut values = values;
        values[0][1] += 1.0;
        HemisphereMap::new(&Diagram::from_degrees(theta, phi, &values).unwrap()).unwrap()
    }

    /// The blend is the HDS map of the blended diagram: same directions, same pdf, to round-off.
    #[test]
    fn blend_equals_map_of_blended_diagram() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(26);
        for trial in 0..12 {
            let theta: Vec<f64> = (0..=6 + trial % 5)
                .map(|j| 90.0 * j as f64 / (6 + trial % 5) as f64)
                .collect();
            let m = 3 + trial % 7;
            let phi: Vec<f64> = (0..m).map(|i| 360.0 * i as f64 / m as f64).collect();
            let k = 1 + trial % 4;
            let maps: Vec<HemisphereMap> = (0..k)
                .map(|_| random_map(&mut rng, &theta, &phi, trial % 2 == 0))
                .collect();
            let mut w: Vec<f64> = (0..k).map(|_| rng.gen_range(0.05..1.0)).collect();
            let sw: f64 = w.iter().sum();
            w.iter_mut().for_each(|x| *x /= sw);
            let parts: Vec<(&HemisphereMap, f64)> = maps.iter().zip(w.iter().copied()).collect();
            let blend = BlendedMap::new(&parts).unwrap();
            // The blended diagram Σ c_k d_k, built as a plain diagram.
            let n = theta.len();
            let mut vals = vec![vec![0.0; n]; m];
            for (map, wk) in &parts {
                let c = wk / map.disk_power();
                let d = map.diagram();
                for (i, row) in vals.iter_mut().enumerate() {
                    for (j, v) in row.iter_mut().enumerate() {
                        *v += c * d.value(i, j);
                    }
                }
            }
            let reference =
                HemisphereMap::new(&Diagram::from_degrees(&theta, &phi, &vals).unwrap()).unwrap();
            for _ in 0..400 {
                let u = [rng.gen::<f64>(), rng.gen::<f64>()];
                let a = blend.sample(u);
                let b = reference.sample(u);
                let dd: f64 = (0..3)
                    .map(|c| (a.direction[c] - b.direction[c]).abs())
                    .fold(0.0, f64::max);
                assert!(
                    dd < 1e-11,
                    "trial {trial} u {u:?}: {:?} vs {:?}",
                    a.direction,
                    b.direction
                );
                assert!(
                    (a.pdf - b.pdf).abs() <= 1e-10 * b.pdf.max(1e-3),
                    "pdf {} vs {}",
                    a.pdf,
                    b.pdf
                );
                let p = blend.pdf(a.direction);
                assert!(
                    (p - a.pdf).abs() <= 1e-9 * a.pdf.max(1e-6),
                    "pdf() {p} vs sample {}",
                    a.pdf
                );
                assert!((mixture_pdf(&parts, a.direction) - p).abs() <= 1e-9 * p.max(1e-6));
                if a.pdf > 0.0 {
                    let back = blend.invert(a.direction).unwrap();
                    let e = (back[0] - u[0]).abs().max((back[1] - u[1]).abs());
                    assert!(e < 1e-10, "round trip {u:?} -> {back:?}");
                }
            }
        }
    }

    /// Continuity in the weights: moving weight from one part to the other moves every sample
    /// continuously (no jump as a weight crosses 0 or 1).
    #[test]
    fn blend_is_continuous_in_the_weights() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let theta: Vec<f64> = (0..=9).map(|j| 10.0 * j as f64).collect();
        let phi: Vec<f64> = (0..8).map(|i| 45.0 * i as f64).collect();
        let a = random_map(&mut rng, &theta, &phi, false);
        let b = random_map(&mut rng, &theta, &phi, false);
        let us: Vec<Point2> = (0..200).map(|_| [rng.gen(), rng.gen()]).collect();
        for &t in &[0.0, 1.0] {
            for &h in &[1e-6, 1e-9] {
                let tt = if t == 0.0 { h } else { 1.0 - h };
                let edge = BlendedMap::new(&[(&a, 1.0 - t), (&b, t)]).unwrap();
                let near = BlendedMap::new(&[(&a, 1.0 - tt), (&b, tt)]).unwrap();
                for u in &us {
                    let (p, q) = (edge.sample(*u).direction, near.sample(*u).direction);
                    let d: f64 = (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0, f64::max);
                    assert!(d < 1e3 * h, "jump {d} at weight {tt}");
                }
            }
        }
    }

    #[test]
    fn refuses_bad_parts() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let a = random_map(&mut rng, &[0.0, 45.0, 90.0], &[0.0, 180.0], false);
        let b = random_map(&mut rng, &[0.0, 30.0, 90.0], &[0.0, 180.0], false);
        assert_eq!(
            BlendedMap::new(&[(&a, 0.5), (&b, 0.5)]).unwrap_err(),
            BlendError::Grid { part: 1 }
        );
        assert!(matches!(
            BlendedMap::new(&[(&a, 0.5)]),
            Err(BlendError::Weights { .. })
        ));
        assert!(matches!(
            BlendedMap::new(&[(&a, f64::NAN)]),
            Err(BlendError::Weights { .. })
        ));
        assert!(matches!(
            BlendedMap::new(&[]),
            Err(BlendError::Weights { .. })
        ));
    }
}
