//! Branch-free transcendental functions for the lanes of the batch paths.
//!
//! Every function here is written without data-dependent branches (the `if` expressions compile to
//! selects), without table loops and without fused multiply–adds, so that a loop over a block of
//! lanes vectorises and gives **bit-identical results at every SIMD width** (AVX2 or the portable
//! path): IEEE addition, multiplication, division and square root are correctly rounded whatever the
//! vector width, and Rust never contracts `a * b + c` into an FMA on its own.
//!
//! Accuracy, measured against the platform's libm (glibc, itself within 1 ulp) by the tests of this
//! module over the whole input range stated per function:
//!
//! | function | input range | bound vs libm |
//! |---|---|---|
//! | [`sin_cos`] | \|x\| ≤ 2²⁰ (the batch paths use [0, 2π]) | 2 ulp of the result, or 2⁻⁵³ absolute near a zero of the function |
//! | [`atan2`] | every finite (y, x), signed zeros | 2 ulp |
//! | square root | everything | 0 ulp (the IEEE instruction) |
//! | [`angles`] (θ, φ of a direction, from [`atan2`] and a square root) | unit directions | within 2e-15 rad of [`crate::sampler::spherical`] (libm's `hypot` and `atan2`; `envmap` tests) |
//!
//! `acos` is not needed by the batch paths: `pdf` and `invert` use only the azimuth and the disk
//! radius r = √((x² + y²)/(1 + z)), which needs a square root only.

use std::f64::consts::{FRAC_PI_2, PI};

/// π/2 split into three parts for Cody–Waite reduction: the first two have 32 significant bits, so
/// k·P1 and k·P2 are exact for |k| < 2²¹.
pub(crate) const PIO2_1: f64 = 1.570_796_326_734_125_6;
pub(crate) const PIO2_2: f64 = 6.077_100_506_303_966e-11;
pub(crate) const PIO2_3: f64 = 2.022_266_248_795_950_6e-21;
pub(crate) const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;
/// 1.5·2⁵²: adding and subtracting it rounds a double of magnitude < 2⁵¹ to the nearest integer.
pub(crate) const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;

/// sin r and cos r for |r| ≤ π/4 (plus the reduction's round-off): Taylor series to degree 17 / 18,
/// whose truncation error is below 5·10⁻¹⁷ relative there. Horner form in r².
#[inline(always)]
fn sin_cos_kernel(r: f64) -> (f64, f64) {
    let z = r * r;
    let mut ps = SIN_TAYLOR[7];
    let mut pc = COS_TAYLOR[7];
    for k in (0..7).rev() {
        ps = ps * z + SIN_TAYLOR[k];
        pc = pc * z + COS_TAYLOR[k];
    }
    let s = r + r * z * ps;
    // cos r = 1 − z/2 + z²·pc, summed so that the large terms cancel last.
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    let c = w + (((1.0 - w) - hz) + z * z * pc);
    (s, c)
}

/// The sine series of [`sin_cos`] after r + r³·(…): −1/3!, 1/5!, …, 1/17! (Horner in r²).
pub(crate) const SIN_TAYLOR: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];
/// The cosine series of [`sin_cos`] after 1 − r²/2 + r⁴·(…): 1/4!, −1/6!, …, −1/18!.
pub(crate) const COS_TAYLOR: [f64; 8] = [
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
    -1.0 / 6_402_373_705_728_000.0,
];

/// (sin x, cos x) for |x| ≤ 2²⁰, branch-free (see the module's accuracy table). Outside that range
/// the reduction loses accuracy (the batch paths only pass azimuths in [0, 2π]).
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    // k = round(x·2/π), r = x − k·π/2 in three exact-product steps.
    let k = (x * TWO_OVER_PI + ROUND_MAGIC) - ROUND_MAGIC;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let (s, c) = sin_cos_kernel(r);
    // Quadrant q = k − 4⌊k/4⌋ (k is an exact integer in a double; k/4 is exact too).
    let k4 = k * 0.25;
    let n = (k4 + ROUND_MAGIC) - ROUND_MAGIC;
    let q = k - 4.0 * if n > k4 { n - 1.0 } else { n };
    let swap = q == 1.0 || q == 3.0;
    let (s1, c1) = if swap { (c, s) } else { (s, c) };
    let sin = if q == 2.0 || q == 3.0 { -s1 } else { s1 };
    let cos = if q == 1.0 || q == 2.0 { -c1 } else { c1 };
    (sin, cos)
}

