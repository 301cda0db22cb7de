//! The AVX2 + FMA backend: the vocabulary of [`super::kernels`], written once over both element
//! types (one macro over the intrinsics' names, issue 36): f64 at the module's top level over K = 4
//! independent `__m256d` chains of four lanes per block of [`BLOCK`] points, and f32 in
//! [`f32_k2`] over K = 2 chains of eight `__m256` lanes, with the table searches as vector descents
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

/// The AVX2 vocabulary for one element type and the kernels instantiated over it, in the calling
/// module: the same words in f64 (four lanes per `__m256d`, 64-bit indices) and f32 (eight lanes
/// per `__m256`, 32-bit indices), written once over the intrinsics' names (issue 36).
macro_rules! avx2_kernels {
    (
        k: $k:literal,
        lanes: $lanes:literal,
        elem: $e:ident,
        index: $ie:ident,
        vector: $fv:ident,
        float: [$add:ident, $sub:ident, $mul:ident, $div:ident, $cmp:ident, $and:ident, $or:ident,
            $set1:ident, $sqrt:ident, $andnot:ident, $xor:ident, $blendv:ident, $movemask:ident,
            $storeu:ident, $loadu:ident, $castsi:ident, $castfi:ident],
        int: [$iadd:ident, $isub:ident, $imin:expr, $imax:expr, $imul:ident, $iset1:ident,
            $icmpeq:ident, $icmpgt:ident],
        clamp: [$fmin:ident, $fmax:ident, $fzero:ident],
        to_int: |$v:ident| $to_int:expr,
        gather: |$gp:ident, $gi:ident| $gather:expr,
        gather_u32: |$up:ident, $ui:ident| $gather_u32:expr
    ) => {
    /// Vectors per block: independent chains that the core overlaps (the kernel's stages are long
    /// dependency chains of gathers, divisions and square roots).
    const K: usize = $k;
    /// Points per block.
    pub(crate) const BLOCK: usize = $lanes * K;

    /// The element type of the tables and lanes.
    type E = $e;
    /// K vectors of `$lanes` `$e` lanes (a value, or a mask of all-ones / all-zeros lanes).
    #[derive(Clone, Copy)]
    struct F([$fv; K]);
    /// Masks are vectors of all-ones / all-zeros lanes on AVX2.
    type M = F;
    /// K vectors of `$lanes` `$ie` lanes (table indices).
    #[derive(Clone, Copy)]
    struct I([__m256i; K]);

    f_binary! {
        add => $add;
        sub => $sub;
        mul => $mul;
        div => $div;
        lt => $cmp::<_CMP_LT_OQ>;
        le => $cmp::<_CMP_LE_OQ>;
        gt => $cmp::<_CMP_GT_OQ>;
        ge => $cmp::<_CMP_GE_OQ>;
        eq => $cmp::<_CMP_EQ_OQ>;
        and => $and;
        or => $or;
    }

    i_binary! {
        iadd => $iadd;
        isub => $isub;
        imin => $imin;
        imax => $imax;
        // a · b: for $ie lanes below 2³² (the low halves' 64-bit product), for i32 lanes the low
        // 32 bits (wrapping, as the portable `wrapping_mul`).
        imul => $imul;
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    // An f64 constant rounded to the element type, on every lane (no rounding for f64).
    #[allow(clippy::unnecessary_cast)]
    fn splat(x: f64) -> F {
        F([$set1(x as $e); K])
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
            o.0[k] = $sqrt(a.0[k]);
        }
        o
    }
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn abs(a: F) -> F {
        let mut o = a;
        for k in 0..K {
            o.0[k] = $andnot($set1(-0.0), a.0[k]);
        }
        o
    }
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn neg(a: F) -> F {
        let mut o = a;
        for k in 0..K {
            o.0[k] = $xor(a.0[k], $set1(-0.0));
        }
        o
    }
    /// NaN lanes of `a`.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn isnan(a: F) -> F {
        let mut o = a;
        for k in 0..K {
            o.0[k] = $cmp::<_CMP_UNORD_Q>(a.0[k], a.0[k]);
        }
        o
    }
    /// `!m`.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn not(m: F) -> F {
        let mut o = m;
        for k in 0..K {
            o.0[k] = $xor(m.0[k], $castsi($iset1(-1)));
        }
        o
    }
    /// Per lane `if m { a } else { b }`.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn sel(m: F, a: F, b: F) -> F {
        let mut o = a;
        for k in 0..K {
            o.0[k] = $blendv(b.0[k], a.0[k], m.0[k]);
        }
        o
    }
    /// Whether any lane of the mask is set.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn any(m: F) -> bool {
        let mut acc = m.0[0];
        for k in 1..K {
            acc = $or(acc, m.0[k]);
        }
        $movemask(acc) != 0
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn isplat(x: usize) -> I {
        I([$iset1(x as $ie); K])
    }
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn izero() -> I {
        isplat(0)
    }
    /// Per lane `if m { a } else { b }`, `m` a lane mask.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn isel(m: F, a: I, b: I) -> I {
        let mut o = a;
        for k in 0..K {
            o.0[k] = $castfi($blendv(
                $castsi(b.0[k]),
                $castsi(a.0[k]),
                m.0[k],
            ));
        }
        o
    }
    /// `a == b` as a lane mask.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn ieq(a: I, b: I) -> F {
        let mut o = zero();
        for k in 0..K {
            o.0[k] = $castsi($icmpeq(a.0[k], b.0[k]));
        }
        o
    }
    /// `a > b` (signed) as a lane mask.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn igt(a: I, b: I) -> F {
        let mut o = zero();
        for k in 0..K {
            o.0[k] = $castsi($icmpgt(a.0[k], b.0[k]));
        }
        o
    }
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn ilanes(a: I) -> [usize; BLOCK] {
        let mut o: [$ie; BLOCK] = [0; BLOCK];
        for k in 0..K {
            // SAFETY: `o` holds the block's lanes; unaligned store of one vector.
            unsafe { _mm256_storeu_si256(o[$lanes * k..].as_mut_ptr().cast(), a.0[k]) };
        }
        // An explicit loop: `array::map`'s closure was left out of line (a call per block).
        let mut r = [0usize; BLOCK];
        for l in 0..BLOCK {
            r[l] = o[l] as usize;
        }
        r
    }
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn flanes(a: F) -> [$e; BLOCK] {
        let mut o = [0.0; BLOCK];
        for k in 0..K {
            // SAFETY: `o` holds the block's lanes; unaligned store of one vector.
            unsafe { $storeu(o[$lanes * k..].as_mut_ptr(), a.0[k]) };
        }
        o
    }
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn fload(a: &[$e; BLOCK]) -> F {
        let mut o = zero();
        for k in 0..K {
            // SAFETY: `a` holds the block's lanes; unaligned load of one vector.
            o.0[k] = unsafe { $loadu(a[$lanes * k..].as_ptr()) };
        }
        o
    }




    /// Lanes whose sign bit is set (`is_sign_negative`).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn sign_negative(a: F) -> F {
        let mut o = a;
        for k in 0..K {
            o.0[k] = $castsi($icmpgt(
                _mm256_setzero_si256(),
                $castfi(a.0[k]),
            ));
        }
        o
    }

        #[inline]
        #[target_feature(enable = "avx2,fma")]
        fn ifrom(a: [usize; BLOCK]) -> I {
            let mut o = izero();
            let mut b: [$ie; BLOCK] = [0; BLOCK];
            for l in 0..BLOCK {
                b[l] = a[l] as $ie;
            }
            for k in 0..K {
                // SAFETY: `b` holds the block's lanes; unaligned load of one vector.
                o.0[k] = unsafe { _mm256_loadu_si256(b[$lanes * k..].as_ptr().cast()) };
            }
            o
        }

        /// `(x as usize).min(kmax)` per lane (NaN and negatives give 0), for `kmax` < 2³¹ (f64) or
        /// 2²⁴ (f32, exact there).
        #[inline]
        #[target_feature(enable = "avx2,fma")]
        fn to_index(x: F, kmax: usize) -> I {
            // max returns its second operand for a NaN lane: 0, as `as usize` does.
            let mut o = izero();
            for k in 0..K {
                let $v = $fmin($fmax(x.0[k], $fzero()), $set1(kmax as $e));
                o.0[k] = $to_int;
            }
            o
        }

        /// `t[idx]` per lane, the index clamped into `t` first (`t` must not be empty, below 2³¹
        /// entries).
        #[inline]
        #[target_feature(enable = "avx2,fma")]
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

        /// `t[idx] as usize` per lane for a u32 table (entries below 2³¹), the index clamped into `t`
        /// first.
        #[inline]
        #[target_feature(enable = "avx2,fma")]
        fn gather_u32(t: &[u32], idx: I) -> I {
            assert!(!t.is_empty());
            let idx = imax(imin(idx, isplat(t.len() - 1)), izero());
            let mut o = idx;
            for k in 0..K {
                let ($up, $ui) = (t.as_ptr().cast::<i32>(), idx.0[k]);
                // SAFETY: every index lies in 0..t.len(); u32 and i32 have the same layout.
                o.0[k] = unsafe { $gather_u32 };
            }
            o
        }


    crate::mapping::simd::kernels::vector_kernels!("avx2,fma");
    };
}

