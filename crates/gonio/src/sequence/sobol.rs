//! The first two dimensions of the Sobol' sequence, with hash-based Owen scrambling.

use super::{fraction_to_f64, mix64};
use crate::sampler::Point2;

/// Direction numbers of Sobol' dimension 2 as 64-bit binary fractions. The primitive polynomial
/// is x + 1 (degree 1, m₁ = 1), so the recurrence is vᵢ₊₁ = vᵢ ⊕ (vᵢ ≫ 1) with v₁ = ½: the
/// integers mᵢ = 1, 3, 5, 15, 17, 51, … (the generator matrix is Pascal's triangle mod 2).
const DIRECTIONS_DIM2: [u64; 64] = {
    let mut v = [0u64; 64];
    v[0] = 1 << 63;
    let mut i = 1;
    while i < 64 {
        v[i] = v[i - 1] ^ (v[i - 1] >> 1);
        i += 1;
    }
    v
};

/// Bits of a 64-bit fraction that reach an `f64` in [0, 1).
const KEPT_BITS: u32 = 53;
/// Mask of the top [`KEPT_BITS`] bits.
const KEPT_MASK: u64 = !((1u64 << (64 - KEPT_BITS)) - 1);

/// The 2D Sobol' sequence (van der Corput in base 2 × Sobol' dimension 2), in Gray-code order as in
/// Joe & Kuo's reference generator, optionally with Owen scrambling.
///
/// Point `k` is computed from `g = k ⊕ (k ≫ 1)` directly (no state), so it is a pure function of
/// `(seed, k)`. Unscrambled, the first points are (0, 0), (½, ½), (¾, ¼), (¼, ¾), (⅜, ⅜), (⅞, ⅞),
/// (⅝, ⅛), (⅛, ⅝). For every m, the points `j·2ᵐ … (j+1)·2ᵐ − 1` form a (0, m, 2)-net in base 2:
/// each elementary interval [a/2ⁱ, (a+1)/2ⁱ) × [b/2ᵐ⁻ⁱ, (b+1)/2ᵐ⁻ⁱ) holds exactly one point.
///
/// **Owen scrambling** (nested uniform scrambling) flips binary digit ℓ of each coordinate by a
/// random bit that depends on the seed, the dimension and the ℓ − 1 digits above it. It keeps the
/// net property, makes every point uniformly distributed, and gives an unbiased estimator. The
/// random bits come from a keyed 64-bit hash of the node (ℓ, leading digits) of the binary digit
/// tree; because a run of zero digits has the same prefix structure, one hash supplies the flips of
/// all the levels from one 1-digit to the next, so a coordinate costs (number of 1-digits + 1)
/// hashes. Coordinates are scrambled to 53 binary digits, the precision of an `f64` in [0, 1).
///
/// Indices are 64-bit. The generator matrices are 64 × 64, but an `f64` keeps 53 binary digits, so
/// unscrambled points are distinct for indices below 2⁵³ (scrambled ones almost surely beyond).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sobol {
    /// Per-dimension hash keys; `None` for the unscrambled sequence.
    keys: Option<[[u64; 2]; 2]>,
    seed: Option<u64>,
}

impl Sobol {
    /// The plain (unscrambled) sequence.
    pub fn unscrambled() -> Self {
        Sobol {
            keys: None,
            seed: None,
        }
    }

    /// The sequence Owen-scrambled with `seed`; different seeds give independent scramblings.
    pub fn owen(seed: u64) -> Self {
        let key = |d: u64, j: u64| {
            mix64(seed ^ mix64(0x5eed_0000 + 2 * d + j).wrapping_mul(0x9e37_79b9_7f4a_7c15))
        };
        Sobol {
            keys: Some([[key(0, 0), key(0, 1)], [key(1, 0), key(1, 1)]]),
            seed: Some(seed),
        }
    }

    /// The scrambling seed, `None` if unscrambled.
    pub fn seed(&self) -> Option<u64> {
        self.seed
    }

    /// The two coordinates of point `index` as 64-bit binary fractions, before scrambling.
    #[inline]
    fn raw(index: u64) -> [u64; 2] {
        let g = index ^ (index >> 1);
        let mut y = 0u64;
        let mut bits = g;
        while bits != 0 {
            let i = bits.trailing_zeros();
            y ^= DIRECTIONS_DIM2[i as usize];
            bits &= bits - 1;
        }
        [g.reverse_bits(), y]
    }

    /// Point number `index`.
    #[inline]
    pub fn point(&self, index: u64) -> Point2 {
        let [x, y] = Self::raw(index);
        match &self.keys {
            None => [fraction_to_f64(x), fraction_to_f64(y)],
            Some(k) => [
                fraction_to_f64(owen_scramble(x, k[0])),
                fraction_to_f64(owen_scramble(y, k[1])),
            ],
        }
    }

    /// Writes points `start_index, start_index + 1, …` into `out`.
    pub fn fill(&self, start_index: u64, out: &mut [Point2]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.point(start_index.wrapping_add(i as u64));
        }
    }
}

/// Keyed hash of a node of the binary digit tree: 64 random bits.
#[inline]
fn node_hash(node: u64, key: [u64; 2]) -> u64 {
    mix64(mix64(node ^ key[0]) ^ key[1])
}

