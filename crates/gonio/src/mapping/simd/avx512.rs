//! The AVX-512 backend: the vocabulary of [`super::kernels`] on AVX-512 (F and DQ), written once
//! over both element types (issue 36): one macro over the intrinsics' names, instantiated for f64
//! (eight lanes per `__m512d`, `__mmask8` masks, 8-lane gathers; K = 2 independent vectors per
//! block for the forward map in [`k2`], K = 4 for the pdf and the inverse in [`k4`]) and for f32
//! (sixteen lanes per `__m512`, `__mmask16` masks, 32-bit indices; K = 4 in [`f32_k4`]). The same
//! operations in the same order as the AVX2 vocabulary ([`super::avx2`], whose documentation gives
//! the design and the exactness argument), so the results are the same bits on every backend
//! (tested in `tests/batch.rs` and `tests/float32_map.rs`).

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
    ($cmp:ident; $($name:ident => $pred:ident;)*) => {$(
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn $name(a: F, b: F) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = $cmp::<$pred>(a.0[k], b.0[k]);
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

macro_rules! avx512_kernels {
    (
        k: $k:literal,
        lanes: $lanes:literal,
        elem: $e:ident,
        index: $ie:ident,
        vector: $fv:ident,
        mask: $mt:ident,
        float: [$add:ident, $sub:ident, $mul:ident, $div:ident, $andnot:ident, $cmp:ident,
            $set1:ident, $sqrt:ident, $xor:ident, $blend:ident, $storeu:ident, $loadu:ident,
            $cast:ident],
        int: [$iadd:ident, $isub:ident, $imin:ident, $imax:ident, $imul:ident, $iset1:ident,
            $iblend:ident, $icmpeq:ident, $icmpgt:ident, $icmplt:ident],
        clamp: [$fmin:ident, $fmax:ident, $fzero:ident],
        to_int: |$v:ident| $to_int:expr,
        gather: |$gp:ident, $gi:ident| $gather:expr,
        gather_u32: |$up:ident, $ui:ident| $gather_u32:expr
    ) => {
        /// Vectors per block (independent chains the core overlaps).
        const K: usize = $k;
        /// Points per block.
        pub(crate) const BLOCK: usize = $lanes * K;

        /// The element type of the tables and lanes.
        type E = $e;
        /// K vectors of `$lanes` `$e` lanes.
        #[derive(Clone, Copy)]
        struct F([$fv; K]);
        /// K vectors of `$lanes` `$ie` lanes (table indices).
        #[derive(Clone, Copy)]
        struct I([__m512i; K]);
        /// K lane masks.
        #[derive(Clone, Copy)]
        struct M([$mt; K]);

        f_binary! {
            add => $add;
            sub => $sub;
            mul => $mul;
            div => $div;
        }

        f_compare! {
            $cmp;
            lt => _CMP_LT_OQ;
            le => _CMP_LE_OQ;
            gt => _CMP_GT_OQ;
            ge => _CMP_GE_OQ;
            eq => _CMP_EQ_OQ;
        }

        i_binary! {
            iadd => $iadd;
            isub => $isub;
            imin => $imin;
            imax => $imax;
            // a · b: for i64 lanes below 2³² (the low halves' 64-bit product), for i32 lanes
            // the low 32 bits (wrapping).
            imul => $imul;
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
        // An f64 constant rounded to the element type, on every lane (no rounding for f64).
        #[allow(clippy::unnecessary_cast)]
        fn splat(x: f64) -> F {
            F([$set1(x as $e); K])
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
                o.0[k] = $sqrt(a.0[k]);
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn abs(a: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = $andnot($set1(-0.0), a.0[k]);
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn neg(a: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = $xor(a.0[k], $set1(-0.0));
            }
            o
        }
        /// NaN lanes of `a`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn isnan(a: F) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = $cmp::<_CMP_UNORD_Q>(a.0[k], a.0[k]);
            }
            o
        }
        /// Per lane `if m { a } else { b }`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn sel(m: M, a: F, b: F) -> F {
            let mut o = a;
            for k in 0..K {
                o.0[k] = $blend(m.0[k], b.0[k], a.0[k]);
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
                    $icmplt($cast(a.0[k]), _mm512_setzero_si512());
            }
            o
        }

        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn isplat(x: usize) -> I {
            I([$iset1(x as $ie); K])
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
                o.0[k] = $iblend(m.0[k], b.0[k], a.0[k]);
            }
            o
        }
        /// `a == b`.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn ieq(a: I, b: I) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = $icmpeq(a.0[k], b.0[k]);
            }
            o
        }
        /// `a > b` (signed).
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn igt(a: I, b: I) -> M {
            let mut o = M([0; K]);
            for k in 0..K {
                o.0[k] = $icmpgt(a.0[k], b.0[k]);
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn ilanes(a: I) -> [usize; BLOCK] {
            let mut o: [$ie; BLOCK] = [0; BLOCK];
            for k in 0..K {
                // SAFETY: `o` holds the block's lanes; unaligned store of one vector.
                unsafe { _mm512_storeu_si512(o[$lanes * k..].as_mut_ptr().cast(), a.0[k]) };
            }
            // An explicit loop: `array::map`'s closure was left out of line (a call per block).
            let mut r = [0usize; BLOCK];
            for l in 0..BLOCK {
                r[l] = o[l] as usize;
            }
            r
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn flanes(a: F) -> [$e; BLOCK] {
            let mut o = [0.0; BLOCK];
            for k in 0..K {
                // SAFETY: `o` holds the block's lanes; unaligned store of one vector.
                unsafe { $storeu(o[$lanes * k..].as_mut_ptr(), a.0[k]) };
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn fload(a: &[$e; BLOCK]) -> F {
            let mut o = zero();
            for k in 0..K {
                // SAFETY: `a` holds the block's lanes; unaligned load of one vector.
                o.0[k] = unsafe { $loadu(a[$lanes * k..].as_ptr()) };
            }
            o
        }
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn ifrom(a: [usize; BLOCK]) -> I {
            let mut o = izero();
            let mut b = [0 as $ie; BLOCK];
            for l in 0..BLOCK {
                b[l] = a[l] as $ie;
            }
            let a = b;
            for k in 0..K {
                // SAFETY: `a` holds the block's lanes; unaligned load of one vector.
                o.0[k] = unsafe { _mm512_loadu_si512(a[$lanes * k..].as_ptr().cast()) };
            }
            o
        }

        /// `(x as usize).min(kmax)` per lane (NaN and negatives give 0), for `kmax` < 2³¹ (f64)
        /// or 2²⁴ (f32, exact there).
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn to_index(x: F, kmax: usize) -> I {
            let mut o = izero();
            for k in 0..K {
                // max returns its second operand for a NaN lane: 0, as `as usize` does.
                let $v = $fmin($fmax(x.0[k], $fzero()), $set1(kmax as $e));
                o.0[k] = $to_int;
            }
            o
        }

        /// `t[idx]` per lane, the index clamped into `t` first (`t` must not be empty, below 2³¹
        /// entries).
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn gather(t: &[$e], idx: I) -> F {
            assert!(!t.is_empty());
            let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
            let mut o = zero();
            for k in 0..K {
                let ($gp, $gi) = (t.as_ptr(), idx.0[k]);
                // SAFETY: every index lies in 0..t.len().
                o.0[k] = unsafe { $gather };
            }
            o
        }

        /// `t[idx] as usize` per lane for a u32 table (entries below 2³¹), the index clamped
        /// into `t` first.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        fn gather_u32(t: &[u32], idx: I) -> I {
            assert!(!t.is_empty());
            let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
            let mut o = idx;
            for k in 0..K {
                let ($up, $ui) = (t.as_ptr().cast(), idx.0[k]);
                // SAFETY: every index lies in 0..t.len(); u32 and i32 have the same layout.
                o.0[k] = unsafe { $gather_u32 };
            }
            o
        }

        crate::mapping::simd::kernels::vector_kernels!("avx512f,avx512dq");
    };
}

/// The f64 vocabulary: eight f64 lanes per `__m512d`, 64-bit indices, `__mmask8` masks, 8-lane
/// gathers with 64-bit indices.
macro_rules! avx512_f64 {
    ($k:literal) => {
        avx512_kernels! {
            k: $k,
            lanes: 8,
            elem: f64,
            index: i64,
            vector: __m512d,
            mask: __mmask8,
            float: [_mm512_add_pd, _mm512_sub_pd, _mm512_mul_pd, _mm512_div_pd, _mm512_andnot_pd,
                _mm512_cmp_pd_mask, _mm512_set1_pd, _mm512_sqrt_pd, _mm512_xor_pd,
                _mm512_mask_blend_pd, _mm512_storeu_pd, _mm512_loadu_pd, _mm512_castpd_si512],
            int: [_mm512_add_epi64, _mm512_sub_epi64, _mm512_min_epi64, _mm512_max_epi64,
                _mm512_mul_epu32, _mm512_set1_epi64, _mm512_mask_blend_epi64,
                _mm512_cmpeq_epi64_mask, _mm512_cmpgt_epi64_mask, _mm512_cmplt_epi64_mask],
            clamp: [_mm512_min_pd, _mm512_max_pd, _mm512_setzero_pd],
            to_int: |v| _mm512_cvtepi32_epi64(_mm512_cvttpd_epi32(v)),
            gather: |p, i| _mm512_i64gather_pd::<8>(i, p),
            gather_u32: |p, i| _mm512_cvtepu32_epi64(_mm512_i64gather_epi32::<4>(i, p))
        }
    };
}

/// The f32 vocabulary: sixteen f32 lanes per `__m512`, 32-bit indices, `__mmask16` masks,
/// 16-lane gathers with 32-bit indices. The same words, with the same semantics, as
/// [`super::portable`] and the AVX2 f32 vocabulary, so the f32 results are the same bits on
/// every backend.
macro_rules! avx512_f32 {
    ($k:literal) => {
        avx512_kernels! {
            k: $k,
            lanes: 16,
            elem: f32,
            index: i32,
            vector: __m512,
            mask: __mmask16,
            float: [_mm512_add_ps, _mm512_sub_ps, _mm512_mul_ps, _mm512_div_ps, _mm512_andnot_ps,
                _mm512_cmp_ps_mask, _mm512_set1_ps, _mm512_sqrt_ps, _mm512_xor_ps,
                _mm512_mask_blend_ps, _mm512_storeu_ps, _mm512_loadu_ps, _mm512_castps_si512],
            int: [_mm512_add_epi32, _mm512_sub_epi32, _mm512_min_epi32, _mm512_max_epi32,
                _mm512_mullo_epi32, _mm512_set1_epi32, _mm512_mask_blend_epi32,
                _mm512_cmpeq_epi32_mask, _mm512_cmpgt_epi32_mask, _mm512_cmplt_epi32_mask],
            clamp: [_mm512_min_ps, _mm512_max_ps, _mm512_setzero_ps],
            to_int: |v| _mm512_cvttps_epi32(v),
            gather: |p, i| _mm512_i32gather_ps::<4>(i, p),
            gather_u32: |p, i| _mm512_i32gather_epi32::<4>(i, p)
        }
    };
}

/// The forward map with K = 2 vectors per block (16 points), measured best for it (K = 1, 2, 4:
/// 47, 33, 39 ns at 19 × 36). Its pdf and inverse kernels are not used.
#[allow(dead_code)]
pub(crate) mod k2 {
    use super::*;
    avx512_f64!(2);
}

/// The pdf and the inverse with K = 4 vectors per block (32 points): 8–16 % faster than K = 2
/// (docs/PERFORMANCE.md). Its forward kernel is not used.
#[allow(dead_code)]
pub(crate) mod k4 {
    use super::*;
    avx512_f64!(4);
}

/// The f32 kernels with K = 4 vectors per block (64 points): measured faster than K = 1 and
/// K = 2 on all three kernels (`gonio bench --soa`, one thread, 19 × 36 and 181 × 361,
/// alternating processes of one build that chose K at run time: forward 0.52–0.65 of the f64
/// forward's time against 0.64–0.75 for K = 2 and 0.76–0.85 for K = 1; pdf 11.8–20.3 ns against
/// 27–42 and 38–44; docs/PERFORMANCE.md).
pub(crate) mod f32_k4 {
    use super::*;
    avx512_f32!(4);
}