/// atan(k/8) for k = 0..=8 as a double-double (hi, lo) pair, computed from the series with exact
/// rational arithmetic (k = 8: π/4).
const ATAN_K8: [(f64, f64); 9] = [
    (0.0, 0.0),
    (0.124_354_994_546_761_44, -3.125_324_142_453_938_3e-18),
    (0.244_978_663_126_864_14, 1.069_875_561_873_445_1e-17),
    (0.358_770_670_270_572_25, -2.462_381_558_263_863_5e-17),
    (0.463_647_609_000_806_1, 2.269_877_745_296_168_7e-17),
    (0.558_599_315_343_562_4, -5.455_630_548_591_626_4e-18),
    (0.643_501_108_793_284_4, 1.583_478_505_144_428_6e-17),
    (0.718_829_999_621_624_5, -2.147_838_844_445_698_3e-17),
    (std::f64::consts::FRAC_PI_4, 3.061_616_997_868_383e-17),
];
/// [`ATAN_K8`] as the kernels' (hi, lo) tables: f64 hi, f64 lo, f32 hi (hi rounded), f32 lo
/// (what hi's rounding lost plus lo, rounded).
const ATAN_PARTS: ([f64; 9], [f64; 9], [f32; 9], [f32; 9]) = {
    let (mut h64, mut l64, mut h32, mut l32) = ([0.0; 9], [0.0; 9], [0.0f32; 9], [0.0f32; 9]);
    let mut k = 0;
    while k < 9 {
        let (hi, lo) = ATAN_K8[k];
        h64[k] = hi;
        l64[k] = lo;
        h32[k] = hi as f32;
        l32[k] = ((hi - hi as f32 as f64) + lo) as f32;
        k += 1;
    }
    (h64, l64, h32, l32)
};
/// The series of [`atan_unit`] after z + z³·(…): −1/3, 1/5, …, 1/17 (Horner in z²).
pub(crate) const ATAN_TAYLOR: [f64; 8] = [
    -1.0 / 3.0,
    1.0 / 5.0,
    -1.0 / 7.0,
    1.0 / 9.0,
    -1.0 / 11.0,
    1.0 / 13.0,
    -1.0 / 15.0,
    1.0 / 17.0,
];

/// π/2 and π as double-doubles.
pub(crate) const PIO2_LO: f64 = 6.123_233_995_736_766e-17;
pub(crate) const PI_LO: f64 = 1.224_646_799_147_353_2e-16;

/// atan t for 0 ≤ t ≤ 1: c = ⌊8t⌋/8 and atan t = atan c + atan z with z = (t − c)/(1 + tc),
/// 0 ≤ z < 1/8, by its Taylor series to z¹⁷ (truncation below 3·10⁻¹⁸ relative).
#[inline(always)]
fn atan_unit(t: f64) -> f64 {
    // c = ⌊8t⌋/8 ≤ t, so z ≥ 0 and atan c + atan z adds without cancellation.
    let t8 = t * 8.0;
    let kf = (t8 + ROUND_MAGIC) - ROUND_MAGIC;
    let kf = if kf > t8 { kf - 1.0 } else { kf };
    let c = kf * 0.125;
    let z = (t - c) / (1.0 + t * c);
    let z2 = z * z;
    let mut p = ATAN_TAYLOR[7];
    for k in (0..7).rev() {
        p = p * z2 + ATAN_TAYLOR[k];
    }
    let k = kf as usize;
    // k ∈ 0..=8 always (t ∈ [0, 1]); `min` keeps the index in bounds for a NaN t (k = 0).
    let (hi, lo) = ATAN_K8[k.min(8)];
    hi + (lo + (z + z * z2 * p))
}

