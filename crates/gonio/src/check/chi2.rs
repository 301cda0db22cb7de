//! Pearson's chi-square goodness-of-fit test of a sampler's histogram against its own pdf, in the
//! manner of Mitsuba 3's `ChiSquareTest`.

use super::grid::BinGrid;
use super::{for_each_sample_chunk, sidak_threshold, Status};
use crate::sampler::{Point2, Sample, Sampler};
use crate::sequence::{Random, Sequence};
use rayon::prelude::*;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Settings of the chi-square test.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ChiSquareOptions {
    /// `[z_bins, phi_bins]`; `None` takes [`BinGrid::chi_square_default`] (16 × 32 hemisphere,
    /// 32 × 32 sphere).
    pub resolution: Option<[usize; 2]>,
    /// Number of iid sample points (ignored by [`chi_square_points`]).
    pub samples: usize,
    /// Seed of the [`Random`] stream of sample points.
    pub seed: u64,
    /// Significance level α of the whole family of tests.
    pub alpha: f64,
    /// Number K of chi-square tests run at level α together (Šidák correction); at least 1.
    pub tests: usize,
    /// Bins whose expected count is below this are pooled (Mitsuba uses 5).
    pub min_expected: f64,
    /// Gauss–Legendre nodes per axis and bin for the pdf integrals.
    pub quad_nodes: usize,
    /// Largest share of the samples allowed where the **target** (the data) is 0: light the data
    /// does not have (1e-6, issue 9's allowance for the zero guard bands of completion). The
    /// histogram is compared with the sampler's own pdf, so a map that *invents* light elsewhere
    /// would pass the Pearson statistic; this support test catches it (iid points only).
    pub max_outside_target: f64,
}

impl Default for ChiSquareOptions {
    fn default() -> Self {
        ChiSquareOptions {
            resolution: None,
            samples: 1_000_000,
            seed: 0x00c0_ffee,
            alpha: 0.01,
            tests: 1,
            min_expected: 5.0,
            quad_nodes: 3,
            max_outside_target: 1e-6,
        }
    }
}

impl ChiSquareOptions {
    /// The bin grid these options give for `sampler`'s domain.
    pub fn grid(&self, sampler: &dyn Sampler) -> BinGrid {
        match self.resolution {
            Some([nz, np]) => BinGrid::new(sampler.domain(), nz, np),
            None => BinGrid::chi_square_default(sampler.domain()),
        }
    }
}

/// Pearson's statistic after pooling, from expected and observed counts per bin.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PooledChiSquare {
    /// Σ (observed − expected)² / expected over the bins after pooling.
    pub chi2: f64,
    /// Degrees of freedom: number of bins after pooling − 1 (0 if fewer than two bins remain).
    pub dof: usize,
    /// Number of original bins merged into the pooled bin.
    pub pooled_bins: usize,
    /// Expected count of the pooled bin.
    pub pooled_expected: f64,
    /// Observed count of the pooled bin.
    pub pooled_observed: u64,
    /// Samples that fell into bins of expected count exactly 0 (each one is a failure).
    pub zero_expected_hits: u64,
    /// Largest |observed − expected| / expected over the bins that were not pooled.
    pub max_rel_deviation: f64,
    /// Flat index of the bin with the largest relative deviation.
    pub max_rel_deviation_bin: Option<usize>,
    /// The most extreme single bin: the smallest two-sided Poisson tail probability of a bin's
    /// count over every bin of positive expectation (pooled or not), times the number of such bins
    /// (Bonferroni), at most 1. See [`bin_tail_p_value`].
    pub bin_p_value: f64,
    /// Flat index of that bin.
    pub bin_p_value_bin: Option<usize>,
}

