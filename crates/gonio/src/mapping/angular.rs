//! M_C: the angular remap that gives every disk sector between two meridians its power
//! (ALGORITHM §5).
//!
//! The star domain S = {r ≤ ρ(φ)} has, in sector i with fraction ε = (φ − φ_i)/β_i,
//! ρ(φ)² = (1−ε)R_i² + εR_{i+1}², where R_i² = U(i, N−1)/s is the squared radius that meridian i's
//! power would fill at the constant density s. The wedge of the B-disk between the angles Γ_i and
//! Γ_i + γ (unit radius) is sent to the part of sector i between φ_i and φ_i + εβ_i that has the same
//! area:
//!
//! ```text
//! ½γ = ∫₀^{εβ} ½ρ² dφ  ⇔  (β/2)(R_{i+1}² − R_i²) ε² + βR_i² ε − γ = 0.
//! ```
//!
//! The stage inverts the marginal CDF in φ of the disk density; it preserves area pointwise
//! (dφ_C/dφ_B = 1/ρ², ∂r_C/∂r_B = ρ, so the area ratio is 1).

/// Area factor of the angular stage: dA_C = 1 · dA_B.
pub const ANGULAR_AREA: f64 = 1.0;

/// Area of the wedge of sector width `beta` between ε = 0 and `eps`, per unit ½ (that is, the angle
/// of the B-disk wedge with the same area): βR_a²ε + (β/2)(R_b² − R_a²)ε².
#[inline]
pub fn wedge_angle(beta: f64, r2a: f64, r2b: f64, eps: f64) -> f64 {
    beta * eps * (r2a + 0.5 * (r2b - r2a) * eps)
}

/// Solves [`wedge_angle`]`(beta, r2a, r2b, ε) = gamma` for ε ∈ [0, 1] with the cancellation-free
/// form ε = 2c / (b + √(b² + 4ac)), valid when a → 0, a < 0 and R_a = 0 (ALGORITHM §5, A13).
#[inline]
pub fn solve_wedge(beta: f64, r2a: f64, r2b: f64, gamma: f64) -> f64 {
    let a = 0.5 * beta * (r2b - r2a);
    let b = beta * r2a;
    let c = gamma.max(0.0);
    let den = b + (b * b + 4.0 * a * c).max(0.0).sqrt();
    if den > 0.0 {
        (2.0 * c / den).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// ρ² at fraction ε of a sector whose meridians have squared star radii `r2a`, `r2b`.
#[inline]
pub fn star_radius2(r2a: f64, r2b: f64, eps: f64) -> f64 {
    (1.0 - eps) * r2a + eps * r2b
}

/// dφ_C/dφ_B at a point of sector with star radius² `rho2` (unit B-disk): 1/ρ².
#[inline]
pub fn angular_derivative(rho2: f64) -> f64 {
    1.0 / rho2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_inverts_wedge_angle() {
        for &(beta, ra, rb) in &[
            (0.5, 1.0, 3.0),
            (0.5, 3.0, 1.0),
            (1.0, 0.0, 2.0),
            (1.0, 2.0, 0.0),
            (0.1, 1.0, 1.0),
            (2.0, 1e-12, 5.0),
        ] {
            for k in 0..=100 {
                let eps = k as f64 / 100.0;
                let g = wedge_angle(beta, ra, rb, eps);
                let e = solve_wedge(beta, ra, rb, g);
                assert!((e - eps).abs() < 1e-10, "{beta} {ra} {rb} {eps} -> {e}");
            }
        }
    }

    #[test]
    fn derivative_matches_finite_difference() {
        let (beta, ra, rb) = (0.7, 0.4, 2.5);
        for k in 1..100 {
            let eps = k as f64 / 100.0;
            let h = 1e-7;
            let g0 = wedge_angle(beta, ra, rb, eps - h);
            let g1 = wedge_angle(beta, ra, rb, eps + h);
            // dφ_C/dφ_B = β dε / dγ
            let fd = beta * 2.0 * h / (g1 - g0);
            let want = angular_derivative(star_radius2(ra, rb, eps));
            assert!((fd - want).abs() < 1e-6 * want);
        }
    }
}
