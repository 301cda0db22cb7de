//! Marginal–conditional inversion of the bilinear-in-(θ, φ) target itself, with the sin θ factor:
//! the continuous analogue of Mitsuba 3's `Marginal2D` whose density is exactly the target.

use super::{build_cdf, clamp_unit, invert_cdf, BuildError, Target};
use crate::diagram::{cell_weights, segment, Diagram};
use crate::sampler::{
    direction, normalize, spherical, Domain, InvertError, Point2, Sample, Sampler, Vec3,
};
use std::f64::consts::TAU;

/// Most Newton–bisection iterations of the θ solve; bisection alone reaches 2⁻⁶⁴ of the cell.
const MAX_ITERATIONS: usize = 64;
/// The θ solve stops when a Newton step is below this fraction of the cell height Δθ.
const THETA_TOLERANCE: f64 = 1e-12;

/// Bilinear marginal–conditional sampling whose density per steradian is **exactly** the target,
/// pdf(ω) = interpolate(θ, φ) / integral ([`Diagram::interpolate`], [`Diagram::integral`]).
///
/// In the (θ, φ) parameter plane the density is f(θ, φ) sin θ, with f bilinear on each cell
/// [θ_j, θ_{j+1}] × [φ_i, φ_i + β_i] (φ wrapping around 2π). The sampler inverts it in two steps:
///
/// 1. **φ from u₀.** The marginal g(φ) = ∫ f sin θ dθ is linear in φ inside each sector, between
///    G_i = Σ_j (w0_j p_{i,j} + w1_j p_{i,j+1}) at its meridians (w0, w1 the exact sin θ cell
///    weights). A binary search over the sector CDF picks sector i; inside it the CDF of the linear
///    density (1 − e)A + eB (A = G_i, B = G_{i+1}, e the fraction of the sector) is a quadratic,
///    inverted in closed form: e = ξ(A + B) / (A + √((1 − ξ)A² + ξB²)).
/// 2. **θ from u₁ given φ.** The conditional is ∝ f(θ, φ) sin θ with f piecewise linear in θ
///    (nodal values q_j = (1 − e)p_{i,j} + e p_{i+1,j}). Its cumulative cell masses are the same
///    blend of per-meridian prefix sums, so a binary search picks the cell j in O(log N) without
///    allocating. Inside the cell, F(s) = ∫₀ˢ (a + (b − a)x/Δ) sin(θ_j + x) dx
///    = a·K₀(s) + (b − a)·K₁(s)/Δ with K₀(s) = cos θ_j − cos(θ_j + s) and
///    K₁(s) = sin θ_j (s sin s − (1 − cos s)) + cos θ_j (sin s − s cos s) has no closed-form inverse;
///    it is solved by Newton's method safeguarded by bisection, started from the exact solution
///    for f linear in cos θ, to a step below 10⁻¹² Δθ (at most 64 iterations).
///
/// **Inverse**, closed form: u₀ = the sector CDF at φ, u₁ = the conditional CDF at θ given φ.
/// Seams of measure zero: φ = φ₀ (u₀ = 1 and u₀ = 0 meet there), the poles (φ is lost) and
/// meridians where g(φ) = 0 (the conditional is then taken as the limit from inside the sector and
/// the direction has density 0).
///
/// u₀ → φ, u₁ → θ: the map is continuous in u₁ and, across sectors, in u₀.
///
/// ```
/// use gonio::baselines::Bilinear;
/// use gonio::{Diagram, Domain, Sampler};
/// let d = Diagram::from_degrees(&[0.0, 45.0, 90.0], &[0.0, 180.0], &[vec![1.0, 0.7, 0.0], vec![2.0, 1.0, 0.0]])
///     .unwrap();
/// let b = Bilinear::new(&d, Domain::Hemisphere).unwrap();
/// let s = b.sample([0.6, 0.3]);
/// // The density is the target itself.
/// assert!((s.pdf - b.target_pdf(s.direction)).abs() <= 1e-12 * s.pdf);
/// let u = b.invert(s.direction).unwrap();
/// assert!((u[0] - 0.6).abs() < 1e-9 && (u[1] - 0.3).abs() < 1e-9);
/// ```
#[derive(Debug, Clone)]
pub struct Bilinear {
    target: Target,
    /// Normalised CDF over the sectors, M + 1 entries.
    sector_cdf: Vec<f64>,
    sector_last: usize,
    /// Σ of the sector masses (≈ the diagram's integral), diagram units × sr.
    total: f64,
    /// Sector widths β_i, radians.
    beta: Vec<f64>,
    /// Per meridian i and parallel j, `prefix[i * N + j]` = ∫_{θ_0}^{θ_j} row_i(θ) sin θ dθ, of
    /// the values times `scale`.
    prefix: Vec<f64>,
    /// A power of two that brings the largest value near 1, so that the tables (whose inversion
    /// squares masses) neither overflow nor underflow for values from 1e-300 to 1e300; the
    /// densities do not depend on it.
    scale: f64,
}