/// Pearson's chi-square statistic with Mitsuba's pooling rule.
///
/// Bins are visited in increasing order of expected count. A bin of expected count exactly 0 takes
/// no part (but every sample in it is counted in `zero_expected_hits`); a bin with expected count
/// below `min_expected` joins the pool, and so does the next bin while the pool's expected count is
/// still below `min_expected`; every other bin contributes (o − e)²/e on its own. The pool then
/// counts as one bin. Non-finite or negative expected counts must be rejected by the caller.
///
/// # Panics
/// If the slices differ in length.
pub fn pooled_chi_square(expected: &[f64], observed: &[u64], min_expected: f64) -> PooledChiSquare {
    assert_eq!(expected.len(), observed.len(), "pooled_chi_square: lengths");
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let mut r = PooledChiSquare {
        chi2: 0.0,
        dof: 0,
        pooled_bins: 0,
        pooled_expected: 0.0,
        pooled_observed: 0,
        zero_expected_hits: 0,
        max_rel_deviation: 0.0,
        max_rel_deviation_bin: None,
        bin_p_value: 1.0,
        bin_p_value_bin: None,
    };
    let mut bins = 0usize;
    let mut positive = 0usize;
    let mut min_tail = f64::INFINITY;
    for i in order {
        let (e, o) = (expected[i], observed[i]);
        if e > 0.0 {
            positive += 1;
            let t = bin_tail_p_value(e, o);
            if t < min_tail || r.bin_p_value_bin.is_none() {
                min_tail = t;
                r.bin_p_value_bin = Some(i);
            }
        }
        if e == 0.0 {
            r.zero_expected_hits += o;
        } else if e < min_expected || (r.pooled_bins > 0 && r.pooled_expected < min_expected) {
            r.pooled_bins += 1;
            r.pooled_expected += e;
            r.pooled_observed += o;
        } else {
            let d = o as f64 - e;
            r.chi2 += d * d / e;
            bins += 1;
            let rel = d.abs() / e;
            if rel > r.max_rel_deviation || r.max_rel_deviation_bin.is_none() {
                r.max_rel_deviation = rel;
                r.max_rel_deviation_bin = Some(i);
            }
        }
    }
    if r.pooled_bins > 0 && r.pooled_expected > 0.0 {
        let d = r.pooled_observed as f64 - r.pooled_expected;
        r.chi2 += d * d / r.pooled_expected;
        bins += 1;
    }
    r.dof = bins.saturating_sub(1);
    if positive > 0 {
        // NaN (a tail that could not be computed) stays NaN and so never passes.
        r.bin_p_value = (min_tail * positive as f64).min(1.0);
    }
    r
}

/// Two-sided tail probability of a count `observed` for a bin of expected count `expected` > 0:
/// 2 · min(P(X ≤ o), P(X ≥ o)) for X ~ Poisson(e), at most 1.
///
/// A bin's count is binomial (N, q) with q = e/N; Poisson tails with the same mean are heavier
/// (the binomial's variance is (1 − q) times smaller), so the probability is conservative: a
/// correct sampler gives a value below x with probability at most about x.
pub fn bin_tail_p_value(expected: f64, observed: u64) -> f64 {
    use statrs::function::gamma::{checked_gamma_lr, checked_gamma_ur};
    let (e, o) = (expected, observed as f64);
    if !(e.is_finite() && e > 0.0) {
        return f64::NAN;
    }
    // P(X ≤ o) = Q(o + 1, e); P(X ≥ o) = P(o, e) (1 for o = 0).
    let lower = checked_gamma_ur(o + 1.0, e).unwrap_or(f64::NAN);
    let upper = if observed == 0 {
        1.0
    } else {
        checked_gamma_lr(o, e).unwrap_or(f64::NAN)
    };
    if lower.is_nan() || upper.is_nan() {
        return f64::NAN;
    }
    (2.0 * lower.min(upper)).min(1.0)
}