/// atan2(y, x) in (−π, π], branch-free, for every finite (y, x) including signed zeros (the result
/// follows libm's conventions: atan2(±0, +0) = ±0, atan2(±0, −0) = ±π).
#[inline(always)]
pub fn atan2(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    let t = if den > 0.0 { num / den } else { 0.0 };
    let a = atan_unit(t);
    // |y| > |x|: π/2 − a. x < 0 (or −0): π − that.
    let a = if swap { (FRAC_PI_2 - a) + PIO2_LO } else { a };
    let neg_x = x.is_sign_negative();
    let a = if neg_x { (PI - a) + PI_LO } else { a };
    if y.is_sign_negative() {
        -a
    } else {
        a
    }
}

/// The constants of the vector kernels that depend on the element type's precision, one set
/// per element type (`f64`, `f32`): the kernels of [`super::kernels`] read them as `E::NAME`,
/// so that one body serves both precisions. The f64 values are the ones the kernels always had
/// (their f64 results are unchanged bit for bit); the f32 values are derived below, each from
/// the same rule as its f64 counterpart with the f32 unit roundoff u₃₂ = 2⁻²⁴ in place of
/// u₆₄ = 2⁻⁵³.
pub(crate) trait Precision: Copy + PartialOrd + 'static {
    /// π/2 in three parts for the Cody–Waite reduction of [`sin_cos`]: k·P1 and k·P2 are exact
    /// for the kernels' |k| ≤ 4 (their azimuths lie in [0, 2π]).
    const PIO2_PARTS: [f64; 3];
    /// 1.5·2^(p−1) for a p-bit significand: (x + c) − c rounds |x| < 2^(p−2) to an integer.
    const ROUND_MAGIC: f64;
    /// The sine series after r + r³·(…), as many terms as the precision needs for |r| ≤ π/4.
    const SIN_SERIES: &'static [f64];
    /// The cosine series after 1 − r²/2 + r⁴·(…).
    const COS_SERIES: &'static [f64];
    /// The arctangent series after z + z³·(…), for 0 ≤ z < 1/8.
    const ATAN_SERIES: &'static [f64];
    /// atan(k/8), k = 0..=8, high parts (nearest values of the type).
    const ATAN_HI: [Self; 9];
    /// atan(k/8) − `ATAN_HI`, rounded to the type.
    const ATAN_LO: [Self; 9];
    /// π/2 − (π/2 rounded to the type), rounded to the type.
    const HALF_PI_LO: f64;
    /// π − (π rounded to the type), rounded to the type.
    const PI_LO_PART: f64;
    /// The radial solve's step rule: stop once a step is below this fraction of the radius.
    const STOP_STEP: f64;
    /// The radial solve's predicted-step rule: stop once Halley's next step is predicted below
    /// this fraction of the radius.
    const STOP_CUBIC: f64;
    /// The radial solve uses the prediction only for steps below this fraction of the radius
    /// (where the cubic model of the error holds).
    const HALLEY_SMALL: f64;
    /// The density is 0 beyond the map's edge radius times this factor (the slack absorbs the
    /// round-off of a direction's disk radius).
    const EDGE: f64;
}

impl Precision for f64 {
    const PIO2_PARTS: [f64; 3] = [PIO2_1, PIO2_2, PIO2_3];
    const ROUND_MAGIC: f64 = ROUND_MAGIC;
    const SIN_SERIES: &'static [f64] = &SIN_TAYLOR;
    const COS_SERIES: &'static [f64] = &COS_TAYLOR;
    const ATAN_SERIES: &'static [f64] = &ATAN_TAYLOR;
    const ATAN_HI: [f64; 9] = ATAN_PARTS.0;
    const ATAN_LO: [f64; 9] = ATAN_PARTS.1;
    const HALF_PI_LO: f64 = PIO2_LO;
    const PI_LO_PART: f64 = PI_LO;
    /// ≈ 9 u₆₄.
    const STOP_STEP: f64 = 1e-15;
    /// ≈ 0.09 u₆₄.
    const STOP_CUBIC: f64 = 1e-17;
    /// = STOP_STEP^(1/3).
    const HALLEY_SMALL: f64 = 1e-5;
    /// ≈ 9000 u₆₄.
    const EDGE: f64 = 1.0 + 1e-12;
}

