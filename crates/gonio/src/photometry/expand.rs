//! Symmetry expansion to the whole sphere, in the crate's frame (the readers classify the
//! symmetry in `validate`).

use super::validate::{is_closing, vertical_plan};
use super::{
    PhotometricType, Photometry, Symmetry, RESAMPLE_STEP_PHI_DEG, RESAMPLE_STEP_THETA_DEG,
};
use crate::diagram::{segment, Diagram};
use std::f64::consts::PI;

/// Mirror images closer than this (degrees) to another plane are the same plane (floating-point
/// round-off of 180° − C and the like); stored planes are at least `MIN_ANGLE_STEP_DEG` apart.
const SAME_ANGLE_DEG: f64 = 1e-12;

/// The images of stored plane angle `c` (degrees) under the symmetry, identity first.
fn images(sym: Symmetry, c: f64) -> Vec<f64> {
    match sym {
        Symmetry::Quadrant => vec![c, 180.0 - c, 180.0 + c, 360.0 - c],
        Symmetry::BilateralC0C180 => vec![c, 360.0 - c],
        Symmetry::BilateralC90C270 => vec![c, 180.0 - c],
        _ => vec![c],
    }
}

/// An angle in degrees brought into [0, 360).
fn norm360(x: f64) -> f64 {
    let r = x.rem_euclid(360.0);
    if r >= 360.0 - SAME_ANGLE_DEG {
        0.0
    } else {
        r
    }
}

/// The meridians of the expansion: (φ in degrees in [0, 360), stored plane index), strictly
/// increasing. Stored planes win over images at the same angle; the lower index wins otherwise.
pub(crate) fn meridians(sym: Symmetry, horiz: &[f64]) -> Vec<(f64, usize)> {
    let mut all: Vec<(f64, u8, usize)> = Vec::new();
    if sym == Symmetry::Rotational {
        return vec![(norm360(horiz[0]), 0)];
    }
    let stored = if sym == Symmetry::None && is_closing(horiz) {
        &horiz[..horiz.len() - 1]
    } else {
        horiz
    };
    for (k, &c) in stored.iter().enumerate() {
        for (m, img) in images(sym, c).into_iter().enumerate() {
            all.push((norm360(img), u8::from(m > 0), k));
        }
    }
    all.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    let mut out: Vec<(f64, usize)> = Vec::with_capacity(all.len());
    for (a, _, k) in all {
        match out.last() {
            Some(&(b, _)) if a - b < SAME_ANGLE_DEG => {}
            _ => out.push((a, k)),
        }
    }
    out
}

/// The expanded diagram (see [`Photometry::to_diagram`]).
pub(crate) fn to_diagram(p: &Photometry) -> Result<Diagram, crate::DiagramError> {
    // The fields are public: check the shape before indexing.
    let (n_v, n_h) = (p.vertical_angles_deg.len(), p.horizontal_angles_deg.len());
    if n_v == 0 || n_h == 0 {
        return Err(crate::DiagramError::Empty {
            parallels: n_v,
            meridians: n_h,
        });
    }
    let expected = n_v.saturating_mul(n_h);
    if p.candela.len() != expected {
        return Err(crate::DiagramError::Shape {
            what: "candela (stored planes × vertical angles)".into(),
            expected,
            found: p.candela.len(),
        });
    }
    match p.photometric_type {
        PhotometricType::C => type_c(p),
        t => type_ab(p, t),
    }
}