/// Nested uniform scrambling of the top 53 digits of the binary fraction `x`.
///
/// Digit ℓ (0-based from the most significant) is flipped by a bit that is a function of the key
/// and of the digits 0 … ℓ−1 only. The flips for a run of levels `start ..= start + z`, where
/// digit `start − 1` is 1 (or `start = 0`) and digits `start … start + z − 1` are 0, all have the
/// same "prefix ending in a 1, then zeros" shape, so they are taken as consecutive bits of the hash
/// of the tree node (start, digits 0 … start−1); every (level, prefix) pair thus reads its own bit
/// of its own hash.
#[inline]
fn owen_scramble(x: u64, key: [u64; 2]) -> u64 {
    let x = x & KEPT_MASK;
    let mut flips = 0u64;
    let mut start = 0u32;
    while start < KEPT_BITS {
        let prefix = if start == 0 { 0 } else { x >> (64 - start) };
        // Heap numbering of the node: unique over all levels (start ≤ 52).
        let h = node_hash((1u64 << start) | prefix, key);
        let rest = x << start;
        let end = if rest == 0 {
            KEPT_BITS
        } else {
            (start + rest.leading_zeros() + 1).min(KEPT_BITS)
        };
        let n = end - start;
        flips |= (h >> (64 - n) << (64 - n)) >> start;
        start = end;
    }
    (x ^ flips) & KEPT_MASK
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_numbers_are_the_standard_ones() {
        // m_i = v_i · 2^i for the first few i.
        let m: Vec<u64> = (0..8).map(|i| DIRECTIONS_DIM2[i] >> (63 - i)).collect();
        assert_eq!(m, [1, 3, 5, 15, 17, 51, 85, 255]);
    }

    #[test]
    fn unscrambled_first_points() {
        let want = [
            [0.0, 0.0],
            [0.5, 0.5],
            [0.75, 0.25],
            [0.25, 0.75],
            [0.375, 0.375],
            [0.875, 0.875],
            [0.625, 0.125],
            [0.125, 0.625],
        ];
        let mut got = [[0.0; 2]; 8];
        Sobol::unscrambled().fill(0, &mut got);
        assert_eq!(got, want);
    }

    /// Every elementary interval of volume 2^-m holds exactly one of `pts` (2^m points).
    fn is_net(pts: &[Point2], m: u32) -> bool {
        assert_eq!(pts.len(), 1 << m);
        for a in 0..=m {
            let (na, nb) = (1usize << a, 1usize << (m - a));
            let mut cells = vec![0u32; 1 << m];
            for p in pts {
                let i = (p[0] * na as f64) as usize;
                let j = (p[1] * nb as f64) as usize;
                cells[i * nb + j] += 1;
            }
            if cells.iter().any(|&c| c != 1) {
                return false;
            }
        }
        true
    }

    #[test]
    fn scrambled_is_a_net() {
        for seed in [0u64, 1, 0xdead_beef] {
            let s = Sobol::owen(seed);
            for m in 0..=10 {
                let mut pts = vec![[0.0; 2]; 1 << m];
                s.fill(0, &mut pts);
                assert!(is_net(&pts, m), "seed {seed}, m = {m}");
                // The second block of 2^m points is a net too.
                s.fill(1 << m, &mut pts);
                assert!(is_net(&pts, m), "seed {seed}, m = {m}, block 1");
            }
        }
        let mut pts = vec![[0.0; 2]; 1 << 10];
        Sobol::unscrambled().fill(0, &mut pts);
        assert!(is_net(&pts, 10));
    }

    #[test]
    fn deterministic_and_seed_dependent() {
        let (a, b, c) = (Sobol::owen(5), Sobol::owen(5), Sobol::owen(6));
        let mut pa = vec![[0.0; 2]; 256];
        let mut pb = pa.clone();
        let mut pc = pa.clone();
        a.fill(0, &mut pa);
        b.fill(0, &mut pb);
        c.fill(0, &mut pc);
        assert_eq!(pa, pb);
        let same = pa.iter().zip(&pc).filter(|(x, y)| x == y).count();
        assert_eq!(same, 0);
        assert_eq!(a.seed(), Some(5));
        assert_eq!(Sobol::unscrambled().seed(), None);
    }

    #[test]
    fn scrambled_points_are_uniform_in_the_fine_digits() {
        // The first point (index 0, all digits 0) is uniform over seeds: its mean over 4096 seeds
        // is 1/2 within 5 standard errors (sd of U(0,1) = 0.2887).
        let n = 4096;
        let mean: f64 = (0..n).map(|s| Sobol::owen(s).point(0)[1]).sum::<f64>() / n as f64;
        assert!(
            (mean - 0.5).abs() < 5.0 * 0.2887 / (n as f64).sqrt(),
            "{mean}"
        );
    }

    #[test]
    fn scramble_is_a_bijection_on_digits() {
        // Distinct inputs stay distinct (the permutation property of nested scrambling).
        let key = [1, 2];
        let mut out: Vec<u64> = (0..4096u64).map(|i| owen_scramble(i << 52, key)).collect();
        out.iter_mut().for_each(|o| *o >>= 52);
        out.sort_unstable();
        out.dedup();
        assert_eq!(out.len(), 4096);
    }
}
