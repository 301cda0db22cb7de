//! The portable backend: the vocabulary of [`super::kernels`] over plain arrays of [`BLOCK`]
//! lanes (values `[E; BLOCK]`, indices `[I; BLOCK]`, masks of all-ones or all-zeros lanes in an
//! unsigned integer of the element's width), compiled for the target's baseline instruction set
//! (SSE2 on x86-64, NEON on aarch64), where the compiler vectorises the element-wise loops. Written
//! once over both element types (issue 36): f64 at the module's top level (eight lanes, 64-bit
//! indices; also the backend of maps whose tables are too large for the explicit kernels' 32-bit
//! index conversions) and f32 in [`f32_lanes`] (sixteen lanes, 32-bit indices: the float32 map's
//! fallback on every CPU). Every word has the semantics of its AVX2/AVX-512 spelling
//! (IEEE-rounded arithmetic, no fused multiply–add, ordered comparisons, wrapping index
//! arithmetic, the same clamping of indices and of `to_index`; f32 `to_index` exact while
//! `kmax` < 2²⁴, which [`crate::mapping::Float32Map`] guarantees), so this backend gives the same
//! bits as the others (tested in `tests/batch.rs` and `tests/float32_map.rs`).

// Lane loops index several arrays by the same lane number on purpose (they vectorise).
#![allow(clippy::needless_range_loop)]

use crate::mapping::hds::TablesView;
use crate::mapping::simd::math::Precision;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

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

