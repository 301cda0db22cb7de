//! M_B: the Shirley–Chiu concentric map from the unit square to the unit disk, with the azimuth in
//! [0, 2π) (docs/DERIVATION.md §2).
//!
//! The map is equal-area: |∂(x, y)/∂(u, v)| = π everywhere, so uniform points on the square become
//! uniform points on the disk (density 1/π), and (r², φ/2π) are independent U(0, 1) variables. It is
//! chosen over the polar map (r = √u, φ = 2πv) for its low distortion: strata of the square stay
//! compact on the disk, which keeps the stratification of QMC points.
//!
//! Continuity: C⁰ everywhere on the square; the azimuth φ jumps from 2π to 0 across the half-line
//! v = ½, u > ½ (the seam of the [0, 2π) convention), where the disk point itself is continuous.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// 4/π.
const FRAC_4_PI: f64 = 4.0 / PI;

/// Area factor of [`square_to_disk`]: dA_disk = π du dv.
pub const SQUARE_TO_DISK_AREA: f64 = PI;

/// Maps (u, v) ∈ [0, 1]² to polar coordinates (r, φ) on the unit disk with r ∈ [0, 1] and
/// φ ∈ [0, 2π), radians.
#[inline]
pub fn square_to_disk(u: [f64; 2]) -> (f64, f64) {
    let a = 2.0 * u[0] - 1.0;
    let b = 2.0 * u[1] - 1.0;
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    // Branch-reduced form (docs/DERIVATION.md §2): signed radius and φ ∈ (−π/4, 3π/4], then
    // unfolded.
    let (mut r, mut phi) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, FRAC_PI_2 - FRAC_PI_4 * (a / b))
    };
    if r < 0.0 {
        r = -r;
        phi += PI;
    }
    if phi < 0.0 {
        phi += TAU;
    }
    // −tiny + 2π rounds to 2π; that direction is φ = 0.
    if phi >= TAU {
        phi = 0.0;
    }
    (r, phi)
}

/// Inverse of [`square_to_disk`]: polar coordinates (r, φ), r ∈ [0, 1], φ in radians (any value in
/// [0, 2π]), to the point of the unit square.
#[inline]
pub fn disk_to_square(r: f64, phi: f64) -> [f64; 2] {
    // Radiance's SDdisk2square rewritten for φ ∈ [0, 2π) (docs/DERIVATION.md §2).
    let p = if phi >= 7.0 * FRAC_PI_4 {
        phi - TAU
    } else {
        phi
    };
    // r / (π/4), multiplied instead of divided in every branch.
    let s = r * FRAC_4_PI;
    let (a, b) = if p < FRAC_PI_4 {
        (r, s * p)
    } else if p < 3.0 * FRAC_PI_4 {
        (-(p - FRAC_PI_2) * s, r)
    } else if p < 5.0 * FRAC_PI_4 {
        (-r, -s * (p - PI))
    } else {
        ((p - 1.5 * PI) * s, -r)
    };
    [
        (0.5 * (a + 1.0)).clamp(0.0, 1.0),
        (0.5 * (b + 1.0)).clamp(0.0, 1.0),
    ]
}

/// The original four-region form of Shirley and Chiu with the paper's +2π in region 1, kept as an
/// independent reference for the tests.
#[cfg(test)]
pub(crate) fn square_to_disk_four_regions(u: [f64; 2]) -> (f64, f64) {
    let a = 2.0 * u[0] - 1.0;
    let b = 2.0 * u[1] - 1.0;
    if a > -b {
        if a > b {
            let phi = FRAC_PI_4 * (b / a);
            (a, if b < 0.0 { phi + TAU } else { phi })
        } else {
            (b, FRAC_PI_4 * (2.0 - a / b))
        }
    } else if a < b {
        (-a, FRAC_PI_4 * (4.0 + b / a))
    } else if b == 0.0 {
        (0.0, 0.0)
    } else {
        (-b, FRAC_PI_4 * (6.0 - a / b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn cart(r: f64, p: f64) -> [f64; 2] {
        [r * p.cos(), r * p.sin()]
    }

    #[test]
    fn round_trip_and_range() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let mut worst = 0.0f64;
        for _ in 0..100_000 {
            let u = [rng.gen::<f64>(), rng.gen::<f64>()];
            let (r, p) = square_to_disk(u);
            assert!((0.0..=1.0).contains(&r) && (0.0..TAU).contains(&p));
            let w = disk_to_square(r, p);
            worst = worst.max((w[0] - u[0]).abs()).max((w[1] - u[1]).abs());
        }
        assert!(worst < 1e-14, "round trip {worst}");
    }

    #[test]
    fn agrees_with_four_region_form() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(2);
        for _ in 0..100_000 {
            let u = [rng.gen::<f64>(), rng.gen::<f64>()];
            let (r1, p1) = square_to_disk(u);
            let (r2, p2) = square_to_disk_four_regions(u);
            let (a, b) = (cart(r1, p1), cart(r2, p2));
            assert!((a[0] - b[0]).abs() < 1e-15 && (a[1] - b[1]).abs() < 1e-15);
        }
    }

    #[test]
    fn edges_corners_and_centre() {
        for &u in &[
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [1.0, 1.0],
            [0.5, 0.5],
            [1.0, 0.5],
            [0.5, 0.0],
        ] {
            let (r, p) = square_to_disk(u);
            assert!(r.is_finite() && p.is_finite() && (0.0..TAU).contains(&p));
            let w = disk_to_square(r, p);
            assert!(
                (w[0] - u[0]).abs() < 1e-15 && (w[1] - u[1]).abs() < 1e-15,
                "{u:?}"
            );
        }
        // the corners land on the rim
        assert!((square_to_disk([0.0, 0.0]).0 - 1.0).abs() < 1e-15);
    }

    #[test]
    fn area_factor_is_pi() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let h = 1e-6;
        for _ in 0..2000 {
            let u = [rng.gen_range(0.01..0.99), rng.gen_range(0.01..0.99)];
            let f = |u: [f64; 2]| {
                let (r, p) = square_to_disk(u);
                cart(r, p)
            };
            let (x0, x1) = (f([u[0] - h, u[1]]), f([u[0] + h, u[1]]));
            let (y0, y1) = (f([u[0], u[1] - h]), f([u[0], u[1] + h]));
            let du = [(x1[0] - x0[0]) / (2.0 * h), (x1[1] - x0[1]) / (2.0 * h)];
            let dv = [(y1[0] - y0[0]) / (2.0 * h), (y1[1] - y0[1]) / (2.0 * h)];
            let det = (du[0] * dv[1] - du[1] * dv[0]).abs();
            // skip points straddling the diagonals, where the map has a kink
            if ((2.0 * u[0] - 1.0).abs() - (2.0 * u[1] - 1.0).abs()).abs() < 1e-4 {
                continue;
            }
            assert!((det - SQUARE_TO_DISK_AREA).abs() < 1e-6, "det {det}");
        }
    }
}
