//! The whole battery: every check on one sampler, one report.

use super::chi2::{chi_square_points, chi_square_test_with_progress};
use super::density::pdf_consistency_with_progress;
use super::flux::flux_estimate_with_progress;
use super::roundtrip::round_trip_with_progress;
use super::*;
use crate::sampler::Domain;
use crate::sequence::Halton;
use std::fmt;

/// Settings of every item of [`run_battery`]. `Default` is the CLI's thorough run (a few seconds for
/// a fast sampler); [`BatteryOptions::quick`] is about ten times cheaper.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BatteryOptions {
    /// The chi-square test on iid points.
    pub chi_square: ChiSquareOptions,
    /// Halton points for the informational chi²/dof of QMC points (same bins); 0 skips it.
    pub qmc_points: usize,
    /// The round-trip check.
    pub round_trip: RoundTripOptions,
    /// The pdf-consistency check.
    pub pdf_consistency: PdfConsistencyOptions,
    /// The normalisation check.
    pub normalisation: NormalisationOptions,
    /// The pdf/target ratio check (set `ratio.claimed_bound` to test a sampler's claimed bound).
    pub ratio: RatioOptions,
    /// The flux check.
    pub flux: FluxOptions,
    /// Closed-form total Φ of the intensity I = Φ · target_pdf for the flux check (1 checks the
    /// normalised target; the CLI passes the diagram's flux).
    pub flux_total: f64,
}

impl Default for BatteryOptions {
    fn default() -> Self {
        BatteryOptions {
            chi_square: ChiSquareOptions::default(),
            qmc_points: 1 << 18,
            round_trip: RoundTripOptions::default(),
            pdf_consistency: PdfConsistencyOptions::default(),
            normalisation: NormalisationOptions::default(),
            ratio: RatioOptions::default(),
            flux: FluxOptions::default(),
            flux_total: 1.0,
        }
    }
}

impl BatteryOptions {
    /// A cheaper run for tests and quick looks: 2·10⁵ chi-square and flux samples, 2·10⁴ round-trip
    /// and pdf points, coarser quadrature and ratio grids. Same tolerances and significance.
    pub fn quick() -> Self {
        let d = BatteryOptions::default();
        BatteryOptions {
            chi_square: ChiSquareOptions {
                samples: 200_000,
                ..d.chi_square
            },
            qmc_points: 1 << 15,
            round_trip: RoundTripOptions {
                points: 20_000,
                lines: 8,
                points_per_line: 65,
                ..d.round_trip
            },
            pdf_consistency: PdfConsistencyOptions {
                points: 20_000,
                ..d.pdf_consistency
            },
            normalisation: NormalisationOptions {
                resolution: Some([32, 64]),
                ..d.normalisation
            },
            ratio: RatioOptions {
                theta_steps: 91,
                phi_steps: 180,
                ..d.ratio
            },
            flux: FluxOptions {
                samples: 200_000,
                ..d.flux
            },
            flux_total: 1.0,
        }
    }

    /// These options with every seed derived from `seed` (distinct per item).
    pub fn with_seed(mut self, seed: u64) -> Self {
        let s = |i: u64| crate::sequence::mix64(seed ^ i.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        self.chi_square.seed = s(1);
        self.round_trip.seed = s(2);
        self.pdf_consistency.seed = s(3);
        self.flux.seed = s(4);
        self
    }
}

/// Everything [`run_battery`] found; `serde_json::to_string(&report)` is what `gonio check --json`
/// prints, and `Display` is the human-readable summary.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Report {
    /// [`Sampler::name`] of the sampler checked.
    pub sampler: String,
    /// Its domain, "hemisphere" or "sphere".
    pub domain: String,
    /// True if no item failed.
    pub passed: bool,
    /// Chi-square test on iid points.
    pub chi_square: ChiSquareReport,
    /// Chi-square statistic of Halton points (status [`Status::Info`]: chi²/dof far below 1 is
    /// what a correct sampler gives).
    pub qmc_chi_square: Option<ChiSquareReport>,
    /// Round trip.
    pub round_trip: RoundTripReport,
    /// pdf consistency.
    pub pdf_consistency: PdfConsistencyReport,
    /// Normalisation.
    pub normalisation: NormalisationReport,
    /// pdf/target ratio.
    pub ratio: RatioReport,
    /// Flux estimate.
    pub flux: FluxReport,
    /// The options the battery ran with.
    pub options: BatteryOptions,
}

/// One line of the report: item name, status, summary.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ItemSummary {
    /// Item name: "chi-square", "qmc chi-square", "round trip", "pdf consistency",
    /// "normalisation", "pdf/target ratio", "flux".
    pub name: &'static str,
    /// Its status.
    pub status: Status,
    /// One line of figures and verdict.
    pub summary: String,
}

