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
