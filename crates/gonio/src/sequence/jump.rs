//! Jumping the Xoshiro256 state ahead by `b · 2¹²⁸` steps in O(log b) (issue 25).
//!
//! The state transition of the xoshiro256 family is linear over GF(2)²⁵⁶, and so is its `jump()`
//! (2¹²⁸ steps). The matrices of `jump^(2^k)`, k < 48, are built once per process by repeated
//! squaring (≈ 10 ms), and `jump^b` is the product of those of the set bits of `b`. The result is
//! the same state as `b` calls of `jump()` (tested against `rand_xoshiro`).

use std::sync::OnceLock;

/// A 256-bit state as four words, in the order `rand_xoshiro` reads its seed.
pub(crate) type State = [u64; 4];

/// The largest number of bits of a block number (indices are u64, blocks of 2¹⁶ points).
const BITS: usize = 48;

/// One step of the xoshiro256 state (the `++` and `**` variants share it).
fn step(s: &mut State) {
    let t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = s[3].rotate_left(45);
}

/// The published `jump()` of xoshiro256: 2¹²⁸ steps.
fn jump_once(s: &State) -> State {
    const JUMP: [u64; 4] = [
        0x180e_c6d3_3cfd_0aba,
        0xd5a6_1266_f0c9_392c,
        0xa958_2618_e03f_c9aa,
        0x39ab_dc45_29b1_661c,
    ];
    let mut cur = *s;
    let mut acc = [0u64; 4];
    for j in JUMP {
        for b in 0..64 {
            if j & (1 << b) != 0 {
                for (a, c) in acc.iter_mut().zip(&cur) {
                    *a ^= c;
                }
            }
            step(&mut cur);
        }
    }
    acc
}

/// A linear map of GF(2)²⁵⁶ by its columns: `cols[i]` is the image of the i-th unit vector.
struct Matrix {
    cols: Vec<State>,
}

impl Matrix {
    fn apply(&self, v: &State) -> State {
        let mut out = [0u64; 4];
        for (w, &word) in v.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let b = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                for (o, c) in out.iter_mut().zip(&self.cols[64 * w + b]) {
                    *o ^= c;
                }
            }
        }
        out
    }
    fn square(&self) -> Matrix {
        Matrix {
            cols: self.cols.iter().map(|c| self.apply(c)).collect(),
        }
    }
}

/// `jump^(2^k)` for k < [`BITS`].
fn powers() -> &'static [Matrix] {
    static P: OnceLock<Vec<Matrix>> = OnceLock::new();
    P.get_or_init(|| {
        let unit = |i: usize| {
            let mut s = [0u64; 4];
            s[i / 64] = 1 << (i % 64);
            s
        };
        let mut m = Matrix {
            cols: (0..256).map(|i| jump_once(&unit(i))).collect(),
        };
        let mut all = Vec::with_capacity(BITS);
        for _ in 1..BITS {
            let next = m.square();
            all.push(m);
            m = next;
        }
        all.push(m);
        all
    })
}

/// The state after `b` calls of `jump()` from `s`, in O(log b) (b < 2⁴⁸; higher bits of `b`
/// never occur for u64 point indices in blocks of 2¹⁶).
pub(crate) fn jump_times(s: &State, b: u64) -> State {
    debug_assert!(b >> BITS == 0);
    if b == 0 {
        return *s;
    }
    let p = powers();
    let mut out = *s;
    for (k, m) in p.iter().enumerate() {
        if b & (1 << k) != 0 {
            out = m.apply(&out);
        }
    }
    out
}

/// The state as the 32 seed bytes `rand_xoshiro`'s `from_seed` reads (little-endian words).
pub(crate) fn to_seed(s: &State) -> [u8; 32] {
    let mut out = [0u8; 32];
    for (o, w) in out.chunks_exact_mut(8).zip(s) {
        o.copy_from_slice(&w.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngCore, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn seeded(seed: u64) -> State {
        let mut bytes = [0u8; 32];
        rand_xoshiro::SplitMix64::seed_from_u64(seed).fill_bytes(&mut bytes);
        let mut s = [0u64; 4];
        for (w, b) in s.iter_mut().zip(bytes.chunks_exact(8)) {
            *w = u64::from_le_bytes(b.try_into().unwrap());
        }
        s
    }

    #[test]
    fn equals_repeated_jumps_of_rand_xoshiro() {
        for seed in [0u64, 7, u64::MAX] {
            let s0 = seeded(seed);
            assert_eq!(
                Xoshiro256PlusPlus::from_seed(to_seed(&s0)),
                Xoshiro256PlusPlus::seed_from_u64(seed)
            );
            let mut g = Xoshiro256PlusPlus::seed_from_u64(seed);
            for b in 0..=37u64 {
                let mut h = Xoshiro256PlusPlus::from_seed(to_seed(&jump_times(&s0, b)));
                assert_eq!(h, g, "seed {seed}, {b} jumps");
                assert_eq!(h.next_u64(), g.clone().next_u64());
                g.jump();
            }
        }
    }

    #[test]
    fn powers_compose() {
        let s0 = seeded(3);
        let b = (1u64 << 47) + (1 << 20) + 5;
        let once = jump_times(&s0, b);
        let twice = jump_times(&jump_times(&s0, b - 5), 5);
        assert_eq!(once, twice);
        assert_ne!(once, s0);
    }
}
