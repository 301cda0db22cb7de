//! The portable backend: the vocabulary of [`super::kernels`] over plain arrays of [`BLOCK`]
//! lanes (values `[f64; BLOCK]`, indices `[i64; BLOCK]`, masks `[u64; BLOCK]` of all-ones or
//! all-zeros lanes), compiled for the
//! target's baseline instruction set (SSE2 on x86-64), where the compiler vectorises the
//! element-wise loops. Every word has the semantics of its AVX2/AVX-512 spelling (IEEE-rounded
//! arithmetic, no fused multiply–add, ordered comparisons, signed 64-bit indices, the same
//! clamping of indices and of `to_index`), so this backend gives the same bits as the others
//! (tested in `tests/batch.rs`). Indices are full 64-bit here, so this backend also serves the
//! maps whose tables are too large for the explicit kernels' 32-bit index conversions.

// Lane loops index several arrays by the same lane number on purpose (they vectorise).
#![allow(clippy::needless_range_loop)]

use crate::mapping::hds::TablesView;
use crate::mapping::simd::math::Precision;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// Points per block.
pub(crate) const BLOCK: usize = 8;

/// The element type of the tables and lanes.
type E = f64;
/// A block of f64 lanes.
type F = [f64; BLOCK];
/// A block of table indices (signed, as the vector backends' 64-bit lanes).
type I = [i64; BLOCK];
/// A block of lane masks: all-ones (true) or all-zeros (false) per lane, as the vector backends'
/// masks, so that a comparison is one `cmppd` and a select three bit operations on SSE2 (masks of
/// `bool` made the compiler pack and unpack bytes around every select).
type M = [u64; BLOCK];

/// The mask lane of `b`.
#[inline(always)]
fn mask(b: bool) -> u64 {
    (b as u64).wrapping_neg()
}

// Every word is an explicit loop over the lanes (not `array::map`/`from_fn`, whose closures the
// compiler left out of line: a call per gather, ~30 % of the forward map's instructions).
macro_rules! lanewise {
    ($($name:ident($($a:ident: $t:ty),*) -> $r:ty => $e:expr;)*) => {$(
        #[inline(always)]
        fn $name($($a: $t),*) -> $r {
            let mut o: $r = [Default::default(); BLOCK];
            for l in 0..BLOCK {
                $(let $a = $a[l];)*
                o[l] = $e;
            }
            o
        }
    )*};
}

lanewise! {
    add(a: F, b: F) -> F => a + b;
    sub(a: F, b: F) -> F => a - b;
    mul(a: F, b: F) -> F => a * b;
    div(a: F, b: F) -> F => a / b;
    lt(a: F, b: F) -> M => mask(a < b);
    le(a: F, b: F) -> M => mask(a <= b);
    gt(a: F, b: F) -> M => mask(a > b);
    ge(a: F, b: F) -> M => mask(a >= b);
    eq(a: F, b: F) -> M => mask(a == b);
    and(a: M, b: M) -> M => a & b;
    or(a: M, b: M) -> M => a | b;
    not(a: M) -> M => !a;
    sqrt(a: F) -> F => a.sqrt();
    abs(a: F) -> F => a.abs();
    neg(a: F) -> F => -a;
    isnan(a: F) -> M => mask(a.is_nan());
    sign_negative(a: F) -> M => ((a.to_bits() as i64) >> 63) as u64;
    sel(m: M, a: F, b: F) -> F => f64::from_bits((m & a.to_bits()) | (!m & b.to_bits()));
    iadd(a: I, b: I) -> I => a.wrapping_add(b);
    isub(a: I, b: I) -> I => a.wrapping_sub(b);
    imin(a: I, b: I) -> I => a.min(b);
    imax(a: I, b: I) -> I => a.max(b);
    imul(a: I, b: I) -> I => a.wrapping_mul(b);
    isel(m: M, a: I, b: I) -> I => ((m & a as u64) | (!m & b as u64)) as i64;
    ieq(a: I, b: I) -> M => mask(a == b);
    igt(a: I, b: I) -> M => mask(a > b);
    ilanes(a: I) -> [usize; BLOCK] => a as usize;
    ifrom(a: [usize; BLOCK]) -> I => a as i64;
}

