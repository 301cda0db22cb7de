//! Rejection sampling against the maximum of the target.

use super::uniform::square_to_uniform;
use super::{clamp_unit, BuildError, Target};
use crate::diagram::Diagram;
use crate::sampler::{direction, spherical, Domain, InvertError, Point2, Sample, Sampler, Vec3};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::TAU;

/// Smallest acceptance rate (mean target / max target over the domain) a [`Rejection`] sampler is
/// built for: below it one sample would cost more than a million proposals on average.
pub const MIN_ACCEPTANCE: f64 = 1e-6;

/// Largest probability that one call of [`Rejection`]'s `sample` stops at its trial cap, which is
/// also a bound on the total-variation distance between its output distribution and the target.
pub const MAX_TV_ERROR: f64 = 1e-15;

/// Rejection sampling: uniform proposals on the domain (the map of [`super::Uniform`]), each
/// accepted with probability target(ω) / max target. The bilinear interpolant never exceeds its
/// largest node value, so the envelope is `max_value / integral`, exact.
///
/// * **Density**: pdf(ω) = target(ω) = interpolate(θ, φ) / integral, per steradian.
/// * **Determinism**: `sample(u)` depends on `u` only: the bits of u are hashed (splitmix64
///   finaliser) into the seed of a `Xoshiro256PlusPlus` that draws the proposals and the acceptance
///   tests. So any two distinct points give independent pseudo-random samples and the
///   stratification of a low-discrepancy sequence is **not** preserved.
/// * **Trial cap**: with acceptance rate a, a call gives up after the smallest n with
///   (1 − a)ⁿ ≤ [`MAX_TV_ERROR`] = 10⁻¹⁵ proposals (n ≈ 34.5 / a) and then returns a fixed direction
///   of positive target (the centre of the cell with the largest target), with its exact target
///   density. The output distribution therefore differs from the target by at most 10⁻¹⁵ in total
///   variation, and the reported pdf is always `pdf(direction)`. Diagrams with a < [`MIN_ACCEPTANCE`]
///   are refused.
/// * **Inverse**: none ([`InvertError::Unsupported`]).
///
/// ```
/// use gonio::baselines::Rejection;
/// use gonio::{Diagram, Domain, InvertError, Sampler};
/// let d = Diagram::from_degrees(&[0.0, 60.0, 90.0], &[0.0], &[vec![1.0, 0.5, 0.0]]).unwrap();
/// let r = Rejection::new(&d, Domain::Hemisphere).unwrap();
/// let s = r.sample([0.3, 0.7]);
/// assert_eq!(s, r.sample([0.3, 0.7])); // deterministic in u
/// assert_eq!(s.pdf, r.target_pdf(s.direction));
/// assert_eq!(r.invert(s.direction), Err(InvertError::Unsupported));
/// assert!(r.acceptance_rate() > 0.0 && r.acceptance_rate() <= 1.0);
/// ```
#[derive(Debug, Clone)]
pub struct Rejection {
    target: Target,
    /// Largest node value (diagram units): the envelope of the interpolant.
    max_value: f64,
    max_trials: u64,
    fallback: Sample,
    /// Mixed into the hash of `u` that seeds the proposals (0: the historical stream).
    seed: u64,
}

impl Rejection {
    /// A rejection sampler of the target of `diagram` over `domain`.
    ///
    /// # Errors
    /// [`BuildError::NotHemisphere`], [`BuildError::NoPower`] as for every baseline;
    /// [`BuildError::AcceptanceTooLow`] if mean target / max target < [`MIN_ACCEPTANCE`].
    pub fn new(diagram: &Diagram, domain: Domain) -> Result<Self, BuildError> {
        Self::with_seed(diagram, domain, 0)
    }

    /// As [`Rejection::new`], with `seed` mixed into the hash of each point `u` that seeds its
    /// proposals: another seed gives another pseudo-random stream for the same points. Seed 0 is the stream
    /// of [`Rejection::new`].
    ///
    /// # Errors
    /// As [`Rejection::new`].
    pub fn with_seed(diagram: &Diagram, domain: Domain, seed: u64) -> Result<Self, BuildError> {
        let target = Target::new(diagram, domain)?;
        let max_value = diagram.max_value();
        let rate = target.integral / (domain.solid_angle() * max_value);
        if rate < MIN_ACCEPTANCE {
            return Err(BuildError::AcceptanceTooLow {
                rate,
                min: MIN_ACCEPTANCE,
            });
        }
        let max_trials = if rate >= 1.0 {
            1
        } else {
            (MAX_TV_ERROR.ln() / (-rate).ln_1p()).ceil().max(1.0) as u64
        };
        // The fallback: the cell centre with the largest target (a cell centre is positive whenever
        // one of its corners is, and some cell has a positive corner because the integral is > 0).
        let (th, ph) = (diagram.theta(), diagram.phi());
        let beta = diagram.sector_widths();
        let mut fallback = Sample::default();
        for j in 0..th.len() - 1 {
            for (i, b) in beta.iter().enumerate() {
                let d = direction(0.5 * (th[j] + th[j + 1]), (ph[i] + 0.5 * b).rem_euclid(TAU));
                let pdf = target.pdf(d);
                if pdf > fallback.pdf {
                    fallback = Sample { direction: d, pdf };
                }
            }
        }
        Ok(Self {
            target,
            max_value,
            max_trials,
            fallback,
            seed,
        })
    }

    /// The exact probability that one proposal is accepted: (integral / solid angle of the domain) /
    /// max node value, i.e. mean target / max target. The mean number of proposals per sample is its
    /// reciprocal.
    pub fn acceptance_rate(&self) -> f64 {
        self.target.integral / (self.target.domain.solid_angle() * self.max_value)
    }

    /// The most proposals one call of `sample` draws before it returns the fallback direction.
    pub fn max_trials(&self) -> u64 {
        self.max_trials
    }
}

/// splitmix64's output finaliser: a bijective 64-bit mix.
#[inline]
fn splitmix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Sampler for Rejection {
    target_methods!("rejection");
    fn sample(&self, u: Point2) -> Sample {
        let (a, b) = (clamp_unit(u[0]).to_bits(), clamp_unit(u[1]).to_bits());
        let seed = splitmix64(splitmix64(a ^ 0x9e37_79b9_7f4a_7c15 ^ self.seed) ^ b);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let domain = self.target.domain;
        for _ in 0..self.max_trials {
            let d = square_to_uniform(domain, [rng.gen::<f64>(), rng.gen::<f64>()]);
            let (t, p) = spherical(d);
            let f = self.target.diagram.interpolate(t, p);
            // ξ ∈ [0, 1): accepted with probability f / max exactly; f = 0 is never accepted.
            if rng.gen::<f64>() * self.max_value < f {
                return Sample {
                    direction: d,
                    pdf: self.target.pdf(d),
                };
            }
        }
        self.fallback
    }
    fn pdf(&self, direction: Vec3) -> f64 {
        self.target.pdf(direction)
    }
    fn invert(&self, _direction: Vec3) -> Result<Point2, InvertError> {
        Err(InvertError::Unsupported)
    }
    fn memory_bytes(&self) -> usize {
        self.target.diagram_bytes()
    }
}
