//! The AVX-512 backend in f32: the vocabulary of [`super::kernels`] on AVX-512 (F and DQ):
//! sixteen f32 lanes per `__m512`, K = 4 independent vectors per block, 32-bit indices (`__m512i`),
//! comparisons into `__mmask16` mask registers, 16-lane gathers. The same words, with the same
//! semantics, as [`super::portable32`] and [`super::avx2_f32`], so the f32 results are the same
//! bits on every backend.

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
                o.0[k] = _mm512_cmp_ps_mask::<$pred>(a.0[k], b.0[k]);
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

/// The f32 vector vocabulary for K vectors per block and the kernels instantiated over it, in
/// the calling module.
macro_rules! avx512_f32_kernels {
    ($k:literal) => {
        /// Vectors per block (independent chains the core overlaps).
        const K: usize = $k;
        /// Points per block.
        pub(crate) const BLOCK: usize = 16 * K;

        /// The element type of the tables and lanes.
        type E = f32;
        /// K vectors of sixteen f32 lanes.
        #[derive(Clone, Copy)]
        struct F([__m512; K]);
        /// K vectors of sixteen i32 lanes (table indices).
        #[derive(Clone, Copy)]
        struct I([__m512i; K]);
        /// K lane masks.
        #[derive(Clone, Copy)]
        struct M([__mmask16; K]);

        f_binary! {
            add => _mm512_add_ps;
            sub => _mm512_sub_ps;
            mul => _mm512_mul_ps;
            div => _mm512_div_ps;
        }

        f_compare! {
            lt => _CMP_LT_OQ;
            le => _CMP_LE_OQ;
            gt => _CMP_GT_OQ;
            ge => _CMP_GE_OQ;
            eq => _CMP_EQ_OQ;
        }

        i_binary! {
            iadd => _mm512_add_epi32;
            isub => _mm512_sub_epi32;
            imin => _mm512_min_epi32;
            imax => _mm512_max_epi32;
            // The low 32 bits of the product (wrapping).
            imul => _mm512_mullo_epi32;
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
        /// An f64 constant rounded to f32, on every lane.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn splat(x: f64) -> F {
            F([_mm512_set1_ps(x as f32); K])
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
                o.0[k] = _mm512_sqrt_ps(a.0[k]);
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn abs(a: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = _mm512_andnot_ps(_mm512_set1_ps(-0.0), a.0[k]);
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn neg(a: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = _mm512_xor_ps(a.0[k], _mm512_set1_ps(-0.0));
            }
            o
        }
        /// NaN lanes of `a`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn isnan(a: F) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(a.0[k], a.0[k]);
            }
            o
        }
        /// Per lane `if m { a } else { b }`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn sel(m: M, a: F, b: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = _mm512_mask_blend_ps(m.0[k], b.0[k], a.0[k]);
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
                    _mm512_cmplt_epi32_mask(_mm512_castps_si512(a.0[k]), _mm512_setzero_si512());
            }
            o
        }

        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn isplat(x: usize) -> I {
            I([_mm512_set1_epi32(x as i32); K])
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
                o.0[k] = _mm512_mask_blend_epi32(m.0[k], b.0[k], a.0[k]);
            }
            o
        }
        /// `a == b`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn ieq(a: I, b: I) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = _mm512_cmpeq_epi32_mask(a.0[k], b.0[k]);
            }
            o
        }
        /// `a > b` (signed).
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn igt(a: I, b: I) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = _mm512_cmpgt_epi32_mask(a.0[k], b.0[k]);
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn ilanes(a: I) -> [usize; BLOCK] {
            let mut o = [0i32; BLOCK];
            for k in 0..K {
                // SAFETY: `o` holds 16K i32; unaligned store of sixteen.
                unsafe { _mm512_storeu_si512(o[16 * k..].as_mut_ptr().cast(), a.0[k]) };
            }
            o.map(|x| x as usize)
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn flanes(a: F) -> [f32; BLOCK] {
            let mut o = [0.0; BLOCK];
            for k in 0..K {
                // SAFETY: `o` holds 16K f32; unaligned store of sixteen.
                unsafe { _mm512_storeu_ps(o[16 * k..].as_mut_ptr(), a.0[k]) };
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn fload(a: &[f32; BLOCK]) -> F {
            let mut o = zero();
            for k in 0..K {
                // SAFETY: `a` holds 16K f32; unaligned load of sixteen.
                o.0[k] = unsafe { _mm512_loadu_ps(a[16 * k..].as_ptr()) };
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn ifrom(a: [usize; BLOCK]) -> I {
            let mut o = izero();
            let a = a.map(|x| x as i32);
            for k in 0..K {
                // SAFETY: `a` holds 16K i32; unaligned load of sixteen.
                o.0[k] = unsafe { _mm512_loadu_si512(a[16 * k..].as_ptr().cast()) };
            }
            o
        }

        /// `(x as usize).min(kmax)` per lane (NaN and negatives give 0), for `kmax` < 2²⁴.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn to_index(x: F, kmax: usize) -> I {
            let mut o = izero();
            for k in 0..K {
                // maxps returns its second operand for a NaN lane: 0, as `as usize` does.
                let v = _mm512_min_ps(
                    _mm512_max_ps(x.0[k], _mm512_setzero_ps()),
                    _mm512_set1_ps(kmax as f32),
                );
                o.0[k] = _mm512_cvttps_epi32(v);
            }
            o
        }

        /// `t[idx]` per lane, the index clamped into `t` first (`t` must not be empty, below
        /// 2³¹ entries).
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn gather(t: &[f32], idx: I) -> F {
            assert!(!t.is_empty());
            let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
            let mut o = zero();
            for k in 0..K {
                // SAFETY: every index lies in 0..t.len().
                o.0[k] = unsafe { _mm512_i32gather_ps::<4>(idx.0[k], t.as_ptr()) };
            }
            o
        }

        /// `t[idx]` per lane for a u32 table (entries below 2³¹), the index clamped into `t`
        /// first.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn gather_u32(t: &[u32], idx: I) -> I {
            assert!(!t.is_empty());
            let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
            let mut o = idx;
            for k in 0..K {
                // SAFETY: every index lies in 0..t.len(); u32 and i32 have the same layout.
                o.0[k] = unsafe { _mm512_i32gather_epi32::<4>(idx.0[k], t.as_ptr().cast()) };
            }
            o
        }

        crate::mapping::simd::kernels::vector_kernels!("avx512f,avx512dq");
    };
}

/// The f32 kernels with K = 4 vectors per block (64 points): measured faster than K = 1 and
/// K = 2 on all three kernels (`gonio bench --soa`, one thread, 19 × 36 and 181 × 361,
/// alternating processes of one build that chose K at run time: forward 0.52–0.65 of the f64
/// forward's time against 0.64–0.75 for K = 2 and 0.76–0.85 for K = 1; pdf 11.8–20.3 ns against
/// 27–42 and 38–44; docs/PERFORMANCE.md).
pub(crate) mod k4 {
    use super::*;
    avx512_f32_kernels!(4);
}
