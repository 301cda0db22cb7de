//! The precomputed tables of docs/DERIVATION.md §4 and the composed map F = M_E ∘ M_D ∘ M_C ∘ M_B
//! on one disk.
//!
//! `HdsCore` works on a *completed* grid: θ_0 = 0 (the pole), φ_0 = 0, and θ_{N−1} anywhere up to
//! π/2 for a hemisphere (π for the whole-sphere Lambert lift): the map covers the zone
//! [0, θ_{N−1}], whose disk has radius x_{N−1} = √2 sin(θ_{N−1}/2). The public samplers in this
//! module complete a user's diagram first (docs/DERIVATION.md §8.1, A15) and then build a core.

use super::angular::{Angular, AngularView};
use super::bound::{density_ratio_range, density_ratio_range_grid};
use super::concentric::{disk_to_square, square_to_disk};
use super::lift::{disk_to_sphere, parallel_radius, sphere_to_disk_azimuth, sphere_to_disk_radius};
use super::radial::{Radial, RadialView};
use crate::diagram::{Diagram, DiagramError};
use crate::sampler::Vec3;
use std::f64::consts::PI;

/// The read-only view of one map's tables through which the vector kernels read them (see
/// [`AngularView`], [`RadialView`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct TablesView<'a, T = f64> {
    /// M_C's tables.
    pub(crate) angular: AngularView<'a, T>,
    /// M_D's tables.
    pub(crate) radial: RadialView<'a, T>,
}

/// One HDS map's tables in element type `T`: those of its two table-driven stages, M_C
/// ([`Angular`]) and M_D ([`Radial`]); M_B and M_E need no tables. The one table type of every
/// map: an f64 map's own ([`HdsCore`]), a float32 map's (`T = f32`) and its exact twin (the f32
/// values widened), and the blob's (`mapping::blob` writes and reads them field by field).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Tables<T = f64> {
    /// M_C: meridians, star radii, wedge angles.
    pub(crate) angular: Angular<T>,
    /// M_D: parallel radii, nodal densities, radial masses.
    pub(crate) radial: Radial<T>,
}

impl<T: Copy> Tables<T> {
    /// The read-only view that the vector kernels read.
    #[inline]
    pub(crate) fn view(&self) -> TablesView<'_, T> {
        TablesView {
            angular: self.angular.view(),
            radial: self.radial.view(),
        }
    }

    /// The same tables with every float converted by `f`.
    pub(crate) fn map<U>(&self, f: impl Fn(T) -> U + Copy) -> Tables<U> {
        Tables {
            angular: self.angular.map(f),
            radial: self.radial.map(f),
        }
    }

    /// Bytes of the tables' contents.
    pub(crate) fn table_bytes(&self) -> usize {
        self.angular.table_bytes() + self.radial.table_bytes()
    }
}

/// One HDS map (docs/DERIVATION.md §4): its [`Tables`] plus the completed diagram it was built
/// from.
#[derive(Debug, Clone)]
pub(crate) struct HdsCore {
    /// M_C's and M_D's tables.
    tables: Tables,
    /// T = ∫_disk D dA (docs/DERIVATION.md §4.3), in diagram units × disk area.
    total: f64,
    /// The completed diagram, kept by the maps that hand it out ([`crate::HemisphereMap::diagram`]);
    /// only its grid for the sphere maps, whose target reads the same values from `radial.d`
    /// (one copy of the nodal values instead of two).
    diagram: KeptDiagram,
    /// ∫ target dω over the domain (diagram units × sr).
    target_total: f64,
    /// Guaranteed range of D/B over directions where B > 0 (B: the (θ, φ)-bilinear interpolant):
    /// set at build time, or on the first [`HdsCore::db_range`] call for a core built by
    /// [`HdsCore::build_lean`] (the same numbers, from the same grid and values).
    db_range: std::sync::OnceLock<(f64, f64)>,
}

/// What an [`HdsCore`] keeps of its completed diagram.
#[derive(Debug, Clone)]
enum KeptDiagram {
    /// The whole diagram (its values are a copy of `radial.d`).
    Diagram(Diagram),
    /// Only the grid: parallels θ_j (N entries) and meridians φ_i (M entries), radians.
    Grid { theta: Vec<f64>, phi: Vec<f64> },
}

impl KeptDiagram {
    fn theta(&self) -> &[f64] {
        match self {
            KeptDiagram::Diagram(d) => d.theta(),
            KeptDiagram::Grid { theta, .. } => theta,
        }
    }
    fn phi(&self) -> &[f64] {
        match self {
            KeptDiagram::Diagram(d) => d.phi(),
            KeptDiagram::Grid { phi, .. } => phi,
        }
    }
}

