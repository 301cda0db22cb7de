//! The AVX2 + FMA backend in f32: the vocabulary of [`super::kernels`] over K = 2 independent
//! `__m256` chains of eight f32 lanes per block of [`BLOCK`] points, 32-bit indices (`__m256i`)
//! and `vpgatherdd`/`vgatherdps` gathers. The same words, with the same semantics, as
//! [`super::portable32`] (whose documentation states them): no fused multiply–add, so the f32
//! results are the same bits on every backend. The design notes of [`super::avx2`] hold here.

use crate::mapping::hds::TablesView;
use crate::mapping::simd::math::Precision;
use std::arch::x86_64::*;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// Vectors per block: independent chains that the core overlaps.
const K: usize = 2;
/// Points per block.
pub(crate) const BLOCK: usize = 8 * K;

/// The element type of the tables and lanes.
type E = f32;
/// K vectors of eight f32 lanes (a value, or a mask of all-ones / all-zeros lanes).
#[derive(Clone, Copy)]
struct F([__m256; K]);
/// Masks are vectors of all-ones / all-zeros lanes on AVX2.
type M = F;
/// K vectors of eight i32 lanes (table indices).
#[derive(Clone, Copy)]
struct I([__m256i; K]);

macro_rules! f_binary {
    ($($name:ident => $op:expr;)*) => {$(
        #[inline]
        #[target_feature(enable = "avx2,fma")]
        fn $name(a: F, b: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = $op(a.0[k], b.0[k]);
            }
            o
        }
    )*};
}
f_binary! {
    add => _mm256_add_ps;
    sub => _mm256_sub_ps;
    mul => _mm256_mul_ps;
    div => _mm256_div_ps;
    lt => _mm256_cmp_ps::<_CMP_LT_OQ>;
    le => _mm256_cmp_ps::<_CMP_LE_OQ>;
    gt => _mm256_cmp_ps::<_CMP_GT_OQ>;
    ge => _mm256_cmp_ps::<_CMP_GE_OQ>;
    eq => _mm256_cmp_ps::<_CMP_EQ_OQ>;
    and => _mm256_and_ps;
    or => _mm256_or_ps;
}

macro_rules! i_binary {
    ($($name:ident => $op:expr;)*) => {$(
        #[inline]
        #[target_feature(enable = "avx2,fma")]
        fn $name(a: I, b: I) -> I {
            let mut o = a;
            for k in 0..K {
                o.0[k] = $op(a.0[k], b.0[k]);
            }
            o
        }
    )*};
}
i_binary! {
    iadd => _mm256_add_epi32;
    isub => _mm256_sub_epi32;
    imin => _mm256_min_epi32;
    imax => _mm256_max_epi32;
    // The low 32 bits of the product (wrapping, as the portable `wrapping_mul`).
    imul => _mm256_mullo_epi32;
}

/// An f64 constant rounded to f32, on every lane.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn splat(x: f64) -> F {
    F([_mm256_set1_ps(x as f32); K])
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn zero() -> F {
    splat(0.0)
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn sqrt(a: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_sqrt_ps(a.0[k]);
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn abs(a: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_andnot_ps(_mm256_set1_ps(-0.0), a.0[k]);
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn neg(a: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_xor_ps(a.0[k], _mm256_set1_ps(-0.0));
    }
    o
}
/// NaN lanes of `a`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn isnan(a: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_cmp_ps::<_CMP_UNORD_Q>(a.0[k], a.0[k]);
    }
    o
}
/// `!m`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn not(m: F) -> F {
    let mut o = m;
    for k in 0..K {
        o.0[k] = _mm256_xor_ps(m.0[k], _mm256_castsi256_ps(_mm256_set1_epi32(-1)));
    }
    o
}
/// Per lane `if m { a } else { b }`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn sel(m: F, a: F, b: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_blendv_ps(b.0[k], a.0[k], m.0[k]);
    }
    o
}
/// Whether any lane of the mask is set.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn any(m: F) -> bool {
    let mut acc = m.0[0];
    for k in 1..K {
        acc = _mm256_or_ps(acc, m.0[k]);
    }
    _mm256_movemask_ps(acc) != 0
}
/// Lanes whose sign bit is set (`is_sign_negative`).
#[inline]
#[target_feature(enable = "avx2,fma")]
fn sign_negative(a: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_castsi256_ps(_mm256_cmpgt_epi32(
            _mm256_setzero_si256(),
            _mm256_castps_si256(a.0[k]),
        ));
    }
    o
}

