//! The MERL BRDF database's binary format (Matusik et al. 2003) and its resampling to a table of
//! incident slices.
//!
//! **File.** Three little-endian int32 dimensions (90, 90, 180), then three channel planes (R, G,
//! B) of 90·90·180 little-endian float64, indexed `(i_θh·90 + i_θd)·180 + i_φd` in the
//! half/difference angles of Rusinkiewicz: θ_h with the square-root index
//! i_θh = ⌊√(θ_h / 90°)·90⌋, θ_d with i_θd = ⌊θ_d / 90°·90⌋, φ_d folded into [0°, 180°) (φ_d and
//! φ_d + 180° are the same by reciprocity) with i_φd = ⌊φ_d / 180°·180⌋. A channel's f_r is the
//! stored value times [`MERL_SCALE`]; **negative values mean no data**.
//!
//! **Lookup** ([`MerlRaw::lookup`]): the stored values are read as samples at the cells' centres
//! (θ_h = ((k + ½)/90)²·90°, θ_d = (k + ½)°, φ_d = k + ½°) and interpolated trilinearly in index
//! space (clamped at θ_h, θ_d ends, periodic in φ_d with period 180°), over the neighbours that
//! have data (weights renormalised; 0 when none has).
//!
//! **Resampling** ([`MerlRaw::resample`], [`MerlOptions`]): the lookup at the nodes of an isotropic
//! (θ_i, θ_o, Δφ) grid, `n_theta` nodes 0°…90° for both polar angles and `n_phi` for Δφ ∈ [0°,
//! 360°). [`MerlRaw::resampling_error`] reports what that costs: the L1 distance between the
//! normalised f̄·cos θ_o of the table and of the lookup at θ_i = 0°, 30°, 60°, 75°, 85°.

use super::{uniform_phi, uniform_theta, BrdfError, Symmetry, TabulatedBrdf};
use crate::sampler::{direction, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// MERL's published channel scales: f_r = stored value × scale (R 1/1500, G 1.15/1500, B
/// 1.66/1500).
pub const MERL_SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

const DIMS: [usize; 3] = [90, 90, 180];
const CELLS: usize = 90 * 90 * 180;
const FORMAT: &str = "merl";

/// The resampling grid of a MERL file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MerlOptions {
    /// Polar nodes 0°…90° (incident and outgoing), ≥ 2. Default 46 (2°).
    pub n_theta: usize,
    /// Relative azimuth nodes in [0°, 360°), ≥ 1. Default 90 (4°).
    pub n_phi: usize,
}

impl Default for MerlOptions {
    fn default() -> Self {
        MerlOptions {
            n_theta: 46,
            n_phi: 90,
        }
    }
}

/// A MERL file as stored: three planes of f_r (scaled, negative = no data).
#[derive(Debug, Clone)]
pub struct MerlRaw {
    /// Scaled values, plane-major (R, G, B), negative where the file has no data.
    values: Vec<f64>,
    no_data: usize,
}

fn rotate(v: Vec3, axis: Vec3, angle: f64) -> Vec3 {
    let (s, c) = angle.sin_cos();
    let d = axis[0] * v[0] + axis[1] * v[1] + axis[2] * v[2];
    let cr = [
        axis[1] * v[2] - axis[2] * v[1],
        axis[2] * v[0] - axis[0] * v[2],
        axis[0] * v[1] - axis[1] * v[0],
    ];
    [
        v[0] * c + axis[0] * d * (1.0 - c) + cr[0] * s,
        v[1] * c + axis[1] * d * (1.0 - c) + cr[1] * s,
        v[2] * c + axis[2] * d * (1.0 - c) + cr[2] * s,
    ]
}

/// (θ_h, θ_d, φ_d) of a pair of directions (Rusinkiewicz's half/difference angles), φ_d ∈ (−π, π].
pub fn half_diff(wi: Vec3, wo: Vec3) -> Option<(f64, f64, f64)> {
    let h = crate::sampler::normalize([wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]])?;
    let th = h[2].clamp(-1.0, 1.0).acos();
    let ph = h[1].atan2(h[0]);
    let d = rotate(rotate(wi, [0.0, 0.0, 1.0], -ph), [0.0, 1.0, 0.0], -th);
    Some((th, d[2].clamp(-1.0, 1.0).acos(), d[1].atan2(d[0])))
}

