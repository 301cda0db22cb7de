//! The AVX2 + FMA backend: the vocabulary of [`super::kernels`] over K = 4 independent `__m256d`
//! chains of four lanes per block of [`BLOCK`] points, with the table searches as vector descents
//! over AVX2 gathers. The kernels themselves are written once in [`super::kernels`] and
//! instantiated here, in [`super::portable`] and, for AVX-512, in [`super::avx512`]. The design
//! notes below hold for every backend.
//!
//! Every stage runs on whole vectors: the guide-table lookups and the descents of the wedge and
//! radial searches read the tables with `vgatherqpd`, the searches' rare settling steps (an answer
//! that round-off left outside its bracket) are detected on the vector and redone per lane only
//! where needed. (Compiled per-lane search loops, the design before, made up more than half of the
//! forward map's instructions: `docs/PERFORMANCE.md`.)
//!
//! **Bit for bit on every backend.** Every word is an IEEE-rounded instruction with the semantics of
//! its portable spelling (no fused multiply–add); `f64::min`/`max` are spelled out with their NaN
//! rules (`fmin`, `fmax`), and `math::sin_cos`/`atan2` are written operation by operation. The
//! batch tests compare this backend with the portable one bit for bit.
//!
//! **Inlining.** The small helpers are safe `#[target_feature]` functions, which the compiler
//! inlines by itself; the stages used by more than one kernel (searches, `atan2`, the radial solve)
//! are `#[inline(always)] unsafe fn` without the attribute (the two cannot be combined on stable
//! Rust), so that they are inlined into every kernel: measured 10–15 % faster on the inverse. Their
//! one safety condition is the module's: the CPU has the module's instruction set, which every
//! caller, an entry point compiled with `#[target_feature]` for it, guarantees.
//!
//! **Memory safety.** Every gather index is clamped into its table ([`gather`]), so that no input
//! (NaN, infinities, points outside the square) can make a gather read outside a table; the clamp
//! never changes an index the scalar path would use, since those are in bounds by construction.

use crate::mapping::hds::TablesView;
use crate::mapping::simd::math::Precision;
use std::arch::x86_64::*;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// Vectors per block: independent chains that the core overlaps (the kernel's stages are long
/// dependency chains of gathers, divisions and square roots).
const K: usize = 4;
/// Points per block.
pub(crate) const BLOCK: usize = 4 * K;

/// The element type of the tables and lanes.
type E = f64;
/// K vectors of four f64 lanes (a value, or a mask of all-ones / all-zeros lanes).
#[derive(Clone, Copy)]
struct F([__m256d; K]);
/// Masks are vectors of all-ones / all-zeros lanes on AVX2.
type M = F;
/// K vectors of four i64 lanes (table indices).
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
    add => _mm256_add_pd;
    sub => _mm256_sub_pd;
    mul => _mm256_mul_pd;
    div => _mm256_div_pd;
    lt => _mm256_cmp_pd::<_CMP_LT_OQ>;
    le => _mm256_cmp_pd::<_CMP_LE_OQ>;
    gt => _mm256_cmp_pd::<_CMP_GT_OQ>;
    ge => _mm256_cmp_pd::<_CMP_GE_OQ>;
    eq => _mm256_cmp_pd::<_CMP_EQ_OQ>;
    and => _mm256_and_pd;
    or => _mm256_or_pd;
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
    iadd => _mm256_add_epi64;
    isub => _mm256_sub_epi64;
    imin => |a, b| _mm256_blendv_epi8(a, b, _mm256_cmpgt_epi64(a, b));
    imax => |a, b| _mm256_blendv_epi8(b, a, _mm256_cmpgt_epi64(a, b));
    // a · b for lanes below 2³² (the low halves' 64-bit product).
    imul => _mm256_mul_epu32;
}

#[inline]
#[target_feature(enable = "avx2,fma")]
fn splat(x: f64) -> F {
    F([_mm256_set1_pd(x); K])
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
        o.0[k] = _mm256_sqrt_pd(a.0[k]);
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn abs(a: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_andnot_pd(_mm256_set1_pd(-0.0), a.0[k]);
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn neg(a: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_xor_pd(a.0[k], _mm256_set1_pd(-0.0));
    }
    o
}
/// NaN lanes of `a`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn isnan(a: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_cmp_pd::<_CMP_UNORD_Q>(a.0[k], a.0[k]);
    }
    o
}
/// `!m`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn not(m: F) -> F {
    let mut o = m;
    for k in 0..K {
        o.0[k] = _mm256_xor_pd(m.0[k], _mm256_castsi256_pd(_mm256_set1_epi64x(-1)));
    }
    o
}
/// Per lane `if m { a } else { b }`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn sel(m: F, a: F, b: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_blendv_pd(b.0[k], a.0[k], m.0[k]);
    }
    o
}
/// Whether any lane of the mask is set.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn any(m: F) -> bool {
    let mut acc = m.0[0];
    for k in 1..K {
        acc = _mm256_or_pd(acc, m.0[k]);
    }
    _mm256_movemask_pd(acc) != 0
}

