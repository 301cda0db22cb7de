//! The vector layer of the HDS map: the backends, their vocabularies and the kernels written once
//! over them, plus the run-time choice between them.
//!
//! | file | what |
//! |---|---|
//! | [`math`] | branch-free sin/cos and atan2 (the kernels' transcendental functions, also scalar) |
//! | `kernels.rs` | the forward map, pdf and inverse, **one body each**, over a vocabulary of vector words (`add`, `gather`, `sel`, `descend`, …): the `vector_kernels!` macro, which stamps a backend's `#[target_feature]` on one body |
//! | `portable.rs` | the vocabulary over plain arrays (the target's baseline instruction set), **one macro over both element types**: f64 over eight lanes (the fallback on every CPU and for tables too large for 32-bit index conversions) and f32 (module `f32_lanes`) over sixteen lanes, 32-bit indices (the float32 map's fallback) |
//! | `avx2.rs` | the vocabulary over AVX2 + FMA (detected at run time), **one macro over both element types**: f64 over four `__m256d` per value, f32 (module `f32_k2`) over two `__m256` per value, 32-bit indices and gathers |
//! | `avx512.rs` | the vocabulary over AVX-512 F + DQ (detected at run time), **one macro over both element types**: f64 over `__m512d`, instantiated twice (two vectors per block for the forward map, four for pdf and inverse), and f32 over four `__m512` per value, 32-bit indices and gathers |
//! | `dispatch.rs` | backend choice per call, the f32 calls' widening to the f64 kernels (the f64 maps' f32 batches), and the kernels over a table view in f32 or f64 ([`crate::mapping::Float32Map`] and its exact reference) |
//!
//! **Why this and not `wide`/`pulp`/`multiversion`.** The kernels need gathers and vector
//! descents, which `wide` lacks; `pulp` would add a dependency for one instruction set that
//! `core::arch` covers on stable Rust. What stable Rust forbids (`#[target_feature]` together with
//! `#[inline(always)]`) is solved by one macro around one body.
//!
//! **Bit-identical at every width.** No fused multiply–add is used (Rust never contracts on its
//! own), every lane is computed independently of its neighbours (the Halley iteration is masked
//! per lane with the scalar path's stopping rule), and every backend's words have the same IEEE
//! semantics, so every backend, block size and thread count gives the same bits (tested, including
//! on NaN, infinite and out-of-domain inputs). The f64 kernels perform the scalar path's operations
//! in its order: they equal [`crate::HemisphereMap`]'s scalar results bit for bit except through
//! sin/cos and atan2 (see [`math`] for their bounds; `docs/PERFORMANCE.md` for the measured
//! end-to-end differences). **f32** calls on the f64 maps are widened to f64, run through the
//! same kernels and rounded once (`dispatch.rs`). The **float32 map**
//! ([`crate::mapping::Float32Map`]) runs the same kernel bodies over the f32 vocabularies, with
//! the f32 values of the precision-dependent constants (`math::Precision`): its results, too,
//! are the same bits on every backend, block size and thread count.

pub mod math;

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
#[cfg(target_arch = "x86_64")]
pub(crate) mod dispatch;
mod kernels;
mod portable;

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
pub trait BatchFloat: sealed::Elem {}
impl BatchFloat for f64 {}
impl BatchFloat for f32 {}

pub(crate) use sealed::Elem;

mod sealed {
    use std::fmt::Debug;
    use std::ops::{Add, Div, Mul, Neg, Sub};

    /// What the batch paths do with an element outside the kernels (which run in f64): convert,
    /// scale, compare, split the sphere (`mapping::sphere::SplitRule`).
    pub trait Elem:
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
        const NAN: Self;
        fn from_f64(x: f64) -> Self;
        fn to_f64(self) -> f64;
        fn is_finite(self) -> bool;
        /// `f64::min` semantics (the non-NaN operand).
        fn min(self, o: Self) -> Self;
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
        /// The largest value of the type below `self`, for finite `self` > 0.
        fn next_below(self) -> Self;
    }

    macro_rules! elem {
        ($t:ident) => {
            impl Elem for $t {
                const ZERO: $t = 0.0;
                const ONE: $t = 1.0;
                const NAN: $t = $t::NAN;
                #[inline(always)]
                fn from_f64(x: f64) -> $t {
                    x as $t
                }
                #[inline(always)]
                fn to_f64(self) -> f64 {
                    self as f64
                }
                #[inline(always)]
                fn is_finite(self) -> bool {
                    $t::is_finite(self)
                }
                #[inline(always)]
                fn min(self, o: $t) -> $t {
                    $t::min(self, o)
                }
                #[inline(always)]
                fn next_below(self) -> Self {
                    Self::from_bits(self.to_bits() - 1)
                }
            }
        };
    }
    elem!(f64);
    elem!(f32);
}