/// The directions (ω_i, ω_o) of half/difference angles (φ_h = 0).
pub fn from_half_diff(th: f64, td: f64, pd: f64) -> (Vec3, Vec3) {
    let d = direction(td, pd);
    let wi = rotate(d, [0.0, 1.0, 0.0], th);
    let h = direction(th, 0.0);
    let c = wi[0] * h[0] + wi[1] * h[1] + wi[2] * h[2];
    let wo = [
        2.0 * c * h[0] - wi[0],
        2.0 * c * h[1] - wi[1],
        2.0 * c * h[2] - wi[2],
    ];
    (wi, wo)
}

/// Continuous cell coordinates of half/difference angles (cell centres at integers).
fn coords(th: f64, td: f64, pd: f64) -> [f64; 3] {
    let pd = if pd < 0.0 { pd + PI } else { pd };
    [
        (th.max(0.0) / FRAC_PI_2).sqrt() * 90.0 - 0.5,
        td / FRAC_PI_2 * 90.0 - 0.5,
        pd / PI * 180.0 - 0.5,
    ]
}

impl MerlRaw {
    /// Parses a MERL file: header, size (checked before anything is allocated), values (NaN and
    /// infinities refused with their index and byte offset).
    pub fn parse(bytes: &[u8]) -> Result<Self, BrdfError> {
        if bytes.len() < 12 {
            return Err(BrdfError::Size {
                format: FORMAT,
                expected: 12,
                found: bytes.len() as u64,
                what: "the header of three int32 dimensions".into(),
            });
        }
        for (k, &want) in DIMS.iter().enumerate() {
            let v = i32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap());
            if v as i64 != want as i64 {
                return Err(BrdfError::Header {
                    format: FORMAT,
                    offset: 4 * k as u64,
                    what: format!(
                        "dimension {} is {v}, expected {want} (90 θ_h × 90 θ_d × 180 φ_d)",
                        k + 1
                    ),
                });
            }
        }
        let expected = 12 + 3 * CELLS as u64 * 8;
        if bytes.len() as u64 != expected {
            return Err(BrdfError::Size {
                format: FORMAT,
                expected,
                found: bytes.len() as u64,
                what: "3 planes of 90·90·180 float64 after the header".into(),
            });
        }
        let mut values = Vec::with_capacity(3 * CELLS);
        let mut no_data = 0;
        for (index, chunk) in bytes[12..].chunks_exact(8).enumerate() {
            let v = f64::from_le_bytes(chunk.try_into().unwrap());
            if !v.is_finite() {
                return Err(BrdfError::BadValue {
                    format: FORMAT,
                    index,
                    offset: 12 + 8 * index as u64,
                    value: v,
                    hint: "",
                });
            }
            if v < 0.0 {
                no_data += 1;
                values.push(-1.0);
            } else {
                values.push(v * MERL_SCALE[index / CELLS]);
            }
        }
        if !values.iter().any(|&v| v > 0.0) {
            return Err(BrdfError::NoReflectance { format: FORMAT });
        }
        Ok(MerlRaw { values, no_data })
    }

    /// Number of stored values marked as no data (negative).
    pub fn no_data(&self) -> usize {
        self.no_data
    }

    /// f_r per channel at a pair of directions (see the module documentation); 0 below the
    /// horizon.
    pub fn lookup(&self, wi: Vec3, wo: Vec3) -> [f64; 3] {
        if !(wi[2] >= 0.0 && wo[2] >= 0.0) {
            return [0.0; 3];
        }
        let Some((th, td, pd)) = half_diff(wi, wo) else {
            return [0.0; 3];
        };
        let c = coords(th, td, pd);
        let mut idx = [[0usize; 2]; 3];
        let mut t = [0.0; 3];
        for a in 0..2 {
            let x = c[a].clamp(0.0, 89.0);
            let k = (x.floor() as usize).min(88);
            idx[a] = [k, k + 1];
            t[a] = x - k as f64;
        }
        let x = c[2].rem_euclid(180.0);
        let k = (x.floor() as usize).min(179);
        idx[2] = [k, (k + 1) % 180];
        t[2] = x - k as f64;
        let mut out = [0.0; 3];
        for (ch, o) in out.iter_mut().enumerate() {
            let (mut acc, mut wsum) = (0.0, 0.0);
            for a in 0..2 {
                for b in 0..2 {
                    for p in 0..2 {
                        let w = (if a == 0 { 1.0 - t[0] } else { t[0] })
                            * (if b == 0 { 1.0 - t[1] } else { t[1] })
                            * (if p == 0 { 1.0 - t[2] } else { t[2] });
                        if w == 0.0 {
                            continue;
                        }
                        let v = self.values
                            [ch * CELLS + (idx[0][a] * 90 + idx[1][b]) * 180 + idx[2][p]];
                        if v >= 0.0 {
                            acc += w * v;
                            wsum += w;
                        }
                    }
                }
            }
            *o = if wsum > 0.0 { acc / wsum } else { 0.0 };
        }
        out
    }

    /// The isotropic table of the lookup at the nodes of `options`' grid.
    pub fn resample(&self, options: &MerlOptions) -> Result<TabulatedBrdf, BrdfError> {
        if options.n_theta < 2 || options.n_phi < 1 {
            return Err(BrdfError::Shape {
                expected: 2,
                found: options.n_theta.min(options.n_phi),
                what: "MERL resampling grid: at least 2 θ and 1 φ nodes".into(),
            });
        }
        TabulatedBrdf::from_fn(
            Symmetry::Isotropic,
            3,
            uniform_theta(options.n_theta, 90.0),
            vec![0.0],
            uniform_theta(options.n_theta, 90.0),
            uniform_phi(options.n_phi),
            |ti, _, to, dp| self.lookup(direction(ti, 0.0), direction(to, dp)),
        )
    }

    /// The resampling error of `table` (made by [`MerlRaw::resample`]): the mean over θ_i = 0°,
    /// 30°, 60°, 75°, 85° of ∫ |p_table − p_lookup| dω_o, p the normalised f̄·cos θ_o (luminance), by a
    /// 64 × 128 midpoint quadrature. 0 = identical, 2 = disjoint.
    pub fn resampling_error(&self, table: &TabulatedBrdf) -> f64 {
        let n = 64;
        let mut total = 0.0;
        let angles = [0.0f64, 30.0, 60.0, 75.0, 85.0];
        for &t in &angles {
            let wi = direction(t.to_radians(), 0.0);
            let grid = super::scalar_albedo_grid(table, wi, n);
            let raw: Vec<f64> = grid
                .iter()
                .map(|&(wo, _)| table.scalar(self.lookup(wi, wo)) * wo[2])
                .collect();
            let (sa, sb): (f64, f64) = (grid.iter().map(|g| g.1).sum(), raw.iter().sum());
            if sa > 0.0 && sb > 0.0 {
                total += grid
                    .iter()
                    .zip(&raw)
                    .map(|(g, r)| (g.1 / sa - r / sb).abs())
                    .sum::<f64>();
            } else if sa > 0.0 || sb > 0.0 {
                total += 2.0;
            }
        }
        total / angles.len() as f64
    }
}

