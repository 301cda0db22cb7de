//! The portable backend in f32: the vocabulary of [`super::kernels`] over plain arrays of
//! [`BLOCK`] f32 lanes (values `[f32; BLOCK]`, 32-bit indices `[i32; BLOCK]`, masks
//! `[bool; BLOCK]`), compiled for the target's baseline instruction set. The float32 map's
//! fallback on every CPU. Every word has the semantics of its AVX2/AVX-512 f32 spelling
//! ([`super::avx2`], [`super::avx512`]): IEEE-rounded f32 arithmetic, no fused
//! multiply–add, ordered comparisons, wrapping 32-bit index arithmetic, the same clamping of
//! indices and of `to_index` (exact while `kmax` < 2²⁴, which [`crate::mapping::Float32Map`]
//! guarantees), so this backend gives the same bits as the others.

// Lane loops index several arrays by the same lane number on purpose (they vectorise).
#![allow(clippy::needless_range_loop)]

use crate::mapping::hds::TablesView;
use crate::mapping::simd::math::Precision;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// Points per block.
pub(crate) const BLOCK: usize = 16;

/// The element type of the tables and lanes.
type E = f32;
/// A block of f32 lanes.
type F = [f32; BLOCK];
/// A block of table indices (signed 32-bit, as the vector backends' lanes).
type I = [i32; BLOCK];
/// A block of lane masks.
type M = [bool; BLOCK];

macro_rules! lanewise {
    ($($name:ident($($a:ident: $t:ty),*) -> $r:ty => $e:expr;)*) => {$(
        #[inline(always)]
        fn $name($($a: $t),*) -> $r {
            std::array::from_fn(|l| {
                $(let $a = $a[l];)*
                $e
            })
        }
    )*};
}

lanewise! {
    add(a: F, b: F) -> F => a + b;
    sub(a: F, b: F) -> F => a - b;
    mul(a: F, b: F) -> F => a * b;
    div(a: F, b: F) -> F => a / b;
    lt(a: F, b: F) -> M => a < b;
    le(a: F, b: F) -> M => a <= b;
    gt(a: F, b: F) -> M => a > b;
    ge(a: F, b: F) -> M => a >= b;
    eq(a: F, b: F) -> M => a == b;
    and(a: M, b: M) -> M => a & b;
    or(a: M, b: M) -> M => a | b;
    not(a: M) -> M => !a;
    sqrt(a: F) -> F => a.sqrt();
    abs(a: F) -> F => a.abs();
    neg(a: F) -> F => -a;
    isnan(a: F) -> M => a.is_nan();
    sign_negative(a: F) -> M => a.is_sign_negative();
    sel(m: M, a: F, b: F) -> F => if m { a } else { b };
    iadd(a: I, b: I) -> I => a.wrapping_add(b);
    isub(a: I, b: I) -> I => a.wrapping_sub(b);
    imin(a: I, b: I) -> I => a.min(b);
    imax(a: I, b: I) -> I => a.max(b);
    imul(a: I, b: I) -> I => a.wrapping_mul(b);
    isel(m: M, a: I, b: I) -> I => if m { a } else { b };
    ieq(a: I, b: I) -> M => a == b;
    igt(a: I, b: I) -> M => a > b;
}

/// An f64 constant rounded to f32, on every lane.
#[inline(always)]
fn splat(x: f64) -> F {
    [x as f32; BLOCK]
}
#[inline(always)]
fn zero() -> F {
    splat(0.0)
}
#[inline(always)]
fn any(m: M) -> bool {
    m.iter().any(|&b| b)
}
#[inline(always)]
fn isplat(x: usize) -> I {
    [x as i32; BLOCK]
}
#[inline(always)]
fn izero() -> I {
    isplat(0)
}
#[inline(always)]
fn ilanes(a: I) -> [usize; BLOCK] {
    a.map(|x| x as usize)
}
#[inline(always)]
fn flanes(a: F) -> [f32; BLOCK] {
    a
}
#[inline(always)]
fn fload(a: &[f32; BLOCK]) -> F {
    *a
}
#[inline(always)]
fn ifrom(a: [usize; BLOCK]) -> I {
    a.map(|x| x as i32)
}

/// `(x as usize).min(kmax)` per lane (NaN and negatives give 0), as the vector backends compute
/// it: max with 0 (NaN gives 0), min with `kmax` (as f32: exact for `kmax` < 2²⁴), truncation.
#[inline(always)]
fn to_index(x: F, kmax: usize) -> I {
    let top = kmax as f32;
    x.map(|x| {
        let v = if x > 0.0 { x } else { 0.0 };
        (if v < top { v } else { top }) as i32
    })
}

/// `t[idx]` per lane, the index clamped into `t` first (`t` must not be empty).
#[inline(always)]
fn gather(t: &[f32], idx: I) -> F {
    let last = t.len() as i32 - 1;
    idx.map(|i| t[i.clamp(0, last) as usize])
}

/// `t[idx]` per lane for a u32 table (entries below 2³¹), the index clamped into `t` first.
#[inline(always)]
fn gather_u32(t: &[u32], idx: I) -> I {
    let last = t.len() as i32 - 1;
    idx.map(|i| t[i.clamp(0, last) as usize] as i32)
}

super::kernels::vector_kernels!();

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
