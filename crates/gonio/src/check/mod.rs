//! Checks: the statistical and numerical tests every sampler must pass.
//!
//! Every check takes any `&dyn Sampler` (hemisphere or sphere) and returns a serialisable report
//! with a [`Status`] and every figure it measured; [`run_battery`] runs them all (`gonio check
//! FILE` in the CLI). Directions and densities follow [`crate::sampler`]: unit vectors, pdfs per
//! steradian. A sampler that returns NaN, a non-unit direction or a negative pdf fails the check
//! concerned; no check panics on a sampler's output.
//!
//! | item | what | passes when |
//! |---|---|---|
//! | [`chi_square_test`] | histogram of iid samples in equal-solid-angle bins vs ∫pdf per bin | p ≥ 1 − (1 − α)^(1/K) (Šidák), no sample in a bin of zero expectation |
//! | [`round_trip`] | `invert(sample(u))` vs `u` on sequence points, grid lines of the square and (with [`cell_boundary_points`]) the preimages of the diagram's cell boundaries | max error ≤ tolerance (1e-8) beyond the inverse's [`roundoff_reach`]; not applicable without inverse |
//! | [`pdf_consistency`] | `sample(u).pdf` vs `pdf(direction)` | relative difference ≤ 1e-9 |
//! | [`normalisation`] | ∫pdf dω and ∫target dω by quadrature | both within 1e-3 of 1 |
//! | [`pdf_target_ratio`] | pdf/target where target > 1 % of max | finite, positive, within a claimed bound (1e-9 relative slack) |
//! | [`flux_estimate`] | mean(Φ·target/pdf) over iid samples vs Φ | within 5 standard errors |
//!
//! See `docs/CHECKS.md` for the reasoning behind each tolerance.
//!
//! ```
//! # use gonio::sampler::*;
//! # struct Uniform;
//! # impl Sampler for Uniform {
//! #     fn name(&self) -> &'static str { "uniform" }
//! #     fn domain(&self) -> Domain { Domain::Sphere }
//! #     fn sample(&self, u: Point2) -> Sample {
//! #         let z = 1.0 - 2.0 * u[0];
//! #         let r = (1.0 - z * z).max(0.0).sqrt();
//! #         let p = std::f64::consts::TAU * u[1];
//! #         Sample { direction: [r * p.cos(), r * p.sin(), z], pdf: 0.25 / std::f64::consts::PI }
//! #     }
//! #     fn pdf(&self, _: Vec3) -> f64 { 0.25 / std::f64::consts::PI }
//! #     fn invert(&self, _: Vec3) -> Result<Point2, InvertError> { Err(InvertError::Unsupported) }
//! #     fn target_pdf(&self, _: Vec3) -> f64 { 0.25 / std::f64::consts::PI }
//! #     fn memory_bytes(&self) -> usize { 0 }
//! # }
//! use gonio::check::{run_battery, BatteryOptions, Status};
//! let report = run_battery(&Uniform, &BatteryOptions::quick());
//! assert!(report.passed);
//! assert_eq!(report.round_trip.status, Status::NotApplicable);
//! println!("{report}");
//! ```

mod battery;
mod chi2;
mod density;
mod flux;
mod grid;
mod roundtrip;

#[cfg(test)]
mod tests;

pub use battery::{
    chi_square_two_stage, chi_square_two_stage_with_integrals, flux_two_stage, run_battery,
    run_battery_with_progress, BatteryOptions, ConfirmOptions, ItemSummary, Report,
};
pub use chi2::{
    bin_integrals, bin_tail_p_value, chi_square_points, chi_square_test,
    chi_square_test_with_integrals, pooled_chi_square, ChiSquareOptions, ChiSquareReport,
    PooledChiSquare,
};
pub use density::{
    normalisation, pdf_consistency, pdf_target_ratio, NormalisationOptions, NormalisationReport,
    PdfConsistencyOptions, PdfConsistencyReport, RatioOptions, RatioReport,
};
pub use flux::{flux_estimate, FluxOptions, FluxReport};
pub use grid::{BinGrid, QUAD_REL_TOL, QUAD_TOL};
pub use roundtrip::{
    cell_boundary_points, round_trip, roundoff_reach, RoundTripOptions, RoundTripReport,
};

