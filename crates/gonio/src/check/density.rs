//! Checks of the density alone: `sample().pdf` against `pdf()`, normalisation, and the ratio of the
//! pdf to the target.

use super::grid::BinGrid;
use super::{for_each_sample_chunk, sample_defect, Status};
use crate::sampler::{Domain, Point2, Sampler};
use crate::sequence::{Sequence, SequenceKind};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

// ---------------------------------------------------------------------------------------------
// pdf consistency

/// Settings of the pdf-consistency check.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PdfConsistencyOptions {
    /// Number of sample points.
    pub points: usize,
    /// Which sequence supplies them.
    pub sequence: SequenceKind,
    /// Its seed.
    pub seed: u64,
    /// Largest accepted |a − b| / max(|a|, |b|) between `sample(u).pdf` and `pdf(direction)`.
    pub tolerance: f64,
}

impl Default for PdfConsistencyOptions {
    fn default() -> Self {
        PdfConsistencyOptions {
            points: 100_000,
            sequence: SequenceKind::Random,
            seed: 0x0bad_5eed,
            tolerance: 1e-9,
        }
    }
}

/// What the pdf-consistency check measured.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PdfConsistencyReport {
    /// Pass or fail.
    pub status: Status,
    /// One line saying why.
    pub message: String,
    /// Samples compared.
    pub tested: usize,
    /// Samples with a non-finite or non-unit direction (|‖d‖ − 1| > 1e-9), a direction outside the
    /// domain, or a non-finite or negative pdf; and samples where `pdf()` is non-finite or negative.
    pub invalid_samples: usize,
    /// What was wrong with the first invalid sample.
    pub first_invalid: Option<String>,
    /// Largest relative difference |a − b| / max(|a|, |b|) (0 where both are 0).
    pub max_rel_error: f64,
    /// The point u of the square where it occurred.
    pub worst_point: Option<Point2>,
    /// The tolerance applied.
    pub tolerance: f64,
}

/// Compares `sample(u).pdf` with `pdf(sample(u).direction)` on `opts.points` sequence points, and
/// checks that every sample is a finite unit direction in the domain with a finite pdf ≥ 0.
pub fn pdf_consistency(
    sampler: &dyn Sampler,
    opts: &PdfConsistencyOptions,
) -> PdfConsistencyReport {
    pdf_consistency_with_progress(sampler, opts, &|_| {})
}

pub(crate) fn pdf_consistency_with_progress(
    sampler: &dyn Sampler,
    opts: &PdfConsistencyOptions,
    progress: &dyn Fn(f64),
) -> PdfConsistencyReport {
    let seq = Sequence::new(opts.sequence, opts.seed);
    let domain = sampler.domain();
    let mut r = PdfConsistencyReport {
        status: Status::Fail,
        message: String::new(),
        tested: 0,
        invalid_samples: 0,
        first_invalid: None,
        max_rel_error: 0.0,
        worst_point: None,
        tolerance: opts.tolerance,
    };
    for_each_sample_chunk(sampler, &seq, opts.points, progress, |_, pts, samples| {
        let evals: Vec<f64> = samples
            .par_iter()
            .map(|s| sampler.pdf(s.direction))
            .collect();
        for ((u, s), &p) in pts.iter().zip(samples).zip(&evals) {
            let defect = sample_defect(domain, s).or(if p.is_finite() && p >= 0.0 {
                None
            } else {
                Some("pdf(direction) is not a finite non-negative number")
            });
            if let Some(why) = defect {
                r.invalid_samples += 1;
                if r.first_invalid.is_none() {
                    r.first_invalid = Some(format!("u = {u:?}: {why} ({s:?}, pdf() = {p})"));
                }
                continue;
            }
            r.tested += 1;
            let m = s.pdf.abs().max(p.abs());
            let e = if m == 0.0 { 0.0 } else { (s.pdf - p).abs() / m };
            if e > r.max_rel_error || r.worst_point.is_none() {
                r.max_rel_error = e;
                r.worst_point = Some(*u);
            }
        }
    });
    r.message = if let Some(first) = &r.first_invalid {
        format!("{} invalid samples; first: {first}", r.invalid_samples)
    } else if r.tested == 0 {
        "no samples tested".to_string()
    } else if r.max_rel_error > opts.tolerance {
        format!(
            "relative difference {:.3e} > {:.1e} at u = {:?}",
            r.max_rel_error,
            opts.tolerance,
            r.worst_point.unwrap_or_default()
        )
    } else {
        r.status = Status::Pass;
        format!(
            "max relative difference {:.3e} ≤ {:.1e}",
            r.max_rel_error, opts.tolerance
        )
    };
    r
}

impl PdfConsistencyReport {
    /// One line for the human-readable summary.
    pub fn summary(&self) -> String {
        format!("{} samples — {}", self.tested, self.message)
    }
}

// ---------------------------------------------------------------------------------------------
// normalisation

