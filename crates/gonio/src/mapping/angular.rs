//! M_C: the angular remap that gives every disk sector between two meridians its power
//! (docs/DERIVATION.md §5).
//!
//! The star domain S = {r ≤ ρ(φ)} has, in sector i with fraction ε = (φ − φ_i)/β_i,
//! ρ(φ)² = (1−ε)R_i² + εR_{i+1}², where R_i² = U(i, N−1)/s is the squared radius that meridian i's
//! power would fill at the constant density s. The wedge of the B-disk between the angles Γ_i and
//! Γ_i + γ (unit radius) is sent to the part of sector i between φ_i and φ_i + εβ_i that has the same
//! area:
//!
//! ```text
//! ½γ = ∫₀^{εβ} ½ρ² dφ  ⇔  (β/2)(R_{i+1}² − R_i²) ε² + βR_i² ε − γ = 0.
//! ```
//!
//! The stage inverts the marginal CDF in φ of the disk density; it preserves area pointwise
//! (dφ_C/dφ_B = 1/ρ², ∂r_C/∂r_B = ρ, so the area ratio is 1).

use super::guided_search;
use crate::diagram::segment;
use std::f64::consts::TAU;

/// Area factor of the angular stage: dA_C = 1 · dA_B.
pub const ANGULAR_AREA: f64 = 1.0;

/// The tables of M_C for one map (docs/DERIVATION.md §4.4), in element type `T` (f64: the map's
/// own; f32: a float32 map's, [`super::float32`]): the meridians, the squared star radii and the
/// cumulative wedge angles, with (for f64) the forward map (B-disk azimuth → sector and
/// fraction), its inverse and the sector lookup of a D-disk azimuth. The fields are the blob's
/// tables (`mapping::blob` writes and reads them by name).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Angular<T = f64> {
    pub(super) m: usize,
    /// Meridian azimuths, M + 1 entries with φ_M = 2π.
    pub(super) phi: Vec<T>,
    /// Sector widths β_i, M entries.
    pub(super) beta: Vec<T>,
    /// 1/β when the meridians are uniform (O(1) sector lookup), else 0.
    pub(super) inv_uniform_beta: T,
    /// Squared star radii R_i² = U(i, N−1)/s, M + 1 entries (R_M = R_0).
    pub(super) r2: Vec<T>,
    /// Cumulative wedge angles Γ_i, M + 1 entries, Γ_0 = 0, Γ_M = 2π exactly.
    pub(super) cum: Vec<T>,
    /// Γ_M / Σγ^i (1 up to round-off): keeps Γ exactly cumulative.
    pub(super) kappa: T,
    /// Guide table of the wedge search: entry k is the wedge that holds φ_B = 2πk/K (K = the
    /// table's length, 2M), so the search starts at most a step or two below its answer (O(1)
    /// for all but pathological Γ).
    pub(super) wedge_guide: Vec<u32>,
    /// K / 2π for [`Angular::wedge_guide`].
    pub(super) guide_scale: T,
}

/// The read-only view of [`Angular`]'s tables, the one door through which code outside this file
/// (the vector kernels of `mapping::simd`, the blended maps) reads them: a layout change touches
/// this file only. Fields as in [`Angular`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct AngularView<'a, T = f64> {
    /// M, the number of meridians.
    pub(crate) m: usize,
    /// Meridian azimuths, M + 1 entries with φ_M = 2π.
    pub(crate) phi: &'a [T],
    /// Sector widths β_i, M entries.
    pub(crate) beta: &'a [T],
    /// 1/β when the meridians are uniform, else 0.
    pub(crate) inv_uniform_beta: T,
    /// Squared star radii R_i², M + 1 entries.
    pub(crate) r2: &'a [T],
    /// Cumulative wedge angles Γ_i, M + 1 entries.
    pub(crate) cum: &'a [T],
    /// Γ_M / Σγ^i.
    pub(crate) kappa: T,
    /// Guide table of the wedge search.
    pub(crate) wedge_guide: &'a [u32],
    /// K / 2π for the guide table.
    pub(crate) guide_scale: T,
}

