//! Independent uniform points from Xoshiro256++.

use super::fraction_to_f64;
use crate::sampler::Point2;
use rand::{RngCore, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// log₂ of the number of points per block; block b is drawn from the seeded generator after b
/// jumps of 2¹²⁸ steps.
const BLOCK_BITS: u32 = 16;
/// Points per block.
pub(crate) const BLOCK_POINTS: usize = 1 << BLOCK_BITS;

/// Iid uniform points of [0, 1)² from `Xoshiro256PlusPlus::seed_from_u64(seed)`.
///
/// Each coordinate is the top 53 bits of one 64-bit output, times 2⁻⁵³ (so never 1.0); a point
/// takes two outputs, u then v. To make point `k` a pure function of `(seed, k)` (and parallel
/// fills deterministic), the stream is cut into blocks of 2¹⁶ points: block b is produced by the
/// seeded generator advanced by b calls of `jump()` (2¹²⁸ steps each, so blocks never overlap).
/// Starting a fill at index k costs one jump of ⌊k / 2¹⁶⌋ · 2¹²⁸ steps in O(log k) (see
/// `jump.rs`) plus 2·(k mod 2¹⁶) discarded outputs: at most ≈ 0.2 ms whatever k.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Random {
    seed: u64,
    base: Xoshiro256PlusPlus,
    /// The state of `base` as words, for jumping ahead.
    state: super::jump::State,
}

impl Random {
    /// The stream for `seed`.
    pub fn new(seed: u64) -> Self {
        // `seed_from_u64` fills the 32 seed bytes from SplitMix64 (rand_core's `from_rng`); the
        // same bytes give the words to jump from (tested: the two generators are equal).
        let mut bytes = [0u8; 32];
        rand_xoshiro::SplitMix64::seed_from_u64(seed).fill_bytes(&mut bytes);
        let mut state = [0u64; 4];
        for (w, b) in state.iter_mut().zip(bytes.chunks_exact(8)) {
            let mut word = [0u8; 8];
            word.copy_from_slice(b);
            *w = u64::from_le_bytes(word);
        }
        Random {
            seed,
            base: Xoshiro256PlusPlus::from_seed(bytes),
            state,
        }
    }

    /// The seed this stream was built with.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Writes points `start_index, start_index + 1, …` into `out`.
    pub fn fill(&self, start_index: u64, out: &mut [Point2]) {
        if out.is_empty() {
            return;
        }
        let blocks = start_index >> BLOCK_BITS;
        let mut block_start = if blocks == 0 {
            self.base.clone()
        } else {
            let s = super::jump::jump_times(&self.state, blocks);
            Xoshiro256PlusPlus::from_seed(super::jump::to_seed(&s))
        };
        let mut rng = block_start.clone();
        let offset = start_index & ((1 << BLOCK_BITS) - 1);
        for _ in 0..2 * offset {
            rng.next_u64();
        }
        let mut index = start_index;
        for o in out.iter_mut() {
            *o = [
                fraction_to_f64(rng.next_u64()),
                fraction_to_f64(rng.next_u64()),
            ];
            index = index.wrapping_add(1);
            if index & ((1 << BLOCK_BITS) - 1) == 0 {
                if index == 0 {
                    block_start = self.base.clone();
                } else {
                    block_start.jump();
                }
                rng = block_start.clone();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_variance() {
        // n = 2^17 points: the mean of U(0,1) has sd 0.2887/sqrt(n) = 8.0e-4, the variance
        // estimate sd sqrt(1/180/n) = 2.1e-4; accept 5 sd.
        let n = 1 << 17;
        let mut pts = vec![[0.0; 2]; n];
        Random::new(42).fill(0, &mut pts);
        for c in 0..2 {
            let mean = pts.iter().map(|p| p[c]).sum::<f64>() / n as f64;
            let var = pts.iter().map(|p| (p[c] - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
            assert!((mean - 0.5).abs() < 5.0 * 8.0e-4, "mean {mean}");
            assert!((var - 1.0 / 12.0).abs() < 5.0 * 2.1e-4, "var {var}");
        }
        let cov = pts.iter().map(|p| (p[0] - 0.5) * (p[1] - 0.5)).sum::<f64>() / n as f64;
        assert!(cov.abs() < 5.0 / 12.0 / (n as f64).sqrt(), "cov {cov}");
    }

    #[test]
    fn deterministic_across_blocks_and_seeds() {
        let r = Random::new(7);
        let n = (1 << BLOCK_BITS) + 100;
        let mut all = vec![[0.0; 2]; n];
        r.fill(0, &mut all);
        let mut tail = vec![[0.0; 2]; 200];
        r.fill((1 << BLOCK_BITS) - 100, &mut tail);
        assert_eq!(&all[(1 << BLOCK_BITS) - 100..], &tail[..]);
        let mut other = vec![[0.0; 2]; 100];
        Random::new(8).fill(0, &mut other);
        assert!(other.iter().zip(&all).all(|(a, b)| a != b));
        assert_eq!(r.seed(), 7);
        // The first point is the first two outputs of the seeded generator.
        let mut g = Xoshiro256PlusPlus::seed_from_u64(7);
        assert_eq!(all[0][0], fraction_to_f64(g.next_u64()));
        assert_eq!(r.base, Xoshiro256PlusPlus::seed_from_u64(7));
    }

    #[test]
    fn far_starts_are_immediate_and_continue_the_stream() {
        // Issue 25: a start of 2^63 took years (one jump per block); now O(log k). The points
        // straddling a block boundary far out equal a fill from before the boundary.
        let r = Random::new(11);
        let k = (1u64 << 63) + (5 << BLOCK_BITS) - 3;
        let mut a = [[0.0; 2]; 6];
        r.fill(k, &mut a);
        let mut b = [[0.0; 2]; 3];
        r.fill(k + 3, &mut b);
        assert_eq!(&a[3..], &b[..]);
        // The first block from 2^16 is the generator after one jump().
        let mut g = Xoshiro256PlusPlus::seed_from_u64(11);
        g.jump();
        let mut c = [[0.0; 2]; 1];
        r.fill(1 << BLOCK_BITS, &mut c);
        assert_eq!(c[0][0], fraction_to_f64(g.next_u64()));
    }
}