/// Settings of the normalisation check.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NormalisationOptions {
    /// `[z_cells, phi_cells]` of the (z = cos θ, φ) quadrature grid; `None` takes 64 × 128 on the
    /// hemisphere and 128 × 128 on the sphere.
    pub resolution: Option<[usize; 2]>,
    /// Gauss–Legendre nodes per axis and cell.
    pub quad_nodes: usize,
    /// Largest accepted |∫ pdf dω − 1| (and the same for the target).
    pub tolerance: f64,
}

impl Default for NormalisationOptions {
    fn default() -> Self {
        NormalisationOptions {
            resolution: None,
            quad_nodes: 3,
            tolerance: 1e-3,
        }
    }
}

/// What the normalisation check measured.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NormalisationReport {
    /// Pass or fail.
    pub status: Status,
    /// One line saying why.
    pub message: String,
    /// ∫ pdf dω over the domain (should be 1).
    pub pdf_integral: f64,
    /// ∫ target_pdf dω over the domain (should be 1).
    pub target_integral: f64,
    /// Quadrature nodes where pdf or target_pdf was not a finite non-negative number.
    pub invalid_evaluations: usize,
    /// `[z_cells, phi_cells]` used.
    pub cells: [usize; 2],
    /// Gauss–Legendre nodes per axis and cell.
    pub quad_nodes: usize,
    /// The tolerance applied.
    pub tolerance: f64,
}

/// ∫ pdf dω and ∫ target_pdf dω over the domain by Gauss–Legendre quadrature on a (z, φ) grid
/// (dω = dz dφ); both must equal 1 within `opts.tolerance`.
pub fn normalisation(sampler: &dyn Sampler, opts: &NormalisationOptions) -> NormalisationReport {
    let domain = sampler.domain();
    let [nz, np] = opts.resolution.unwrap_or(match domain {
        Domain::Hemisphere => [64, 128],
        Domain::Sphere => [128, 128],
    });
    let grid = BinGrid::new(domain, nz, np);
    let bad = AtomicUsize::new(0);
    let checked = |v: f64| {
        if !(v.is_finite() && v >= 0.0) {
            bad.fetch_add(1, Ordering::Relaxed);
        }
        v
    };
    let pdf_integral: f64 = grid
        .integrate(opts.quad_nodes, |d| checked(sampler.pdf(d)))
        .iter()
        .sum();
    let target_integral: f64 = grid
        .integrate(opts.quad_nodes, |d| checked(sampler.target_pdf(d)))
        .iter()
        .sum();
    let invalid = bad.into_inner();
    let tol = opts.tolerance;
    let mut r = NormalisationReport {
        status: Status::Fail,
        message: String::new(),
        pdf_integral,
        target_integral,
        invalid_evaluations: invalid,
        cells: [grid.z_bins(), grid.phi_bins()],
        quad_nodes: opts.quad_nodes.max(1),
        tolerance: tol,
    };
    r.message = if invalid > 0 {
        format!("{invalid} evaluations of pdf or target_pdf are not finite non-negative numbers")
    } else if !super::within((pdf_integral - 1.0).abs(), tol) {
        format!("the pdf integrates to {pdf_integral:.6}, not 1 (tolerance {tol:.1e})")
    } else if !super::within((target_integral - 1.0).abs(), tol) {
        format!("the target pdf integrates to {target_integral:.6}, not 1 (tolerance {tol:.1e})")
    } else {
        r.status = Status::Pass;
        format!(
            "|∫pdf − 1| = {:.2e}, |∫target − 1| = {:.2e} ≤ {tol:.1e}",
            (pdf_integral - 1.0).abs(),
            (target_integral - 1.0).abs()
        )
    };
    r
}

impl NormalisationReport {
    /// One line for the human-readable summary.
    pub fn summary(&self) -> String {
        format!(
            "∫pdf = {:.6}, ∫target = {:.6} ({}×{} cells, {}² nodes) — {}",
            self.pdf_integral,
            self.target_integral,
            self.cells[0],
            self.cells[1],
            self.quad_nodes,
            self.message
        )
    }
}

// ---------------------------------------------------------------------------------------------
// pdf / target ratio

/// Settings of the pdf/target ratio check.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RatioOptions {
    /// Directions in θ, from the pole to the horizon (hemisphere) or the far pole (sphere), both
    /// included, evenly spaced in angle.
    pub theta_steps: usize,
    /// Directions in φ, φ_j = 2πj / phi_steps.
    pub phi_steps: usize,
    /// Only directions where the target exceeds this fraction of its maximum over the grid count.
    pub min_target_fraction: f64,
    /// A bound (low, high) the sampler claims for pdf/target (the HDS map computes one at build
    /// time). `None`: the check only requires every ratio to be finite and positive.
    pub claimed_bound: Option<(f64, f64)>,
    /// Relative slack on the claimed bound: pass if low·(1 − slack) ≤ ratio ≤ high·(1 + slack).
    pub slack: f64,
}

impl Default for RatioOptions {
    fn default() -> Self {
        RatioOptions {
            theta_steps: 257,
            phi_steps: 512,
            min_target_fraction: 0.01,
            claimed_bound: None,
            slack: 1e-9,
        }
    }
}

