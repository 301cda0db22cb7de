//! Points of the unit square: Halton (bases 2, 3), Owen-scrambled Sobol' in 2D, and seeded iid.
//!
//! Every generator here is reproducible: point `k` of a [`Halton`] or [`Sobol`] sequence is a pure
//! function of `(seed, k)`, and so is point `k` of the [`Random`] stream (its generator is
//! advanced to `k` by jumps, see [`Random`]). Filling a slice in parallel chunks therefore gives the
//! same points as filling it in one go.
//!
//! All points lie in the half-open square **[0, 1)²**: no coordinate is ever 1.0. Coordinates are
//! multiples of 2⁻⁵³ for Sobol' and [`Random`], and the correctly rounded radical inverse (clamped
//! to the largest `f64` below 1) for Halton.
//!
//! ```
//! use gonio::sequence::{Sequence, SequenceKind};
//! let seq = Sequence::new("sobol".parse::<SequenceKind>().unwrap(), 7);
//! let mut pts = [[0.0; 2]; 16];
//! seq.fill(0, &mut pts);
//! assert!(pts.iter().all(|p| p.iter().all(|&c| (0.0..1.0).contains(&c))));
//! ```

mod halton;
mod jump;
mod random;
mod sobol;

pub use halton::Halton;
pub use random::Random;
pub use sobol::Sobol;

use crate::sampler::Point2;
use rayon::prelude::*;
use std::fmt;
use std::str::FromStr;

/// Which generator of points of the unit square to use; parsed from `"halton"`, `"sobol"` or
/// `"random"` (case-insensitive).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SequenceKind {
    /// The Halton sequence in bases 2 and 3 ([`Halton`]).
    Halton,
    /// The 2D Sobol' sequence with Owen scrambling ([`Sobol`]).
    Sobol,
    /// Independent uniform points from Xoshiro256++ ([`Random`]).
    Random,
}

impl SequenceKind {
    /// Every kind, in the order of the CLI's help text.
    pub const ALL: [SequenceKind; 3] = [
        SequenceKind::Halton,
        SequenceKind::Sobol,
        SequenceKind::Random,
    ];

    /// The lowercase name that [`FromStr`] accepts.
    pub fn name(self) -> &'static str {
        match self {
            SequenceKind::Halton => "halton",
            SequenceKind::Sobol => "sobol",
            SequenceKind::Random => "random",
        }
    }
}

impl fmt::Display for SequenceKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The text given to [`SequenceKind::from_str`] names no sequence.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown sequence {0:?}: expected one of halton, sobol, random")]
pub struct UnknownSequence(pub String);

impl FromStr for SequenceKind {
    type Err = UnknownSequence;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        crate::input::find_by_name(SequenceKind::ALL, SequenceKind::name, s)
            .ok_or_else(|| UnknownSequence(s.to_string()))
    }
}

/// A seeded generator of points of [0, 1)², any of the three kinds.
#[derive(Debug, Clone, PartialEq)]
pub enum Sequence {
    /// Halton in bases 2 and 3.
    Halton(Halton),
    /// Sobol' (2D), Owen-scrambled unless built with [`Sobol::unscrambled`].
    Sobol(Sobol),
    /// Iid uniform points.
    Random(Random),
}

// Points per rayon task in [`Sequence::fill_par`]: the crate's batch task size.
use crate::batch::PAR_CHUNK;

impl Sequence {
    /// The generator of `kind` for `seed`.
    ///
    /// * Halton is deterministic and ignores `seed` (it starts at index 0, the point (0, 0); use
    ///   [`Halton::with_skip`] for another start);
    /// * Sobol' is Owen-scrambled with `seed` ([`Sobol::owen`]);
    /// * Random is Xoshiro256++ seeded with `seed` ([`Random::new`]).
    pub fn new(kind: SequenceKind, seed: u64) -> Self {
        match kind {
            SequenceKind::Halton => Sequence::Halton(Halton::new()),
            SequenceKind::Sobol => Sequence::Sobol(Sobol::owen(seed)),
            SequenceKind::Random => Sequence::Random(Random::new(seed)),
        }
    }