/// Everything the chi-square test measured; serialisable for `gonio check --json`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ChiSquareReport {
    /// Pass or fail.
    pub status: Status,
    /// One line saying why.
    pub message: String,
    /// Number of sample points drawn.
    pub points: usize,
    /// Bins in z = cos θ.
    pub z_bins: usize,
    /// Bins in φ.
    pub phi_bins: usize,
    /// The statistic after pooling (see [`pooled_chi_square`]).
    pub chi2: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// chi2 / dof: about 1 for a correct sampler with iid points, far below 1 for good QMC points.
    pub chi2_per_dof: f64,
    /// P(χ²_dof ≥ chi2), from `statrs`' survival function (Pearson's omnibus statistic).
    /// Meaningful for iid points only.
    pub p_value: f64,
    /// The most extreme single bin, Bonferroni-corrected over the bins (see
    /// [`PooledChiSquare::bin_p_value`]): sensitive to an error confined to one bin, where the
    /// omnibus statistic spreads its attention over every degree of freedom.
    pub bin_p_value: f64,
    /// `[iz, iφ]` of that bin.
    pub bin_p_value_bin: Option<[usize; 2]>,
    /// Pearson's statistic on the coarse grid of blocks of up to 4 × 4 bins (8 × 8 on the
    /// sphere's default 32 × 32): few degrees of freedom, so an error spread over a region of a few
    /// per cent of the probability stands out, where the fine statistic dilutes it.
    pub coarse_p_value: f64,
    /// `[z_bins, phi_bins]` of the coarse grid.
    pub coarse_bins: [usize; 2],
    /// The test's p-value: min(1, 3 · min(`p_value`, `coarse_p_value`, `bin_p_value`))
    /// (Bonferroni over the three statistics, so a correct sampler gives a value below x with
    /// probability at most about x).
    pub combined_p_value: f64,
    /// Family significance level α.
    pub alpha: f64,
    /// Number K of tests in the family.
    pub tests: usize,
    /// Per-test threshold 1 − (1 − α)^(1/K); the test passes if `combined_p_value ≥ threshold`.
    pub threshold: f64,
    /// Bins merged into the pool.
    pub pooled_bins: usize,
    /// Expected count of the pool.
    pub pooled_expected: f64,
    /// Observed count of the pool.
    pub pooled_observed: u64,
    /// Samples in bins of expected count 0 (immediate failure).
    pub zero_expected_hits: u64,
    /// Largest |observed − expected| / expected over the unpooled bins.
    pub max_rel_deviation: f64,
    /// `[iz, iφ]` of that bin.
    pub max_rel_deviation_bin: Option<[usize; 2]>,
    /// Σ expected / points: the integral of the pdf over the domain by the bin quadrature (≈ 1).
    pub expected_total: f64,
    /// Samples whose direction is not finite or lies outside the domain (immediate failure).
    pub invalid_samples: usize,
    /// Samples (iid test only) that landed where the target (the data) is 0.
    pub outside_target: u64,
    /// The most such samples accepted: λ + 5√λ + 5 with λ = `max_outside_target` · points (a
    /// sampler that leaks exactly the allowance fails with probability < 1e-8).
    pub outside_target_allowed: f64,
}

/// The chi-square test on `opts.samples` iid points of a [`Random`] stream seeded with
/// `opts.seed`: expected counts are `samples · ∫_bin pdf dω` (Gauss–Legendre per bin, no
/// renormalisation, so a pdf that does not integrate to 1 fails), observed counts come from
/// [`crate::Batches::sample_batch`] in parallel chunks.
pub fn chi_square_test(sampler: &dyn Sampler, opts: &ChiSquareOptions) -> ChiSquareReport {
    chi_square_test_with_progress(sampler, opts, None, &|_| {})
}

/// ∫pdf dω over every bin of `opts`' grid (flat, row-major in (z, φ)), by the adaptive quadrature
/// of [`BinGrid::integrate`]: the expected counts per sample. It depends on the sampler and the
/// grid only, so one computation serves every seed and both stages
/// ([`chi_square_test_with_integrals`]).
pub fn bin_integrals(sampler: &dyn Sampler, opts: &ChiSquareOptions) -> Vec<f64> {
    opts.grid(sampler)
        .integrate(opts.quad_nodes, |d| sampler.pdf(d))
}