impl Bilinear {
    /// A bilinear sampler of the target of `diagram` over `domain`.
    ///
    /// # Errors
    /// [`BuildError::NotHemisphere`] if `domain` is the hemisphere and the diagram passes θ = 90°;
    /// [`BuildError::NoPower`] if the interpolated diagram integrates to 0.
    pub fn new(diagram: &Diagram, domain: Domain) -> Result<Self, BuildError> {
        let target = Target::new(diagram, domain)?;
        let (m, n) = (diagram.n_meridians(), diagram.n_parallels());
        let th = diagram.theta();
        let scale = unit_scale(diagram.max_value());
        let mut prefix = vec![0.0; m * n];
        for i in 0..m {
            let row = &mut prefix[i * n..(i + 1) * n];
            for j in 0..n - 1 {
                let (w0, w1) = cell_weights(th[j], th[j + 1]);
                row[j + 1] = row[j]
                    + w0 * (scale * diagram.value(i, j))
                    + w1 * (scale * diagram.value(i, j + 1));
            }
        }
        let beta = diagram.sector_widths();
        let g = |i: usize| prefix[i * n + n - 1];
        let masses: Vec<f64> = (0..m)
            .map(|i| 0.5 * beta[i] * (g(i) + g((i + 1) % m)))
            .collect();
        let mut sector_cdf = vec![0.0; m + 1];
        let (total, sector_last) = build_cdf(&masses, &mut sector_cdf);
        if !(total > 0.0 && total.is_finite()) {
            return Err(BuildError::no_power(total, diagram.max_value()));
        }
        Ok(Self {
            target,
            sector_cdf,
            sector_last,
            total,
            beta,
            prefix,
            scale,
        })
    }

    /// G_i = ∫ row_i(θ) sin θ dθ: the φ-marginal at meridian i (diagram units).
    #[inline]
    fn g(&self, i: usize) -> f64 {
        let n = self.target.diagram.n_parallels();
        self.prefix[i * n + n - 1]
    }

    /// Weights (1 − e, e) of meridians i and i + 1 in the conditional at fraction e of sector i, and
    /// the conditional's total mass. Where that mass is 0 (a meridian of zero power, reached only at
    /// e = 0 or 1), the limit from inside the sector is used.
    #[inline]
    fn blend(&self, i: usize, i1: usize, e: f64) -> (f64, f64, f64) {
        let (a, b) = (self.g(i), self.g(i1));
        let (wa, wb) = (1.0 - e, e);
        let t = wa * a + wb * b;
        if t > 0.0 {
            (wa, wb, t)
        } else if a > 0.0 {
            (1.0, 0.0, a)
        } else {
            (0.0, 1.0, b)
        }
    }

    /// The sector holding azimuth `phi` (radians) and the fraction e ∈ [0, 1] of the way through it.
    #[inline]
    fn sector_of(&self, phi: f64) -> (usize, f64) {
        let d = &self.target.diagram;
        let i = if d.n_meridians() == 1 {
            0
        } else {
            d.meridian_weights(phi).0
        };
        let e = ((phi - d.phi()[i]).rem_euclid(TAU) / self.beta[i]).clamp(0.0, 1.0);
        (i, e)
    }
}

