//! SIMD support of the batch paths ([`crate::mapping::batch`]): the instruction-set choice made at
//! run time, the lane element types (f64, f32) and the branch-free transcendental functions
//! ([`math`]).
//!
//! **How the lanes are written.** The generic batch kernels work on blocks of [`LANES`] points held
//! in plain arrays, structure-of-arrays. Each stage is a loop over the block: the arithmetic stages
//! (the concentric map, the wedge equation, the Halley iteration of the radial cubic, the lift, the
//! inverse's closed form, sin/cos/atan2) are branch-free and vectorise; the table searches (guide
//! tables, branch-free descents) run lane by lane over scalar loads. The same source is compiled
//! twice: once inside a function with `#[target_feature(enable = "avx2,fma")]`, chosen at run time
//! when the CPU has both ([`Backend::detect`]), and once for the baseline x86-64 (SSE2) or any other
//! target ([`Backend::Portable`]). On the AVX2 and AVX-512 backends the **f64** paths (forward,
//! pdf, inverse) go instead through explicit `core::arch` kernels (`mapping/core/kernels.rs`,
//! instantiated over `avx2.rs` and `avx512.rs`) that run every stage, the searches included, on
//! whole vectors with gathers: 37–59 % fewer instructions per point than the compiled lane loops on
//! AVX2, and on AVX-512 eight lanes per vector (`docs/PERFORMANCE.md`). **f32** calls are widened
//! to f64, run through the same kernels and rounded once (`mapping::batch`).
//!
//! **Why this and not `wide`/`pulp`/`multiversion`.** The generic kernels need no vector type: plain
//! loops over fixed-size arrays plus one `target_feature` function per entry point keep one source
//! for f64 and f32 and let the compiler choose the width (`multiversion` is that pattern as a
//! macro). What the compiler does not produce from them are gathers and vector descents; for those
//! the explicit kernels use `core::arch` directly, since `wide` has no gathers and `pulp` would add
//! a dependency for one instruction set that `core::arch` covers on stable Rust.
//!
//! **Bit-identical at every width.** No fused multiply–add is used (Rust never contracts on its
//! own), and every lane is computed independently of its neighbours (the Halley iteration is masked
//! per lane with the scalar path's stopping rule), so the AVX2 and the portable paths give the same
//! bits, and so do any block size and any thread count; the explicit AVX2 f64 kernels perform the
//! same operations in the same order and give the same bits too (tested, including on NaN,
//! infinite and out-of-domain inputs). The f64 lanes perform the scalar path's
//! operations in its order: they equal [`crate::HemisphereMap`]'s scalar results bit for bit except
//! through sin/cos and atan2 (see [`math`] for their bounds; `docs/PERFORMANCE.md` for the measured
//! end-to-end differences).

pub mod math;

/// Points per block of the generic lane kernels (two AVX2 vectors of f64, one of f32).
pub const LANES: usize = 8;

/// The instruction set a batch call runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    /// AVX-512 F and DQ with AVX2 and FMA (x86-64 only, detected at run time): the explicit f64
    /// kernels on eight lanes per vector.
    Avx512,
    /// AVX2 with FMA available (x86-64 only, detected at run time).
    Avx2Fma,
    /// The baseline instruction set of the target (SSE2 on x86-64).
    Portable,
}

impl Backend {
    /// The fastest backend this CPU supports.
    pub fn detect() -> Backend {
        #[cfg(target_arch = "x86_64")]
        {
            let avx2 =
                std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
            if avx2
                && std::is_x86_feature_detected!("avx512f")
                && std::is_x86_feature_detected!("avx512dq")
            {
                return Backend::Avx512;
            }
            if avx2 {
                return Backend::Avx2Fma;
            }
        }
        Backend::Portable
    }

    /// Every backend this CPU can run, fastest first (the portable one always, last).
    pub fn available() -> Vec<Backend> {
        [Backend::Avx512, Backend::Avx2Fma, Backend::Portable]
            .into_iter()
            .filter(|&b| b.usable() == b)
            .collect()
    }

    /// Short name, as `gonio bench` prints it.
    pub fn as_str(self) -> &'static str {
        match self {
            Backend::Avx512 => "avx512",
            Backend::Avx2Fma => "avx2+fma",
            Backend::Portable => "portable",
        }
    }

    /// This backend if the CPU supports it, else the fastest one below it that it supports.
    pub(crate) fn usable(self) -> Backend {
        let best = Backend::detect();
        match (self, best) {
            (Backend::Avx512, b) => b,
            (Backend::Avx2Fma, Backend::Avx512 | Backend::Avx2Fma) => Backend::Avx2Fma,
            _ => Backend::Portable,
        }
    }
}

/// An element type of the batch paths: `f64` or `f32` (sealed).
pub trait BatchFloat: sealed::Lane {}
impl BatchFloat for f64 {}
impl BatchFloat for f32 {}

pub(crate) use sealed::Lane;

mod sealed {
    use std::fmt::Debug;
    use std::ops::{Add, Div, Mul, Neg, Sub};