/// [`chi_square_test`] with the bin integrals computed beforehand by [`bin_integrals`] for the
/// same sampler and grid. A slice of the wrong length fails the test (it cannot be the grid's).
pub fn chi_square_test_with_integrals(
    sampler: &dyn Sampler,
    opts: &ChiSquareOptions,
    integrals: &[f64],
) -> ChiSquareReport {
    chi_square_test_with_progress(sampler, opts, Some(integrals), &|_| {})
}

pub(crate) fn chi_square_test_with_progress(
    sampler: &dyn Sampler,
    opts: &ChiSquareOptions,
    integrals: Option<&[f64]>,
    progress: &dyn Fn(f64),
) -> ChiSquareReport {
    let grid = opts.grid(sampler);
    let mut observed = vec![0u64; grid.len()];
    let mut invalid = 0usize;
    let seq = Sequence::from(Random::new(opts.seed));
    let mut outside = 0u64;
    for_each_sample_chunk(sampler, &seq, opts.samples, progress, |_, _, samples| {
        count(&grid, samples, &mut observed, &mut invalid);
        outside += samples
            .par_iter()
            .filter(|s| s.pdf > 0.0 && sampler.target_pdf(s.direction) == 0.0)
            .count() as u64;
    });
    let mut r = finish(
        sampler,
        opts,
        &grid,
        opts.samples,
        &observed,
        invalid,
        integrals,
    );
    let lambda = opts.max_outside_target * opts.samples as f64;
    r.outside_target = outside;
    r.outside_target_allowed = lambda + 5.0 * lambda.sqrt() + 5.0;
    if r.status != Status::Fail && outside as f64 > r.outside_target_allowed {
        r.status = Status::Fail;
        r.message = format!(
            "{outside} of {} samples landed where the target (the data) is 0, more than {:.0} \
             allowed: the sampler invents light",
            opts.samples, r.outside_target_allowed
        );
    }
    r
}

/// The chi-square statistic of the given points (iid or not) against `sampler`'s pdf, on the bins
/// and with the pooling of `opts` (`opts.samples` and `opts.seed` are ignored).
///
/// For low-discrepancy points (Halton, Sobol') the p-value and the pass/fail verdict are not
/// meaningful; read [`ChiSquareReport::chi2_per_dof`] instead, which for a correct sampler falls
/// far below 1 (too *good* a fit is what QMC points give).
pub fn chi_square_points(
    sampler: &dyn Sampler,
    points: &[Point2],
    opts: &ChiSquareOptions,
) -> ChiSquareReport {
    chi_square_points_with(sampler, points, opts, None)
}

pub(crate) fn chi_square_points_with(
    sampler: &dyn Sampler,
    points: &[Point2],
    opts: &ChiSquareOptions,
    integrals: Option<&[f64]>,
) -> ChiSquareReport {
    let grid = opts.grid(sampler);
    let mut observed = vec![0u64; grid.len()];
    let mut invalid = 0usize;
    let mut buf = vec![Sample::default(); super::STREAM_POINTS.min(points.len())];
    for chunk in points.chunks(super::STREAM_POINTS) {
        let out = &mut buf[..chunk.len()];
        crate::sampler::sample_batch_par(sampler, chunk, out);
        count(&grid, out, &mut observed, &mut invalid);
    }
    finish(
        sampler,
        opts,
        &grid,
        points.len(),
        &observed,
        invalid,
        integrals,
    )
}

fn count(grid: &BinGrid, samples: &[Sample], observed: &mut [u64], invalid: &mut usize) {
    for s in samples {
        match grid.bin_of(s.direction) {
            Some(b) => observed[b] += 1,
            None => *invalid += 1,
        }
    }
}

