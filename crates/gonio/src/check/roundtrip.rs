//! Round trip: `invert(sample(u)) ≈ u`.

use super::{sample_defect, Status};
use crate::sampler::{InvertError, Point2, Sample, Sampler, Vec3};
use crate::sequence::{Sequence, SequenceKind};
use rayon::prelude::*;

/// Settings of the round-trip check.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RoundTripOptions {
    /// Number of sequence points.
    pub points: usize,
    /// Which sequence supplies them.
    pub sequence: SequenceKind,
    /// Its seed.
    pub seed: u64,
    /// K: besides the sequence points, the lines u = k/K and v = k/K for k = 0 … K (the square's
    /// edges included) are tested; 0 tests no lines.
    pub lines: usize,
    /// Evenly spaced points per line, end points (the square's corners) included.
    pub points_per_line: usize,
    /// Largest accepted max(|u′ − u|, |v′ − v|).
    pub tolerance: f64,
    /// Further points of the square to test, e.g. the preimages of the diagram's cell boundaries
    /// from [`cell_boundary_points`] (not serialised; their number is in the report).
    #[serde(skip)]
    pub extra_points: Vec<Point2>,
}

impl Default for RoundTripOptions {
    fn default() -> Self {
        RoundTripOptions {
            points: 100_000,
            sequence: SequenceKind::Sobol,
            seed: 0x0005_eed5,
            lines: 16,
            points_per_line: 257,
            tolerance: 1e-8,
            extra_points: Vec::new(),
        }
    }
}

/// What the round-trip check measured.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RoundTripReport {
    /// Pass, fail, or not applicable (the sampler has no inverse).
    pub status: Status,
    /// One line saying why.
    pub message: String,
    /// Points whose round trip was measured.
    pub tested: usize,
    /// Points skipped because the sample's pdf is 0 (the map need not be invertible there).
    pub skipped_zero_pdf: usize,
    /// Samples with a non-finite or non-unit direction, a direction outside the domain, or a
    /// non-finite or negative pdf (failures).
    pub invalid_samples: usize,
    /// Samples of positive pdf whose inversion failed or gave a non-finite point (failures).
    pub invert_failures: usize,
    /// Tested points where u′ = invert(sample(u)) differs from u by more than the tolerance but
    /// sample(u′) is the same direction (within the tolerance, max norm): points where the map is
    /// not injective (seams, poles). Their error counts as that direction difference.
    pub seam_points: usize,
    /// Tested points where |u′ − u| exceeds the tolerance by no more than the inverse's round-off
    /// reach at the sampled direction ([`roundoff_reach`]: where the inverse is ill conditioned,
    /// e.g. next to a meridian carrying ~1e-8 of its neighbour's light). Their error counts as the
    /// excess over that reach.
    pub ill_conditioned_points: usize,
    /// Largest max(|u′ − u|, |v′ − v|) over the tested points (seam points: the direction
    /// difference instead; other points beyond the tolerance: the excess over the inverse's
    /// round-off reach).
    pub max_error: f64,
    /// The point u of the square with the largest error.
    pub worst_point: Option<Point2>,
    /// What `invert(sample(worst_point))` gave.
    pub worst_inverse: Option<Point2>,
    /// The tolerance applied.
    pub tolerance: f64,
    /// How many of the points were [`RoundTripOptions::extra_points`] (cell boundaries).
    pub extra_points: usize,
}

#[derive(Default)]
struct Acc {
    tested: usize,
    skipped: usize,
    invalid: usize,
    invert_failures: usize,
    seam: usize,
    ill_conditioned: usize,
    unsupported: bool,
    max_error: f64,
    worst: Option<(Point2, Point2)>,
}

