//! Equal-area maps from the unit square to the sphere and to the upper hemisphere, with their
//! inverses (docs/DERIVATION.md §2, §3).
//!
//! * [`equal_area_square_to_sphere`]: Clarberg's octahedral map (2008). The inner diamond
//!   |u'| + |v'| ≤ 1 (u' = 2u − 1, v' = 2v − 1) is the upper hemisphere, the four outer corners fold
//!   onto the lower one. Jacobian |∂ω/∂(u, v)| = 4π everywhere.
//! * [`equal_area_square_to_hemisphere`]: Shirley–Chiu's concentric square → disk map followed by
//!   the Lambert lift (x, y) ↦ (x√(2 − r²), y√(2 − r²), 1 − r²), both the HDS mapping's own
//!   stages ([`crate::mapping::concentric`], [`crate::mapping::lift`]). Jacobian 2π everywhere.
//!
//! Both are bijective up to measure-zero seams (the square's boundary and, for the sphere map, the
//! axes u' = 0, v' = 0), continuous, and their inverses use `atan2` (no polynomial approximation).
//! Directions are unit vectors `[x, y, z]` (the inverses expect unit length); square points are
//! `[u, v]` in [0, 1]², and the inverses clamp their result into it.
//!
//! ```
//! use gonio::baselines::equal_area::{
//!     equal_area_hemisphere_to_square, equal_area_sphere_to_square,
//!     equal_area_square_to_hemisphere, equal_area_square_to_sphere,
//! };
//! let u = [0.3, 0.8];
//! let w = equal_area_square_to_sphere(u);
//! assert!((w[0] * w[0] + w[1] * w[1] + w[2] * w[2] - 1.0).abs() < 1e-12);
//! let back = equal_area_sphere_to_square(w);
//! assert!((back[0] - u[0]).abs() < 1e-12 && (back[1] - u[1]).abs() < 1e-12);
//! let h = equal_area_square_to_hemisphere(u);
//! assert!(h[2] >= 0.0);
//! let back = equal_area_hemisphere_to_square(h);
//! assert!((back[0] - u[0]).abs() < 1e-12 && (back[1] - u[1]).abs() < 1e-12);
//! ```