/// What the ratio check measured.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RatioReport {
    /// Pass or fail.
    pub status: Status,
    /// One line saying why.
    pub message: String,
    /// Directions where the target exceeds the threshold.
    pub evaluated: usize,
    /// Smallest pdf/target.
    pub min_ratio: f64,
    /// Largest pdf/target.
    pub max_ratio: f64,
    /// (θ, φ) in degrees of the smallest ratio.
    pub argmin_deg: Option<[f64; 2]>,
    /// (θ, φ) in degrees of the largest ratio.
    pub argmax_deg: Option<[f64; 2]>,
    /// Largest target_pdf on the grid, per steradian.
    pub target_max: f64,
    /// The claimed bound, if any.
    pub claimed_bound: Option<(f64, f64)>,
    /// Directions where pdf or target_pdf is not a finite non-negative number.
    pub invalid_evaluations: usize,
}

/// pdf/target_pdf over a (θ, φ) grid of directions where the target exceeds
/// `opts.min_target_fraction` of its maximum: min and max, and agreement with a claimed bound.
pub fn pdf_target_ratio(sampler: &dyn Sampler, opts: &RatioOptions) -> RatioReport {
    let theta_max = match sampler.domain() {
        Domain::Hemisphere => std::f64::consts::FRAC_PI_2,
        Domain::Sphere => std::f64::consts::PI,
    };
    let nt = opts.theta_steps.max(2);
    let np = opts.phi_steps.max(1);
    let angles = |k: usize| {
        let (i, j) = (k / np, k % np);
        (
            theta_max * i as f64 / (nt - 1) as f64,
            std::f64::consts::TAU * j as f64 / np as f64,
        )
    };
    let values: Vec<(f64, f64)> = (0..nt * np)
        .into_par_iter()
        .map(|k| {
            let (t, p) = angles(k);
            let d = crate::sampler::direction(t, p);
            (sampler.pdf(d), sampler.target_pdf(d))
        })
        .collect();
    let ok = |v: f64| v.is_finite() && v >= 0.0;
    let invalid = values.iter().filter(|(p, t)| !(ok(*p) && ok(*t))).count();
    let target_max = values
        .iter()
        .filter(|(p, t)| ok(*p) && ok(*t))
        .map(|v| v.1)
        .fold(0.0, f64::max);
    let cut = opts.min_target_fraction * target_max;
    let mut r = RatioReport {
        status: Status::Fail,
        message: String::new(),
        evaluated: 0,
        min_ratio: f64::INFINITY,
        max_ratio: f64::NEG_INFINITY,
        argmin_deg: None,
        argmax_deg: None,
        target_max,
        claimed_bound: opts.claimed_bound,
        invalid_evaluations: invalid,
    };
    let deg = |k: usize| {
        let (t, p) = angles(k);
        [t.to_degrees(), p.to_degrees()]
    };
    for (k, &(p, t)) in values.iter().enumerate() {
        if !(ok(p) && ok(t)) || t <= cut {
            continue;
        }
        r.evaluated += 1;
        let q = p / t;
        if q < r.min_ratio {
            r.min_ratio = q;
            r.argmin_deg = Some(deg(k));
        }
        if q > r.max_ratio {
            r.max_ratio = q;
            r.argmax_deg = Some(deg(k));
        }
    }
    r.message = if invalid > 0 {
        format!("{invalid} directions where pdf or target_pdf is not a finite non-negative number")
    } else if r.evaluated == 0 {
        "the target is zero on the whole grid".to_string()
    } else if !(r.min_ratio > 0.0 && r.max_ratio.is_finite()) {
        format!(
            "the pdf vanishes where the target is above {} of its maximum (θ, φ = {:?}°)",
            opts.min_target_fraction,
            r.argmin_deg.unwrap_or_default()
        )
    } else {
        match opts.claimed_bound {
            Some((lo, hi))
                if !(r.min_ratio >= lo * (1.0 - opts.slack)
                    && r.max_ratio <= hi * (1.0 + opts.slack)) =>
            {
                format!(
                    "observed ratio [{:.6}, {:.6}] exceeds the claimed bound [{lo:.6}, {hi:.6}]",
                    r.min_ratio, r.max_ratio
                )
            }
            Some((lo, hi)) => {
                r.status = Status::Pass;
                format!(
                    "observed [{:.6}, {:.6}] within the claimed bound [{lo:.6}, {hi:.6}]",
                    r.min_ratio, r.max_ratio
                )
            }
            None => {
                r.status = Status::Pass;
                format!(
                    "observed [{:.6}, {:.6}] (no bound claimed)",
                    r.min_ratio, r.max_ratio
                )
            }
        }
    };
    r
}

impl RatioReport {
    /// One line for the human-readable summary.
    pub fn summary(&self) -> String {
        format!(
            "pdf/target in [{:.4}, {:.4}] over {} directions — {}",
            self.min_ratio, self.max_ratio, self.evaluated, self.message
        )
    }
}
