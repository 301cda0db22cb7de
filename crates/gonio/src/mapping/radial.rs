//! M_D: the radial remap that inverts the conditional CDF of a density linear in the disk radius
//! (docs/DERIVATION.md §6).
//!
//! On a segment [x_j, x_{j+1}] with end densities d_j, d_{j+1}, write X = x_j + τ and
//! d(X) = d_j + kτ, k = (d_{j+1} − d_j)/(x_{j+1} − x_j). The mass between x_j and X is
//!
//! ```text
//! g(τ) = ∫ 2x d(x) dx = 2x_j d_j τ + (x_j k + d_j) τ² + (2k/3) τ³,
//! ```
//!
//! the slide's cubic written in the local variable τ, which avoids the cancellation of the intercept
//! form X³ − x_j³. g is increasing (g′ = 2X d(X) ≥ 0), so g(τ) = m has one root on the segment. The
//! root is found by Halley's method from the root of the density linear in area (`area_guess`),
//! safeguarded by bisection and
//! polished to the last bits (plain Cardano misses by up to 1e-4 of the segment,
//! docs/DERIVATION.md §6.4).
//!
//! The stage maps the constant density s of the C-domain to D: the area ratio is dA_D/dA_C = s/D.

use super::guided_search;
use super::simd::math::Precision;
use crate::diagram::segment;

/// Mass ∫_{x0}^{x0+τ} 2x d(x) dx of the density d(x) = d0 + k(x − x0): the radial cumulative
/// between a parallel at radius `x0` and radius x0 + τ.
#[inline]
pub fn partial_mass(x0: f64, d0: f64, k: f64, tau: f64) -> f64 {
    tau * (2.0 * x0 * d0 + tau * ((x0 * k + d0) + tau * (2.0 / 3.0) * k))
}

/// Mass of a whole segment [x0, x1] with end densities d0, d1: the U-table increment of
/// docs/DERIVATION.md §4.2.
#[inline]
pub fn segment_mass(x0: f64, x1: f64, d0: f64, d1: f64) -> f64 {
    let h = x1 - x0;
    h / 3.0 * (d0 * (2.0 * x0 + x1) + d1 * (x0 + 2.0 * x1))
}

/// The radial segment [x_j, x_{j+1}] a forward solve landed in, with its end densities
/// interpolated between the two meridians.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Segment {
    j: usize,
    d0: f64,
    d1: f64,
}

/// One row of the radial stage at an azimuth: the cumulative masses Ũ_j and nodal densities
/// d̃_j interpolated from the tables' rows, and the bracket their radial guide tables give. The
/// map's own tables give two rows (one wedge, [`Radial::forward`]); a blend of K maps gives 2K
/// ([`super::blend`]). [`forward_on`] and [`inverse_on`] are M_D over any such row, written once.
pub(crate) trait RadialRow {
    /// Ũ_j.
    fn u(&self, j: usize) -> f64;
    /// d̃_j.
    fn d(&self, j: usize) -> f64;
    /// `[lo, hi]`, an interval that holds the largest j ≤ N − 2 with Ũ_j ≤ r_B²·Ũ_{N−1} for every
    /// r_B² in guide cell `k`: Ũ/Ũ_{N−1} is a convex combination of the rows' normalised
    /// cumulatives, so the answer lies between the rows' own answers, which their radial guide
    /// tables bracket.
    fn bracket(&self, k: usize) -> (usize, usize);
}

/// Two rows of the map's tables interpolated at fraction `eps` (one wedge).
struct WedgeRow<'a> {
    ua: &'a [f64],
    ub: &'a [f64],
    da: &'a [f64],
    db: &'a [f64],
    ga: &'a [u32],
    gb: &'a [u32],
    eps: f64,
}

impl RadialRow for WedgeRow<'_> {
    #[inline]
    fn u(&self, j: usize) -> f64 {
        (1.0 - self.eps) * self.ua[j] + self.eps * self.ub[j]
    }
    #[inline]
    fn d(&self, j: usize) -> f64 {
        (1.0 - self.eps) * self.da[j] + self.eps * self.db[j]
    }
    #[inline]
    fn bracket(&self, k: usize) -> (usize, usize) {
        let (ga, gb) = (self.ga, self.gb);
        (ga[k].min(gb[k]) as usize, ga[k + 1].max(gb[k + 1]) as usize)
    }
}