impl HdsCore {
    /// The radial tables' nodal densities and cumulative masses, taken out (see
    /// [`Radial::take_d_u`]): the core is consumed by the caller's conversion.
    pub(super) fn take_d_u(&mut self) -> (Vec<f64>, Vec<f64>) {
        self.tables.radial.take_d_u()
    }

    /// Drops the radial guide tables of a core about to be converted to float32 (which makes its
    /// own): see [`Radial::drop_radial_guide`].
    pub(super) fn drop_radial_guide(&mut self) {
        self.tables.radial.drop_radial_guide()
    }

    /// Whether the explicit kernels can index this map's tables (indices below 2³¹; every map
    /// that fits in memory today, checked anyway).
    #[cfg(target_arch = "x86_64")]
    pub(crate) fn explicit_indexable(&self) -> bool {
        let lim = 1usize << 31;
        let (a, r) = (self.tables.angular.view(), self.tables.radial.view());
        r.u.len() < lim
            && r.radial_guide.len() < lim
            && a.wedge_guide.len() < lim
            && a.m < lim
            && r.n < lim
    }

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
        Self::assemble(diagram, Some(db_range), true)
    }

    /// As [`HdsCore::build`], without keeping the completed diagram ([`HdsCore::diagram`] is not
    /// available; the target is read from the tables): the sphere maps' cores.
    /// The range of D/B is not computed here but on the first [`HdsCore::db_range`] call (sampling
    /// never needs it).
    pub(crate) fn build_lean(diagram: Diagram) -> Result<Self, DiagramError> {
        Self::assemble(diagram, None, false)
    }

    /// As [`HdsCore::build_with_range`], without keeping the completed diagram (see
    /// [`HdsCore::build_lean`]).
    pub(crate) fn build_lean_with_range(
        diagram: Diagram,
        db_range: (f64, f64),
    ) -> Result<Self, DiagramError> {
        Self::assemble(diagram, Some(db_range), false)
    }

    /// The tables of `diagram`; `keep`: whether the core keeps the diagram itself too; `db_range`:
    /// the range of D/B if known (else computed on first use).
    fn assemble(
        diagram: Diagram,
        db_range: Option<(f64, f64)>,
        keep: bool,
    ) -> Result<Self, DiagramError> {
        let n = diagram.n_parallels();
        debug_assert!(n >= 2 && diagram.theta()[0] == 0.0 && diagram.phi()[0] == 0.0);
        let x = parallel_radii(diagram.theta());
        let target_total = diagram.integral();
        let (kept, values) = if keep {
            let v = diagram.values().to_vec();
            (KeptDiagram::Diagram(diagram), v)
        } else {
            let (theta, phi, v) = diagram.into_parts();
            (KeptDiagram::Grid { theta, phi }, v)
        };
        // The nodal densities are the diagram's values themselves (moved, not copied, when the
        // diagram is not kept).
        let radial = Radial::build(x, values);
        let (angular, total) = Angular::build(kept.phi(), |i| radial.meridian_mass(i));
        if !(total > 0.0 && total.is_finite()) {
            return Err(DiagramError::UnresolvedLight);
        }
        Ok(HdsCore {
            tables: Tables { angular, radial },
            total,
            diagram: kept,
            target_total,
            db_range: match db_range {
                Some(r) => std::sync::OnceLock::from(r),
                None => std::sync::OnceLock::new(),
            },
        })
    }

    /// ∫ D dA over the cells of the completed grid that lie outside θ ∈ [`lo`, `hi`] (radians,
    /// the measured range; completion puts nodes exactly at its ends): the map's power there,
    /// exactly, in the units of [`HdsCore::total`].
    pub(crate) fn power_outside(&self, lo: f64, hi: f64) -> f64 {
        let theta = self.diagram.theta();
        let beta = self.tables.angular.beta();
        let mut p = 0.0;
        for j in 0..theta.len() - 1 {
            if theta[j] >= lo && theta[j + 1] <= hi {
                continue;
            }
            for (i, b) in beta.iter().enumerate() {
                let i1 = self.tables.angular.next(i);
                let du = |r: usize| self.tables.radial.segment_mass_of(r, j);
                p += b * (du(i) + du(i1)) / 4.0;
            }
        }
        p
    }

    /// The tables of M_C and M_D (for the blended maps of [`super::blend`], the float32
    /// conversion and the blob).
    pub(crate) fn tables(&self) -> &Tables {
        &self.tables
    }

    /// The read-only view of the tables that the vector kernels read.
    #[inline]
    pub(crate) fn view(&self) -> TablesView<'_> {
        self.tables.view()
    }

    /// T = ∫_disk D dA.
    pub(crate) fn total(&self) -> f64 {
        self.total
    }
    /// ∫ target dω over the domain, in diagram units × sr.
    pub(crate) fn target_total(&self) -> f64 {
        self.target_total
    }
    /// The completed diagram, for a core that keeps it ([`HdsCore::build`],
    /// [`HdsCore::build_with_range`]: the hemisphere maps).
    pub(crate) fn diagram(&self) -> &Diagram {
        match &self.diagram {
            KeptDiagram::Diagram(d) => d,
            KeptDiagram::Grid { .. } => {
                unreachable!(
                    "only the hemisphere maps' cores hand out their diagram, and they keep it"
                )
            }
        }
    }
    /// The completed diagram interpolated bilinearly in (θ, φ) ([`Diagram::interpolate`], from
    /// the same values): the target density, in the completed diagram's units.
    pub(crate) fn target_value(&self, theta: f64, phi: f64) -> f64 {
        let (t, p) = (self.diagram.theta(), self.diagram.phi());
        crate::diagram::interpolate_grid(t, p, self.tables.radial.view().d, theta, phi)
    }
    /// Number of parallels N of the completed grid.
    pub(crate) fn n_parallels(&self) -> usize {
        self.diagram.theta().len()
    }
    /// Bytes held beside the tables for the completed diagram: its grid's angles (θ, φ), and its
    /// values when the core keeps the whole diagram.
    pub(crate) fn diagram_bytes(&self) -> usize {
        let grid = 8 * (self.diagram.theta().len() + self.diagram.phi().len());
        match &self.diagram {
            KeptDiagram::Diagram(d) => grid + 8 * d.values().len(),
            KeptDiagram::Grid { .. } => grid,
        }
    }
    /// Guaranteed (min, max) of D/B over directions where the target is positive.
    /// Computed on the first call for a core built by [`HdsCore::build_lean`] and kept: the same
    /// numbers as [`super::bound::density_ratio_range`] of the completed diagram, since the
    /// parallel radii and the nodal densities are its own (`radial.x`, `radial.d`).
    pub(crate) fn db_range(&self) -> (f64, f64) {
        *self.db_range.get_or_init(|| {
            let r = self.tables.radial.view();
            density_ratio_range_grid(self.diagram.theta(), r.d, r.x)
        })
    }

    /// The range of D/B computed now from the completed grid, whether or not it is cached (for
    /// the tests that the lazy bound equals the eager one).
    #[cfg(test)]
    pub(crate) fn db_range_eager(&self) -> (f64, f64) {
        let x = parallel_radii(self.diagram.theta());
        density_ratio_range_grid(self.diagram.theta(), self.tables.radial.view().d, &x)
    }

    /// Whether the range of D/B is known (set at build time or computed already).
    #[cfg(test)]
    pub(crate) fn db_range_cached(&self) -> bool {
        self.db_range.get().is_some()
    }

    /// Bytes of the precomputed tables (the vectors' lengths, not their capacities), including the
    /// nodal densities and angles that the run time needs, excluding the diagram kept for the target.
    pub(crate) fn memory_bytes(&self) -> usize {
        self.tables.table_bytes() + std::mem::size_of::<Self>()
    }

    /// [`HdsCore::memory_bytes`] of the core that [`HdsCore::build`] would make from `diagram`.
    pub(crate) fn table_bytes(diagram: &Diagram) -> usize {
        let (n, m) = (diagram.n_parallels(), diagram.n_meridians());
        let radial_k = n.div_ceil(2).max(1);
        8 * (n + (m + 1) + m + 2 * m * n + m + 2 * (m + 1))
            + 8 * (n - 1)
            + 4 * (2 * m + 2 * n + m * (radial_k + 1))
            + std::mem::size_of::<Self>()
    }

    /// The intermediate points of the forward map (for pictures and tests).
    pub(crate) fn stages(&self, uv: [f64; 2]) -> super::Stages {
        let (rb, phib) = square_to_disk(uv);
        let (i, eps, phi) = self.tables.angular.forward(phib);
        let rho2 = self.tables.angular.star_radius2(i, eps);
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

    /// The forward map F = M_E ∘ M_D ∘ M_C ∘ M_B: a point of the unit square to (direction, D at
    /// the sample).
    #[inline]
    pub(crate) fn sample(&self, uv: [f64; 2]) -> (Vec3, f64) {
        let (rb, phib) = square_to_disk(uv); // M_B
        let (i, eps, phi) = self.tables.angular.forward(phib); // M_C
        let i1 = self.tables.angular.next(i);
        let (xr, seg) = self.tables.radial.forward(rb, i, i1, eps); // M_D
        let dir = disk_to_sphere(xr, phi); // M_E
                                           // The density at the radius the returned direction has (what `density` reads), not at xr:
                                           // they differ by the lift's round-off, which a steep segment (a zero guard band) would
                                           // turn into a visible disagreement between sample() and pdf().
        let dens = self
            .tables
            .radial
            .density_on(seg, sphere_to_disk_radius(dir));
        if dir[0] == 0.0 && dir[1] == 0.0 {
            // The pole: every meridian meets there, and `density` reads meridian 0 (φ = 0);
            // the sample carries that same value, so sample() and pdf() agree at (±0, ±0, 1).
            return (dir, self.density(dir));
        }
        (dir, dens)
    }

    /// The disk density D at a direction (bilinear in (x, φ)), the numerator of the pdf.
    #[inline]
    pub(crate) fn density(&self, dir: Vec3) -> f64 {
        let xr = sphere_to_disk_radius(dir);
        let (i, eps) = self.tables.angular.sector(sphere_to_disk_azimuth(dir));
        self.tables
            .radial
            .density(xr, i, self.tables.angular.next(i), eps)
    }

    /// The inverse map: a direction to its point of the unit square (closed form,
    /// docs/DERIVATION.md §5, §6.5, §7.4), the four inverses in reverse order.
    #[inline]
    pub(crate) fn invert(&self, dir: Vec3) -> [f64; 2] {
        let xr = sphere_to_disk_radius(dir); // M_E⁻¹ (radius)
        let (i, eps) = self.tables.angular.sector(sphere_to_disk_azimuth(dir)); // M_E⁻¹ (azimuth)
        let rb = self
            .tables
            .radial
            .inverse(xr, i, self.tables.angular.next(i), eps); // M_D⁻¹
        let phib = self.tables.angular.inverse(i, eps); // M_C⁻¹
        disk_to_square(rb, phib) // M_B⁻¹
    }

    /// ρ² of the star domain at azimuth `p` (for tests of the angular stage).
    #[cfg(test)]
    pub(crate) fn star_radius2_at(&self, p: f64) -> f64 {
        let (i, eps) = self.tables.angular.sector(p);
        self.tables.angular.star_radius2(i, eps)
    }
}

