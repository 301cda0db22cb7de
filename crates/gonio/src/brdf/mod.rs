//! Tabulated BRDFs (issue 26): measured or generated reflectance f_r(ω_i, ω_o) on a grid of angles,
//! its readers and writers (MERL binary, UTIA raw, a self-describing JSON table), analytic
//! generators for tests, and exact importance sampling of f_r·cos θ_o through the HDS map of the
//! slice diagram blended between the tabulated incident directions ([`BrdfSampler`]).
//!
//! **Frame.** The local shading frame: z is the surface normal, x the tangent, y = z × x. Both
//! directions point **away from the surface** (ω_i towards the light, ω_o towards the viewer), so a
//! mirror reflects (θ, φ) to (θ, φ + π). θ is measured from +z, φ from +x towards +y, as in the rest
//! of the crate ([`crate::sampler::spherical`]). f_r is in **1/sr**; one or three channels (R, G,
//! B). Reciprocity is not assumed.
//!
//! **Grids.** A table holds f_r at the nodes of
//! * isotropic: (θ_i, θ_o, Δφ) with Δφ = φ_o − φ_i (mod 2π);
//! * anisotropic: (θ_i, φ_i, θ_o, φ_o), φ_o absolute.
//!
//! θ nodes strictly increasing in [0°, 90°], φ nodes strictly increasing in [0°, 360°) (periodic).
//! Values are stored channel-major: `values[((c·A + a)·B + b)·P + p]` with a the incident node
//! (θ_i index × number of φ_i + φ_i index), b the θ_o index, p the φ_o index.
//!
//! **Interpolation** ([`TabulatedBrdf::eval`]): multilinear in (θ_i, φ_i, θ_o, φ_o) (Δφ for
//! isotropic tables), periodic in the azimuths; θ_i outside the tabulated range is clamped to its
//! ends (the last slice holds beyond it); θ_o outside [θ_o,first, θ_o,last] gives 0 (no data, e.g.
//! UTIA beyond 75°); a direction below the horizon gives 0.

mod analytic;
mod baselines;
mod json;
mod merl;
mod sampler;
mod utia;

#[cfg(test)]
mod tests;

pub use analytic::Analytic;
pub use baselines::{BrdfMethod, CosineBrdf, GgxFit, IncidentSampler, PerSliceConstant};
pub use json::{read_json, write_json, BrdfJson};
pub use merl::{
    from_half_diff, half_diff, read_merl, write_merl, MerlOptions, MerlRaw, MERL_SCALE,
};
pub use sampler::{scalar_albedo, BrdfSample, BrdfSampler, SamplerOptions};
pub use utia::{read_utia, write_utia, write_utia_dirs, UTIA_SIZE};

use crate::sampler::{spherical, Vec3};
use std::f64::consts::{FRAC_PI_2, TAU};

/// Largest number of values a table may hold (3 channels included): 2²⁷ (1 GiB of f64).
pub const MAX_VALUES: usize = 1 << 27;

/// The largest BRDF value a table may hold, `f64::MAX`/16 ≈ 1.12e307: the albedo (≤ π × the
/// largest value) and the sample weights of any table stay finite (issue 40: a table of 1.7e308
/// gave albedo `inf` and infinite weights).
pub const MAX_VALUE: f64 = f64::MAX / 16.0;

/// Whether the table depends on the incident azimuth.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Symmetry {
    /// f depends on (θ_i, θ_o, φ_o − φ_i).
    Isotropic,
    /// f depends on (θ_i, φ_i, θ_o, φ_o).
    Anisotropic,
}