impl Acc {
    fn add(&mut self, sampler: &dyn Sampler, tolerance: f64, u: Point2, s: &Sample) {
        if sample_defect(sampler.domain(), s).is_some() {
            self.invalid += 1;
            return;
        }
        if s.pdf == 0.0 {
            self.skipped += 1;
            return;
        }
        match sampler.invert(s.direction) {
            Err(InvertError::Unsupported) => self.unsupported = true,
            Err(InvertError::OutsideDomain | InvertError::ZeroDensity) => self.invert_failures += 1,
            Ok(w) if !(w[0].is_finite() && w[1].is_finite()) => self.invert_failures += 1,
            Ok(w) => {
                let mut e = (w[0] - u[0]).abs().max((w[1] - u[1]).abs());
                if e > tolerance {
                    // Where the map is not injective (an azimuth seam v = 0 ≡ v = 1, a pole
                    // reached from a whole edge) any preimage is a correct inverse: accept u′
                    // if it samples the same direction.
                    let d = sampler.sample(w).direction;
                    let dd = (0..3)
                        .map(|i| (d[i] - s.direction[i]).abs())
                        .fold(0.0, f64::max);
                    if dd <= tolerance {
                        self.seam += 1;
                        e = dd;
                    } else {
                        // Where the inverse is ill conditioned, the round-off of the sampled
                        // direction alone moves u′ by up to the reach: only the excess counts.
                        let excess = (e - roundoff_reach(sampler, s.direction, w)).max(0.0);
                        if excess <= tolerance {
                            self.ill_conditioned += 1;
                        }
                        e = excess;
                    }
                }
                self.tested += 1;
                if e > self.max_error || self.worst.is_none() {
                    self.max_error = e;
                    self.worst = Some((u, w));
                }
            }
        }
    }

    fn merge(mut self, o: Acc) -> Acc {
        self.tested += o.tested;
        self.skipped += o.skipped;
        self.invalid += o.invalid;
        self.invert_failures += o.invert_failures;
        self.seam += o.seam;
        self.ill_conditioned += o.ill_conditioned;
        self.unsupported |= o.unsupported;
        if o.worst.is_some() && (self.worst.is_none() || o.max_error > self.max_error) {
            self.max_error = o.max_error;
            self.worst = o.worst;
        }
        self
    }
}

/// The points of the lines u = k/K and v = k/K, k = 0 … K, `per_line` points each.
fn line_points(k_lines: usize, per_line: usize) -> Vec<Point2> {
    let mut pts = Vec::new();
    if k_lines == 0 || per_line == 0 {
        return pts;
    }
    let t = |j: usize| {
        if per_line == 1 {
            0.5
        } else {
            j as f64 / (per_line - 1) as f64
        }
    };
    for k in 0..=k_lines {
        let c = k as f64 / k_lines as f64;
        for j in 0..per_line {
            pts.push([c, t(j)]);
            pts.push([t(j), c]);
        }
    }
    pts
}

/// Measures max |invert(sample(u)) − u| over `opts.points` sequence points and the grid lines of
/// `opts` (see [`RoundTripOptions`]). Points of zero pdf are skipped; an inverse reporting
/// [`InvertError::Unsupported`] makes the item [`Status::NotApplicable`]. Where the map is not
/// injective (e.g. v = 0 and v = 1 on an azimuth seam) an inverse u′ ≠ u is accepted if
/// `sample(u′)` gives the same direction ([`RoundTripReport::seam_points`]); where the inverse is
/// ill conditioned, only the part of |u′ − u| beyond its [`roundoff_reach`] counts
/// ([`RoundTripReport::ill_conditioned_points`]).
pub fn round_trip(sampler: &dyn Sampler, opts: &RoundTripOptions) -> RoundTripReport {
    round_trip_with_progress(sampler, opts, &|_| {})
}