#[inline(always)]
fn splat(x: f64) -> F {
    [x; BLOCK]
}
#[inline(always)]
fn zero() -> F {
    splat(0.0)
}
#[inline(always)]
fn any(m: M) -> bool {
    let mut acc = 0;
    for l in 0..BLOCK {
        acc |= m[l];
    }
    acc != 0
}
#[inline(always)]
fn isplat(x: usize) -> I {
    [x as i64; BLOCK]
}
#[inline(always)]
fn izero() -> I {
    isplat(0)
}
#[inline(always)]
fn flanes(a: F) -> [f64; BLOCK] {
    a
}
#[inline(always)]
fn fload(a: &[f64; BLOCK]) -> F {
    *a
}

/// `(x as usize).min(kmax)` per lane (NaN and negatives give 0), as the vector backends compute
/// it: max with 0 (NaN gives 0), min with `kmax`, truncation.
#[inline(always)]
fn to_index(x: F, kmax: usize) -> I {
    // Every caller's kmax is a table length less one, far below 2⁶² (the bound keeps the
    // conversion below sound for any argument).
    let top = (kmax as u64).min(1 << 62) as f64;
    let mut o = [0; BLOCK];
    for l in 0..BLOCK {
        let v = if x[l] > 0.0 { x[l] } else { 0.0 };
        let v = if v < top { v } else { top };
        // SAFETY: v lies in [0, 2⁶²] (a NaN became 0 above), so it truncates to an i64 (the
        // saturating `as` would add a NaN and overflow check per lane).
        o[l] = unsafe { v.to_int_unchecked::<i64>() };
    }
    o
}

/// `t[i]`, the index clamped into `t` first (as the vector backends clamp their gather indices):
/// in bounds one comparison and one load, the clamp out of line (no index the kernels compute
/// from valid inputs is out of bounds; NaN or out-of-domain inputs may give one).
#[inline(always)]
fn at<T: Copy>(t: &[T], i: i64) -> T {
    match t.get(i as usize) {
        Some(&x) => x,
        None => at_clamped(t, i),
    }
}

/// `t[i.clamp(0, t.len() - 1)]` for an index outside `t` (`t` must not be empty).
#[cold]
#[inline(never)]
fn at_clamped<T: Copy>(t: &[T], i: i64) -> T {
    t[if i < 0 { 0 } else { t.len() - 1 }]
}

/// `t[idx]` per lane, the index clamped into `t` first (`t` must not be empty).
#[inline(always)]
fn gather(t: &[f64], idx: I) -> F {
    let mut o = [0.0; BLOCK];
    for l in 0..BLOCK {
        o[l] = at(t, idx[l]);
    }
    o
}

/// `t[idx] as usize` per lane for a u32 table, the index clamped into `t` first.
#[inline(always)]
fn gather_u32(t: &[u32], idx: I) -> I {
    let mut o = [0; BLOCK];
    for l in 0..BLOCK {
        o[l] = at(t, idx[l]) as i64;
    }
    o
}

super::kernels::vector_kernels!();

#[cfg(test)]
mod tests {
    use super::*;

    /// The vector radial solve equals the scalar one bit for bit, on ordinary segments and on one
    /// whose linear-in-area guess underflows (d0 = 0, densities ~1e-306: the guess is not finite
    /// and the constant-density guess must be used, as in `radial::area_guess`).
    #[test]
    fn radial_solve_lanes_equal_scalar() {
        let mut segs = vec![(
            7.584728575995813e-1,
            1.0,
            0.0,
            1.348951026719991e-306,
            1.0491368806029343e-308,
        )];
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..63 {
            let x0 = rnd() * 0.9;
            let x1 = x0 + rnd() * 0.1 + 1e-3;
            let (d0, d1) = (rnd().powi(4) + 1e-3, rnd().powi(4) + 1e-3);
            let mass = crate::mapping::radial::segment_mass(x0, x1, d0, d1);
            segs.push((x0, x1, d0, d1, rnd() * mass));
        }
        for block in segs.chunks(BLOCK) {
            let get = |k: usize| -> F {
                let mut a = [0.0; BLOCK];
                for (l, s) in block.iter().enumerate() {
                    a[l] = [s.0, s.1, s.2, s.3, s.4][k];
                }
                a
            };
            // SAFETY: the portable vocabulary needs no instruction-set extension.
            let got = unsafe { solve_radius(get(0), get(1), get(2), get(3), get(4)) };
            for (l, s) in block.iter().enumerate() {
                let want = crate::mapping::radial::solve_radius(s.0, s.1, s.2, s.3, s.4);
                assert!(want.is_finite() && want < s.1 || s.4 <= 0.0);
                assert_eq!(got[l].to_bits(), want.to_bits(), "segment {s:?}");
            }
        }
    }
}