/// Why a BRDF file or table was refused. Every variant says what and where.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BrdfError {
    /// The file is shorter or longer than its header says.
    #[error("{format}: the file has {found} bytes, expected {expected} ({what})")]
    Size {
        /// The format read.
        format: &'static str,
        /// Bytes expected.
        expected: u64,
        /// Bytes present.
        found: u64,
        /// What was being read.
        what: String,
    },
    /// A header field is out of range.
    #[error("{format}: byte {offset}: {what}")]
    Header {
        /// The format read.
        format: &'static str,
        /// Byte offset of the field.
        offset: u64,
        /// What is wrong.
        what: String,
    },
    /// A value is NaN or infinite (or negative where the format has no "no data" code).
    #[error("{format}: value #{index} (byte {offset}) = {} is not a finite number{hint}", crate::decimal::shortest(*value))]
    BadValue {
        /// The format read.
        format: &'static str,
        /// Index of the value in the file's order.
        index: usize,
        /// Byte offset (0 for text formats).
        offset: u64,
        /// The value.
        value: f64,
        /// Extra words.
        hint: &'static str,
    },
    /// The file holds no reflectance at all (every value zero or "no data").
    #[error("{format}: the file holds no reflectance (every value is zero or marked as no data)")]
    NoReflectance {
        /// The format read.
        format: &'static str,
    },
    /// An angle grid is not valid.
    #[error("{axis}: angle #{index} = {value_deg}° {what}")]
    Grid {
        /// Which grid (`theta_i`, `phi_i`, `theta_o`, `phi_o`).
        axis: &'static str,
        /// Index of the angle.
        index: usize,
        /// The angle in degrees.
        value_deg: f64,
        /// What is wrong.
        what: &'static str,
    },
    /// The value table does not match the grid.
    #[error("values: expected {expected} entries ({what}), found {found}")]
    Shape {
        /// Entries expected.
        expected: usize,
        /// Entries found.
        found: usize,
        /// The grid, in words.
        what: String,
    },
    /// JSON syntax or schema error (1-based line and column).
    #[error("json {line}:{column}: {message}")]
    Json {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What serde_json said.
        message: String,
    },
    /// The file was not read (not a regular file, over the BRDF limit, missing: the one file
    /// reader's message, [`crate::input::file`]).
    #[error(transparent)]
    File(#[from] crate::input::file::ReadFileError),
    /// A family blob ([`from_tables`]) refused: the table reader's message.
    #[error("{0}")]
    Tables(String),
    /// The format was not recognised from the content.
    #[error(
        "not a BRDF file this library reads (MERL .binary, UTIA .bin or gonio BRDF JSON): {why}"
    )]
    UnknownFormat {
        /// What was seen.
        why: String,
    },
}

/// A tabulated BRDF: see the [module documentation](self) for frame, grids and interpolation.
#[derive(Debug, Clone, PartialEq)]
pub struct TabulatedBrdf {
    symmetry: Symmetry,
    channels: usize,
    theta_i: Vec<f64>,
    phi_i: Vec<f64>,
    theta_o: Vec<f64>,
    phi_o: Vec<f64>,
    values: Vec<f64>,
}

fn check_axis(axis: &'static str, a: &[f64], theta: bool) -> Result<(), BrdfError> {
    if a.is_empty() {
        return Err(BrdfError::Grid {
            axis,
            index: 0,
            value_deg: f64::NAN,
            what: "missing: the grid needs at least one node",
        });
    }
    for (index, &v) in a.iter().enumerate() {
        let value_deg = v.to_degrees();
        let bad = |what| BrdfError::Grid {
            axis,
            index,
            value_deg,
            what,
        };
        if !v.is_finite() {
            return Err(bad("is not finite"));
        }
        if theta && !(0.0..=FRAC_PI_2 * (1.0 + 1e-12)).contains(&v) {
            return Err(bad("is outside [0°, 90°]"));
        }
        if !theta && !(0.0..TAU).contains(&v) {
            return Err(bad("is outside [0°, 360°)"));
        }
        if index > 0 && !(v > a[index - 1]) {
            return Err(bad(
                "does not follow its predecessor (angles must increase strictly)",
            ));
        }
    }
    Ok(())
}