pub(crate) fn round_trip_with_progress(
    sampler: &dyn Sampler,
    opts: &RoundTripOptions,
    progress: &dyn Fn(f64),
) -> RoundTripReport {
    let seq = Sequence::new(opts.sequence, opts.seed);
    let mut lines = line_points(opts.lines, opts.points_per_line);
    lines.extend_from_slice(&opts.extra_points);
    let total = opts.points + lines.len();
    let mut acc = Acc::default();
    let mut pts = vec![[0.0; 2]; super::STREAM_POINTS.min(total)];
    let mut done = 0usize;
    let run = |u: &[Point2]| {
        u.par_chunks(1024)
            .map(|c| {
                let mut a = Acc::default();
                for &p in c {
                    a.add(sampler, opts.tolerance, p, &sampler.sample(p));
                }
                a
            })
            .collect::<Vec<_>>()
            .into_iter()
            .fold(Acc::default(), Acc::merge)
    };
    while done < opts.points && !acc.unsupported {
        let n = (opts.points - done).min(super::STREAM_POINTS);
        seq.fill_par(done as u64, &mut pts[..n]);
        acc = acc.merge(run(&pts[..n]));
        done += n;
        progress(done as f64 / total as f64);
    }
    if !acc.unsupported {
        acc = acc.merge(run(&lines));
    }
    progress(1.0);

    let mut r = RoundTripReport {
        status: Status::Fail,
        message: String::new(),
        tested: acc.tested,
        skipped_zero_pdf: acc.skipped,
        invalid_samples: acc.invalid,
        invert_failures: acc.invert_failures,
        seam_points: acc.seam,
        ill_conditioned_points: acc.ill_conditioned,
        max_error: acc.max_error,
        worst_point: acc.worst.map(|w| w.0),
        worst_inverse: acc.worst.map(|w| w.1),
        tolerance: opts.tolerance,
        extra_points: opts.extra_points.len(),
    };
    r.message = if acc.unsupported {
        r.status = Status::NotApplicable;
        format!("the '{}' sampler has no inverse", sampler.name())
    } else if acc.invalid > 0 {
        format!("{} samples are invalid (direction or pdf)", acc.invalid)
    } else if acc.invert_failures > 0 {
        format!(
            "the inverse failed on {} sampled directions of positive pdf",
            acc.invert_failures
        )
    } else if acc.tested == 0 {
        "no point of positive pdf to test".to_string()
    } else if !super::within(acc.max_error, opts.tolerance) {
        format!(
            "max error {:.3e} > {:.1e} at u = {:?} (inverse {:?})",
            acc.max_error,
            opts.tolerance,
            r.worst_point.unwrap_or_default(),
            r.worst_inverse.unwrap_or_default()
        )
    } else {
        r.status = Status::Pass;
        format!("max error {:.3e} ≤ {:.1e}", acc.max_error, opts.tolerance)
    };
    r
}

/// Points of the square on the preimages of the cell boundaries of `diagram`: for every parallel
/// θ_j and every meridian φ_i, `per_line` directions along it (within the sampler's domain) are
/// inverted by the sampler. These are where the map's pieces meet (kinks of the radial and angular
/// stages), so they are the points most likely to expose an inverse that picks the wrong cell.
/// Empty when the sampler has no inverse. Directions of zero pdf are left out.
pub fn cell_boundary_points(
    sampler: &dyn Sampler,
    diagram: &crate::Diagram,
    per_line: usize,
) -> Vec<Point2> {
    let (theta, phi) = (diagram.theta(), diagram.phi());
    let t_max = match sampler.domain() {
        crate::Domain::Hemisphere => std::f64::consts::FRAC_PI_2,
        crate::Domain::Sphere => std::f64::consts::PI,
    };
    let steps = per_line.max(2);
    let mut dirs = Vec::with_capacity((theta.len() + phi.len()) * steps);
    // Parallels at the poles are single directions, not lines: left out.
    for &t in theta
        .iter()
        .filter(|&&t| t > 0.0 && t < std::f64::consts::PI && t <= t_max)
    {
        for k in 0..steps {
            let p = std::f64::consts::TAU * (k as f64 + 0.5) / steps as f64;
            dirs.push(crate::sampler::direction(t, p));
        }
    }
    for &p in phi {
        for k in 0..steps {
            let t = t_max * (k as f64 + 0.5) / steps as f64;
            dirs.push(crate::sampler::direction(t, p));
        }
    }
    let mut out = Vec::with_capacity(dirs.len());
    for d in dirs {
        if sampler.pdf(d) <= 0.0 {
            continue;
        }
        match sampler.invert(d) {
            Ok(u) if u[0].is_finite() && u[1].is_finite() => out.push(u),
            Err(InvertError::Unsupported) => return Vec::new(),
            _ => {}
        }
    }
    out
}

