//! The UTIA BTF database's BRDF format (Filip & Vávra): raw little-endian float64, 3 planes
//! (R, G, B) × 6 θ_i × 48 φ_i × 6 θ_v × 48 φ_v, θ in 15° steps 0°…75°, φ in 7.5° steps, value
//! index `plane·288² + 288·(48·i_θi + i_φi) + 48·i_θv + i_φv`.
//!
//! **Decoding**, as the database's own reader does: negative values clamped to 0, divided by 140,
//! the sRGB transfer undone (v ≤ 0.0375: v / 12.92, else ((v + 0.055)/1.055)^2.4), times 100.
//! There is no data beyond 75°: the table's θ_o grid ends there, so f_r is 0 beyond it
//! ([`super::TabulatedBrdf::eval`]), and θ_i beyond 75° uses the 75° slices (clamped).
//! [`write_utia`] encodes exactly the inverse, so analytic files round-trip.

use super::{uniform_phi, BrdfError, Symmetry, TabulatedBrdf};
use crate::sampler::direction;

/// Size in bytes of a UTIA file: 3 · 288² float64.
pub const UTIA_SIZE: u64 = 3 * 288 * 288 * 8;
const FORMAT: &str = "utia";
const THRESHOLD: f64 = 0.0375;

fn decode(v: f64) -> f64 {
    let v = v.max(0.0) / 140.0;
    let lin = if v <= THRESHOLD {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    };
    lin * 100.0
}

fn encode(f: f64) -> f64 {
    let g = f.max(0.0) / 100.0;
    let v = if g * 12.92 <= THRESHOLD {
        g * 12.92
    } else {
        1.055 * g.powf(1.0 / 2.4) - 0.055
    };
    v * 140.0
}

fn theta_grid() -> Vec<f64> {
    (0..6).map(|k| (15.0 * k as f64).to_radians()).collect()
}

/// Reads a UTIA file into an anisotropic table on its own grid (see the module documentation).
pub fn read_utia(bytes: &[u8]) -> Result<TabulatedBrdf, BrdfError> {
    if bytes.len() as u64 != UTIA_SIZE {
        return Err(BrdfError::Size {
            format: FORMAT,
            expected: UTIA_SIZE,
            found: bytes.len() as u64,
            what: "3 planes × 6 θ_i × 48 φ_i × 6 θ_v × 48 φ_v float64".into(),
        });
    }
    let mut values = Vec::with_capacity(3 * 288 * 288);
    for (index, chunk) in bytes.chunks_exact(8).enumerate() {
        let v = f64::from_le_bytes(chunk.try_into().unwrap());
        if !v.is_finite() {
            return Err(BrdfError::BadValue {
                format: FORMAT,
                index,
                offset: 8 * index as u64,
                value: v,
                hint: "",
            });
        }
        values.push(decode(v));
    }
    if !values.iter().any(|&v| v > 0.0) {
        return Err(BrdfError::NoReflectance { format: FORMAT });
    }
    // The file's order (plane, θ_i, φ_i, θ_v, φ_v) is the table's order.
    TabulatedBrdf::new(
        Symmetry::Anisotropic,
        3,
        theta_grid(),
        uniform_phi(48),
        theta_grid(),
        uniform_phi(48),
        values,
    )
}

/// Writes a UTIA file of `f(θ_i, φ_i, θ_v, φ_v) → [R, G, B]` (radians, f_r in 1/sr) at the
/// database's nodes, encoded as the inverse of the decoding.
pub fn write_utia(f: impl Fn(f64, f64, f64, f64) -> [f64; 3]) -> Vec<u8> {
    let (t, p) = (theta_grid(), uniform_phi(48));
    let mut planes = vec![0.0f64; 3 * 288 * 288];
    for (a, &ti) in t.iter().enumerate() {
        for (b, &pi) in p.iter().enumerate() {
            for (c, &tv) in t.iter().enumerate() {
                for (d, &pv) in p.iter().enumerate() {
                    let v = f(ti, pi, tv, pv);
                    for (ch, x) in v.iter().enumerate() {
                        planes[ch * 288 * 288 + 288 * (48 * a + b) + 48 * c + d] = encode(*x);
                    }
                }
            }
        }
    }
    let mut out = Vec::with_capacity(UTIA_SIZE as usize);
    for v in planes {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// [`write_utia`] of an analytic BRDF given as `f(ω_i, ω_o)`.
pub fn write_utia_dirs(f: impl Fn(crate::Vec3, crate::Vec3) -> [f64; 3]) -> Vec<u8> {
    write_utia(|ti, pi, tv, pv| f(direction(ti, pi), direction(tv, pv)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encoding_round_trips() {
        for k in 0..2000 {
            let f = 1e-4 * 1.01f64.powi(k);
            let back = decode(encode(f));
            assert!((back - f).abs() <= 1e-12 * f.max(1e-3), "{f} -> {back}");
        }
        assert_eq!(decode(-5.0), 0.0);
    }
}
