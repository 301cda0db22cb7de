//! The whole battery: every check on one sampler, one report.

use super::chi2::{bin_integrals, chi_square_points_with, chi_square_test_with_progress};
use super::density::pdf_consistency_with_progress;
use super::flux::flux_estimate_with_progress;
use super::roundtrip::round_trip_with_progress;
use super::*;
use crate::sampler::Domain;
use crate::sequence::Halton;
use std::fmt;

/// Settings of every item of [`run_battery`]. `Default` is the CLI's thorough run (a few seconds for
/// a fast sampler); [`BatteryOptions::quick`] is about ten times cheaper, with the same
/// false-alarm rate but far less power (docs/CHECKS.md).
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
    /// The second stage of the statistical items (chi-square and flux): a first-stage failure is
    /// re-tested with independent points and more samples, and only a failure of both is reported.
    pub confirm: ConfirmOptions,
}

/// Settings of the second stage of the statistical items of [`run_battery`] (`docs/CHECKS.md`,
/// "False alarms"). The designed false-alarm rate of the whole battery for a correct sampler is
/// α₁·α₂ (chi-square) + the flux item's two-stage rate, at most 1e-4 per file at the defaults.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConfirmOptions {
    /// Whether a first-stage statistical failure is re-tested (false: one stage, as before).
    pub enabled: bool,
    /// Significance α₂ of the second chi-square stage (the first stage uses
    /// `chi_square.alpha`).
    pub alpha: f64,
    /// Accepted deviation of the second flux stage, in standard errors.
    pub flux_k_sigma: f64,
    /// The second stage draws this many times the first stage's samples.
    pub samples_factor: usize,
}

impl Default for ConfirmOptions {
    fn default() -> Self {
        ConfirmOptions {
            enabled: true,
            alpha: 0.005,
            flux_k_sigma: 5.0,
            samples_factor: 2,
        }
    }
}

impl ConfirmOptions {
    /// One stage only: a first-stage failure is reported as it is.
    pub fn disabled() -> Self {
        ConfirmOptions {
            enabled: false,
            ..ConfirmOptions::default()
        }
    }
}

impl Default for BatteryOptions {
    fn default() -> Self {
        BatteryOptions {
            // 2²⁴ samples: enough to catch a 2 % density error over 2 % of the probability and a
            // 5 % error in one bin (docs/CHECKS.md, "Power").
            chi_square: ChiSquareOptions {
                samples: 1 << 24,
                ..ChiSquareOptions::default()
            },
            qmc_points: 1 << 18,
            round_trip: RoundTripOptions::default(),
            pdf_consistency: PdfConsistencyOptions::default(),
            normalisation: NormalisationOptions::default(),
            ratio: RatioOptions::default(),
            flux: FluxOptions::default(),
            flux_total: 1.0,
            confirm: ConfirmOptions::default(),
        }
    }
}