/// π/2 with its low 12 significand bits cleared and rounded to f32: the high part of the f32
/// reduction (k·P1 exact for |k| < 2¹²).
const F32_PIO2_1: f64 = 1.570_312_5;
/// The next 12 bits of π/2 (k·P2 exact for |k| < 2¹²).
const F32_PIO2_2: f64 = 4.837_512_969_970_703e-4;
/// The rest of π/2, rounded to f32.
const F32_PIO2_3: f64 = (FRAC_PI_2 - F32_PIO2_1 - F32_PIO2_2) as f32 as f64;

impl Precision for f32 {
    const PIO2_PARTS: [f64; 3] = [F32_PIO2_1, F32_PIO2_2, F32_PIO2_3];
    /// 1.5·2²³.
    const ROUND_MAGIC: f64 = 12_582_912.0;
    /// To r⁹: the truncation r¹¹/11! is below 2.5·10⁻⁹ relative for |r| ≤ π/4 (0.04 u₃₂).
    const SIN_SERIES: &'static [f64] =
        &[SIN_TAYLOR[0], SIN_TAYLOR[1], SIN_TAYLOR[2], SIN_TAYLOR[3]];
    /// To r¹⁰: the truncation r¹²/12! is below 1.6·10⁻¹⁰ relative for |r| ≤ π/4.
    const COS_SERIES: &'static [f64] =
        &[COS_TAYLOR[0], COS_TAYLOR[1], COS_TAYLOR[2], COS_TAYLOR[3]];
    /// To z⁷: the truncation z⁹/9 is below 8⁻⁸/9 = 6.7·10⁻⁹ relative for z < 1/8 (0.11 u₃₂).
    const ATAN_SERIES: &'static [f64] = &[ATAN_TAYLOR[0], ATAN_TAYLOR[1], ATAN_TAYLOR[2]];
    const ATAN_HI: [f32; 9] = ATAN_PARTS.2;
    const ATAN_LO: [f32; 9] = ATAN_PARTS.3;
    const HALF_PI_LO: f64 = ((FRAC_PI_2 - FRAC_PI_2 as f32 as f64) + PIO2_LO) as f32 as f64;
    const PI_LO_PART: f64 = ((PI - PI as f32 as f64) + PI_LO) as f32 as f64;
    /// 2⁻²¹ = 8 u₃₂ (the f64 rule's ≈ 9 u₆₄, as a power of two).
    const STOP_STEP: f64 = 4.768_371_582_031_25e-7;
    /// 2⁻²⁸ ≈ 0.06 u₃₂.
    const STOP_CUBIC: f64 = 3.725_290_298_461_914e-9;
    /// 2⁻⁷ = STOP_STEP^(1/3).
    const HALLEY_SMALL: f64 = 7.812_5e-3;
    /// 1 + 2⁻¹⁷ (128 u₃₂): a direction of the edge, rounded to f32, has a disk radius within a
    /// few u₃₂ of the edge's.
    const EDGE: f64 = 1.0 + 7.629_394_531_25e-6;
}