/// Linear weights of `x` on the non-periodic grid `a`, clamped to its ends: (j0, j1, t).
fn clamped(a: &[f64], x: f64) -> (usize, usize, f64) {
    let n = a.len();
    if n == 1 || !(x > a[0]) {
        return (0, 0, 0.0);
    }
    if x >= a[n - 1] {
        return (n - 1, n - 1, 0.0);
    }
    let j = interval(a, x, a[0], a[n - 1]);
    (j, j + 1, (x - a[j]) / (a[j + 1] - a[j]))
}

/// Linear weights of azimuth `x` (any real) on the periodic grid `a` ⊂ [0, 2π): (i0, i1, t).
fn periodic(a: &[f64], x: f64) -> (usize, usize, f64) {
    let m = a.len();
    let x = x.rem_euclid(TAU);
    if m == 1 {
        return (0, 0, 0.0);
    }
    if x < a[0] || x >= a[m - 1] {
        let (lo, hi) = (a[m - 1], a[0] + TAU);
        let xx = if x < a[0] { x + TAU } else { x };
        return (m - 1, 0, ((xx - lo) / (hi - lo)).clamp(0.0, 1.0));
    }
    let i = interval(a, x, a[0], a[m - 1]);
    (i, i + 1, (x - a[i]) / (a[i + 1] - a[i]))
}

/// The index j with a[j] ≤ x < a[j + 1] on the increasing grid `a` (n ≥ 2) for
/// a[0] ≤ x < a[n − 1] = `hi` (`lo` = a[0]): the largest node ≤ x, as a binary search finds it.
/// The guess of a uniform grid is tried first (direct index, exact on uniform grids and on most
/// cells of nearly uniform ones); a wrong guess falls back to the binary search.
#[inline]
fn interval(a: &[f64], x: f64, lo: f64, hi: f64) -> usize {
    let n = a.len();
    let g = ((x - lo) / (hi - lo) * (n - 1) as f64) as usize;
    let g = g.min(n - 2);
    if a[g] <= x && x < a[g + 1] {
        return g;
    }
    a.partition_point(|&v| v <= x) - 1
}

/// Luminance weights of three channels (Rec. 709 / sRGB primaries), the scalar the sampler follows.
pub const LUMINANCE: [f64; 3] = [0.2126, 0.7152, 0.0722];