/// K₀(s) = ∫₀ˢ sin(θ_j + x) dx and K₁(s) = ∫₀ˢ x sin(θ_j + x) dx, from (sin θ_j, cos θ_j) and s,
/// written without cancellation for small s; also sin(θ_j + s) for the derivative.
#[inline]
fn cell_moments(st: f64, ct: f64, s: f64) -> (f64, f64, f64) {
    let (sh, ch) = (0.5 * s).sin_cos();
    let sin_s = 2.0 * sh * ch;
    let one_minus_cos = 2.0 * sh * sh;
    let cos_s = 1.0 - one_minus_cos;
    let k0 = ct * one_minus_cos + st * sin_s;
    // sin s − s cos s = s³/3 − s⁵/30 + s⁷/840 − s⁹/45360 + …, cancelling for small s.
    let sin_minus_scos = if s < 0.1 {
        let s2 = s * s;
        s * s2 * (1.0 / 3.0 - s2 * (1.0 / 30.0 - s2 * (1.0 / 840.0 - s2 / 45360.0)))
    } else {
        sin_s - s * cos_s
    };
    let k1 = st * (s * sin_s - one_minus_cos) + ct * sin_minus_scos;
    let sin_at = st * cos_s + ct * sin_s;
    (k0, k1, sin_at)
}

/// F(s) = a K₀(s) + (b − a) K₁(s)/Δ: the mass of the profile a → b (linear in θ) weighted by sin θ
/// over [θ_j, θ_j + s], and its derivative (a + (b − a)s/Δ) sin(θ_j + s).
#[inline]
fn cell_cdf(st: f64, ct: f64, a: f64, b: f64, delta: f64, s: f64) -> (f64, f64) {
    let (k0, k1, sin_at) = cell_moments(st, ct, s);
    let slope = (b - a) / delta;
    (a * k0 + slope * k1, (a + slope * s) * sin_at)
}

