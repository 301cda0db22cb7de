//! The AVX-512 backend: the vocabulary of [`super::kernels`] on AVX-512 (F and DQ): eight f64 lanes per
//! `__m512d`, K independent vectors per block (K = 2 for the forward map in [`k2`], K = 4 for the
//! pdf and the inverse in [`k4`]), comparisons into `__mmask8` mask registers, 8-lane gathers. The same operations in the same order as the AVX2 vocabulary
//! ([`super::avx2`], whose documentation gives the design and the exactness argument), so the
//! results are the same bits on every backend (tested in `tests/batch.rs`).

use crate::mapping::hds::TablesView;
use crate::mapping::simd::math::Precision;
use std::arch::x86_64::*;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

macro_rules! f_binary {
    ($($name:ident => $op:expr;)*) => {$(
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn $name(a: F, b: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = $op(a.0[k], b.0[k]);
            }
            o
        }
    )*};
}

macro_rules! f_compare {
    ($($name:ident => $pred:ident;)*) => {$(
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn $name(a: F, b: F) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = _mm512_cmp_pd_mask::<$pred>(a.0[k], b.0[k]);
            }
            o
        }
    )*};
}

macro_rules! i_binary {
    ($($name:ident => $op:expr;)*) => {$(
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn $name(a: I, b: I) -> I {
            let mut o = a;
            for k in 0..K {
                o.0[k] = $op(a.0[k], b.0[k]);
            }
            o
        }
    )*};
}