use crate::mapping::{concentric, lift};
use crate::sampler::{Point2, Vec3};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// Clarberg's equal-area map from the unit square to the unit sphere (area 4π, so a density q on the
/// square becomes q / 4π per steradian).
///
/// With u' = 2u − 1, v' = 2v − 1, d = 1 − (|u'| + |v'|), r = 1 − |d| and
/// φ = (π/4)((|v'| − |u'|)/r + 1) ∈ [0, π/2]:
/// z = sign(d)(1 − r²), x = sign(u') cos φ · r√(2 − r²), y = sign(v') sin φ · r√(2 − r²).
pub fn equal_area_square_to_sphere(p: Point2) -> Vec3 {
    let (u, v) = (2.0 * p[0] - 1.0, 2.0 * p[1] - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    let signed_d = 1.0 - (up + vp);
    let r = 1.0 - signed_d.abs();
    let phi = if r == 0.0 {
        FRAC_PI_4
    } else {
        ((vp - up) / r + 1.0) * FRAC_PI_4
    };
    let z = (1.0 - r * r).copysign(signed_d);
    let (sin_phi, cos_phi) = phi.sin_cos();
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    [cos_phi.copysign(u) * s, sin_phi.copysign(v) * s, z]
}

/// Inverse of [`equal_area_square_to_sphere`]: the point of the unit square that maps to the unit
/// direction `w`.
///
/// r² = (x² + y²)/(1 + |z|) (= 1 − |z|, written without cancellation near the poles),
/// φ = atan2(|y|, |x|); on the upper hemisphere |v'| = 2rφ/π and |u'| = r − |v'|; on the lower one
/// the point is mirrored across the diamond: |u'| = 1 − 2rφ/π, |v'| = 1 − r + 2rφ/π. The signs of
/// u', v' are those of x, y.
pub fn equal_area_sphere_to_square(w: Vec3) -> Point2 {
    let (ax, ay, az) = (w[0].abs(), w[1].abs(), w[2].abs());
    let r = ((ax * ax + ay * ay) / (1.0 + az)).min(1.0).sqrt();
    let phi = ay.atan2(ax);
    let t = r * phi / FRAC_PI_2; // r · 2φ/π
    let (up, vp) = if w[2] >= 0.0 {
        (r - t, t)
    } else {
        (1.0 - t, 1.0 - r + t)
    };
    let u = up.copysign(w[0]);
    let v = vp.copysign(w[1]);
    [
        (0.5 * (u + 1.0)).clamp(0.0, 1.0),
        (0.5 * (v + 1.0)).clamp(0.0, 1.0),
    ]
}

/// Equal-area map from the unit square to the upper hemisphere z ≥ 0 (area 2π, so a density q on
/// the square becomes q / 2π per steradian): the HDS mapping's own M_B, the concentric map
/// ([`concentric::square_to_disk`]), followed by its M_E, the Lambert lift
/// ([`lift::disk_to_sphere`]) (docs/DERIVATION.md §2, §3).
pub fn equal_area_square_to_hemisphere(p: Point2) -> Vec3 {
    let (r, phi) = concentric::square_to_disk(p);
    lift::disk_to_sphere(r, phi)
}

/// Inverse of [`equal_area_square_to_hemisphere`] for a unit direction with z ≥ 0: the inverse
/// lift ([`lift::sphere_to_disk_radius`], [`lift::sphere_to_disk_azimuth`]), then
/// [`concentric::disk_to_square`].
pub fn equal_area_hemisphere_to_square(w: Vec3) -> Point2 {
    let r = lift::sphere_to_disk_radius(w).min(1.0);
    concentric::disk_to_square(r, lift::sphere_to_disk_azimuth(w))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;
    use std::f64::consts::PI;

    fn cross_norm(a: Vec3, b: Vec3) -> f64 {
        let c = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
    }

    fn check(fwd: fn(Point2) -> Vec3, inv: fn(Vec3) -> Point2, area: f64, upper: bool) {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let h = 1e-6;
        for _ in 0..20_000 {
            let p = [rng.gen_range(h..1.0 - h), rng.gen_range(h..1.0 - h)];
            let w = fwd(p);
            let len = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-14, "not unit at {p:?}");
            assert!(!upper || w[2] >= 0.0);
            let q = inv(w);
            assert!(
                (q[0] - p[0]).abs() < 1e-12 && (q[1] - p[1]).abs() < 1e-12,
                "round trip {p:?} -> {q:?}"
            );
            // Jacobian by central differences, away from the seams where the map has kinks.
            let (a, b) = (2.0 * p[0] - 1.0, 2.0 * p[1] - 1.0);
            let seam = 1e-4;
            if a.abs() < seam
                || b.abs() < seam
                || (a.abs() - b.abs()).abs() < seam
                || (a.abs() + b.abs() - 1.0).abs() < seam
            {
                continue;
            }
            let du = fwd([p[0] + h, p[1]]);
            let dd = fwd([p[0] - h, p[1]]);
            let dv = fwd([p[0], p[1] + h]);
            let dw = fwd([p[0], p[1] - h]);
            let ju = [0, 1, 2].map(|k| (du[k] - dd[k]) / (2.0 * h));
            let jv = [0, 1, 2].map(|k| (dv[k] - dw[k]) / (2.0 * h));
            let jac = cross_norm(ju, jv);
            assert!(
                (jac / area - 1.0).abs() < 1e-5,
                "Jacobian {jac} at {p:?}, want {area}"
            );
        }
        // Edges and corners give unit directions.
        for &p in &[
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [1.0, 1.0],
            [0.5, 0.5],
            [0.5, 0.0],
            [1.0, 0.5],
        ] {
            let w = fwd(p);
            let len = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-14 && w.iter().all(|c| c.is_finite()));
            let q = inv(w);
            assert!(q.iter().all(|c| (0.0..=1.0).contains(c)));
        }
    }

    #[test]
    fn sphere_map_round_trip_and_area() {
        check(
            equal_area_square_to_sphere,
            equal_area_sphere_to_square,
            4.0 * PI,
            false,
        );
        // The centre is the north pole, the corners the south pole.
        assert_eq!(equal_area_square_to_sphere([0.5, 0.5])[2], 1.0);
        assert_eq!(equal_area_square_to_sphere([0.0, 1.0])[2], -1.0);
    }

    #[test]
    fn hemisphere_map_round_trip_and_area() {
        check(
            equal_area_square_to_hemisphere,
            equal_area_hemisphere_to_square,
            2.0 * PI,
            true,
        );
        assert_eq!(equal_area_square_to_hemisphere([0.5, 0.5]), [0.0, 0.0, 1.0]);
    }
}