/// Forward M_D on `row` over the parallel radii `x` (docs/DERIVATION.md §6.3, A6): the D-disk
/// radius whose radial CDF equals r_B², and the segment it lies in.
#[inline]
pub(crate) fn forward_on<R: RadialRow>(
    x: &[f64],
    radial_k: usize,
    row: &R,
    rb: f64,
) -> (f64, Segment) {
    let n = x.len();
    let w = rb * rb * row.u(n - 1);
    // Largest j ≤ N−2 with Ũ_j ≤ w, bisected inside the rows' guide bracket.
    let k = ((rb * rb * radial_k as f64) as usize).min(radial_k - 1);
    let (mut lo, mut hi) = row.bracket(k);
    while hi > lo {
        let mid = (lo + hi).div_ceil(2);
        if row.u(mid) <= w {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    let mut j = lo;
    // Round-off may move the answer just outside the bracket: settle it exactly.
    while j > 0 && row.u(j) > w {
        j -= 1;
    }
    while j + 2 < n && row.u(j + 1) <= w {
        j += 1;
    }
    // The edge of the square (r_B = 1, w = Ũ_{N−1}) where the last segments carry no mass (an
    // unlit zone at the end of the map): the search ends on a segment without light, and the
    // sample would land inside that zone, with zero density all around it. Step back to the
    // last segment with mass: the sample is then the end of the lit zone (the same B-radius,
    // so the inverse still round-trips). Elsewhere segment j always has mass.
    while j > 0 && row.u(j + 1) <= row.u(j) {
        j -= 1;
    }
    let (d0, d1) = (row.d(j), row.d(j + 1));
    let (x0, x1) = (x[j], x[j + 1]);
    let xr = solve_radius(x0, x1, d0, d1, w - row.u(j)).min(x1);
    (xr, Segment { j, d0, d1 })
}

/// Inverse M_D on `row`: the B-disk radius r_B = √(Ũ(x_r)/Ũ_{N−1}) of D-disk radius `xr` in
/// segment `j` of the parallel radii `x` (closed form, docs/DERIVATION.md §6.5).
#[inline]
pub(crate) fn inverse_on<R: RadialRow>(
    x: &[f64],
    inv_dx: &[f64],
    j: usize,
    row: &R,
    xr: f64,
) -> f64 {
    let n = x.len();
    let (x0, x1) = (x[j], x[j + 1]);
    let (d0, d1) = (row.d(j), row.d(j + 1));
    let k = (d1 - d0) * inv_dx[j];
    let tau = (xr - x0).clamp(0.0, x1 - x0);
    let w = row.u(j) + partial_mass(x0, d0, k, tau);
    let wn = row.u(n - 1);
    if wn > 0.0 {
        (w / wn).clamp(0.0, 1.0).sqrt()
    } else {
        0.0
    }
}

/// The radius X ∈ [x0, x1] with [`partial_mass`] = `m` on the segment with end densities d0, d1.
/// `m` outside [0, segment mass] is clamped to the segment's ends.
#[inline]
pub fn solve_radius(x0: f64, x1: f64, d0: f64, d1: f64, m: f64) -> f64 {
    let h = x1 - x0;
    if !(m > 0.0) || !(h > 0.0) {
        return x0;
    }
    let k = (d1 - d0) / h;
    let dbar = 0.5 * (d0 + d1);
    if !(dbar > 0.0) {
        return x0;
    }
    if k == 0.0 {
        // Exact for a constant density: X = √(x0² + m/d), as τ without cancellation.
        let q = m / dbar;
        return x0 + (q / ((x0 * x0 + q).sqrt() + x0)).min(h);
    }
    let mut tau = area_guess(x0, x1, d0, d1, m);
    let (mut lo, mut hi) = (0.0, h);
    tau = tau.clamp(lo, hi);
    for _ in 0..60 {
        let f = partial_mass(x0, d0, k, tau) - m;
        if f == 0.0 {
            // The root itself (a bisection from here would only move away from it).
            break;
        }
        if f > 0.0 {
            hi = tau;
        } else {
            lo = tau;
        }
        // Halley's method (cubic convergence): g′ = 2X d(X), g″ = 2d(X) + 2kX, g‴ = 4k.
        let (xx, dd) = (x0 + tau, d0 + k * tau);
        let g1 = 2.0 * xx * dd;
        let g2 = 2.0 * (dd + k * xx);
        let den = g1 * g1 - 0.5 * f * g2;
        let mut next = if g1 > 0.0 && den > 0.0 {
            tau - f * g1 / den
        } else {
            f64::NAN
        };
        let halley = next > lo && next < hi;
        if !halley {
            next = 0.5 * (lo + hi);
        }
        let step = (next - tau).abs();
        tau = next;
        let scale = x0 + tau;
        if step <= 1e-15 * scale || hi - lo <= 1e-15 * (x0 + hi) {
            break;
        }
        // After a Halley step of size δ the error is about C·δ³ with
        // C = g″²/(4g′²) + |g‴|/(6g′) (evaluated at the previous iterate, which differs from the
        // root by about δ); stop as soon as that is below the last bits, which saves the final
        // confirming iteration of a plain "step below 1e-15" test.
        // (Multiplied through by g′² > 0, which a Halley step implies: no division.)
        if halley && step <= 1e-5 * scale {
            let c = 0.25 * g2 * g2 + (4.0 * k).abs() * g1 * (1.0 / 6.0);
            if c * (step * step * step) <= 1e-17 * scale * (g1 * g1) {
                break;
            }
        }
    }
    x0 + tau
}

/// The starting point of [`solve_radius`]'s iteration: the exact root for a density linear in the
/// disk *area* s = x² (instead of the radius) with the same end values, Δs = 2m / (d0 + √(d0² +
/// 2Km)) with K = (d1 − d0)/(x1² − x0²), returned as τ = Δs / (x0 + √(x0² + Δs)) without
/// cancellation. The two models differ by O(h/x0) of the density's variation, so the guess is
/// already close where the constant-density guess is not (a density varying 1000× along the
/// segment): Halley's method then needs 1.9 iterations on average instead of 2.9, and a block of
/// 8 SIMD lanes 2.2 instead of 3.8 (random r⁴ + 10⁻³ densities, 181 parallels; measured by
/// `docs/experiments/radial_solve_iterations.py`, a model of this iteration).
#[inline]
pub(crate) fn area_guess(x0: f64, x1: f64, d0: f64, d1: f64, m: f64) -> f64 {
    let kk = (d1 - d0) / ((x1 - x0) * (x0 + x1));
    let ds = 2.0 * m / (d0 + (d0 * d0 + 2.0 * kk * m).max(0.0).sqrt());
    let tau = ds / (x0 + (x0 * x0 + ds).sqrt());
    if tau.is_finite() {
        tau
    } else {
        // d0 = 0 and 2Km below the smallest subnormal (densities ~1e-306): the denominator is 0
        // and τ = ∞/∞ = NaN, which the iteration would carry to the segment's end. The
        // constant-density guess, whose m/d̄ does not underflow, instead.
        let q = m / (0.5 * (d0 + d1));
        q / ((x0 * x0 + q).sqrt() + x0)
    }
}

/// The slide's Cardano solution of the intercept-form cubic (2k/3)X³ + b₀X² = RHS, without polish,
/// kept to show why the polish is needed (docs/DERIVATION.md §6.4, §12.2).
#[cfg(test)]
pub(crate) fn cardano_radius(x0: f64, x1: f64, d0: f64, d1: f64, m: f64) -> f64 {
    let k = (d1 - d0) / (x1 - x0);
    let b0 = d0 - k * x0;
    let a = 2.0 * k / 3.0;
    let rhs = m + b0 * x0 * x0 + a * x0 * x0 * x0;
    let a2 = b0 / a;
    let a0 = -rhs / a;
    let p = -a2 * a2 / 3.0;
    let q = 2.0 * a2 * a2 * a2 / 27.0 + a0;
    let disc = q * q / 4.0 + p * p * p / 27.0;
    let shift = -a2 / 3.0;
    let candidates: Vec<f64> = if disc > 0.0 {
        let sd = disc.sqrt();
        vec![(-q / 2.0 + sd).cbrt() + (-q / 2.0 - sd).cbrt() + shift]
    } else {
        let rr = 2.0 * (-p / 3.0).sqrt();
        let arg = ((3.0 * q / (2.0 * p)) * (-3.0 / p).sqrt()).clamp(-1.0, 1.0);
        let phi = arg.acos() / 3.0;
        (0..3)
            .map(|kk| rr * (phi - 2.0 * std::f64::consts::PI * kk as f64 / 3.0).cos() + shift)
            .collect()
    };
    candidates
        .into_iter()
        .min_by(|a, b| {
            let da = (a.clamp(x0, x1) - a).abs();
            let db = (b.clamp(x0, x1) - b).abs();
            da.total_cmp(&db)
        })
        .unwrap_or(x0)
        .clamp(x0, x1)
}

/// Area factor of the radial stage at a point where the disk density is `d`: dA_D/dA_C = s/D.
#[inline]
pub fn radial_area(s: f64, d: f64) -> f64 {
    s / d
}

/// The tables of M_D for one map (docs/DERIVATION.md §4.1–§4.2), in element type `T` (f64: the
/// map's own; f32: a float32 map's, [`super::float32`]): the parallel radii, the nodal disk
/// densities and the cumulative radial masses of every meridian, with (for f64) the forward map
/// (B-disk radius → D-disk radius on the meridian pair of an angular fraction), its inverse and
/// the disk density D that the map's pdf is made of. The fields are the blob's tables
/// (`mapping::blob` writes and reads them by name).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Radial<T = f64> {
    pub(super) n: usize,
    /// Parallel radii x_j = √(1 − cos θ_j) on the disk, N entries.
    pub(super) x: Vec<T>,
    /// Nodal disk densities d_{i,j} = p_{i,j}, row-major M × N.
    pub(super) d: Vec<T>,
    /// Cumulative radial masses U(i, j) = 2∫₀^{x_j} d_i(x) x dx, row-major M × N.
    pub(super) u: Vec<T>,
    /// U(i, N−1), the total radial mass of each meridian (M entries): the last column of `u`,
    /// kept apart so that the batch kernels read it from 8·M contiguous bytes instead of one
    /// cache line per meridian (the inverse at 1024 × 1024: 54 → 47 ns per point).
    pub(super) total: Vec<T>,
    /// Guide table of the parallel search: entry k is the segment of x that holds radius
    /// k·x_{N−1}/K (K = the table's length, 2N), for `pdf` and `invert`.
    pub(super) radius_guide: Vec<u32>,
    /// K / x_{N−1} for [`Radial::radius_guide`].
    pub(super) radius_scale: T,
    /// 1 / (x_{j+1} − x_j), N − 1 entries (0 for an empty segment).
    pub(super) inv_dx: Vec<T>,
    /// Radial guide tables, row-major M × (K + 1) with K = [`Radial::radial_k`]: entry (i, k) is
    /// the largest j ≤ N − 2 with U(i, j) ≤ (k/K)·U(i, N−1), the segment of meridian i's own radial
    /// CDF at r_B² = k/K. They bracket the forward map's radial search.
    pub(super) radial_guide: Vec<u32>,
    /// K = ⌈N/2⌉ cells per radial guide table.
    pub(super) radial_k: usize,
    /// The radius beyond which the density is 0: x_{N−1} times the element type's
    /// [`Precision::EDGE`] (slack for the round-off of a direction's disk radius).
    pub(super) edge: T,
}

/// The radial guide tables of the cumulative masses `u` (row-major M × N, rows non-decreasing),
/// K = `radial_k` cells each: entry (i, k) is the largest j ≤ N − 2 with U(i, j) ≤ (k/K)·U(i, N−1)
/// (see [`Radial`]'s field `radial_guide`).
pub(crate) fn radial_guides<T: Copy + Into<f64>>(u: &[T], n: usize, radial_k: usize) -> Vec<u32> {
    let m = u.len() / n;
    let mut radial_guide = Vec::with_capacity(m * (radial_k + 1));
    for i in 0..m {
        let row = &u[i * n..(i + 1) * n];
        // The count of entries ≤ level (`partition_point` on the non-decreasing row), found by
        // one walk up the row as the levels rise.
        let mut count = 0;
        for k in 0..=radial_k {
            let level = k as f64 / radial_k as f64 * row[n - 1].into();
            while count < n && row[count].into() <= level {
                count += 1;
            }
            let j = count.max(1) - 1;
            radial_guide.push(j.min(n - 2) as u32);
        }
    }
    radial_guide
}

/// The guide table of the parallel search over the parallel radii `x`: `len` entries, entry k
/// the segment that holds radius `level(k)` (see [`Radial`]'s field `radius_guide`).
pub(crate) fn radius_guides(x: &[f64], len: usize, level: impl Fn(usize) -> f64) -> Vec<u32> {
    (0..len).map(|k| segment(x, level(k)) as u32).collect()
}

/// `round`(1 / (x_{j+1} − x_j)) of each segment of the parallel radii `x`, 0 for an empty one.
pub(crate) fn inverse_widths(x: &[f64], round: impl Fn(f64) -> f64) -> Vec<f64> {
    x.windows(2)
        .map(|w| {
            if w[1] > w[0] {
                round(1.0 / (w[1] - w[0]))
            } else {
                0.0
            }
        })
        .collect()
}

/// The read-only view of [`Radial`]'s tables, the one door through which code outside this file
/// (the vector kernels of `mapping::simd`, the blended maps) reads them: a layout change touches
/// this file only. Fields as in [`Radial`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct RadialView<'a, T = f64> {
    /// N, the number of parallels.
    pub(crate) n: usize,
    /// Parallel radii x_j, N entries.
    pub(crate) x: &'a [T],
    /// Nodal disk densities, row-major M × N.
    pub(crate) d: &'a [T],
    /// Cumulative radial masses U(i, j), row-major M × N.
    pub(crate) u: &'a [T],
    /// U(i, N−1), M entries.
    pub(crate) total: &'a [T],
    /// Guide table of the parallel search.
    pub(crate) radius_guide: &'a [u32],
    /// K / x_{N−1} for the parallel guide table.
    pub(crate) radius_scale: T,
    /// 1 / (x_{j+1} − x_j), N − 1 entries.
    pub(crate) inv_dx: &'a [T],
    /// Radial guide tables, row-major M × (K + 1).
    pub(crate) radial_guide: &'a [u32],
    /// K, cells per radial guide table.
    pub(crate) radial_k: usize,
    /// The radius beyond which the density is 0: x_{N−1} times the element type's
    /// [`Precision::EDGE`] (slack for the round-off of a direction's disk radius).
    pub(crate) edge: T,
}

