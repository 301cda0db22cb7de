//! gonio's self-describing BRDF table (JSON), for any grid:
//!
//! ```json
//! {"format": "gonio-brdf", "version": 1, "symmetry": "isotropic", "channels": 3,
//!  "theta_i_deg": [0, 45, 90], "phi_i_deg": [0],
//!  "theta_o_deg": [0, 45, 90], "phi_o_deg": [0, 90, 180, 270],
//!  "values": [ ... ]}
//! ```
//!
//! `values` is flat, in the C order of an array of shape (channels, θ_i, φ_i, θ_o, φ_o) (numpy's
//! `a.ravel()`), f_r in 1/sr. For `"isotropic"` tables `phi_i_deg` is `[0]` and `phi_o_deg` holds
//! Δφ = φ_o − φ_i; for `"anisotropic"` ones φ_o is absolute. Angles in degrees, frame and
//! interpolation as in [`super`]. Unknown keys are refused.

use super::{BrdfError, Symmetry, TabulatedBrdf};
use serde::{Deserialize, Serialize};

/// The JSON form of a [`TabulatedBrdf`] (see the module documentation).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrdfJson {
    /// Always `"gonio-brdf"`.
    pub format: String,
    /// Always 1.
    pub version: u32,
    /// `"isotropic"` or `"anisotropic"`.
    pub symmetry: Symmetry,
    /// 1 or 3.
    pub channels: usize,
    /// Incident polar angles, degrees.
    pub theta_i_deg: Vec<f64>,
    /// Incident azimuths, degrees (`[0]` when isotropic).
    pub phi_i_deg: Vec<f64>,
    /// Outgoing polar angles, degrees.
    pub theta_o_deg: Vec<f64>,
    /// Outgoing azimuths (Δφ when isotropic), degrees.
    pub phi_o_deg: Vec<f64>,
    /// The values, flat (see the module documentation).
    pub values: Vec<f64>,
}

fn rad(v: &[f64]) -> Vec<f64> {
    v.iter().map(|d| d.to_radians()).collect()
}
/// Degrees, with the round-off of the radians → degrees conversion (29.999999999999996) removed
/// where the angle is within 1e-9° of a multiple of 1e-9°.
fn deg(v: &[f64]) -> Vec<f64> {
    v.iter()
        .map(|r| {
            let d = r.to_degrees();
            let k = (d * 1e9).round() / 1e9;
            if (k - d).abs() < 1e-9 {
                k
            } else {
                d
            }
        })
        .collect()
}

/// Reads the JSON table.
pub fn read_json(text: &str) -> Result<TabulatedBrdf, BrdfError> {
    // A UTF-8 byte order mark is not JSON, but editors write one: skipped.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let j: BrdfJson = serde_json::from_str(text).map_err(|e| BrdfError::Json {
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    if j.format != "gonio-brdf" || j.version != 1 {
        return Err(BrdfError::Json {
            line: 1,
            column: 1,
            message: format!(
                "format {:?} version {}: expected \"gonio-brdf\" version 1",
                j.format, j.version
            ),
        });
    }
    TabulatedBrdf::new(
        j.symmetry,
        j.channels,
        rad(&j.theta_i_deg),
        rad(&j.phi_i_deg),
        rad(&j.theta_o_deg),
        rad(&j.phi_o_deg),
        j.values,
    )
    .map_err(|e| match e {
        // A value error of the table names the value's line and column in the text, not "byte 0".
        BrdfError::BadValue {
            index, value, hint, ..
        } => {
            let (line, column) = locate_value(text, index).unwrap_or((1, 1));
            BrdfError::Json {
                line,
                column,
                message: format!(
                    "values[{index}] = {} is not a finite number{hint}",
                    crate::decimal::shortest(value)
                ),
            }
        }
        e => e,
    })
}

/// The 1-based line and column of element `index` of the top-level `"values"` array.
fn locate_value(text: &str, index: usize) -> Option<(usize, usize)> {
    let b = text.as_bytes();
    let (mut depth, mut i, mut in_values, mut count, mut at_element) = (0usize, 0, false, 0, false);
    let mut last_key: &[u8] = b"";
    while i < b.len() {
        let c = b[i];
        if c == b'"' {
            let start = i + 1;
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            if depth == 1 {
                last_key = &b[start..i.min(b.len())];
            }
        } else if c == b'[' || c == b'{' {
            depth += 1;
            if depth == 2 && c == b'[' && last_key == b"values" {
                in_values = true;
                at_element = true;
            }
        } else if c == b']' || c == b'}' {
            if depth == 2 && in_values {
                return None;
            }
            depth = depth.saturating_sub(1);
        } else if in_values && depth == 2 && c == b',' {
            count += 1;
            at_element = true;
        } else if in_values && depth == 2 && at_element && !c.is_ascii_whitespace() {
            if count == index {
                let line = 1 + b[..i].iter().filter(|&&x| x == b'\n').count();
                let line_start = b[..i]
                    .iter()
                    .rposition(|&x| x == b'\n')
                    .map_or(0, |p| p + 1);
                let column = 1 + text[line_start..i].chars().count();
                return Some((line, column));
            }
            at_element = false;
        }
        i += 1;
    }
    None
}

/// Writes the JSON table of `brdf`.
pub fn write_json(brdf: &TabulatedBrdf) -> String {
    let j = BrdfJson {
        format: "gonio-brdf".into(),
        version: 1,
        symmetry: brdf.symmetry(),
        channels: brdf.channels(),
        theta_i_deg: deg(brdf.theta_i()),
        phi_i_deg: deg(brdf.phi_i()),
        theta_o_deg: deg(brdf.theta_o()),
        phi_o_deg: deg(brdf.phi_o()),
        values: brdf.values().to_vec(),
    };
    serde_json::to_string(&j).expect("a table of finite numbers serialises")
}