/// The portable vocabulary for one element type and the kernels instantiated over it, in the
/// calling module.
macro_rules! portable_kernels {
    (
        lanes: $lanes:literal,
        elem: $e:ident,
        index: $ie:ident,
        bits: $mt:ident,
        sign_shift: $shift:literal,
        top: $top:expr
    ) => {
        /// Points per block.
        pub(crate) const BLOCK: usize = $lanes;

        /// The element type of the tables and lanes.
        type E = $e;
        /// A block of lanes.
        type F = [$e; BLOCK];
        /// A block of table indices (signed, as the vector backends' lanes).
        type I = [$ie; BLOCK];
        /// A block of lane masks: all-ones (true) or all-zeros (false) per lane, as the vector
        /// backends' masks, so that a comparison is one compare instruction and a select three
        /// bit operations (masks of `bool` made the compiler pack and unpack bytes around every
        /// select).
        type M = [$mt; BLOCK];

        /// The mask lane of `b`.
        #[inline(always)]
        fn mask(b: bool) -> $mt {
            (b as $mt).wrapping_neg()
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
            sign_negative(a: F) -> M => ((a.to_bits() as $ie) >> $shift) as $mt;
            sel(m: M, a: F, b: F) -> F => $e::from_bits((m & a.to_bits()) | (!m & b.to_bits()));
            iadd(a: I, b: I) -> I => a.wrapping_add(b);
            isub(a: I, b: I) -> I => a.wrapping_sub(b);
            imin(a: I, b: I) -> I => a.min(b);
            imax(a: I, b: I) -> I => a.max(b);
            imul(a: I, b: I) -> I => a.wrapping_mul(b);
            isel(m: M, a: I, b: I) -> I => ((m & a as $mt) | (!m & b as $mt)) as $ie;
            ieq(a: I, b: I) -> M => mask(a == b);
            igt(a: I, b: I) -> M => mask(a > b);
            ilanes(a: I) -> [usize; BLOCK] => a as usize;
            ifrom(a: [usize; BLOCK]) -> I => a as $ie;
        }

        /// An f64 constant rounded to the element type, on every lane (no rounding for f64).
        #[allow(clippy::unnecessary_cast)]
        #[inline(always)]
        fn splat(x: f64) -> F {
            [x as $e; BLOCK]
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
            [x as $ie; BLOCK]
        }
        #[inline(always)]
        fn izero() -> I {
            isplat(0)
        }
        #[inline(always)]
        fn flanes(a: F) -> [$e; BLOCK] {
            a
        }
        #[inline(always)]
        fn fload(a: &[$e; BLOCK]) -> F {
            *a
        }

        /// `(x as usize).min(kmax)` per lane (NaN and negatives give 0), as the vector backends
        /// compute it: max with 0 (NaN gives 0), min with `kmax`, truncation.
        #[inline(always)]
        fn to_index(x: F, kmax: usize) -> I {
            // Every caller's kmax is a table length less one, far below the bound, which keeps
            // the conversion below sound for any argument.
            let top = kmax.min($top) as $e;
            let mut o = [0; BLOCK];
            for l in 0..BLOCK {
                let v = if x[l] > 0.0 { x[l] } else { 0.0 };
                let v = if v < top { v } else { top };
                // SAFETY: v lies in [0, top] (a NaN became 0 above), so it truncates to the
                // index type (the saturating `as` would add a NaN and overflow check per lane).
                o[l] = unsafe { v.to_int_unchecked::<$ie>() };
            }
            o
        }

        /// `t[idx]` per lane, the index clamped into `t` first (`t` must not be empty).
        #[inline(always)]
        fn gather(t: &[$e], idx: I) -> F {
            let mut o = [0.0; BLOCK];
            for l in 0..BLOCK {
                o[l] = at(t, idx[l] as i64);
            }
            o
        }

        /// `t[idx]` per lane for a u32 table, the index clamped into `t` first.
        #[inline(always)]
        fn gather_u32(t: &[u32], idx: I) -> I {
            let mut o = [0; BLOCK];
            for l in 0..BLOCK {
                o[l] = at(t, idx[l] as i64) as $ie;
            }
            o
        }

        crate::mapping::simd::kernels::vector_kernels!();
    };
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

portable_kernels! {
    lanes: 8,
    elem: f64,
    index: i64,
    bits: u64,
    sign_shift: 63,
    top: 1 << 62
}

/// The f32 kernels: sixteen f32 lanes, 32-bit indices.
pub(crate) mod f32_lanes {
    use super::*;
    portable_kernels! {
        lanes: 16,
        elem: f32,
        index: i32,
        bits: u32,
        sign_shift: 31,
        top: 1 << 30
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        /// Distance in f32 ulps of `want` (an f64 libm value) — near a zero of the function, where the
        /// reduction's absolute error is the honest measure, in units of 2⁻²⁴ absolute.
        fn err(got: f32, want: f64) -> f64 {
            let w = want as f32;
            let ulp = (f32::from_bits(w.abs().to_bits() + 1) - w.abs()) as f64;
            let e = (got as f64 - want).abs();
            if want.abs() < 2f64.powi(-10) {
                (e / 2f64.powi(-24)).min(e / ulp)
            } else {
                e / ulp
            }
        }

        /// The f32 sin/cos of the kernels over [−1, 2π + 1] (the kernels use [0, 2π]), 2²⁰ points:
        /// within 2 f32 ulps of the exact values (measured 1.44).
        #[test]
        fn f32_sin_cos_within_2_ulp() {
            let n = 1 << 20;
            let mut worst = 0.0f64;
            for c in 0..n / BLOCK {
                let x: F = std::array::from_fn(|l| {
                    (-1.0 + (2.0 * std::f64::consts::PI + 2.0) * (c * BLOCK + l) as f64 / n as f64)
                        as f32
                });
                // SAFETY: the portable vocabulary needs no instruction-set extension.
                let (s, co) = unsafe { sin_cos(x) };
                for l in 0..BLOCK {
                    let xf = x[l] as f64;
                    worst = worst.max(err(s[l], xf.sin())).max(err(co[l], xf.cos()));
                }
            }
            println!("f32 sin_cos worst {worst:.2} ulp");
            assert!(worst <= 2.0, "f32 sin_cos worst error {worst} ulp");
        }

        /// The f32 atan2 of the kernels on the unit circle and at random points of [−2, 2]², 2²⁰ in
        /// all: within 2 f32 ulps of the exact values (measured 1.73).
        #[test]
        fn f32_atan2_within_2_ulp() {
            let n = 1 << 20;
            let mut worst = 0.0f64;
            let mut state = 99u64;
            let mut rnd = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 40) as f64 / (1u64 << 24) as f64
            };
            for c in 0..n / BLOCK {
                let (y, x): (F, F) = if c % 2 == 0 {
                    let p: [f64; BLOCK] = std::array::from_fn(|l| {
                        std::f64::consts::TAU * (c * BLOCK + l) as f64 / n as f64
                    });
                    (p.map(|p| p.sin() as f32), p.map(|p| p.cos() as f32))
                } else {
                    let a: [f32; BLOCK] = std::array::from_fn(|_| (rnd() * 4.0 - 2.0) as f32);
                    let b: [f32; BLOCK] = std::array::from_fn(|_| (rnd() * 4.0 - 2.0) as f32);
                    (a, b)
                };
                // SAFETY: as above.
                let a = unsafe { atan2(y, x) };
                for l in 0..BLOCK {
                    worst = worst.max(err(a[l], (y[l] as f64).atan2(x[l] as f64)));
                }
            }
            println!("f32 atan2 worst {worst:.2} ulp");
            assert!(worst <= 2.0, "f32 atan2 worst error {worst} ulp");
        }
    }
}

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