impl Radial {
    /// Gives away the nodal densities and the cumulative masses (M × N each), leaving them empty:
    /// for a conversion that drops each f64 table as soon as its f32 twin is made
    /// (`Tables::of_owned`); the tables are unusable afterwards.
    pub(super) fn take_d_u(&mut self) -> (Vec<f64>, Vec<f64>) {
        (std::mem::take(&mut self.d), std::mem::take(&mut self.u))
    }

    /// Drops the radial guide tables (a float32 conversion makes its own from the f32 masses);
    /// the tables are unusable afterwards.
    pub(super) fn drop_radial_guide(&mut self) {
        self.radial_guide = Vec::new();
    }
}

impl<T: Copy> Radial<T> {
    /// The read-only view of the tables ([`RadialView`]).
    #[inline]
    pub(crate) fn view(&self) -> RadialView<'_, T> {
        RadialView {
            n: self.n,
            x: &self.x,
            d: &self.d,
            u: &self.u,
            total: &self.total,
            radius_guide: &self.radius_guide,
            radius_scale: self.radius_scale,
            inv_dx: &self.inv_dx,
            radial_guide: &self.radial_guide,
            radial_k: self.radial_k,
            edge: self.edge,
        }
    }

    /// The same tables with every float converted by `f`.
    pub(super) fn map<U>(&self, f: impl Fn(T) -> U + Copy) -> Radial<U> {
        let v = |a: &[T]| a.iter().map(|&x| f(x)).collect::<Vec<U>>();
        Radial {
            n: self.n,
            x: v(&self.x),
            d: v(&self.d),
            u: v(&self.u),
            total: v(&self.total),
            radius_guide: self.radius_guide.clone(),
            radius_scale: f(self.radius_scale),
            inv_dx: v(&self.inv_dx),
            radial_guide: self.radial_guide.clone(),
            radial_k: self.radial_k,
            edge: f(self.edge),
        }
    }

    /// Bytes of the tables' contents (`T` and u32 entries).
    pub(crate) fn table_bytes(&self) -> usize {
        std::mem::size_of::<T>()
            * (self.x.len() + self.d.len() + self.u.len() + self.total.len() + self.inv_dx.len())
            + 4 * (self.radius_guide.len() + self.radial_guide.len())
    }
}