    /// Which kind of generator this is.
    pub fn kind(&self) -> SequenceKind {
        match self {
            Sequence::Halton(_) => SequenceKind::Halton,
            Sequence::Sobol(_) => SequenceKind::Sobol,
            Sequence::Random(_) => SequenceKind::Random,
        }
    }

    /// Point number `index` of the sequence. For [`Random`] this costs O(log index + 2¹⁶) (see
    /// there); prefer [`Sequence::fill`] for runs of points.
    pub fn point(&self, index: u64) -> Point2 {
        match self {
            Sequence::Halton(h) => h.point(index),
            Sequence::Sobol(s) => s.point(index),
            Sequence::Random(r) => {
                let mut p = [[0.0; 2]];
                r.fill(index, &mut p);
                p[0]
            }
        }
    }

    /// Writes points `start_index, start_index + 1, …` into `out`. Indices wrap around at 2⁶⁴.
    pub fn fill(&self, start_index: u64, out: &mut [Point2]) {
        match self {
            Sequence::Halton(h) => h.fill(start_index, out),
            Sequence::Sobol(s) => s.fill(start_index, out),
            Sequence::Random(r) => r.fill(start_index, out),
        }
    }

    /// [`Sequence::fill`] on all rayon threads; the result is identical to the sequential one.
    pub fn fill_par(&self, start_index: u64, out: &mut [Point2]) {
        // A Random fill pays for reaching its start index, so give it whole generator blocks.
        let chunk = match self {
            Sequence::Random(_) => random::BLOCK_POINTS,
            _ => PAR_CHUNK,
        };
        out.par_chunks_mut(chunk)
            .enumerate()
            .for_each(|(c, part)| self.fill(start_index.wrapping_add((c * chunk) as u64), part));
    }
}

impl From<Halton> for Sequence {
    fn from(h: Halton) -> Self {
        Sequence::Halton(h)
    }
}
impl From<Sobol> for Sequence {
    fn from(s: Sobol) -> Self {
        Sequence::Sobol(s)
    }
}
impl From<Random> for Sequence {
    fn from(r: Random) -> Self {
        Sequence::Random(r)
    }
}

/// The largest `f64` below 1 (1 − 2⁻⁵³).
pub(crate) const ONE_MINUS_EPSILON: f64 = 1.0 - f64::EPSILON / 2.0;

/// The top 53 bits of a 64-bit binary fraction as an `f64` in [0, 1) (truncation, never 1.0).
#[inline]
pub(crate) fn fraction_to_f64(x: u64) -> f64 {
    (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A bijective 64-bit mixer (the SplitMix64 finaliser, constants of Stafford's "variant 13").
#[inline]
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kind_parses_and_prints() {
        for k in SequenceKind::ALL {
            assert_eq!(k.name().parse::<SequenceKind>().unwrap(), k);
            assert_eq!(
                k.to_string()
                    .to_uppercase()
                    .parse::<SequenceKind>()
                    .unwrap(),
                k
            );
        }
        assert!("sobel".parse::<SequenceKind>().is_err());
        assert_eq!(
            serde_json::to_string(&SequenceKind::Sobol).unwrap(),
            "\"sobol\""
        );
    }

    #[test]
    fn fill_par_equals_fill_and_point() {
        for kind in SequenceKind::ALL {
            let seq = Sequence::new(kind, 99);
            let n = random::BLOCK_POINTS + 3 * PAR_CHUNK + 17;
            let mut a = vec![[0.0; 2]; n];
            let mut b = vec![[0.0; 2]; n];
            seq.fill(5, &mut a);
            seq.fill_par(5, &mut b);
            assert_eq!(a, b, "{kind}");
            for k in [0usize, 1, 4095, 4096, 9000, n - 1] {
                assert_eq!(seq.point(5 + k as u64), a[k], "{kind} point {k}");
            }
            assert!(a.iter().flatten().all(|&c| (0.0..1.0).contains(&c)));
        }
    }

    #[test]
    fn fraction_never_one() {
        assert!(fraction_to_f64(u64::MAX) < 1.0);
        assert_eq!(fraction_to_f64(1 << 63), 0.5);
    }
}