/// The guide table of the wedge search over the cumulative wedge angles `cum` (M + 1 entries):
/// `len` entries, entry k the wedge that holds φ_B = `level(k)` (see [`Angular`]'s field
/// `wedge_guide`).
pub(crate) fn wedge_guides(cum: &[f64], len: usize, level: impl Fn(usize) -> f64) -> Vec<u32> {
    let m = cum.len() - 1;
    (0..len)
        .map(|k| {
            let p = level(k);
            (cum.partition_point(|&g| g <= p).clamp(1, m) - 1) as u32
        })
        .collect()
}

impl<T: Copy> Angular<T> {
    /// The read-only view of the tables ([`AngularView`]).
    #[inline]
    pub(crate) fn view(&self) -> AngularView<'_, T> {
        AngularView {
            m: self.m,
            phi: &self.phi,
            beta: &self.beta,
            inv_uniform_beta: self.inv_uniform_beta,
            r2: &self.r2,
            cum: &self.cum,
            kappa: self.kappa,
            wedge_guide: &self.wedge_guide,
            guide_scale: self.guide_scale,
        }
    }

    /// The same tables with every float converted by `f`.
    pub(super) fn map<U>(&self, f: impl Fn(T) -> U + Copy) -> Angular<U> {
        let v = |a: &[T]| a.iter().map(|&x| f(x)).collect::<Vec<U>>();
        Angular {
            m: self.m,
            phi: v(&self.phi),
            beta: v(&self.beta),
            inv_uniform_beta: f(self.inv_uniform_beta),
            r2: v(&self.r2),
            cum: v(&self.cum),
            kappa: f(self.kappa),
            wedge_guide: self.wedge_guide.clone(),
            guide_scale: f(self.guide_scale),
        }
    }

    /// Bytes of the tables' contents (`T` and u32 entries).
    pub(crate) fn table_bytes(&self) -> usize {
        std::mem::size_of::<T>()
            * (self.phi.len() + self.beta.len() + self.r2.len() + self.cum.len())
            + 4 * self.wedge_guide.len()
    }
}

impl Angular {
    /// Builds the tables from the meridians `phi` (M entries, φ_0 = 0) and each meridian's total
    /// radial mass U(i, N−1) (`mass(i)`, i < M). Returns them with T = ∫_disk D dA
    /// (docs/DERIVATION.md §4.3).
    pub(crate) fn build(phi: &[f64], mass: impl Fn(usize) -> f64) -> (Self, f64) {
        let m = phi.len();
        let mut phi = phi.to_vec();
        phi.push(TAU);
        let beta: Vec<f64> = (0..m).map(|i| phi[i + 1] - phi[i]).collect();
        let uniform = beta.iter().all(|b| (b - TAU / m as f64).abs() <= 1e-12);
        let last = |i: usize| mass(i % m);
        let total: f64 = (0..m)
            .map(|i| beta[i] * (last(i) + last(i + 1)) / 4.0)
            .sum();
        let s = total / std::f64::consts::PI;
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
        let wedge_guide = wedge_guides(&cum, guide_len, |k| k as f64 * TAU / guide_len as f64);
        let angular = Angular {
            m,
            phi,
            beta,
            inv_uniform_beta: if uniform { m as f64 / TAU } else { 0.0 },
            r2,
            cum,
            kappa,
            wedge_guide,
            guide_scale: guide_len as f64 / TAU,
        };
        (angular, total)
    }

    /// Number of meridians M.
    #[cfg(test)]
    pub(crate) fn meridians(&self) -> usize {
        self.m
    }

    /// The meridian after `i`, wrapping around.
    #[inline]
    pub(crate) fn next(&self, i: usize) -> usize {
        if i + 1 == self.m {
            0
        } else {
            i + 1
        }
    }