/// The disk radii x_j = √(1 − cos θ_j) of a completed grid's parallels ([`parallel_radius`], M_E's
/// inverse in r), with the pole at exactly 0 and a horizon at π/2 at exactly 1.
pub(crate) fn parallel_radii(theta: &[f64]) -> Vec<f64> {
    let n = theta.len();
    let mut x: Vec<f64> = theta.iter().map(|&t| parallel_radius(t)).collect();
    x[0] = 0.0;
    if (theta[n - 1] - PI / 2.0).abs() < 1e-15 {
        x[n - 1] = 1.0;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mapping::angular::solve_wedge;
    use crate::mapping::complete::complete;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;
    use std::f64::consts::TAU;

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
        let values = crate::synthetic::grid_values(phi.len(), theta.len(), |_, _| {
            let v: f64 = rng.gen();
            if zeros && v < 0.4 {
                0.0
            } else {
                v
            }
        });
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

    /// docs/DERIVATION.md §4.4 and §12.2: Σγ^i = 2π and the star domain has the area π of the
    /// B-disk.
    #[test]
    fn wedges_cover_the_circle_and_the_star_has_area_pi() {
        for seed in 0..50 {
            let c = random_core(
                seed,
                2 + seed as usize % 20,
                1 + seed as usize % 40,
                seed % 2 == 0,
            );
            let a = &c.tables.angular;
            let cum = a.wedge_cumulative();
            assert_eq!(cum[0], 0.0);
            assert_eq!(*cum.last().unwrap(), TAU);
            assert!((a.kappa() - 1.0).abs() < 1e-14, "Σγ = 2π/{}", a.kappa());
            assert!(cum.windows(2).all(|w| w[0] <= w[1]));
            let (beta, r2) = (a.beta(), a.r2());
            let area: f64 = (0..a.meridians())
                .map(|i| beta[i] * (r2[i] + r2[i + 1]) / 4.0)
                .sum();
            assert!((area - PI).abs() < 1e-13);
        }
    }

    /// M_C preserves area pointwise: dφ_C/dφ_B = 1/ρ(φ_C)² (with r_C = r_B ρ, the area ratio is 1).
    #[test]
    fn angular_stage_preserves_area() {
        let c = random_core(3, 8, 9, false);
        let a = &c.tables.angular;
        let (cum, beta, r2, phi) = (a.wedge_cumulative(), a.beta(), a.r2(), a.phi());
        // M_C written out from its tables, independently of `Angular::forward`.
        let phi_c = |phib: f64| {
            let i = cum.partition_point(|&g| g <= phib).clamp(1, a.meridians()) - 1;
            let e = solve_wedge(beta[i], r2[i], r2[i + 1], (phib - cum[i]) / a.kappa());
            phi[i] + e * beta[i]
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
