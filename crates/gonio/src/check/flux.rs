//! Total power of a radiant intensity estimated with the sampler's own samples (pbrt-style).

use super::{for_each_sample_chunk, Status};
use crate::sampler::Sampler;
use crate::sequence::{Random, Sequence};
use rayon::prelude::*;

/// Settings of the flux check.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FluxOptions {
    /// Number of iid samples.
    pub samples: usize,
    /// Seed of the [`Random`] stream.
    pub seed: u64,
    /// Accepted deviation in standard errors (5 by default: a false alarm about once in 1.7
    /// million runs for a normal estimate).
    pub k_sigma: f64,
}

impl Default for FluxOptions {
    fn default() -> Self {
        FluxOptions {
            samples: 1_000_000,
            seed: 0x0f1e_0f1e,
            k_sigma: 5.0,
        }
    }
}

/// What the flux check measured.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FluxReport {
    /// Pass or fail.
    pub status: Status,
    /// One line saying why.
    pub message: String,
    /// The closed-form total Φ = ∫ I dω.
    pub total: f64,
    /// The Monte Carlo estimate mean(I(ωᵢ) / pᵢ).
    pub estimate: f64,
    /// Its standard error (sample standard deviation / √n).
    pub standard_error: f64,
    /// (estimate − total) / standard_error.
    pub deviation_sigmas: f64,
    /// Number of samples.
    pub samples: usize,
    /// Samples with a non-finite value, or of zero or invalid pdf where the target is positive.
    pub invalid_samples: usize,
    /// The accepted deviation in standard errors.
    pub k_sigma: f64,
}

/// Welford accumulator (count, mean, sum of squared deviations), mergeable (Chan et al.).
#[derive(Clone, Copy, Default)]
struct Moments {
    n: f64,
    mean: f64,
    m2: f64,
}

impl Moments {
    fn push(&mut self, x: f64) {
        self.n += 1.0;
        let d = x - self.mean;
        self.mean += d / self.n;
        self.m2 += d * (x - self.mean);
    }
    fn merge(self, o: Moments) -> Moments {
        if o.n == 0.0 {
            return self;
        }
        if self.n == 0.0 {
            return o;
        }
        let n = self.n + o.n;
        let d = o.mean - self.mean;
        Moments {
            n,
            mean: self.mean + d * o.n / n,
            m2: self.m2 + o.m2 + d * d * self.n * o.n / n,
        }
    }
}

/// Estimates the power Φ = ∫ I dω of the radiant intensity I(ω) = `total` · target_pdf(ω) as
/// mean(I(ωᵢ) / pdfᵢ) over `opts.samples` iid samples (pdfᵢ the density the sample carries), and
/// requires |estimate − total| ≤ k_sigma · standard error + 1e-9 · |total| (the second term covers
/// a sampler whose pdf equals the target exactly, where the standard error is 0).
///
/// `total` is the closed-form flux of the intensity in the caller's units (e.g. lumens for a
/// diagram in candela); 1 checks the normalised target. The estimate is unbiased only if the pdf
/// is positive wherever the target is, which is what this check tests.
pub fn flux_estimate(sampler: &dyn Sampler, total: f64, opts: &FluxOptions) -> FluxReport {
    flux_estimate_with_progress(sampler, total, opts, &|_| {})
}

pub(crate) fn flux_estimate_with_progress(
    sampler: &dyn Sampler,
    total: f64,
    opts: &FluxOptions,
    progress: &dyn Fn(f64),
) -> FluxReport {
    let seq = Sequence::from(Random::new(opts.seed));
    let mut m = Moments::default();
    let mut invalid = 0usize;
    for_each_sample_chunk(sampler, &seq, opts.samples, progress, |_, _, samples| {
        let (cm, ci) = samples
            .par_chunks(1024)
            .map(|c| {
                let mut m = Moments::default();
                let mut bad = 0usize;
                for s in c {
                    let t = sampler.target_pdf(s.direction);
                    let y = if t == 0.0 && s.pdf >= 0.0 {
                        0.0
                    } else {
                        total * t / s.pdf
                    };
                    if y.is_finite() && s.pdf >= 0.0 && t >= 0.0 {
                        m.push(y);
                    } else {
                        bad += 1;
                    }
                }
                (m, bad)
            })
            .collect::<Vec<_>>()
            .into_iter()
            .fold((Moments::default(), 0), |(a, x), (b, y)| {
                (a.merge(b), x + y)
            });
        m = m.merge(cm);
        invalid += ci;
    });
    let se = if m.n > 1.0 {
        (m.m2 / (m.n - 1.0) / m.n).sqrt()
    } else {
        f64::NAN
    };
    let dev = m.mean - total;
    let mut r = FluxReport {
        status: Status::Fail,
        message: String::new(),
        total,
        estimate: m.mean,
        standard_error: se,
        deviation_sigmas: if se > 0.0 { dev / se } else { 0.0 },
        samples: opts.samples,
        invalid_samples: invalid,
        k_sigma: opts.k_sigma,
    };
    r.message = if invalid > 0 {
        format!("{invalid} samples give a non-finite or negative I/pdf (pdf 0 or NaN where the target is positive?)")
    } else if !total.is_finite() {
        format!("the closed-form total {total} is not finite")
    } else if !super::within(dev.abs(), opts.k_sigma * se + 1e-9 * total.abs()) {
        format!(
            "estimate {:.6} ± {:.2e} differs from {total:.6} by {:.1} standard errors (> {})",
            m.mean, se, r.deviation_sigmas, opts.k_sigma
        )
    } else {
        r.status = Status::Pass;
        format!(
            "estimate {:.6} ± {:.2e} vs {total:.6}: {:+.2} standard errors",
            m.mean, se, r.deviation_sigmas
        )
    };
    r
}

impl FluxReport {
    /// One line for the human-readable summary.
    pub fn summary(&self) -> String {
        format!("{} samples — {}", self.samples, self.message)
    }
}
