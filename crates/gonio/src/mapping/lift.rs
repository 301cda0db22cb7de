//! M_E: Shirley's equal-area lift from a disk to the sphere (Lambert azimuthal projection,
//! docs/DERIVATION.md §3).
//!
//! A point at polar radius r and azimuth φ goes to the direction with cos θ = 1 − r², i.e.
//! `(r√(2−r²) cos φ, r√(2−r²) sin φ, 1 − r²)`. The unit disk (r ≤ 1) covers the upper hemisphere and
//! the disk of radius √2 the whole sphere. dω = 2 dA everywhere, so a density q on the disk becomes
//! q/2 per steradian.

/// Area factor of [`disk_to_sphere`]: dω = 2 dA.
pub const DISK_TO_SPHERE_AREA: f64 = 2.0;

/// Disk radius of the parallel at polar angle θ (radians from +z): x = √(1 − cos θ) = √2 sin(θ/2).
#[inline]
pub fn parallel_radius(theta: f64) -> f64 {
    std::f64::consts::SQRT_2 * (0.5 * theta).sin()
}

/// Lifts disk polar coordinates (r, φ), 0 ≤ r ≤ √2, φ in radians, to a unit direction.
#[inline]
pub fn disk_to_sphere(r: f64, phi: f64) -> [f64; 3] {
    let r2 = r * r;
    let s = r * (2.0 - r2).max(0.0).sqrt();
    let (sp, cp) = phi.sin_cos();
    [s * cp, s * sp, 1.0 - r2]
}

/// Disk radius r of a unit direction, the inverse of [`disk_to_sphere`] in r (the azimuth is
/// `atan2(y, x)`). Written without cancellation near both poles: r² = (x² + y²)/(1 + z) for z > 0.
#[inline]
pub fn sphere_to_disk_radius(d: [f64; 3]) -> f64 {
    let z = d[2];
    let r2 = if z > 0.0 {
        (d[0] * d[0] + d[1] * d[1]) / (1.0 + z)
    } else {
        1.0 - z
    };
    r2.clamp(0.0, 2.0).sqrt()
}

/// Disk azimuth φ ∈ [0, 2π) of a direction (the inverse of [`disk_to_sphere`] in φ), as
/// [`crate::sampler::spherical`] computes it, without the polar angle: 0 at the poles (x = y = 0,
/// any signs of zero), where every meridian meets and meridian 0 is read.
#[inline]
pub fn sphere_to_disk_azimuth(d: [f64; 3]) -> f64 {
    if d[0] == 0.0 && d[1] == 0.0 {
        return 0.0;
    }
    let mut phi = d[1].atan2(d[0]);
    if phi < 0.0 {
        phi += std::f64::consts::TAU;
    }
    if phi >= std::f64::consts::TAU {
        phi = 0.0;
    }
    phi
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn round_trip_and_poles() {
        for k in 0..=1000 {
            let r = std::f64::consts::SQRT_2 * k as f64 / 1000.0;
            let phi = TAU * ((k * 37) % 1000) as f64 / 1000.0;
            let d = disk_to_sphere(r, phi);
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-15);
            assert!((sphere_to_disk_radius(d) - r).abs() < 1e-12, "r {r}");
        }
        assert_eq!(disk_to_sphere(0.0, 1.0), [0.0, 0.0, 1.0]);
        assert!((parallel_radius(std::f64::consts::FRAC_PI_2) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn area_factor_is_two() {
        // dω/dA from the band between two radii: 2π(cos θ0 − cos θ1) / π(r1² − r0²) = 2.
        for k in 0..100 {
            let (r0, r1) = (k as f64 * 0.014, k as f64 * 0.014 + 1e-3);
            let band = TAU * (disk_to_sphere(r0, 0.0)[2] - disk_to_sphere(r1, 0.0)[2]);
            let area = std::f64::consts::PI * (r1 * r1 - r0 * r0);
            assert!((band / area - DISK_TO_SPHERE_AREA).abs() < 1e-9);
        }
    }
}