fn type_c(p: &Photometry) -> Result<Diagram, crate::DiagramError> {
    let vert = &p.vertical_angles_deg;
    let n_v = vert.len();
    // The measured rows only, θ = 180° − γ ascending; the ends snapped to 0°, 90° or 180° (interior
    // angles are snapped by `Diagram::new` when the order allows).
    let ((a, b), _) = vertical_plan(vert);
    let rows: Vec<(f64, usize)> = vert
        .iter()
        .enumerate()
        .map(|(k, &g)| {
            let g = if k == 0 {
                a
            } else if k == n_v - 1 {
                b
            } else {
                g
            };
            (g, k)
        })
        .rev()
        .collect();
    let theta: Vec<f64> = rows
        .iter()
        .map(|&(g, _)| (180.0 - g).to_radians().clamp(0.0, PI))
        .collect();
    let mer = meridians(p.symmetry, &p.horizontal_angles_deg);
    let phi: Vec<f64> = mer.iter().map(|&(c, _)| c.to_radians()).collect();
    let n = theta.len();
    let total = n.saturating_mul(phi.len());
    if total > crate::diagram::MAX_NODES {
        return Err(crate::DiagramError::TooLarge {
            parallels: n,
            meridians: phi.len(),
        });
    }
    let mut values = Vec::with_capacity(total);
    for &(_, plane) in &mer {
        for &(_, row) in &rows {
            values.push(p.candela[plane * n_v + row]);
        }
    }
    Diagram::new(theta, phi, values)
}

/// One axis of a type A/B table, mirrored about 0 when asked: (angle, stored index), increasing.
fn mirrored_axis(angles: &[f64], mirror: bool) -> Vec<(f64, usize)> {
    let mut out = Vec::with_capacity(2 * angles.len());
    if mirror {
        // An axis starting at 0° has its own mirror image there; one starting above 0° (outside
        // LM-63's rule, warned) mirrors its first angle too.
        let first = usize::from(crate::diagram::snap_deg(angles[0], &[0.0]) == 0.0);
        for k in (first..angles.len()).rev() {
            out.push((-angles[k], k));
        }
    }
    out.extend(angles.iter().enumerate().map(|(k, &a)| (a, k)));
    out
}

/// Bilinear interpolation weights on an increasing axis: (k0, k1, t), or None outside.
fn weights(axis: &[f64], x: f64) -> Option<(usize, usize, f64)> {
    const EPS: f64 = 1e-9;
    let n = axis.len();
    if !(x >= axis[0] - EPS && x <= axis[n - 1] + EPS) {
        return None;
    }
    if n == 1 {
        return Some((0, 0, 0.0));
    }
    let k = segment(axis, x);
    let t = ((x - axis[k]) / (axis[k + 1] - axis[k])).clamp(0.0, 1.0);
    Some((k, k + 1, t))
}

/// (H, V) in degrees of a unit direction, for type B or A (see [`Photometry::to_diagram`]).
pub(crate) fn hv_of(t: PhotometricType, d: [f64; 3]) -> (f64, f64) {
    // At the poles of the (H, V) system (±y for type B, ±x for type A) the plane angle is
    // undefined: 0° is used there.
    const POLE: f64 = 1e-12;
    let [x, y, z] = d;
    match t {
        PhotometricType::B => {
            let v = if x.hypot(z) < POLE {
                0.0
            } else {
                x.atan2(-z).to_degrees()
            };
            (y.clamp(-1.0, 1.0).asin().to_degrees(), v)
        }
        _ => {
            let h = if y.hypot(z) < POLE {
                0.0
            } else {
                y.atan2(-z).to_degrees()
            };
            (h, x.clamp(-1.0, 1.0).asin().to_degrees())
        }
    }
}

/// The unit direction, in the crate's frame, of horizontal angle `h_deg` and vertical angle
/// `v_deg` (degrees) of a type B or type A file (see [`Photometry::to_diagram`]):
/// type B: sin H·ŷ + cos H (sin V·x̂ − cos V·ẑ); type A (and C, meaningless): sin V·x̂ + cos V (sin H·ŷ − cos H·ẑ).
/// H = V = 0 is nadir (−z).
pub fn direction_of_hv(t: PhotometricType, h_deg: f64, v_deg: f64) -> [f64; 3] {
    let (sh, ch) = h_deg.to_radians().sin_cos();
    let (sv, cv) = v_deg.to_radians().sin_cos();
    match t {
        PhotometricType::B => [ch * sv, sh, -ch * cv],
        _ => [sv, cv * sh, -cv * ch],
    }
}

