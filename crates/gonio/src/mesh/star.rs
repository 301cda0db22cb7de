//! Star-shapedness: a centre from which every triangle of a closed mesh is seen from the same side
//! (its central projection consistently oriented, never edge-on) and the projected triangles cover
//! the sphere exactly once (their signed solid angles, Van Oosterom–Strackee, sum to 4π).
//!
//! Consistent orientation with sum 4π on a closed, consistently oriented mesh means the central
//! projection has degree one everywhere and no fold: each direction meets the surface once, so the
//! surface is the graph r(ω) of a function on the sphere and a map of directions is a map of it.

use super::{Mesh, MeshError};
use std::f64::consts::PI;

/// A centre that passed the check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StarCheck {
    /// The centre.
    pub center: [f64; 3],
    /// +1 when the triangles are counter-clockwise seen from outside (outward normals), −1 when
    /// clockwise.
    pub orientation: f64,
    /// Σ of the triangles' solid angles seen from the centre, times `orientation` (4π up to
    /// rounding).
    pub solid_angle_sum: f64,
    /// How the centre was found: `"given"`, `"centroid"` or `"search"`.
    pub how: &'static str,
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The signed solid angle of the triangle (a, b, c) seen from the origin (Van Oosterom and
/// Strackee 1983): 2 atan2(det(a, b, c), |a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|), positive when
/// the triangle is counter-clockwise seen from the origin's far side.
pub fn solid_angle(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let (la, lb, lc) = (norm(a), norm(b), norm(c));
    let num = dot(a, cross(b, c));
    let den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    2.0 * num.atan2(den)
}

/// Checks that every edge belongs to exactly two triangles that traverse it in opposite
/// directions.
pub fn check_closed(mesh: &Mesh) -> Result<(), MeshError> {
    let mut edges: Vec<u64> = Vec::with_capacity(mesh.triangles.len() * 3);
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (lo, hi, dir) = if a < b { (a, b, 0) } else { (b, a, 1) };
            // 31 bits per vertex are enough below MAX_ELEMENTS = 2^28.
            edges.push(((lo as u64) << 33) | ((hi as u64) << 1) | dir);
        }
    }
    edges.sort_unstable();
    let (mut boundary, mut bad, mut first) = (0usize, 0usize, None);
    let mut i = 0;
    while i < edges.len() {
        let key = edges[i] >> 1;
        let mut j = i;
        while j < edges.len() && edges[j] >> 1 == key {
            j += 1;
        }
        let lo = (key >> 32) as u32;
        let hi = (key & 0xffff_ffff) as u32;
        let ok = j - i == 2 && edges[i] & 1 != edges[i + 1] & 1 && lo != hi;
        if !ok {
            if j - i == 1 && lo != hi {
                boundary += 1;
            } else {
                bad += 1;
            }
            first.get_or_insert([lo, hi]);
        }
        i = j;
    }
    match first {
        None => Ok(()),
        Some(first_edge) => Err(MeshError::NotClosed {
            boundary_edges: boundary,
            nonmanifold_edges: bad,
            first_edge,
        }),
    }
}

/// The volume centroid of a closed mesh (the mean vertex when the volume is 0), and the sign of
/// its signed volume (+1 for outward-facing triangles).
pub fn volume_centroid(mesh: &Mesh) -> ([f64; 3], f64) {
    let n = mesh.positions.len() as f64;
    let mut o = [0.0; 3];
    for p in &mesh.positions {
        for k in 0..3 {
            o[k] += p[k] / n;
        }
    }
    let (mut vol, mut c) = (0.0, [0.0; 3]);
    for t in &mesh.triangles {
        let [a, b, d] = t.map(|i| sub(mesh.positions[i as usize], o));
        let v = dot(a, cross(b, d)) / 6.0;
        vol += v;
        for k in 0..3 {
            c[k] += v * (a[k] + b[k] + d[k]) / 4.0;
        }
    }
    if vol == 0.0 || !vol.is_finite() {
        return (o, 1.0);
    }
    (
        [o[0] + c[0] / vol, o[1] + c[1] / vol, o[2] + c[2] / vol],
        vol.signum(),
    )
}