/// The f64 vocabulary: four f64 lanes per `__m256d`, K = 4, 64-bit indices (AVX2 has no 64-bit
/// min/max: a compare and a blend).
macro_rules! avx2_f64 {
    () => {
        avx2_kernels! {
            k: 4,
            lanes: 4,
            elem: f64,
            index: i64,
            vector: __m256d,
            float: [_mm256_add_pd, _mm256_sub_pd, _mm256_mul_pd, _mm256_div_pd, _mm256_cmp_pd,
                _mm256_and_pd, _mm256_or_pd, _mm256_set1_pd, _mm256_sqrt_pd, _mm256_andnot_pd,
                _mm256_xor_pd, _mm256_blendv_pd, _mm256_movemask_pd, _mm256_storeu_pd,
                _mm256_loadu_pd, _mm256_castsi256_pd, _mm256_castpd_si256],
            int: [_mm256_add_epi64, _mm256_sub_epi64,
                |a, b| _mm256_blendv_epi8(a, b, _mm256_cmpgt_epi64(a, b)),
                |a, b| _mm256_blendv_epi8(b, a, _mm256_cmpgt_epi64(a, b)),
                _mm256_mul_epu32, _mm256_set1_epi64x, _mm256_cmpeq_epi64, _mm256_cmpgt_epi64],
            clamp: [_mm256_min_pd, _mm256_max_pd, _mm256_setzero_pd],
            to_int: |v| _mm256_cvtepi32_epi64(_mm256_cvttpd_epi32(v)),
            gather: |p, i| _mm256_i64gather_pd::<8>(p, i),
            gather_u32: |p, i| _mm256_cvtepu32_epi64(_mm256_i64gather_epi32::<4>(p, i))
        }
    };
}