use crate::sampler::{Domain, Point2, Sample, Sampler};
use crate::sequence::Sequence;

/// Outcome of one check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The sampler passed.
    Pass,
    /// The sampler failed.
    Fail,
    /// The check does not apply to this sampler (e.g. round trip without an inverse); not a failure.
    NotApplicable,
    /// Informational figures only; never a failure.
    Info,
}

impl Status {
    /// Whether this status fails the battery.
    pub fn is_failure(self) -> bool {
        self == Status::Fail
    }
    /// Upper-case label for the text summary.
    pub fn label(self) -> &'static str {
        match self {
            Status::Pass => "PASS",
            Status::Fail => "FAIL",
            Status::NotApplicable => "N/A",
            Status::Info => "INFO",
        }
    }
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

/// Šidák's per-test significance threshold 1 − (1 − α)^(1/K) for K independent tests run at family
/// level α, computed without cancellation. K = 0 counts as 1.
pub fn sidak_threshold(alpha: f64, tests: usize) -> f64 {
    -((-alpha).ln_1p() / tests.max(1) as f64).exp_m1()
}

/// `x ≤ limit`, false if either is NaN (so a NaN figure never passes).
pub(crate) fn within(x: f64, limit: f64) -> bool {
    x <= limit
}

/// Points per block when the battery streams samples: bounds its memory for any sample count
/// (about 2 MiB of samples a block). Not a batch size of the samplers: each block goes through
/// their batch calls, which work in [`crate::batch::CHUNK`]s.
pub(crate) const STREAM_POINTS: usize = 1 << 16;

/// What is wrong with a sample, if anything: direction not finite, not unit (|‖d‖² − 1| > 2e-9),
/// outside the domain (below z = −1e-12 for a hemisphere), or pdf not a finite number ≥ 0.
pub(crate) fn sample_defect(domain: Domain, s: &Sample) -> Option<&'static str> {
    let d = s.direction;
    if !d.iter().all(|c| c.is_finite()) {
        return Some("direction is not finite");
    }
    let n2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (n2 - 1.0).abs() > 2e-9 {
        return Some("direction is not a unit vector");
    }
    if domain == Domain::Hemisphere && d[2] < -grid::HORIZON_SLACK {
        return Some("direction lies outside the domain");
    }
    if !(s.pdf.is_finite() && s.pdf >= 0.0) {
        return Some("pdf is not a finite non-negative number");
    }
    None
}

/// Streams points `0 … n − 1` of `seq` through `sampler` in chunks of [`STREAM_POINTS`] (filled and sampled
/// on all rayon threads; results are independent of the thread count), calling
/// `f(first_index, points, samples)` per chunk in order and `progress(fraction)` after each.
pub(crate) fn for_each_sample_chunk<F>(
    sampler: &dyn Sampler,
    seq: &Sequence,
    n: usize,
    progress: &dyn Fn(f64),
    mut f: F,
) where
    F: FnMut(u64, &[Point2], &[Sample]),
{
    let mut pts = vec![[0.0; 2]; STREAM_POINTS.min(n)];
    let mut out = vec![Sample::default(); STREAM_POINTS.min(n)];
    let mut done = 0usize;
    while done < n {
        let m = (n - done).min(STREAM_POINTS);
        seq.fill_par(done as u64, &mut pts[..m]);
        crate::sampler::sample_batch_par(sampler, &pts[..m], &mut out[..m]);
        f(done as u64, &pts[..m], &out[..m]);
        done += m;
        progress(done as f64 / n as f64);
    }
}