fn finish(
    sampler: &dyn Sampler,
    opts: &ChiSquareOptions,
    grid: &BinGrid,
    points: usize,
    observed: &[u64],
    invalid: usize,
    integrals: Option<&[f64]>,
) -> ChiSquareReport {
    let computed;
    let integrals = match integrals {
        Some(i) if i.len() == grid.len() => i,
        Some(_) => &[f64::NAN][..],
        None => {
            computed = grid.integrate(opts.quad_nodes, |d| sampler.pdf(d));
            &computed[..]
        }
    };
    let expected: Vec<f64> = integrals.iter().map(|&p| p * points as f64).collect();
    let tests = opts.tests.max(1);
    let threshold = sidak_threshold(opts.alpha, tests);
    let mut r = ChiSquareReport {
        status: Status::Fail,
        message: String::new(),
        points,
        z_bins: grid.z_bins(),
        phi_bins: grid.phi_bins(),
        chi2: f64::NAN,
        dof: 0,
        chi2_per_dof: f64::NAN,
        p_value: f64::NAN,
        bin_p_value: f64::NAN,
        bin_p_value_bin: None,
        coarse_p_value: f64::NAN,
        coarse_bins: [0, 0],
        combined_p_value: f64::NAN,
        alpha: opts.alpha,
        tests,
        threshold,
        pooled_bins: 0,
        pooled_expected: 0.0,
        pooled_observed: 0,
        zero_expected_hits: 0,
        max_rel_deviation: f64::NAN,
        max_rel_deviation_bin: None,
        expected_total: integrals.iter().sum(),
        invalid_samples: invalid,
        outside_target: 0,
        outside_target_allowed: f64::NAN,
    };
    if let Some(bad) = expected.iter().position(|e| !(e.is_finite() && *e >= 0.0)) {
        let [iz, ip] = grid.bin_coords(bad);
        r.message = format!(
            "the pdf integrates to {} over bin (z {iz}, phi {ip}): not a finite non-negative density",
            integrals[bad]
        );
        return r;
    }
    let pooled = pooled_chi_square(&expected, observed, opts.min_expected);
    r.chi2 = pooled.chi2;
    r.dof = pooled.dof;
    r.pooled_bins = pooled.pooled_bins;
    r.pooled_expected = pooled.pooled_expected;
    r.pooled_observed = pooled.pooled_observed;
    r.zero_expected_hits = pooled.zero_expected_hits;
    r.max_rel_deviation = pooled.max_rel_deviation;
    r.max_rel_deviation_bin = pooled.max_rel_deviation_bin.map(|b| grid.bin_coords(b));
    r.bin_p_value = pooled.bin_p_value;
    r.bin_p_value_bin = pooled.bin_p_value_bin.map(|b| grid.bin_coords(b));
    if pooled.dof > 0 {
        r.chi2_per_dof = pooled.chi2 / pooled.dof as f64;
        r.p_value = ChiSquared::new(pooled.dof as f64)
            .map(|d| d.sf(pooled.chi2))
            .unwrap_or(f64::NAN);
    }
    // The coarse grid: blocks of bz × bp bins.
    let block = |n: usize| {
        [4, 2, 1]
            .into_iter()
            .find(|b| n.is_multiple_of(*b))
            .unwrap_or(1)
    };
    let (nz, np) = (grid.z_bins(), grid.phi_bins());
    let (bz, bp) = (block(nz), block(np));
    let (cz, cp) = (nz / bz, np / bp);
    let mut ce = vec![0.0; cz * cp];
    let mut co = vec![0u64; cz * cp];
    for (k, (&e, &o)) in expected.iter().zip(observed).enumerate() {
        let [iz, ip] = grid.bin_coords(k);
        let c = (iz / bz) * cp + ip / bp;
        ce[c] += e;
        co[c] += o;
    }
    r.coarse_bins = [cz, cp];
    let coarse = pooled_chi_square(&ce, &co, opts.min_expected);
    if coarse.dof > 0 {
        r.coarse_p_value = ChiSquared::new(coarse.dof as f64)
            .map(|d| d.sf(coarse.chi2))
            .unwrap_or(f64::NAN);
    }
    let parts = [r.p_value, r.coarse_p_value, r.bin_p_value];
    r.combined_p_value = if parts.iter().any(|p| p.is_nan()) {
        f64::NAN
    } else {
        (3.0 * parts.iter().fold(1.0f64, |a, &b| a.min(b))).min(1.0)
    };
    r.message = if invalid > 0 {
        format!("{invalid} samples have a non-finite direction or lie outside the domain")
    } else if pooled.zero_expected_hits > 0 {
        format!(
            "{} samples fell into bins where the pdf integrates to 0",
            pooled.zero_expected_hits
        )
    } else if pooled.dof == 0 {
        "fewer than two bins after pooling: too few samples for the resolution".to_string()
    } else if !super::within(threshold, r.combined_p_value) {
        format!(
            "p = {:.3e} < {:.3e}: the histogram does not follow the pdf (worst bin {:?}, {:+.1} %)",
            r.combined_p_value,
            threshold,
            r.bin_p_value_bin.unwrap_or_default(),
            100.0 * r.max_rel_deviation
        )
    } else {
        r.status = Status::Pass;
        format!("p = {:.3} ≥ {:.3e}", r.combined_p_value, threshold)
    };
    r
}