#[inline]
#[target_feature(enable = "avx2,fma")]
fn isplat(x: usize) -> I {
    I([_mm256_set1_epi32(x as i32); K])
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn izero() -> I {
    isplat(0)
}
/// Per lane `if m { a } else { b }`, `m` an f32 mask.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn isel(m: F, a: I, b: I) -> I {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_castps_si256(_mm256_blendv_ps(
            _mm256_castsi256_ps(b.0[k]),
            _mm256_castsi256_ps(a.0[k]),
            m.0[k],
        ));
    }
    o
}
/// `a == b` as an f32 mask.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn ieq(a: I, b: I) -> F {
    let mut o = zero();
    for k in 0..K {
        o.0[k] = _mm256_castsi256_ps(_mm256_cmpeq_epi32(a.0[k], b.0[k]));
    }
    o
}
/// `a > b` (signed) as an f32 mask.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn igt(a: I, b: I) -> F {
    let mut o = zero();
    for k in 0..K {
        o.0[k] = _mm256_castsi256_ps(_mm256_cmpgt_epi32(a.0[k], b.0[k]));
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn ilanes(a: I) -> [usize; BLOCK] {
    let mut o = [0i32; BLOCK];
    for k in 0..K {
        // SAFETY: `o` holds 8K i32; unaligned store of eight.
        unsafe { _mm256_storeu_si256(o[8 * k..].as_mut_ptr().cast(), a.0[k]) };
    }
    o.map(|x| x as usize)
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn flanes(a: F) -> [f32; BLOCK] {
    let mut o = [0.0; BLOCK];
    for k in 0..K {
        // SAFETY: `o` holds 8K f32; unaligned store of eight.
        unsafe { _mm256_storeu_ps(o[8 * k..].as_mut_ptr(), a.0[k]) };
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn fload(a: &[f32; BLOCK]) -> F {
    let mut o = zero();
    for k in 0..K {
        // SAFETY: `a` holds 8K f32; unaligned load of eight.
        o.0[k] = unsafe { _mm256_loadu_ps(a[8 * k..].as_ptr()) };
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn ifrom(a: [usize; BLOCK]) -> I {
    let mut o = izero();
    let a = a.map(|x| x as i32);
    for k in 0..K {
        // SAFETY: `a` holds 8K i32; unaligned load of eight.
        o.0[k] = unsafe { _mm256_loadu_si256(a[8 * k..].as_ptr().cast()) };
    }
    o
}

/// `(x as usize).min(kmax)` per lane (NaN and negatives give 0), for `kmax` < 2²⁴.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn to_index(x: F, kmax: usize) -> I {
    // maxps returns its second operand for a NaN lane: 0, as `as usize` does.
    let mut o = izero();
    for k in 0..K {
        let v = _mm256_min_ps(
            _mm256_max_ps(x.0[k], _mm256_setzero_ps()),
            _mm256_set1_ps(kmax as f32),
        );
        o.0[k] = _mm256_cvttps_epi32(v);
    }
    o
}

/// `t[idx]` per lane, the index clamped into `t` first (`t` must not be empty, below 2³¹
/// entries).
#[inline]
#[target_feature(enable = "avx2,fma")]
fn gather(t: &[f32], idx: I) -> F {
    assert!(!t.is_empty());
    let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
    let mut o = zero();
    for k in 0..K {
        // SAFETY: every index lies in 0..t.len().
        o.0[k] = unsafe { _mm256_i32gather_ps::<4>(t.as_ptr(), idx.0[k]) };
    }
    o
}

/// `t[idx]` per lane for a u32 table (entries below 2³¹), the index clamped into `t` first.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn gather_u32(t: &[u32], idx: I) -> I {
    assert!(!t.is_empty());
    let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
    let mut o = idx;
    for k in 0..K {
        // SAFETY: every index lies in 0..t.len(); u32 and i32 have the same layout.
        o.0[k] = unsafe { _mm256_i32gather_epi32::<4>(t.as_ptr().cast(), idx.0[k]) };
    }
    o
}

super::kernels::vector_kernels!("avx2,fma");