    /// Arithmetic of one lane. Every method is `#[inline(always)]` so that it compiles inside the
    /// caller's `target_feature` context.
    pub trait Lane:
        Copy
        + Debug
        + Default
        + PartialOrd
        + Send
        + Sync
        + 'static
        + Add<Output = Self>
        + Sub<Output = Self>
        + Mul<Output = Self>
        + Div<Output = Self>
        + Neg<Output = Self>
    {
        const ZERO: Self;
        const ONE: Self;
        const HALF: Self;
        const TWO: Self;
        const NAN: Self;
        /// The radial solve's stopping thresholds (see `radial::solve_radius`), scaled to the
        /// type's precision: step, cubic error prediction, "small step" for the prediction.
        const STOP_STEP: Self;
        const STOP_CUBIC: Self;
        const HALLEY_SMALL: Self;
        fn from_f64(x: f64) -> Self;
        fn to_f64(self) -> f64;
        fn sqrt(self) -> Self;
        fn abs(self) -> Self;
        fn is_sign_negative(self) -> bool;
        fn is_finite(self) -> bool;
        /// `f64::min` semantics (the non-NaN operand).
        fn min(self, o: Self) -> Self;
        /// `f64::max` semantics.
        fn max(self, o: Self) -> Self;
        /// `f64::clamp` semantics (NaN passes through).
        #[inline(always)]
        fn clamp(self, lo: Self, hi: Self) -> Self {
            let x = if self < lo { lo } else { self };
            if x > hi {
                hi
            } else {
                x
            }
        }
        fn sin_cos(self) -> (Self, Self);
        fn atan2(self, x: Self) -> Self;
        /// `self as usize` (saturating, NaN → 0).
        fn to_usize(self) -> usize;
        /// The largest value of the type below `self`, for finite `self` > 0.
        fn next_below(self) -> Self;
    }

    impl Lane for f64 {
        const ZERO: f64 = 0.0;
        const ONE: f64 = 1.0;
        const HALF: f64 = 0.5;
        const TWO: f64 = 2.0;
        const NAN: f64 = f64::NAN;
        const STOP_STEP: f64 = 1e-15;
        const STOP_CUBIC: f64 = 1e-17;
        const HALLEY_SMALL: f64 = 1e-5;
        #[inline(always)]
        fn from_f64(x: f64) -> f64 {
            x
        }
        #[inline(always)]
        fn to_f64(self) -> f64 {
            self
        }
        #[inline(always)]
        fn sqrt(self) -> f64 {
            f64::sqrt(self)
        }
        #[inline(always)]
        fn abs(self) -> f64 {
            f64::abs(self)
        }
        #[inline(always)]
        fn is_sign_negative(self) -> bool {
            f64::is_sign_negative(self)
        }
        #[inline(always)]
        fn is_finite(self) -> bool {
            f64::is_finite(self)
        }
        #[inline(always)]
        fn min(self, o: f64) -> f64 {
            f64::min(self, o)
        }
        #[inline(always)]
        fn max(self, o: f64) -> f64 {
            f64::max(self, o)
        }
        #[inline(always)]
        fn sin_cos(self) -> (f64, f64) {
            super::math::sin_cos(self)
        }
        #[inline(always)]
        fn atan2(self, x: f64) -> f64 {
            super::math::atan2(self, x)
        }
        #[inline(always)]
        fn to_usize(self) -> usize {
            self as usize
        }
        #[inline(always)]
        fn next_below(self) -> Self {
            Self::from_bits(self.to_bits() - 1)
        }
    }

    impl Lane for f32 {
        const ZERO: f32 = 0.0;
        const ONE: f32 = 1.0;
        const HALF: f32 = 0.5;
        const TWO: f32 = 2.0;
        const NAN: f32 = f32::NAN;
        // f64's thresholds scaled by ε₃₂/ε₆₄ = 2²⁹ (the cubic one by the same factor: it compares
        // a predicted error with the last bits).
        const STOP_STEP: f32 = 5.4e-7;
        const STOP_CUBIC: f32 = 5.4e-9;
        const HALLEY_SMALL: f32 = 1e-2;
        #[inline(always)]
        fn from_f64(x: f64) -> f32 {
            x as f32
        }
        #[inline(always)]
        fn to_f64(self) -> f64 {
            self as f64
        }
        #[inline(always)]
        fn sqrt(self) -> f32 {
            f32::sqrt(self)
        }
        #[inline(always)]
        fn abs(self) -> f32 {
            f32::abs(self)
        }
        #[inline(always)]
        fn is_sign_negative(self) -> bool {
            f32::is_sign_negative(self)
        }
        #[inline(always)]
        fn is_finite(self) -> bool {
            f32::is_finite(self)
        }
        #[inline(always)]
        fn min(self, o: f32) -> f32 {
            f32::min(self, o)
        }
        #[inline(always)]
        fn max(self, o: f32) -> f32 {
            f32::max(self, o)
        }
        #[inline(always)]
        fn sin_cos(self) -> (f32, f32) {
            super::math::sin_cos_f32(self)
        }
        #[inline(always)]
        fn atan2(self, x: f32) -> f32 {
            super::math::atan2_f32(self, x)
        }
        #[inline(always)]
        fn to_usize(self) -> usize {
            self as usize
        }
        #[inline(always)]
        fn next_below(self) -> Self {
            Self::from_bits(self.to_bits() - 1)
        }
    }
}
