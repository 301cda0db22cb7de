//! The Halton sequence in bases 2 and 3.

use super::{fraction_to_f64, ONE_MINUS_EPSILON};
use crate::sampler::Point2;

/// The 2D Halton sequence: point `k` is `(Φ₂(k + skip), Φ₃(k + skip))`, where the radical inverse
/// Φ_b(n) = Σ dᵢ b⁻ⁱ⁻¹ mirrors the base-b digits n = Σ dᵢ bⁱ about the radix point.
///
/// Φ₂ is exact (bit reversal, truncated to 53 bits); Φ₃ is the ratio of two exact integers rounded
/// once, clamped to the largest `f64` below 1. With `skip = 0` the first points are
/// (0, 0), (1/2, 1/3), (1/4, 2/3), (3/4, 1/9), …
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Halton {
    skip: u64,
}

impl Halton {
    /// The sequence from index 0 (whose point is (0, 0)).
    pub fn new() -> Self {
        Halton { skip: 0 }
    }

    /// The sequence whose point `k` is the classic sequence's point `k + skip` (indices wrap at
    /// 2⁶⁴). A common choice is `skip = 1`, which drops the corner point (0, 0).
    pub fn with_skip(skip: u64) -> Self {
        Halton { skip }
    }

    /// The number of leading points skipped.
    pub fn skip(&self) -> u64 {
        self.skip
    }

    /// Point number `index`.
    pub fn point(&self, index: u64) -> Point2 {
        let n = index.wrapping_add(self.skip);
        [radical_inverse_2(n), radical_inverse_3(n)]
    }

    /// Writes points `start_index, start_index + 1, …` into `out`.
    pub fn fill(&self, start_index: u64, out: &mut [Point2]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.point(start_index.wrapping_add(i as u64));
        }
    }
}

/// Φ₂(n): the bits of `n` mirrored about the binary point, truncated to 53 bits.
#[inline]
pub fn radical_inverse_2(n: u64) -> f64 {
    fraction_to_f64(n.reverse_bits())
}

/// Φ₃(n) = r / 3ᵐ with r the base-3 digits of `n` reversed (m digits); both integers are exact in
/// `u128` (a `u64` has at most 41 ternary digits), so the result is the correctly rounded ratio,
/// clamped below 1.
#[inline]
pub fn radical_inverse_3(mut n: u64) -> f64 {
    let mut reversed: u128 = 0;
    let mut denom: u128 = 1;
    while n > 0 {
        reversed = reversed * 3 + u128::from(n % 3);
        denom *= 3;
        n /= 3;
    }
    (reversed as f64 / denom as f64).min(ONE_MINUS_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_points_by_hand() {
        let want = [
            [0.0, 0.0],
            [0.5, 1.0 / 3.0],
            [0.25, 2.0 / 3.0],
            [0.75, 1.0 / 9.0],
            [0.125, 4.0 / 9.0],
            [0.625, 7.0 / 9.0],
            [0.375, 2.0 / 9.0],
            [0.875, 5.0 / 9.0],
            [0.0625, 8.0 / 9.0],
            [0.5625, 1.0 / 27.0],
        ];
        let mut got = [[0.0; 2]; 10];
        Halton::new().fill(0, &mut got);
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g[0], w[0], "k = {k}");
            assert!(
                (g[1] - w[1]).abs() <= 1e-16,
                "k = {k}: {} vs {}",
                g[1],
                w[1]
            );
        }
        let h = Halton::with_skip(3);
        assert_eq!(h.point(0), Halton::new().point(3));
        assert_eq!(h.skip(), 3);
    }

    #[test]
    fn never_one() {
        for n in [u64::MAX, u64::MAX - 1, 3u64.pow(40) - 1, (1 << 53) - 1] {
            let p = Halton::new().point(n);
            assert!(p[0] < 1.0 && p[1] < 1.0, "{n}: {p:?}");
        }
    }
}