impl TabulatedBrdf {
    /// A table from its grids (radians) and values (see the module documentation for the order).
    /// For an isotropic table `phi_i` must be `[0.0]` and `phi_o` holds Δφ = φ_o − φ_i. Values must
    /// be finite and ≥ 0.
    pub fn new(
        symmetry: Symmetry,
        channels: usize,
        theta_i: Vec<f64>,
        phi_i: Vec<f64>,
        theta_o: Vec<f64>,
        phi_o: Vec<f64>,
        values: Vec<f64>,
    ) -> Result<Self, BrdfError> {
        if channels != 1 && channels != 3 {
            return Err(BrdfError::Shape {
                expected: 3,
                found: channels,
                what: "channels: 1 or 3".into(),
            });
        }
        check_axis("theta_i", &theta_i, true)?;
        check_axis("phi_i", &phi_i, false)?;
        check_axis("theta_o", &theta_o, true)?;
        check_axis("phi_o", &phi_o, false)?;
        if symmetry == Symmetry::Isotropic && phi_i != [0.0] {
            return Err(BrdfError::Grid {
                axis: "phi_i",
                index: 0,
                value_deg: phi_i[0].to_degrees(),
                what: "an isotropic table has the single incident azimuth 0°",
            });
        }
        let expected = [theta_i.len(), phi_i.len(), theta_o.len(), phi_o.len()]
            .iter()
            .try_fold(channels, |a, &b| a.checked_mul(b))
            .filter(|&n| n <= MAX_VALUES);
        let what = format!(
            "{channels} channels × {} θ_i × {} φ_i × {} θ_o × {} φ_o",
            theta_i.len(),
            phi_i.len(),
            theta_o.len(),
            phi_o.len()
        );
        let Some(expected) = expected else {
            return Err(BrdfError::Shape {
                expected: MAX_VALUES,
                found: usize::MAX,
                what: format!("{what}: more than the limit"),
            });
        };
        if values.len() != expected {
            return Err(BrdfError::Shape {
                expected,
                found: values.len(),
                what,
            });
        }
        if let Some((index, &value)) = values
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && **v >= 0.0 && **v <= MAX_VALUE))
        {
            return Err(BrdfError::BadValue {
                format: "table",
                index,
                offset: 0,
                value,
                hint: " in [0, 1.1235582092889474e307] (f64::MAX/16: larger values overflow the albedo and the sample weights)",
            });
        }
        Ok(TabulatedBrdf {
            symmetry,
            channels,
            theta_i,
            phi_i,
            theta_o,
            phi_o,
            values,
        })
    }

    /// Isotropic or anisotropic.
    pub fn symmetry(&self) -> Symmetry {
        self.symmetry
    }
    /// 1 or 3.
    pub fn channels(&self) -> usize {
        self.channels
    }
    /// Incident polar angles (radians).
    pub fn theta_i(&self) -> &[f64] {
        &self.theta_i
    }
    /// Incident azimuths (radians; `[0]` for isotropic tables).
    pub fn phi_i(&self) -> &[f64] {
        &self.phi_i
    }
    /// Outgoing polar angles (radians).
    pub fn theta_o(&self) -> &[f64] {
        &self.theta_o
    }
    /// Outgoing azimuths (radians): φ_o − φ_i for isotropic tables, φ_o for anisotropic ones.
    pub fn phi_o(&self) -> &[f64] {
        &self.phi_o
    }
    /// The values, in the order of the module documentation.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
    /// Bytes held by the table's vectors.
    pub fn memory_bytes(&self) -> usize {
        8 * (self.values.len()
            + self.theta_i.len()
            + self.phi_i.len()
            + self.theta_o.len()
            + self.phi_o.len())
    }

    #[inline]
    fn at(&self, c: usize, a: usize, b: usize, p: usize) -> f64 {
        let (na, nb, np) = (
            self.theta_i.len() * self.phi_i.len(),
            self.theta_o.len(),
            self.phi_o.len(),
        );
        self.values[((c * na + a) * nb + b) * np + p]
    }

    /// f_r per channel at angles (radians): θ_i, φ_i, θ_o, φ_o (absolute azimuths), with the
    /// interpolation of the module documentation. Channels beyond [`TabulatedBrdf::channels`]
    /// repeat the first.
    pub fn eval_angles(&self, theta_i: f64, phi_i: f64, theta_o: f64, phi_o: f64) -> [f64; 3] {
        let no = self.theta_o.len();
        let (t0, t1) = (self.theta_o[0], self.theta_o[no - 1]);
        if !(theta_o >= t0 - 1e-12 && theta_o <= t1 + 1e-12 && theta_i >= 0.0) {
            return [0.0; 3];
        }
        let (a0, a1, ta) = clamped(&self.theta_i, theta_i);
        let (b0, b1, tb) = clamped(&self.theta_o, theta_o);
        let (q, az) = match self.symmetry {
            Symmetry::Isotropic => ((0, 0, 0.0), phi_o - phi_i),
            Symmetry::Anisotropic => (periodic(&self.phi_i, phi_i), phi_o),
        };
        let (p0, p1, tp) = periodic(&self.phi_o, az);
        let np = self.phi_i.len();
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate().take(self.channels) {
            let mut acc = 0.0;
            for (a, wa) in [(a0, 1.0 - ta), (a1, ta)] {
                if wa == 0.0 {
                    continue;
                }
                for (qi, wq) in [(q.0, 1.0 - q.2), (q.1, q.2)] {
                    if wq == 0.0 {
                        continue;
                    }
                    let inc = a * np + qi;
                    let row = |b: usize| {
                        (1.0 - tp) * self.at(c, inc, b, p0) + tp * self.at(c, inc, b, p1)
                    };
                    acc += wa * wq * ((1.0 - tb) * row(b0) + tb * row(b1));
                }
            }
            *o = acc.max(0.0);
        }
        if self.channels == 1 {
            out = [out[0]; 3];
        }
        out
    }

    /// f_r per channel (1/sr) for unit directions ω_i, ω_o in the local frame (both pointing away
    /// from the surface); 0 when either lies below the horizon.
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> [f64; 3] {
        if !(wi[2] >= 0.0 && wo[2] >= 0.0) {
            return [0.0; 3];
        }
        let (ti, pi) = spherical(wi);
        let (to, po) = spherical(wo);
        self.eval_angles(ti, pi, to, po)
    }

    /// The scalar the sampler follows: f_r itself for one channel, its luminance
    /// ([`LUMINANCE`]) for three.
    pub fn scalar(&self, f: [f64; 3]) -> f64 {
        if self.channels == 1 {
            f[0]
        } else {
            LUMINANCE[0] * f[0] + LUMINANCE[1] * f[1] + LUMINANCE[2] * f[2]
        }
    }

    /// A table of `f(θ_i, φ_i, θ_o, φ_o) → [R, G, B]` (absolute azimuths, radians) at the nodes of
    /// the given grids; for isotropic tables φ_i = 0 and `phi_o` is Δφ.
    #[allow(clippy::too_many_arguments)]
    pub fn from_fn(
        symmetry: Symmetry,
        channels: usize,
        theta_i: Vec<f64>,
        phi_i: Vec<f64>,
        theta_o: Vec<f64>,
        phi_o: Vec<f64>,
        f: impl Fn(f64, f64, f64, f64) -> [f64; 3],
    ) -> Result<Self, BrdfError> {
        let total = [theta_i.len(), phi_i.len(), theta_o.len(), phi_o.len()]
            .iter()
            .try_fold(channels.max(1), |a, &b| a.checked_mul(b))
            .unwrap_or(usize::MAX);
        if total > MAX_VALUES {
            return Err(BrdfError::Shape {
                expected: MAX_VALUES,
                found: total,
                what: "more values than the limit".into(),
            });
        }
        let mut values = vec![0.0; total];
        let na = theta_i.len() * phi_i.len();
        let (nb, np) = (theta_o.len(), phi_o.len());
        for (ti_i, &ti) in theta_i.iter().enumerate() {
            for (pi_i, &pi) in phi_i.iter().enumerate() {
                let a = ti_i * phi_i.len() + pi_i;
                for (b, &to) in theta_o.iter().enumerate() {
                    for (p, &po) in phi_o.iter().enumerate() {
                        let po_abs = match symmetry {
                            Symmetry::Isotropic => po,
                            Symmetry::Anisotropic => po,
                        };
                        let v = f(ti, pi, to, po_abs);
                        for c in 0..channels.min(3) {
                            values[((c * na + a) * nb + b) * np + p] = v[c];
                        }
                    }
                }
            }
        }
        Self::new(symmetry, channels, theta_i, phi_i, theta_o, phi_o, values)
    }
}