impl Radial {
    /// Builds the tables from the parallel radii `x` (N ≥ 2, x_0 = 0) and the nodal densities `d`
    /// (row-major M × N).
    pub(crate) fn build(x: Vec<f64>, d: Vec<f64>) -> Self {
        let n = x.len();
        let m = d.len() / n;
        let mut u = vec![0.0; m * n];
        for i in 0..m {
            let (row, dr) = (&mut u[i * n..(i + 1) * n], &d[i * n..(i + 1) * n]);
            for j in 0..n - 1 {
                row[j + 1] = row[j] + segment_mass(x[j], x[j + 1], dr[j], dr[j + 1]);
            }
        }
        let radius_len = 2 * n;
        let x_max = x[n - 1];
        let radius_guide = radius_guides(&x, radius_len, |k| k as f64 * x_max / radius_len as f64);
        let inv_dx = inverse_widths(&x, |w| w);
        let radial_k = n.div_ceil(2).max(1);
        let radial_guide = radial_guides(&u, n, radial_k);
        let total = (0..m).map(|i| u[i * n + n - 1]).collect();
        Radial {
            n,
            total,
            radius_scale: radius_len as f64 / x_max,
            edge: x_max * <f64 as Precision>::EDGE,
            x,
            d,
            u,
            radius_guide,
            inv_dx,
            radial_guide,
            radial_k,
        }
    }