/// The type A/B intensity (candela) at (H, V) in degrees, bilinear in (H, V) on the mirrored
/// table; 0 outside the measured ranges.
pub(crate) fn ab_intensity(p: &Photometry, h: f64, v: f64) -> f64 {
    let (ha, hx, va, vx) = ab_axes(p);
    ab_eval(p, &ha, &hx, &va, &vx, h, v)
}

/// A type A/B file's horizontal and vertical axes with their mirror images (per its symmetry):
/// (angle, stored index) pairs and the angles alone, for each axis.
#[allow(clippy::type_complexity)]
fn ab_axes(p: &Photometry) -> (Vec<(f64, usize)>, Vec<f64>, Vec<(f64, usize)>, Vec<f64>) {
    let (mh, mv) = match p.symmetry {
        Symmetry::TypeAB {
            horizontal,
            vertical,
        } => (horizontal, vertical),
        _ => (false, false),
    };
    let ha = mirrored_axis(&p.horizontal_angles_deg, mh);
    let va = mirrored_axis(&p.vertical_angles_deg, mv);
    let hx: Vec<f64> = ha.iter().map(|x| x.0).collect();
    let vx: Vec<f64> = va.iter().map(|x| x.0).collect();
    (ha, hx, va, vx)
}

fn ab_eval(
    p: &Photometry,
    ha: &[(f64, usize)],
    hx: &[f64],
    va: &[(f64, usize)],
    vx: &[f64],
    h: f64,
    v: f64,
) -> f64 {
    let n_v = p.vertical_angles_deg.len();
    let (Some((h0, h1, th)), Some((v0, v1, tv))) = (weights(hx, h), weights(vx, v)) else {
        return 0.0;
    };
    let val = |hi: usize, vi: usize| p.candela[ha[hi].1 * n_v + va[vi].1];
    let a = (1.0 - tv) * val(h0, v0) + tv * val(h0, v1);
    let b = (1.0 - tv) * val(h1, v0) + tv * val(h1, v1);
    (1.0 - th) * a + th * b
}

fn type_ab(p: &Photometry, t: PhotometricType) -> Result<Diagram, crate::DiagramError> {
    let (ha, hx, va, vx) = ab_axes(p);
    // Lower hemisphere only when every measured direction has z ≤ 0.
    let lower_only = match t {
        PhotometricType::B => vx[0] >= -90.0 && vx[vx.len() - 1] <= 90.0,
        _ => hx[0] >= -90.0 && hx[hx.len() - 1] <= 90.0,
    };
    let theta_lo = if lower_only { 90.0 } else { 0.0 };
    let n_t = ((180.0 - theta_lo) / RESAMPLE_STEP_THETA_DEG).round() as usize + 1;
    let n_p = (360.0 / RESAMPLE_STEP_PHI_DEG).round() as usize;
    let theta_deg: Vec<f64> = (0..n_t)
        .map(|k| theta_lo + k as f64 * RESAMPLE_STEP_THETA_DEG)
        .collect();
    let phi_deg: Vec<f64> = (0..n_p).map(|k| k as f64 * RESAMPLE_STEP_PHI_DEG).collect();
    let mut values = Vec::with_capacity(n_t * n_p);
    for &c in &phi_deg {
        let (sp, cp) = c.to_radians().sin_cos();
        for &th in &theta_deg {
            let (st, ct) = th.to_radians().sin_cos();
            let (h, v) = hv_of(t, [st * cp, st * sp, ct]);
            values.push(ab_eval(p, &ha, &hx, &va, &vx, h, v));
        }
    }
    let theta = theta_deg.iter().map(|t| t.to_radians().min(PI)).collect();
    let phi = phi_deg.iter().map(|c| c.to_radians()).collect();
    Diagram::new(theta, phi, values)
}