/// The triangles seen from `center` with the wrong orientation (or edge-on): their count and the
/// first 16, and Σ oriented solid angles.
fn failing(mesh: &Mesh, center: [f64; 3], sigma: f64) -> (usize, Vec<usize>, f64) {
    let (mut count, mut first, mut sum) = (0usize, Vec::new(), 0.0);
    for (f, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|i| sub(mesh.positions[i as usize], center));
        let det = dot(a, cross(b, c));
        let scale = norm(a) * norm(b) * norm(c);
        if !(sigma * det > 1e-14 * scale) {
            count += 1;
            if first.len() < 16 {
                first.push(f);
            }
        }
        sum += sigma * solid_angle(a, b, c);
    }
    (count, first, sum)
}

/// Moves `start` into the intersection of the triangles' inner half-spaces (the kernel of the
/// polyhedron) by simultaneous projection onto the violated ones; the point with the fewest
/// failing triangles found in at most `rounds` rounds.
fn search(mesh: &Mesh, start: [f64; 3], sigma: f64, rounds: usize) -> ([f64; 3], usize) {
    // Inward unit normals and offsets n·x ≤ h (inside).
    let mut radius: f64 = 0.0;
    for p in &mesh.positions {
        radius = radius.max(norm(sub(*p, start)));
    }
    let margin = 1e-7 * radius.max(f64::MIN_POSITIVE);
    let planes: Vec<([f64; 3], f64)> = mesh
        .triangles
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let n = cross(sub(b, a), sub(c, a));
            let l = norm(n);
            (l > 0.0).then(|| {
                let n = [sigma * n[0] / l, sigma * n[1] / l, sigma * n[2] / l];
                (n, dot(n, a))
            })
        })
        .collect();
    let mut p = start;
    let mut best = (p, usize::MAX);
    for _ in 0..rounds {
        let (mut step, mut k) = ([0.0; 3], 0usize);
        for (n, h) in &planes {
            let v = h - dot(*n, p) - margin;
            if v < 0.0 {
                k += 1;
                for i in 0..3 {
                    step[i] += v * n[i];
                }
            }
        }
        if k < best.1 {
            best = (p, k);
        }
        if k == 0 {
            break;
        }
        // Over-relaxed mean of the projections onto the violated half-spaces.
        let w = 1.5 / k as f64;
        for i in 0..3 {
            p[i] += w * step[i];
        }
    }
    best
}

/// Finds (or, with `given`, checks) a centre from which the closed mesh is star-shaped: the given
/// point; otherwise the volume centroid; otherwise a search for a point of the kernel started
/// there (at most 200 rounds of simultaneous projection onto the violated half-spaces). Errors:
/// [`MeshError::NotClosed`] for a mesh with holes, [`MeshError::NotStarShaped`] with the best centre
/// found and the failing triangles.
pub fn find_center(mesh: &Mesh, given: Option<[f64; 3]>) -> Result<StarCheck, MeshError> {
    mesh.validate()?;
    check_closed(mesh)?;
    let (centroid, sigma) = volume_centroid(mesh);
    let four_pi = 4.0 * PI;
    let accept = |c: [f64; 3], how| -> Result<StarCheck, (usize, Vec<usize>, f64)> {
        let (n, first, sum) = failing(mesh, c, sigma);
        if n == 0 && (sum - four_pi).abs() <= 1e-6 * four_pi {
            Ok(StarCheck {
                center: c,
                orientation: sigma,
                solid_angle_sum: sum,
                how,
            })
        } else {
            Err((n, first, sum))
        }
    };
    let start = match given {
        Some(c) => {
            if !c.iter().all(|x| x.is_finite()) {
                return Err(MeshError::Density("the centre is not finite".into()));
            }
            match accept(c, "given") {
                Ok(s) => return Ok(s),
                Err(_) => c,
            }
        }
        None => match accept(centroid, "centroid") {
            Ok(s) => return Ok(s),
            Err(_) => centroid,
        },
    };
    let (best, _) = search(mesh, start, sigma, 200);
    if given.is_none() {
        if let Ok(s) = accept(best, "search") {
            return Ok(s);
        }
    }
    let (failing_n, first_failing, solid_angle_sum) = failing(mesh, best, sigma);
    Err(MeshError::NotStarShaped {
        center: best,
        failing: failing_n,
        triangles: mesh.triangles.len(),
        first_failing,
        solid_angle_sum,
    })
}