/// The BRDF table and the validated family of a family blob ([`BrdfSampler::tables`]): the
/// table as [`TabulatedBrdf::new`] checks it, and every slice's map.
///
/// # Errors
/// [`BrdfError::Tables`] for a blob [`crate::mapping::blob::read_family`] refuses or whose table
/// [`TabulatedBrdf::new`] refuses.
pub fn from_tables(
    bytes: &[u8],
) -> Result<(TabulatedBrdf, crate::mapping::blob::FamilyTables), BrdfError> {
    let t =
        crate::mapping::blob::read_family(bytes).map_err(|e| BrdfError::Tables(e.to_string()))?;
    let sym = if t.anisotropic {
        Symmetry::Anisotropic
    } else {
        Symmetry::Isotropic
    };
    let brdf = TabulatedBrdf::new(
        sym,
        t.channels,
        t.theta_i.clone(),
        t.phi_i.clone(),
        t.theta_o.clone(),
        t.phi_o.clone(),
        t.values.clone(),
    )
    .map_err(|e| BrdfError::Tables(format!("its BRDF table: {e}")))?;
    Ok((brdf, t))
}

/// `n` angles from 0° to `max_deg` inclusive, in radians.
pub fn uniform_theta(n: usize, max_deg: f64) -> Vec<f64> {
    let n = n.max(2);
    (0..n)
        .map(|j| (max_deg * j as f64 / (n - 1) as f64).to_radians())
        .collect()
}