/// Polar angle θ (from +z) and azimuth φ ∈ [0, 2π) (from +x toward +y) of a unit direction,
/// branch-free: θ = [`atan2`](√(x² + y²), z), φ = [`atan2`](y, x) (+ 2π when negative, 0 where it
/// rounds to 2π), φ = 0 where x = y = 0 (either sign of zero). The batch kernels compute the same
/// operations on their lanes, so a batch of angles equals this function bit for bit. Compared
/// with [`crate::sampler::spherical`] (libm's `hypot` and `atan2`): within a few ulps.
#[inline(always)]
pub fn angles(d: [f64; 3]) -> (f64, f64) {
    let [x, y, z] = d;
    let theta = atan2((x * x + y * y).sqrt(), z);
    let phi = atan2(y, x);
    let phi = if phi < 0.0 {
        phi + std::f64::consts::TAU
    } else {
        phi
    };
    let phi = if phi >= std::f64::consts::TAU {
        0.0
    } else {
        phi
    };
    let phi = if x == 0.0 && y == 0.0 { 0.0 } else { phi };
    (theta, phi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Distance in units in the last place of `want` (a libm value).
    fn ulps(got: f64, want: f64) -> f64 {
        if got == want {
            return 0.0;
        }
        let ulp = if want == 0.0 {
            f64::from_bits(1)
        } else {
            let e = want.abs().log2().floor();
            2f64.powf(e - 52.0).max(f64::from_bits(1))
        };
        (got - want).abs() / ulp
    }

    /// sin/cos error: ulps of the result, except near a zero of the function, where an absolute
    /// error of 2⁻⁵³ (the reduction's limit for |x| ≤ 2²⁰: |x|·2⁻¹⁰⁷) is the honest measure.
    fn sc_err(got: f64, want: f64) -> f64 {
        if want.abs() < 2f64.powi(-20) {
            ((got - want).abs() / 2f64.powi(-53)).min(ulps(got, want))
        } else {
            ulps(got, want)
        }
    }

    #[test]
    fn sin_cos_within_2_ulp_over_its_range() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let mut worst = 0.0f64;
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            let e = sc_err(s, x.sin()).max(sc_err(c, x.cos()));
            if e > worst {
                worst = e;
            }
        };
        // Dense over the batch paths' [0, 2π] and its neighbourhood …
        for k in 0..=2_000_000 {
            check(-1.0 + (2.0 * PI + 2.0) * k as f64 / 2e6);
        }
        // … log-uniform magnitudes up to 2²⁰ of both signs, and tiny ones.
        for _ in 0..1_000_000 {
            let m = 2f64.powf(rng.gen_range(-40.0..20.0));
            check(if rng.gen() { m } else { -m });
        }
        for x in [
            0.0,
            -0.0,
            PI,
            FRAC_PI_2,
            2.0 * PI,
            1e-300,
            1048576.0,
            -1048576.0,
        ] {
            check(x);
        }
        assert!(worst <= 2.0, "sin_cos worst error {worst} ulp");
    }

    #[test]
    fn atan2_within_2_ulp_for_every_finite_input() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
        let mut worst = 0.0f64;
        let mut check = |y: f64, x: f64| {
            let (g, w) = (atan2(y, x), y.atan2(x));
            assert_eq!(
                g.is_sign_negative(),
                w.is_sign_negative(),
                "sign at ({y}, {x})"
            );
            let e = ulps(g, w);
            if e > worst {
                worst = e;
            }
        };
        // The unit circle densely (the batch paths' inputs) …
        for k in 0..2_000_000 {
            let p = 2.0 * PI * k as f64 / 2e6;
            check(p.sin(), p.cos());
        }
        // … and every exponent range, subnormals included, all four quadrants.
        for _ in 0..2_000_000 {
            let e1 = rng.gen_range(-1074.0..1023.0);
            let e2 = rng.gen_range(-1074.0..1023.0);
            let y = 2f64.powf(e1) * rng.gen_range(1.0..2.0) * if rng.gen() { 1.0 } else { -1.0 };
            let x = 2f64.powf(e2) * rng.gen_range(1.0..2.0) * if rng.gen() { 1.0 } else { -1.0 };
            check(y, x);
            check(y, y * rng.gen_range(0.5..2.0));
        }
        let specials = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            f64::MIN_POSITIVE,
            f64::MAX,
            -f64::MAX,
            5e-324,
        ];
        for &y in &specials {
            for &x in &specials {
                check(y, x);
            }
        }
        assert!(worst <= 2.0, "atan2 worst error {worst} ulp");
    }
}