/// The vector vocabulary for K vectors per block and the kernels instantiated over it, in the
/// calling module.
macro_rules! avx512_kernels {
    ($k:literal) => {
        /// Vectors per block (independent chains the core overlaps).
        const K: usize = $k;
        /// Points per block.
        pub(crate) const BLOCK: usize = 8 * K;

        /// The element type of the tables and lanes.
        type E = f64;
        /// K vectors of eight f64 lanes.
        #[derive(Clone, Copy)]
        struct F([__m512d; K]);
        /// K vectors of eight i64 lanes (table indices).
        #[derive(Clone, Copy)]
        struct I([__m512i; K]);
        /// K lane masks.
        #[derive(Clone, Copy)]
        struct M([__mmask8; K]);

        f_binary! {
            add => _mm512_add_pd;
            sub => _mm512_sub_pd;
            mul => _mm512_mul_pd;
            div => _mm512_div_pd;
        }

        f_compare! {
            lt => _CMP_LT_OQ;
            le => _CMP_LE_OQ;
            gt => _CMP_GT_OQ;
            ge => _CMP_GE_OQ;
            eq => _CMP_EQ_OQ;
        }

        i_binary! {
            iadd => _mm512_add_epi64;
            isub => _mm512_sub_epi64;
            imin => _mm512_min_epi64;
            imax => _mm512_max_epi64;
            // a · b for lanes below 2³² (the low halves' 64-bit product).
            imul => _mm512_mul_epu32;
        }

        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn and(a: M, b: M) -> M {
            let mut o = a;
            for k in 0..K {
                o.0[k] = a.0[k] & b.0[k];
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn or(a: M, b: M) -> M {
            let mut o = a;
            for k in 0..K {
                o.0[k] = a.0[k] | b.0[k];
            }
            o
        }
        /// `!m`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn not(m: M) -> M {
            let mut o = m;
            for k in 0..K {
                o.0[k] = !m.0[k];
            }
            o
        }
        /// Whether any lane of the mask is set.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn any(m: M) -> bool {
            m.0.iter().any(|&k| k != 0)
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn splat(x: f64) -> F {
            F([_mm512_set1_pd(x); K])
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn zero() -> F {
            splat(0.0)
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn sqrt(a: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = _mm512_sqrt_pd(a.0[k]);
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn abs(a: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = _mm512_andnot_pd(_mm512_set1_pd(-0.0), a.0[k]);
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn neg(a: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = _mm512_xor_pd(a.0[k], _mm512_set1_pd(-0.0));
            }
            o
        }
        /// NaN lanes of `a`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn isnan(a: F) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = _mm512_cmp_pd_mask::<_CMP_UNORD_Q>(a.0[k], a.0[k]);
            }
            o
        }
        /// Per lane `if m { a } else { b }`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn sel(m: M, a: F, b: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = _mm512_mask_blend_pd(m.0[k], b.0[k], a.0[k]);
            }
            o
        }
        /// Lanes whose sign bit is set (`is_sign_negative`).
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn sign_negative(a: F) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] =
                    _mm512_cmplt_epi64_mask(_mm512_castpd_si512(a.0[k]), _mm512_setzero_si512());
            }
            o
        }

        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn isplat(x: usize) -> I {
            I([_mm512_set1_epi64(x as i64); K])
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn izero() -> I {
            isplat(0)
        }
        /// Per lane `if m { a } else { b }`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn isel(m: M, a: I, b: I) -> I {
            let mut o = a;
            for k in 0..K {
                o.0[k] = _mm512_mask_blend_epi64(m.0[k], b.0[k], a.0[k]);
            }
            o
        }
        /// `a == b`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn ieq(a: I, b: I) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = _mm512_cmpeq_epi64_mask(a.0[k], b.0[k]);
            }
            o
        }
        /// `a > b` (signed).
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn igt(a: I, b: I) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = _mm512_cmpgt_epi64_mask(a.0[k], b.0[k]);
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn ilanes(a: I) -> [usize; BLOCK] {
            let mut o = [0i64; BLOCK];
            for k in 0..K {
                // SAFETY: `o` holds 8K i64; unaligned store of eight.
                unsafe { _mm512_storeu_si512(o[8 * k..].as_mut_ptr().cast(), a.0[k]) };
            }
            o.map(|x| x as usize)
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn flanes(a: F) -> [f64; BLOCK] {
            let mut o = [0.0; BLOCK];
            for k in 0..K {
                // SAFETY: `o` holds 8K f64; unaligned store of eight.
                unsafe { _mm512_storeu_pd(o[8 * k..].as_mut_ptr(), a.0[k]) };
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn fload(a: &[f64; BLOCK]) -> F {
            let mut o = zero();
            for k in 0..K {
                // SAFETY: `a` holds 8K f64; unaligned load of eight.
                o.0[k] = unsafe { _mm512_loadu_pd(a[8 * k..].as_ptr()) };
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn ifrom(a: [usize; BLOCK]) -> I {
            let mut o = izero();
            let a = a.map(|x| x as i64);
            for k in 0..K {
                // SAFETY: `a` holds 8K i64; unaligned load of eight.
                o.0[k] = unsafe { _mm512_loadu_si512(a[8 * k..].as_ptr().cast()) };
            }
            o
        }

        /// `(x as usize).min(kmax)` per lane (NaN and negatives give 0), for `kmax` < 2³¹.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn to_index(x: F, kmax: usize) -> I {
            let mut o = izero();
            for k in 0..K {
                // maxpd returns its second operand for a NaN lane: 0, as `as usize` does.
                let v = _mm512_min_pd(
                    _mm512_max_pd(x.0[k], _mm512_setzero_pd()),
                    _mm512_set1_pd(kmax as f64),
                );
                o.0[k] = _mm512_cvtepi32_epi64(_mm512_cvttpd_epi32(v));
            }
            o
        }

        /// `t[idx]` per lane, the index clamped into `t` first (`t` must not be empty).
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn gather(t: &[f64], idx: I) -> F {
            assert!(!t.is_empty());
            let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
            let mut o = zero();
            for k in 0..K {
                // SAFETY: every index lies in 0..t.len().
                o.0[k] = unsafe { _mm512_i64gather_pd::<8>(idx.0[k], t.as_ptr()) };
            }
            o
        }

        /// `t[idx] as usize` per lane for a u32 table, the index clamped into `t` first.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn gather_u32(t: &[u32], idx: I) -> I {
            assert!(!t.is_empty());
            let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
            let mut o = idx;
            for k in 0..K {
                // SAFETY: every index lies in 0..t.len(); u32 and i32 have the same layout.
                let g = unsafe { _mm512_i64gather_epi32::<4>(idx.0[k], t.as_ptr().cast()) };
                o.0[k] = _mm512_cvtepu32_epi64(g);
            }
            o
        }

        crate::mapping::simd::kernels::vector_kernels!("avx512f,avx512dq");
    };
}

/// The forward map with K = 2 vectors per block (16 points), measured best for it (K = 1, 2, 4:
/// 47, 33, 39 ns at 19 × 36). Its pdf and inverse kernels are not used.
#[allow(dead_code)]
pub(crate) mod k2 {
    use super::*;
    avx512_kernels!(2);
}

/// The pdf and the inverse with K = 4 vectors per block (32 points): 8–16 % faster than K = 2
/// (docs/PERFORMANCE.md). Its forward kernel is not used.
#[allow(dead_code)]
pub(crate) mod k4 {
    use super::*;
    avx512_kernels!(4);
}