impl ChiSquareReport {
    /// One line for the human-readable summary.
    pub fn summary(&self) -> String {
        format!(
            "chi2 = {:.1}, dof {}, chi2/dof {:.3}, p(chi2) = {:.3e}, p(coarse {}×{}) = {:.3e}, \
             p(worst bin) = {:.3e}, p = {:.3e} (threshold {:.3e}, alpha {}, K {}); {}×{} bins, \
             {} pooled; {} samples — {}",
            self.chi2,
            self.dof,
            self.chi2_per_dof,
            self.p_value,
            self.coarse_bins[0],
            self.coarse_bins[1],
            self.coarse_p_value,
            self.bin_p_value,
            self.combined_p_value,
            self.threshold,
            self.alpha,
            self.tests,
            self.z_bins,
            self.phi_bins,
            self.pooled_bins,
            self.points,
            self.message
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooling_by_hand() {
        // Sorted expected: 0 (o 0), 1, 2, 3 → pooled (6 < 5? no: 1+2 = 3 < 5, +3 → 6 ≥ 5 stop),
        // then 10 and 20 on their own.
        let e = [10.0, 1.0, 0.0, 2.0, 20.0, 3.0];
        let o = [12, 0, 0, 4, 18, 2];
        let r = pooled_chi_square(&e, &o, 5.0);
        assert_eq!(r.pooled_bins, 3);
        assert_eq!(r.pooled_expected, 6.0);
        assert_eq!(r.pooled_observed, 6);
        assert_eq!(r.dof, 2);
        let want = 4.0 / 10.0 + 4.0 / 20.0 + 0.0;
        assert!((r.chi2 - want).abs() < 1e-15);
        assert_eq!(r.max_rel_deviation_bin, Some(0));
        assert_eq!(r.zero_expected_hits, 0);
        let r = pooled_chi_square(&[0.0, 10.0, 10.0], &[3, 5, 9], 5.0);
        assert_eq!(r.zero_expected_hits, 3);
        assert_eq!(r.dof, 1);
    }

    #[test]
    fn pool_grows_past_threshold() {
        // 4 < 5 pools; pool (4) < 5 so the next bin (6) joins; 7 stands alone.
        let r = pooled_chi_square(&[6.0, 4.0, 7.0], &[6, 4, 7], 5.0);
        assert_eq!(r.pooled_bins, 2);
        assert_eq!(r.dof, 1);
        assert_eq!(r.chi2, 0.0);
    }
}