/// `m` azimuths from 0° in steps of 360°/m, in radians.
pub fn uniform_phi(m: usize) -> Vec<f64> {
    let m = m.max(1);
    (0..m).map(|i| TAU * i as f64 / m as f64).collect()
}

/// `bytes` without a UTF-8 byte order mark (as some editors write) when what follows is a JSON
/// object; `bytes` as they are otherwise (a binary file is never shortened).
pub fn strip_json_bom(bytes: &[u8]) -> &[u8] {
    match bytes.strip_prefix(b"\xEF\xBB\xBF") {
        Some(rest) if rest.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{') => rest,
        _ => bytes,
    }
}

/// Reads a BRDF file of any supported format, recognised from its content: gonio JSON (text
/// starting with `{`), UTIA (exactly [`UTIA_SIZE`] bytes), MERL (a 12-byte header whose three
/// int32 dimensions match the file's length). `merl` sets the MERL resampling.
pub fn read_any(bytes: &[u8], merl: &MerlOptions) -> Result<TabulatedBrdf, BrdfError> {
    let bytes = strip_json_bom(bytes);
    let first = bytes.iter().find(|b| !b.is_ascii_whitespace());
    if first == Some(&b'{') {
        let text = std::str::from_utf8(bytes).map_err(|e| BrdfError::Json {
            line: 1,
            column: 1,
            message: format!("not UTF-8 text: {e}"),
        })?;
        return read_json(text);
    }
    if bytes.len() as u64 == UTIA_SIZE {
        return read_utia(bytes);
    }
    if bytes.len() >= 12 {
        let dim = |k: usize| i32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap());
        let (a, b, c) = (dim(0) as i64, dim(1) as i64, dim(2) as i64);
        // i64 holds 24·(2³¹)³ only with checks: garbage headers must not overflow.
        let length = a
            .checked_mul(b)
            .and_then(|ab| ab.checked_mul(c))
            .and_then(|abc| abc.checked_mul(24))
            .and_then(|n| n.checked_add(12));
        if a > 0 && b > 0 && c > 0 && length == Some(bytes.len() as i64) {
            return read_merl(bytes, merl);
        }
        if (a, b, c) == (90, 90, 180) {
            // A MERL header with the wrong length: let the reader say what is missing.
            return read_merl(bytes, merl);
        }
    }
    Err(BrdfError::UnknownFormat {
        why: format!(
            "{} bytes, neither JSON, nor {UTIA_SIZE} bytes (UTIA), nor a MERL header matching the length",
            bytes.len()
        ),
    })
}

/// Reads a BRDF file from disk ([`read_any`]).
pub fn read_file(path: &std::path::Path, merl: &MerlOptions) -> Result<TabulatedBrdf, BrdfError> {
    let bytes = crate::input::file::read_file(path, crate::input::file::FileKind::Brdf)?;
    read_any(&bytes, merl)
}

/// The midpoint quadrature points of ∫ f̄ cos θ_o dω_o in (cos θ_o, φ_o) on n × 2n cells, each with
/// its value f̄(ω_i, ω_o)·cos θ_o (every cell has solid angle 2π / 2n²).
pub(crate) fn scalar_albedo_grid(brdf: &TabulatedBrdf, wi: Vec3, n: usize) -> Vec<(Vec3, f64)> {
    let n = n.max(4);
    let mut out = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        let z = (j as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for i in 0..2 * n {
            let p = TAU * (i as f64 + 0.5) / (2 * n) as f64;
            let wo = [r * p.cos(), r * p.sin(), z];
            out.push((wo, brdf.scalar(brdf.eval(wi, wo)) * z));
        }
    }
    out
}