    /// U(i, N−1): the total radial mass of meridian `i`.
    #[inline]
    pub(crate) fn meridian_mass(&self, i: usize) -> f64 {
        self.total[i]
    }

    /// U(i, j + 1) − U(i, j): the radial mass of meridian `i` between parallels `j` and `j + 1`.
    #[inline]
    pub(crate) fn segment_mass_of(&self, i: usize, j: usize) -> f64 {
        self.u[i * self.n + j + 1] - self.u[i * self.n + j]
    }

    /// The segment of the parallel radii that holds disk radius `xr` (as `diagram::segment`: the
    /// largest j ≤ N − 2 with x_j ≤ xr), found from the guide table.
    #[inline]
    pub(super) fn segment_of(&self, xr: f64) -> usize {
        guided_search(
            &self.x,
            &self.radius_guide,
            self.radius_scale,
            xr,
            self.n - 2,
        )
    }

    /// The row of the wedge between meridians `i` and `i1` at fraction `eps`: the two rows'
    /// entries interpolated linearly ([`RadialRow`]).
    #[inline(always)]
    fn wedge_row(&self, i: usize, i1: usize, eps: f64) -> WedgeRow<'_> {
        let (n, kg) = (self.n, self.radial_k);
        WedgeRow {
            ua: &self.u[i * n..i * n + n],
            ub: &self.u[i1 * n..i1 * n + n],
            da: &self.d[i * n..i * n + n],
            db: &self.d[i1 * n..i1 * n + n],
            ga: &self.radial_guide[i * (kg + 1)..(i + 1) * (kg + 1)],
            gb: &self.radial_guide[i1 * (kg + 1)..(i1 + 1) * (kg + 1)],
            eps,
        }
    }

    /// Forward M_D on the tables interpolated at fraction `eps` between meridians `i` and `i1`
    /// (docs/DERIVATION.md §6.3, A6): the D-disk radius whose radial CDF equals r_B², and the
    /// segment it lies in (for the disk density D there, [`Radial::density_on`]).
    #[inline]
    pub(crate) fn forward(&self, rb: f64, i: usize, i1: usize, eps: f64) -> (f64, Segment) {
        forward_on(&self.x, self.radial_k, &self.wedge_row(i, i1, eps), rb)
    }

    /// The density on the segment the forward map landed in, at D-disk radius `xr` (clamped to
    /// the segment): linear between its end densities.
    #[inline]
    pub(crate) fn density_on(&self, seg: Segment, xr: f64) -> f64 {
        let t = ((xr - self.x[seg.j]) * self.inv_dx[seg.j]).clamp(0.0, 1.0);
        (seg.d0 + (seg.d1 - seg.d0) * t).max(0.0)
    }

    /// Inverse M_D: the B-disk radius r_B = √(Ũ(x_r)/Ũ_{N−1}) of D-disk radius `xr` on the tables
    /// interpolated at fraction `eps` between meridians `i` and `i1` (closed form,
    /// docs/DERIVATION.md §6.5).
    #[inline]
    pub(crate) fn inverse(&self, xr: f64, i: usize, i1: usize, eps: f64) -> f64 {
        let j = self.segment_of(xr);
        inverse_on(&self.x, &self.inv_dx, j, &self.wedge_row(i, i1, eps), xr)
    }

    /// The disk density D at D-disk radius `xr` between meridians `i` and `i1` at fraction `eps`
    /// (bilinear in (x, φ)): the area factor of M_D there is s/D ([`radial_area`]).
    #[inline]
    pub(crate) fn density(&self, xr: f64, i: usize, i1: usize, eps: f64) -> f64 {
        let n = self.n;
        if xr > self.x[n - 1] * (1.0 + 1e-12) {
            // Beyond the zone the map covers (a diagram ending before θ_max): no light.
            return 0.0;
        }
        let j = self.segment_of(xr);
        let t = ((xr - self.x[j]) * self.inv_dx[j]).clamp(0.0, 1.0);
        let row = |r: usize| {
            let a = &self.d[r * n..r * n + n];
            a[j] + t * (a[j + 1] - a[j])
        };
        ((1.0 - eps) * row(i) + eps * row(i1)).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn bisect(x0: f64, x1: f64, d0: f64, d1: f64, m: f64) -> f64 {
        let k = (d1 - d0) / (x1 - x0);
        let (mut lo, mut hi) = (0.0, x1 - x0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if partial_mass(x0, d0, k, mid) > m {
                hi = mid
            } else {
                lo = mid
            }
        }
        x0 + 0.5 * (lo + hi)
    }

    #[test]
    fn segment_mass_is_partial_mass_at_the_end() {
        for &(x0, x1, d0, d1) in &[
            (0.0, 0.3, 1.0, 2.0),
            (0.5, 0.9, 3.0, 0.0),
            (0.2, 0.21, 1.0, 1.0),
        ] {
            let k = (d1 - d0) / (x1 - x0);
            let a = segment_mass(x0, x1, d0, d1);
            let b = partial_mass(x0, d0, k, x1 - x0);
            assert!((a - b).abs() < 1e-15 * a.max(1.0));
        }
    }

    /// docs/DERIVATION.md §6.4, §12.2: the polished root agrees with bisection to ~1e-13 of the
    /// segment, plain Cardano does not (its error reaches 1e-6 or more on generic segments and
    /// fails outright on nearly constant ones).
    #[test]
    fn polished_root_matches_bisection_and_cardano_does_not() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let (mut worst, mut worst_cardano) = (0.0f64, 0.0f64);
        for trial in 0..20_000 {
            let x0 = rng.gen_range(0.0..0.9);
            let x1 = x0 + rng.gen_range(1e-3..0.1);
            let d0 = rng.gen_range(0.0..1.0);
            // every fourth segment is nearly constant
            let d1 = if trial % 4 == 0 {
                d0 * (1.0 + rng.gen_range(-1e-4..1e-4))
            } else {
                rng.gen_range(0.0..1.0)
            };
            let total = segment_mass(x0, x1, d0, d1);
            let m = rng.gen_range(0.0..1.0) * total;
            let want = bisect(x0, x1, d0, d1, m);
            let h = x1 - x0;
            worst = worst.max((solve_radius(x0, x1, d0, d1, m) - want).abs() / h);
            worst_cardano = worst_cardano.max((cardano_radius(x0, x1, d0, d1, m) - want).abs() / h);
        }
        assert!(worst < 1e-12, "polished root error {worst:e}");
        assert!(
            worst_cardano > 1e-8,
            "plain Cardano unexpectedly accurate: {worst_cardano:e}"
        );
    }

    /// A segment from 0 to a density of 1.3e-306 (a fuzz diagram's): the linear-in-area guess
    /// underflows (2Km < 5e-324, so its denominator is 0 and it is NaN); the solve must still
    /// find the root, not the segment's end (found by the ill-conditioned fuzz case's
    /// `gonio check` round trip: u = (0.99255, 0.77244) sampled the horizon and inverted to the
    /// square's edge, 7.4e-3 away).
    #[test]
    fn densities_whose_area_guess_underflows() {
        let (x0, x1, d0, d1) = (7.584728575995813e-1, 1.0, 0.0, 1.348951026719991e-306);
        let m = 1.0491368806029343e-308;
        assert!(area_guess(x0, x1, d0, d1, m).is_finite());
        let x = solve_radius(x0, x1, d0, d1, m);
        let want = bisect(x0, x1, d0, d1, m);
        assert!((x - want).abs() < 1e-12 && x < x1 - 0.1, "{x} vs {want}");
    }

    #[test]
    fn degenerate_segments() {
        // zero density at one end, at the pole
        let x = solve_radius(0.0, 0.5, 0.0, 2.0, segment_mass(0.0, 0.5, 0.0, 2.0));
        assert!((x - 0.5).abs() < 1e-14);
        // constant density: exact
        let m = segment_mass(0.3, 0.6, 1.5, 1.5) * 0.25;
        let x = solve_radius(0.3, 0.6, 1.5, 1.5, m);
        assert!((x - (0.09f64 + m / 1.5).sqrt()).abs() < 1e-15);
        // zero-mass segment, zero or negative m
        assert_eq!(solve_radius(0.3, 0.6, 0.0, 0.0, 0.1), 0.3);
        assert_eq!(solve_radius(0.3, 0.6, 1.0, 0.0, -1.0), 0.3);
    }

    #[test]
    fn area_factor_matches_finite_difference() {
        // Radius r_C at constant density s maps to X: s r_C dr_C = D(X) X dX.
        let (x0, x1, d0, d1) = (0.2, 0.5, 1.0, 3.0);
        let s = 1.7;
        for k in 1..50 {
            let m = segment_mass(x0, x1, d0, d1) * k as f64 / 50.0;
            let hm = 1e-7;
            let xa = solve_radius(x0, x1, d0, d1, m - hm);
            let xb = solve_radius(x0, x1, d0, d1, m + hm);
            let x = solve_radius(x0, x1, d0, d1, m);
            let dens = d0 + (d1 - d0) * (x - x0) / (x1 - x0);
            // dm = s d(r_C²) = 2 s r_C dr_C and dA_C/dA_D = (s r_C dr_C)/(s X dX)... area ratio s/D:
            let fd = (2.0 * hm) / (2.0 * x * (xb - xa)); // = D
            assert!((fd - dens).abs() < 1e-5 * dens);
            assert!((radial_area(s, dens) - s / fd).abs() < 1e-4 * s / fd);
        }
    }
}
