//! Star-shapedness: a centre from which every triangle of a closed mesh is seen from the same side
//! (its central projection consistently oriented, never edge-on) and the projected triangles cover
//! the sphere exactly once (their signed solid angles, Van Oosterom–Strackee, sum to 4π).
//!
//! Consistent orientation with sum 4π on a closed, consistently oriented mesh means the central
//! projection has degree one everywhere and no fold: each direction meets the surface once, so the
//! surface is the graph r(ω) of a function on the sphere and a map of directions is a map of it.

use super::{Mesh, MeshError};
use crate::vector::{cross, dot, norm, sub};
use std::f64::consts::PI;

/// `x`·2^k, exact while the result is normal (in two steps, so 2^k itself never overflows).
pub(crate) fn ldexp(x: f64, k: i32) -> f64 {
    x * 2f64.powi(k / 2) * 2f64.powi(k - k / 2)
}

/// The exponent k that brings the largest coordinate of the mesh (and of the given centre) near 1
/// when it is beyond 2^±64, where the cubic products of the volume and the solid angles could
/// overflow or underflow; `None` for meshes of ordinary size (or no finite extent).
pub(crate) fn extent_scale(mesh: &Mesh, given: Option<[f64; 3]>) -> Option<i32> {
    let mut m: f64 = 0.0;
    for p in mesh.positions.iter().chain(given.iter()) {
        for x in p {
            m = m.max(x.abs());
        }
    }
    if !(m.is_finite() && m > 0.0) || (2f64.powi(-64)..=2f64.powi(64)).contains(&m) {
        return None;
    }
    Some(-(m.log2().floor() as i32))
}

/// A copy of `mesh` with every position times 2^k.
pub(crate) fn scaled_mesh(mesh: &Mesh, k: i32) -> Result<Mesh, MeshError> {
    let mut positions = super::try_vec(mesh.positions.len(), "a scaled copy of the vertices")?;
    positions.extend(mesh.positions.iter().map(|p| p.map(|x| ldexp(x, k))));
    Ok(Mesh {
        positions,
        ..mesh.clone()
    })
}

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
    let mut edges: Vec<u64> = super::try_vec(
        mesh.triangles.len().saturating_mul(3),
        "the edge list of the closedness check",
    )?;
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
    if let Some(k) = extent_scale(mesh, given) {
        // The check is scale-free: a mesh of coordinates near 1e100 (whose volume and solid-angle
        // products overflow) is checked at 2^k times its size, exactly, and the centre scaled back.
        let m = scaled_mesh(mesh, k)?;
        let mut s = find_center(&m, given.map(|c| c.map(|x| ldexp(x, k))))?;
        s.center = s.center.map(|x| ldexp(x, -k));
        return Ok(s);
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    /// Issue 40: `texture_uv` with 10⁸ faces aborted allocating the edge list; the allocation is
    /// fallible now (here forced to fail by a size no allocator grants, nothing allocated).
    #[test]
    fn a_buffer_too_large_is_a_typed_error_not_an_abort() {
        let e = super::super::try_vec::<u64>(usize::MAX / 4, "the edge list").unwrap_err();
        match e {
            MeshError::OutOfMemory { what, bytes } => {
                assert_eq!(what, "the edge list");
                assert!(bytes > 1 << 60);
                assert!(e.to_string().contains("out of memory"));
            }
            other => panic!("{other:?}"),
        }
    }

    /// Issue 40: an OBJ cube of half-side 1e100 was "not star-shaped from [NaN, NaN, NaN] … NaN sr";
    /// huge and tiny meshes are checked at a power-of-two scale and pass like the unit cube.
    #[test]
    fn huge_and_tiny_meshes_are_checked_scale_free() {
        let mut text = String::new();
        for z in [-1, 1] {
            for y in [-1, 1] {
                for x in [-1, 1] {
                    text += &format!("v {x}e100 {y}e100 {z}e100\n");
                }
            }
        }
        text += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
        let big = crate::mesh::obj::read_obj(text.as_bytes()).unwrap().mesh;
        let s = find_center(&big, None).unwrap();
        assert!(
            s.center.iter().all(|c| c.is_finite() && c.abs() < 1e90),
            "{s:?}"
        );
        assert!((s.solid_angle_sum - 4.0 * PI).abs() < 1e-9);
        for scale in [1e-200, 1e-100, 1e100, 1e300] {
            let mut m = generate::geodesic_sphere(2);
            for p in &mut m.positions {
                *p = p.map(|x| x * scale);
            }
            let s = find_center(&m, None).unwrap_or_else(|e| panic!("{scale}: {e}"));
            assert!(s.solid_angle_sum.is_finite());
            let r = crate::mesh::parameterise(&m, &crate::mesh::UvOptions::default())
                .unwrap_or_else(|e| panic!("{scale}: {e}"));
            assert!(r.mesh.positions.iter().flatten().all(|x| x.is_finite()));
            assert!(r.mesh.uvs.iter().flatten().all(|x| x.is_finite()));
            let orig_max = m
                .positions
                .iter()
                .flatten()
                .fold(0f64, |a, x| a.max(x.abs()));
            let out_max = r
                .mesh
                .positions
                .iter()
                .flatten()
                .fold(0f64, |a, x| a.max(x.abs()));
            assert!(
                (out_max / orig_max - 1.0).abs() < 1e-12,
                "{scale}: {out_max} vs {orig_max}"
            );
        }
    }
}