/// Reads a MERL file and resamples it ([`MerlRaw::parse`], [`MerlRaw::resample`]).
pub fn read_merl(bytes: &[u8], options: &MerlOptions) -> Result<TabulatedBrdf, BrdfError> {
    MerlRaw::parse(bytes)?.resample(options)
}

/// Writes a MERL file of `f(ω_i, ω_o) → [R, G, B]` (f_r in 1/sr), evaluated at the cells' centres
/// (see the module documentation); cells whose directions fall below the horizon hold −1 (no
/// data), as the database's files do.
pub fn write_merl(f: impl Fn(Vec3, Vec3) -> [f64; 3]) -> Vec<u8> {
    let mut out = Vec::with_capacity(12 + 24 * CELLS);
    for d in DIMS {
        out.extend_from_slice(&(d as i32).to_le_bytes());
    }
    let mut planes = vec![0.0f64; 3 * CELLS];
    for ih in 0..90 {
        let th = ((ih as f64 + 0.5) / 90.0).powi(2) * FRAC_PI_2;
        for id in 0..90 {
            let td = (id as f64 + 0.5) / 90.0 * FRAC_PI_2;
            for ip in 0..180 {
                let pd = (ip as f64 + 0.5) / 180.0 * PI;
                let (wi, wo) = from_half_diff(th, td, pd);
                let cell = (ih * 90 + id) * 180 + ip;
                let v = if wi[2] >= 0.0 && wo[2] >= 0.0 {
                    Some(f(wi, wo))
                } else {
                    None
                };
                for c in 0..3 {
                    planes[c * CELLS + cell] = match v {
                        Some(v) => v[c] / MERL_SCALE[c],
                        None => -1.0,
                    };
                }
            }
        }
    }
    for v in planes {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}