    /// The wedge of B-disk azimuth `phib`: the largest i ≤ M − 1 with Γ_i ≤ φ_B (empty wedges are
    /// skipped by taking the last such i), found from the guide table.
    #[inline]
    pub(super) fn wedge(&self, phib: f64) -> usize {
        guided_search(
            &self.cum,
            &self.wedge_guide,
            self.guide_scale,
            phib,
            self.m - 1,
        )
    }

    /// Forward M_C: the wedge i with Γ_i ≤ φ_B < Γ_{i+1}, the fraction ε of sector i that has the
    /// wedge's area, and φ_C = φ_i + εβ_i (the radius scales by ρ(φ_C), see
    /// [`Angular::star_radius2`]).
    #[inline]
    pub(crate) fn forward(&self, phib: f64) -> (usize, f64, f64) {
        forward_on(self, &self.beta, &self.phi, phib)
    }

    /// Inverse M_C: the B-disk azimuth of fraction `eps` of sector `i`.
    #[inline]
    pub(crate) fn inverse(&self, i: usize, eps: f64) -> f64 {
        inverse_on(self, &self.beta, i, eps)
    }

    /// Sector of azimuth `p` ∈ [0, 2π) and the fraction ε within it (the azimuth is the same on the
    /// C- and D-disks).
    #[inline]
    pub(crate) fn sector(&self, p: f64) -> (usize, f64) {
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

    /// ρ² at fraction `eps` of sector `i`: the squared radius of the star domain there.
    #[inline]
    pub(crate) fn star_radius2(&self, i: usize, eps: f64) -> f64 {
        star_radius2(self.r2[i], self.r2[i + 1], eps)
    }

    /// Γ_i, M + 1 entries.
    #[cfg(test)]
    pub(crate) fn wedge_cumulative(&self) -> &[f64] {
        &self.cum
    }
    /// Γ_M / Σγ^i.
    #[cfg(test)]
    pub(crate) fn kappa(&self) -> f64 {
        self.kappa
    }
    /// Sector widths β_i.
    pub(crate) fn beta(&self) -> &[f64] {
        &self.beta
    }
    /// R_i², M + 1 entries.
    #[cfg(test)]
    pub(crate) fn r2(&self) -> &[f64] {
        &self.r2
    }
    /// Meridian azimuths, M + 1 entries.
    #[cfg(test)]
    pub(crate) fn phi(&self) -> &[f64] {
        &self.phi
    }
}

/// The wedges of the angular stage: the cumulative wedge angles Γ_i, the squared star radii R_i²,
/// the scale κ and the wedge search. The map's own tables are one source ([`Angular`]); a blend
/// of K maps reads Σ w_k Γ_{k,i} and Σ w_k R²_{k,i} ([`super::blend`]). [`forward_on`] and
/// [`inverse_on`] are M_C over any source, written once.
pub(crate) trait Wedges {
    /// Γ_i.
    fn gamma(&self, i: usize) -> f64;
    /// R_i².
    fn rho2(&self, i: usize) -> f64;
    /// κ = Γ_M / Σγ (1 up to round-off).
    fn scale(&self) -> f64;
    /// The largest i ≤ M − 1 with Γ_i ≤ φ_B.
    fn find(&self, phib: f64) -> usize;
}

impl Wedges for Angular {
    #[inline]
    fn gamma(&self, i: usize) -> f64 {
        self.cum[i]
    }
    #[inline]
    fn rho2(&self, i: usize) -> f64 {
        self.r2[i]
    }
    #[inline]
    fn scale(&self) -> f64 {
        self.kappa
    }
    #[inline]
    fn find(&self, phib: f64) -> usize {
        self.wedge(phib)
    }
}

/// Forward M_C over `w` on the sectors of widths `beta` starting at `phi`: the wedge i with
/// Γ_i ≤ φ_B < Γ_{i+1}, the fraction ε of sector i that has the wedge's area, and φ_C = φ_i + εβ_i.
#[inline]
pub(crate) fn forward_on<W: Wedges>(
    w: &W,
    beta: &[f64],
    phi: &[f64],
    phib: f64,
) -> (usize, f64, f64) {
    let i = w.find(phib);
    let eps = solve_wedge(
        beta[i],
        w.rho2(i),
        w.rho2(i + 1),
        (phib - w.gamma(i)) / w.scale(),
    );
    (i, eps, phi[i] + eps * beta[i])
}

/// Inverse M_C over `w`: the B-disk azimuth of fraction `eps` of sector `i`.
#[inline]
pub(crate) fn inverse_on<W: Wedges>(w: &W, beta: &[f64], i: usize, eps: f64) -> f64 {
    (w.gamma(i) + w.scale() * wedge_angle(beta[i], w.rho2(i), w.rho2(i + 1), eps))
        .min(w.gamma(i + 1))
}

/// Area of the wedge of sector width `beta` between ε = 0 and `eps`, per unit ½ (that is, the angle
/// of the B-disk wedge with the same area): βR_a²ε + (β/2)(R_b² − R_a²)ε².
#[inline]
pub fn wedge_angle(beta: f64, r2a: f64, r2b: f64, eps: f64) -> f64 {
    beta * eps * (r2a + 0.5 * (r2b - r2a) * eps)
}

/// Solves [`wedge_angle`]`(beta, r2a, r2b, ε) = gamma` for ε ∈ [0, 1] with the cancellation-free
/// form ε = 2c / (b + √(b² + 4ac)), valid when a → 0, a < 0 and R_a = 0
/// (docs/DERIVATION.md §5, A13).
#[inline]
pub fn solve_wedge(beta: f64, r2a: f64, r2b: f64, gamma: f64) -> f64 {
    let a = 0.5 * beta * (r2b - r2a);
    let b = beta * r2a;
    let c = gamma.max(0.0);
    let den = b + (b * b + 4.0 * a * c).max(0.0).sqrt();
    if den > 0.0 {
        (2.0 * c / den).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// ρ² at fraction ε of a sector whose meridians have squared star radii `r2a`, `r2b`.
#[inline]
pub fn star_radius2(r2a: f64, r2b: f64, eps: f64) -> f64 {
    (1.0 - eps) * r2a + eps * r2b
}

/// dφ_C/dφ_B at a point of sector with star radius² `rho2` (unit B-disk): 1/ρ².
#[inline]
pub fn angular_derivative(rho2: f64) -> f64 {
    1.0 / rho2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_inverts_wedge_angle() {
        for &(beta, ra, rb) in &[
            (0.5, 1.0, 3.0),
            (0.5, 3.0, 1.0),
            (1.0, 0.0, 2.0),
            (1.0, 2.0, 0.0),
            (0.1, 1.0, 1.0),
            (2.0, 1e-12, 5.0),
        ] {
            for k in 0..=100 {
                let eps = k as f64 / 100.0;
                let g = wedge_angle(beta, ra, rb, eps);
                let e = solve_wedge(beta, ra, rb, g);
                assert!((e - eps).abs() < 1e-10, "{beta} {ra} {rb} {eps} -> {e}");
            }
        }
    }

    #[test]
    fn derivative_matches_finite_difference() {
        let (beta, ra, rb) = (0.7, 0.4, 2.5);
        for k in 1..100 {
            let eps = k as f64 / 100.0;
            let h = 1e-7;
            let g0 = wedge_angle(beta, ra, rb, eps - h);
            let g1 = wedge_angle(beta, ra, rb, eps + h);
            // dφ_C/dφ_B = β dε / dγ
            let fd = beta * 2.0 * h / (g1 - g0);
            let want = angular_derivative(star_radius2(ra, rb, eps));
            assert!((fd - want).abs() < 1e-6 * want);
        }
    }
}