/// η = 2⁻⁴⁸ ≈ 3.6e-15: the round-off budget of a computed direction in [`roundoff_reach`].
const ROUNDOFF_ETA: f64 = 1.0 / (1u64 << 48) as f64;

/// How far the round-off of a computed direction can move the inverse at direction `d`, whose
/// inverse is `w`: the sum, over three perturbations of `d` within that round-off, of the larger
/// (over both signs) max-norm change of `invert` — the inverse's Jacobian times the round-off,
/// measured by finite differences at the round-off's own step. The perturbations, with
/// η = 2⁻⁴⁸ ≈ 3.6e-15: a rotation about z by η (about 4 ulp of 2π: the azimuth the sampler used
/// and the one atan2 reads back differ by that much), x and y scaled by 1 ± η (the disk radius an
/// HDS inverse reads from them above the horizon), z ± η (the radius it reads from z below it, on
/// the Lambert sphere). A step outside the domain is left out.
///
/// It is ~1e-15 where the inverse is well conditioned, and 1e-8 … 1e-7 next to a meridian that
/// carries ~1e-8 of its neighbour's light, where the radial CDF that the inverse interpolates
/// across the sector switches from one meridian's to the other's within ~1e-8 of the sector, so
/// an ulp of azimuth moves the square point by 1e-9 … 1e-8 (docs/CHECKS.md, "Round trip";
/// docs/FUZZING.md, "Ill-conditioned round trips"). Across a seam of the inverse it measures the
/// jump.
pub fn roundoff_reach(sampler: &dyn Sampler, d: Vec3, w: Point2) -> f64 {
    let moved = |q: Vec3| {
        sampler
            .invert(q)
            .map(|g| (g[0] - w[0]).abs().max((g[1] - w[1]).abs()))
            .ok()
            .filter(|m| m.is_finite())
            .unwrap_or(0.0)
    };
    let largest =
        |step: &dyn Fn(f64) -> Vec3| moved(step(ROUNDOFF_ETA)).max(moved(step(-ROUNDOFF_ETA)));
    // A rotation about z by a (to first order; the length changes by a², far below an ulp).
    let azimuth = largest(&|a| [d[0] - d[1] * a, d[1] + d[0] * a, d[2]]);
    let radius_xy = largest(&|a| [d[0] * (1.0 + a), d[1] * (1.0 + a), d[2]]);
    let radius_z = largest(&|a| [d[0], d[1], d[2] + a]);
    azimuth + radius_xy + radius_z
}

impl RoundTripReport {
    /// One line for the human-readable summary.
    pub fn summary(&self) -> String {
        format!(
            "max |invert(sample(u)) - u| = {:.3e} over {} points ({} on cell boundaries, {} on \
             seams, {} ill-conditioned, {} skipped at pdf 0) — {}",
            self.max_error,
            self.tested,
            self.extra_points,
            self.seam_points,
            self.ill_conditioned_points,
            self.skipped_zero_pdf,
            self.message
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_include_edges_and_corners() {
        let p = line_points(4, 5);
        assert_eq!(p.len(), 5 * 5 * 2);
        for c in [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0], [1.0, 0.0], [0.25, 0.5]] {
            assert!(p.contains(&c), "{c:?}");
        }
        assert!(line_points(0, 5).is_empty());
    }
}