/// The f32 vocabulary: eight f32 lanes per `__m256`, K = 2, 32-bit indices and
/// `vpgatherdd`/`vgatherdps` gathers; the same words, with the same semantics, as
/// [`super::portable`] (no fused multiply–add), so the f32 results are the same bits on every
/// backend.
macro_rules! avx2_f32 {
    () => {
        avx2_kernels! {
            k: 2,
            lanes: 8,
            elem: f32,
            index: i32,
            vector: __m256,
            float: [_mm256_add_ps, _mm256_sub_ps, _mm256_mul_ps, _mm256_div_ps, _mm256_cmp_ps,
                _mm256_and_ps, _mm256_or_ps, _mm256_set1_ps, _mm256_sqrt_ps, _mm256_andnot_ps,
                _mm256_xor_ps, _mm256_blendv_ps, _mm256_movemask_ps, _mm256_storeu_ps,
                _mm256_loadu_ps, _mm256_castsi256_ps, _mm256_castps_si256],
            int: [_mm256_add_epi32, _mm256_sub_epi32, _mm256_min_epi32, _mm256_max_epi32,
                _mm256_mullo_epi32, _mm256_set1_epi32, _mm256_cmpeq_epi32, _mm256_cmpgt_epi32],
            clamp: [_mm256_min_ps, _mm256_max_ps, _mm256_setzero_ps],
            to_int: |v| _mm256_cvttps_epi32(v),
            gather: |p, i| _mm256_i32gather_ps::<4>(p, i),
            gather_u32: |p, i| _mm256_i32gather_epi32::<4>(p, i)
        }
    };
}

avx2_f64!();

/// The f32 kernels (K = 2 vectors of eight lanes per block).
pub(crate) mod f32_k2 {
    use super::*;
    avx2_f32!();
}