impl Report {
    /// The items in the order they ran.
    pub fn items(&self) -> Vec<ItemSummary> {
        let mut v = vec![ItemSummary {
            name: "chi-square",
            status: self.chi_square.status,
            summary: self.chi_square.summary(),
        }];
        if let Some(q) = &self.qmc_chi_square {
            v.push(ItemSummary {
                name: "qmc chi-square",
                status: q.status,
                summary: format!(
                    "{} Halton points: chi2/dof = {:.4} (≪ 1 expected for a correct sampler)",
                    q.points, q.chi2_per_dof
                ),
            });
        }
        v.extend([
            ItemSummary {
                name: "round trip",
                status: self.round_trip.status,
                summary: self.round_trip.summary(),
            },
            ItemSummary {
                name: "pdf consistency",
                status: self.pdf_consistency.status,
                summary: self.pdf_consistency.summary(),
            },
            ItemSummary {
                name: "normalisation",
                status: self.normalisation.status,
                summary: self.normalisation.summary(),
            },
            ItemSummary {
                name: "pdf/target ratio",
                status: self.ratio.status,
                summary: self.ratio.summary(),
            },
            ItemSummary {
                name: "flux",
                status: self.flux.status,
                summary: self.flux.summary(),
            },
        ]);
        v
    }

    /// Names of the failed items.
    pub fn failures(&self) -> Vec<&'static str> {
        self.items()
            .into_iter()
            .filter(|i| i.status.is_failure())
            .map(|i| i.name)
            .collect()
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "sampler '{}' ({}): {}",
            self.sampler,
            self.domain,
            if self.passed { "PASS" } else { "FAIL" }
        )?;
        for i in self.items() {
            writeln!(
                f,
                "  [{:<4}] {:<16} {}",
                i.status.label(),
                i.name,
                i.summary
            )?;
        }
        Ok(())
    }
}

/// Runs every check on `sampler` (see the module documentation).
pub fn run_battery(sampler: &dyn Sampler, opts: &BatteryOptions) -> Report {
    run_battery_with_progress(sampler, opts, &|_, _| {})
}

/// [`run_battery`], calling `progress(item, fraction)` as it goes: `item` is the name of the
/// running item (as in [`ItemSummary::name`]) and `fraction` in [0, 1] the part of the whole
/// battery done, non-decreasing, ending at 1. The CLI hooks its progress bar here.
pub fn run_battery_with_progress(
    sampler: &dyn Sampler,
    opts: &BatteryOptions,
    progress: &dyn Fn(&str, f64),
) -> Report {
    // Rough shares of the running time, for the progress fraction only.
    const W: [(&str, f64); 7] = [
        ("chi-square", 0.30),
        ("qmc chi-square", 0.08),
        ("round trip", 0.15),
        ("pdf consistency", 0.07),
        ("normalisation", 0.10),
        ("pdf/target ratio", 0.10),
        ("flux", 0.20),
    ];
    let stage = |i: usize| {
        let before: f64 = W[..i].iter().map(|w| w.1).sum();
        let (name, w) = W[i];
        move |x: f64| progress(name, (before + w * x.clamp(0.0, 1.0)).min(1.0))
    };

    let s = stage(0);
    s(0.0);
    let chi_square = chi_square_test_with_progress(sampler, &opts.chi_square, &s);

    let s = stage(1);
    s(0.0);
    let qmc_chi_square = (opts.qmc_points > 0).then(|| {
        let mut pts = vec![[0.0; 2]; opts.qmc_points];
        // Skip the corner point (0, 0), which maps onto a seam of many samplers.
        Sequence::from(Halton::with_skip(1)).fill_par(0, &mut pts);
        let mut q = chi_square_points(sampler, &pts, &opts.chi_square);
        q.status = Status::Info;
        q
    });
    s(1.0);

    let s = stage(2);
    let round_trip = round_trip_with_progress(sampler, &opts.round_trip, &s);
    let s = stage(3);
    let pdf_consistency = pdf_consistency_with_progress(sampler, &opts.pdf_consistency, &s);
    let s = stage(4);
    s(0.0);
    let normalisation = normalisation(sampler, &opts.normalisation);
    s(1.0);
    let s = stage(5);
    s(0.0);
    let ratio = pdf_target_ratio(sampler, &opts.ratio);
    s(1.0);
    let s = stage(6);
    let flux = flux_estimate_with_progress(sampler, opts.flux_total, &opts.flux, &s);
    progress("flux", 1.0);

    let mut report = Report {
        sampler: sampler.name().to_string(),
        domain: match sampler.domain() {
            Domain::Hemisphere => "hemisphere",
            Domain::Sphere => "sphere",
        }
        .to_string(),
        passed: false,
        chi_square,
        qmc_chi_square,
        round_trip,
        pdf_consistency,
        normalisation,
        ratio,
        flux,
        options: opts.clone(),
    };
    report.passed = report.failures().is_empty();
    report
}