impl BatteryOptions {
    /// A cheaper run for tests and quick looks: 2·10⁵ chi-square and flux samples, 2·10⁴ round-trip
    /// and pdf points, coarser quadrature and ratio grids. Same tolerances, significance and
    /// false-alarm rate; the chi-square test sees only errors about 9 times larger (√(2²⁴/2·10⁵))
    /// than the default run does.
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
            confirm: d.confirm,
        }
    }

    /// The chi-square options of the second stage: independent points (another seed),
    /// `confirm.samples_factor` times the samples, significance `confirm.alpha`.
    pub fn second_stage_chi_square(&self) -> ChiSquareOptions {
        ChiSquareOptions {
            samples: self
                .chi_square
                .samples
                .saturating_mul(self.confirm.samples_factor.max(1)),
            seed: second_seed(self.chi_square.seed),
            alpha: self.confirm.alpha,
            ..self.chi_square.clone()
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

    /// The designed false-alarm rate of the battery for a correct sampler (`docs/CHECKS.md`):
    /// the statistical items are the chi-square test and the flux estimate, every other item
    /// compares figures with numeric tolerances that a correct sampler meets at every point.
    /// With the second stage, an item fails only when two tests on independent points both fail:
    /// chi-square α₁·α₂ (each Šidák-corrected over `chi_square.tests`, times that many tests),
    /// flux f(k₁)·f(k₂) with f(k) = erfc(k/√2) the two-sided normal tail; the battery's rate is
    /// at most their sum (union bound over the items).
    pub fn designed_false_alarm_rate(&self) -> f64 {
        let k = self.chi_square.tests.max(1);
        let a1 = sidak_threshold(self.chi_square.alpha, k);
        let f1 = two_sided_normal_tail(self.flux.k_sigma);
        let (chi, flux) = if self.confirm.enabled {
            let a2 = sidak_threshold(self.confirm.alpha, k);
            (
                k as f64 * a1 * a2,
                f1 * two_sided_normal_tail(self.confirm.flux_k_sigma),
            )
        } else {
            (k as f64 * a1, f1)
        };
        chi + flux
    }
}

/// P(|Z| ≥ k) for a standard normal Z.
fn two_sided_normal_tail(k: f64) -> f64 {
    statrs::function::erf::erfc(k / std::f64::consts::SQRT_2)
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
    /// Chi-square test on iid points: the stage that decided (the first, or the second when the
    /// first failed and [`ConfirmOptions::enabled`]).
    pub chi_square: ChiSquareReport,
    /// The failed first stage of the chi-square test, when a second stage decided.
    pub chi_square_first_stage: Option<ChiSquareReport>,
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
    /// Flux estimate: the stage that decided.
    pub flux: FluxReport,
    /// The failed first stage of the flux estimate, when a second stage decided.
    pub flux_first_stage: Option<FluxReport>,
    /// The designed false-alarm rate of these options for a correct sampler
    /// ([`BatteryOptions::designed_false_alarm_rate`]).
    pub designed_false_alarm_rate: f64,
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
            summary: staged(
                self.chi_square.summary(),
                self.chi_square_first_stage.as_ref().map(|f| {
                    format!(
                        "p = {:.3e} < {:.3e} on {} samples",
                        f.combined_p_value, f.threshold, f.points
                    )
                }),
            ),
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
                summary: staged(
                    self.flux.summary(),
                    self.flux_first_stage.as_ref().map(|f| {
                        format!(
                            "{:+.2} standard errors on {} samples",
                            f.deviation_sigmas, f.samples
                        )
                    }),
                ),
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

/// A statistical item's summary with the stage that decided.
fn staged(summary: String, first_failure: Option<String>) -> String {
    match first_failure {
        None => format!("{summary} [stage 1 decided]"),
        Some(f) => format!(
            "{summary} [stage 2 decided: stage 1 failed ({f}), re-tested on independent points]"
        ),
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "sampler '{}' ({}): {} (designed false-alarm rate {:.1e} for a correct sampler)",
            self.sampler,
            self.domain,
            if self.passed { "PASS" } else { "FAIL" },
            self.designed_false_alarm_rate
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

/// The chi-square item as the battery runs it: the test with `opts.chi_square`, and when it fails
/// in a way a correct sampler can by chance (a small p-value) and `opts.confirm.enabled`, again on
/// independent points with [`BatteryOptions::second_stage_chi_square`]. Returns the report that
/// decided and, when the second stage ran, the failed first one.
pub fn chi_square_two_stage(
    sampler: &dyn Sampler,
    opts: &BatteryOptions,
) -> (ChiSquareReport, Option<ChiSquareReport>) {
    let integrals = bin_integrals(sampler, &opts.chi_square);
    chi_square_two_stage_with(sampler, opts, &integrals, &|_| {})
}

/// [`chi_square_two_stage`] with the bin integrals computed beforehand
/// ([`super::bin_integrals`] with `opts.chi_square`): both stages share them, and so can many
/// seeds of the same sampler.
pub fn chi_square_two_stage_with_integrals(
    sampler: &dyn Sampler,
    opts: &BatteryOptions,
    integrals: &[f64],
) -> (ChiSquareReport, Option<ChiSquareReport>) {
    chi_square_two_stage_with(sampler, opts, integrals, &|_| {})
}

fn chi_square_two_stage_with(
    sampler: &dyn Sampler,
    opts: &BatteryOptions,
    integrals: &[f64],
    progress: &dyn Fn(f64),
) -> (ChiSquareReport, Option<ChiSquareReport>) {
    let first = chi_square_test_with_progress(sampler, &opts.chi_square, Some(integrals), progress);
    if opts.confirm.enabled && chi_square_failed_by_chance(&first) {
        let second = chi_square_test_with_progress(
            sampler,
            &opts.second_stage_chi_square(),
            Some(integrals),
            progress,
        );
        (second, Some(first))
    } else {
        (first, None)
    }
}

/// The flux item as the battery runs it, in two stages like [`chi_square_two_stage`]: the
/// estimate with `opts.flux`, and after a chance failure again on independent points with
/// `confirm.samples_factor` times the samples at `confirm.flux_k_sigma`.
pub fn flux_two_stage(
    sampler: &dyn Sampler,
    opts: &BatteryOptions,
) -> (FluxReport, Option<FluxReport>) {
    flux_two_stage_with_progress(sampler, opts, &|_| {})
}

fn flux_two_stage_with_progress(
    sampler: &dyn Sampler,
    opts: &BatteryOptions,
    progress: &dyn Fn(f64),
) -> (FluxReport, Option<FluxReport>) {
    let first = flux_estimate_with_progress(sampler, opts.flux_total, &opts.flux, progress);
    if opts.confirm.enabled && flux_failed_by_chance(&first) {
        let o = FluxOptions {
            samples: opts
                .flux
                .samples
                .saturating_mul(opts.confirm.samples_factor.max(1)),
            seed: second_seed(opts.flux.seed),
            k_sigma: opts.confirm.flux_k_sigma,
        };
        let second = flux_estimate_with_progress(sampler, opts.flux_total, &o, progress);
        (second, Some(first))
    } else {
        (first, None)
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
    // The bin integrals serve both stages and the QMC statistic.
    let integrals = bin_integrals(sampler, &opts.chi_square);
    let (chi_square, chi_square_first_stage) =
        chi_square_two_stage_with(sampler, opts, &integrals, &s);

    let s = stage(1);
    s(0.0);
    let qmc_chi_square = (opts.qmc_points > 0).then(|| {
        let mut pts = vec![[0.0; 2]; opts.qmc_points];
        // Skip the corner point (0, 0), which maps onto a seam of many samplers.
        Sequence::from(Halton::with_skip(1)).fill_par(0, &mut pts);
        let mut q = chi_square_points_with(sampler, &pts, &opts.chi_square, Some(&integrals));
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
    let (flux, flux_first_stage) = flux_two_stage_with_progress(sampler, opts, &s);
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
        chi_square_first_stage,
        qmc_chi_square,
        round_trip,
        pdf_consistency,
        normalisation,
        ratio,
        flux,
        flux_first_stage,
        designed_false_alarm_rate: opts.designed_false_alarm_rate(),
        options: opts.clone(),
    };
    report.passed = report.failures().is_empty();
    report
}

/// The seed of a second stage: independent of the first stage's stream.
fn second_seed(seed: u64) -> u64 {
    crate::sequence::mix64(seed ^ 0x5ec0_4d57_a6e0_0002)
}

/// A failure a correct sampler can show by chance (a small p-value), as opposed to one no correct
/// sampler ever shows (invalid samples, samples where the pdf integrates to 0, too few bins, a
/// pdf that cannot be integrated): only the former is re-tested.
fn chi_square_failed_by_chance(r: &ChiSquareReport) -> bool {
    r.status == Status::Fail
        && r.invalid_samples == 0
        && r.zero_expected_hits == 0
        && r.dof > 0
        && r.combined_p_value.is_finite()
}

/// As [`chi_square_failed_by_chance`] for the flux estimate.
fn flux_failed_by_chance(r: &FluxReport) -> bool {
    r.status == Status::Fail
        && r.invalid_samples == 0
        && r.total.is_finite()
        && r.standard_error.is_finite()
}