#[inline]
#[target_feature(enable = "avx2,fma")]
fn isplat(x: usize) -> I {
    I([_mm256_set1_epi64x(x as i64); K])
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn izero() -> I {
    isplat(0)
}
/// Per lane `if m { a } else { b }`, `m` an f64 mask.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn isel(m: F, a: I, b: I) -> I {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_castpd_si256(_mm256_blendv_pd(
            _mm256_castsi256_pd(b.0[k]),
            _mm256_castsi256_pd(a.0[k]),
            m.0[k],
        ));
    }
    o
}
/// `a == b` as an f64 mask.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn ieq(a: I, b: I) -> F {
    let mut o = zero();
    for k in 0..K {
        o.0[k] = _mm256_castsi256_pd(_mm256_cmpeq_epi64(a.0[k], b.0[k]));
    }
    o
}
/// `a > b` (signed) as an f64 mask.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn igt(a: I, b: I) -> F {
    let mut o = zero();
    for k in 0..K {
        o.0[k] = _mm256_castsi256_pd(_mm256_cmpgt_epi64(a.0[k], b.0[k]));
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn ilanes(a: I) -> [usize; BLOCK] {
    let mut o = [0i64; BLOCK];
    for k in 0..K {
        // SAFETY: `o` holds 4K i64; unaligned store of four.
        unsafe { _mm256_storeu_si256(o[4 * k..].as_mut_ptr().cast(), a.0[k]) };
    }
    o.map(|x| x as usize)
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn flanes(a: F) -> [f64; BLOCK] {
    let mut o = [0.0; BLOCK];
    for k in 0..K {
        // SAFETY: `o` holds 4K f64; unaligned store of four.
        unsafe { _mm256_storeu_pd(o[4 * k..].as_mut_ptr(), a.0[k]) };
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn fload(a: &[f64; BLOCK]) -> F {
    let mut o = zero();
    for k in 0..K {
        // SAFETY: `a` holds 4K f64; unaligned load of four.
        o.0[k] = unsafe { _mm256_loadu_pd(a[4 * k..].as_ptr()) };
    }
    o
}
#[inline]
#[target_feature(enable = "avx2,fma")]
fn ifrom(a: [usize; BLOCK]) -> I {
    let mut o = izero();
    for k in 0..K {
        let q = &a[4 * k..4 * k + 4];
        o.0[k] = _mm256_setr_epi64x(q[0] as i64, q[1] as i64, q[2] as i64, q[3] as i64);
    }
    o
}

/// `(x as usize).min(kmax)` per lane (NaN and negatives give 0), for `kmax` < 2³¹.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn to_index(x: F, kmax: usize) -> I {
    // maxpd returns its second operand for a NaN lane: 0, as `as usize` does.
    let mut o = izero();
    for k in 0..K {
        let v = _mm256_min_pd(
            _mm256_max_pd(x.0[k], _mm256_setzero_pd()),
            _mm256_set1_pd(kmax as f64),
        );
        o.0[k] = _mm256_cvtepi32_epi64(_mm256_cvttpd_epi32(v));
    }
    o
}

/// `t[idx]` per lane, the index clamped into `t` first (`t` must not be empty).
#[inline]
#[target_feature(enable = "avx2,fma")]
fn gather(t: &[f64], idx: I) -> F {
    assert!(!t.is_empty());
    let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
    let mut o = zero();
    for k in 0..K {
        // SAFETY: every index lies in 0..t.len().
        o.0[k] = unsafe { _mm256_i64gather_pd::<8>(t.as_ptr(), idx.0[k]) };
    }
    o
}

/// `t[idx] as usize` per lane for a u32 table, the index clamped into `t` first.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn gather_u32(t: &[u32], idx: I) -> I {
    assert!(!t.is_empty());
    let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
    let mut o = idx;
    for k in 0..K {
        // SAFETY: every index lies in 0..t.len(); u32 and i32 have the same layout.
        let g = unsafe { _mm256_i64gather_epi32::<4>(t.as_ptr().cast(), idx.0[k]) };
        o.0[k] = _mm256_cvtepu32_epi64(g);
    }
    o
}

/// Lanes whose sign bit is set (`is_sign_negative`).
#[inline]
#[target_feature(enable = "avx2,fma")]
fn sign_negative(a: F) -> F {
    let mut o = a;
    for k in 0..K {
        o.0[k] = _mm256_castsi256_pd(_mm256_cmpgt_epi64(
            _mm256_setzero_si256(),
            _mm256_castpd_si256(a.0[k]),
        ));
    }
    o
}

super::kernels::vector_kernels!("avx2,fma");