/// The s ∈ [0, Δ] with F(s) = `target`, where F is [`cell_cdf`] on the cell of height Δ starting at
/// θ_j (F is non-decreasing). Newton's method safeguarded by bisection, started from the exact
/// solution for a profile linear in cos θ.
fn solve_cell(theta_j: f64, delta: f64, a: f64, b: f64, mass: f64, target: f64) -> f64 {
    let (st, ct) = theta_j.sin_cos();
    // Initial guess: the density a → b linear in z = cos θ, whose CDF in z is a quadratic.
    let rho = if mass > 0.0 {
        (target / mass).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let den = a + ((1.0 - rho) * a * a + rho * b * b).sqrt();
    let t = if den > 0.0 {
        (rho * (a + b) / den).clamp(0.0, 1.0)
    } else {
        rho
    };
    let z_end = (theta_j + delta).cos();
    let z = ct - t * (ct - z_end);
    let mut s = (z.clamp(-1.0, 1.0).acos() - theta_j).clamp(0.0, delta);
    let (mut lo, mut hi) = (0.0, delta);
    for _ in 0..MAX_ITERATIONS {
        let (f, df) = cell_cdf(st, ct, a, b, delta, s);
        let r = f - target;
        if r == 0.0 {
            break;
        }
        if r > 0.0 {
            hi = s;
        } else {
            lo = s;
        }
        let newton = s - r / df;
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        let step = (next - s).abs();
        s = next;
        if step <= THETA_TOLERANCE * delta || hi - lo <= THETA_TOLERANCE * delta {
            break;
        }
    }
    s
}

impl Sampler for Bilinear {
    target_methods!("bilinear");
    fn sample(&self, u: Point2) -> Sample {
        let d = &self.target.diagram;
        let (m, n) = (d.n_meridians(), d.n_parallels());
        let th = d.theta();

        // φ: sector by binary search, then the linear density (1 − e)A + eB inverted.
        let (i, xi) = invert_cdf(&self.sector_cdf, self.sector_last, clamp_unit(u[0]));
        let i1 = (i + 1) % m;
        let (ga, gb) = (self.g(i), self.g(i1));
        let den = ga + ((1.0 - xi) * ga * ga + xi * gb * gb).sqrt();
        let e = if den > 0.0 {
            (xi * (ga + gb) / den).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let phi = (d.phi()[i] + e * self.beta[i]).rem_euclid(TAU);

        // θ: cell by binary search over the blended prefix sums C(j), then the in-cell solve.
        let (wa, wb, total) = self.blend(i, i1, e);
        let (pa, pb) = (
            &self.prefix[i * n..(i + 1) * n],
            &self.prefix[i1 * n..(i1 + 1) * n],
        );
        let c = |j: usize| wa * pa[j] + wb * pb[j];
        let x = clamp_unit(u[1]) * total;
        // Number of interior breakpoints C(1..N−1) that are ≤ x: never lands on an empty cell
        // except at the top, where it steps back to the last cell of positive mass.
        let (mut lo, mut hi) = (1usize, n - 1);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if c(mid) <= x {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let mut j = lo - 1;
        while j > 0 && c(j + 1) <= c(j) {
            j -= 1;
        }
        let (c0, c1) = (c(j), c(j + 1));
        let val = |k: usize| self.scale * (wa * d.value(i, k) + wb * d.value(i1, k));
        let delta = th[j + 1] - th[j];
        let s = solve_cell(
            th[j],
            delta,
            val(j),
            val(j + 1),
            c1 - c0,
            (x - c0).clamp(0.0, c1 - c0),
        );
        let theta = (th[j] + s).min(th[j + 1]);
        let direction = direction(theta, phi);
        Sample {
            direction,
            pdf: self.target.pdf(direction),
        }
    }
    fn pdf(&self, direction: Vec3) -> f64 {
        self.target.pdf(direction)
    }
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        let dir = normalize(direction).ok_or(InvertError::OutsideDomain)?;
        if !self.target.domain.contains(dir) {
            return Err(InvertError::OutsideDomain);
        }
        // The rule of every sampler: no point maps where the density is 0.
        if self.target.pdf(dir) == 0.0 {
            return Err(InvertError::ZeroDensity);
        }
        let d = &self.target.diagram;
        let (m, n) = (d.n_meridians(), d.n_parallels());
        let th = d.theta();
        let (theta, phi) = spherical(dir);
        let (i, e) = self.sector_of(phi);
        let i1 = (i + 1) % m;
        let (ga, gb) = (self.g(i), self.g(i1));
        let partial = self.beta[i] * e * (ga + 0.5 * (gb - ga) * e);
        let u0 = self.sector_cdf[i] + partial / self.total;

        let (wa, wb, total) = self.blend(i, i1, e);
        let theta = theta.clamp(th[0], th[n - 1]);
        let j = segment(th, theta);
        let c0 = wa * self.prefix[i * n + j] + wb * self.prefix[i1 * n + j];
        let val = |k: usize| self.scale * (wa * d.value(i, k) + wb * d.value(i1, k));
        let (st, ct) = th[j].sin_cos();
        let delta = th[j + 1] - th[j];
        let (f, _) = cell_cdf(
            st,
            ct,
            val(j),
            val(j + 1),
            delta,
            (theta - th[j]).clamp(0.0, delta),
        );
        let u1 = (c0 + f) / total;
        Ok([u0.clamp(0.0, 1.0), u1.clamp(0.0, 1.0)])
    }
    fn memory_bytes(&self) -> usize {
        self.target.diagram_bytes()
            + std::mem::size_of::<f64>()
                * (self.sector_cdf.len() + self.beta.len() + self.prefix.len())
    }
}

/// The power of two 2^-e that brings `max` (positive, finite) into [1, 2); 1 for anything else.
fn unit_scale(max: f64) -> f64 {
    if !(max.is_finite() && max > 0.0) {
        return 1.0;
    }
    let e = max.log2().floor().clamp(-1000.0, 1000.0) as i32;
    // 2^-e in two exact steps (2^±1000 alone is representable, but keep the product normal).
    2f64.powi(-e / 2) * 2f64.powi(-e + e / 2)
}
