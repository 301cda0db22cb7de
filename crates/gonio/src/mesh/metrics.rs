//! Measures of a parameterisation: texel area per surface area against the target (its
//! histogram, min/max), Sander et al.'s L2 and L∞ stretch (2001), flipped and degenerate
//! triangles, seam length.
//!
//! * The **ratio** of a triangle is (A_uv / Σ A_uv) / (m / Σ m), with m its target measure (its
//!   area for a uniform texel density over the surface, its solid angle for uniform density per
//!   steradian): 1 everywhere is the target met exactly.
//! * **Stretch** uses the Jacobian J of the affine map UV → surface of each triangle with singular
//!   values Γ ≥ γ: L2 = √((Γ² + γ²)/2), L∞ = Γ; the mesh's L2 is √(Σ L2² A / Σ A), normalised by
//!   √(Σ A_uv / Σ A) so that 1 is the least possible (an isometry up to scale), and L∞ the largest
//!   Γ with the same normalisation. UVs are scaled to the texture's aspect (u × width/height) first.
//! * A triangle is **flipped** when its UV orientation differs from the majority of its chart
//!   (area-weighted), **degenerate** when its ratio is below 1e-6 (collapsed in UV) or its surface
//!   area is 0.
//! * **Seam length**: the total surface length of the edges whose two triangles give them
//!   different UVs (and of boundary edges of the UV layout).

use super::param::{area3, signed_area};
use super::UvMesh;
use crate::sampler::Vec3;
use std::collections::HashMap;

/// The bins of [`Metrics::histogram`]: ratio edges.
pub const RATIO_BINS: [f64; 10] = [
    0.0,
    0.5,
    0.8,
    0.9,
    0.95,
    1.05,
    1.1,
    1.25,
    2.0,
    f64::INFINITY,
];

/// What [`measure`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Metrics {
    /// Output triangles.
    pub triangles: usize,
    /// Flipped triangles.
    pub flipped: usize,
    /// Degenerate triangles.
    pub degenerate: usize,
    /// Smallest and largest ratio over the non-degenerate triangles.
    pub ratio_range: (f64, f64),
    /// 1st and 99th percentile of the ratio, weighted by target measure.
    pub ratio_p01_p99: (f64, f64),
    /// Non-degenerate triangles whose ratio lies outside [0.9, 1.1].
    pub outside_10_percent: usize,
    /// Share of the target measure in each bin of [`RATIO_BINS`].
    pub histogram: Vec<f64>,
    /// Normalised L2 stretch.
    pub l2: f64,
    /// Normalised L∞ stretch.
    pub linf: f64,
    /// Seam length (surface units).
    pub seam_length: f64,
    /// Σ surface area.
    pub area: f64,
    /// Σ UV area (before the aspect scaling).
    pub uv_area: f64,
}

/// Measures `mesh`; `target(source_triangle, corners)` is the target measure of a triangle,
/// `aspect` the texture's width/height.
pub fn measure(mesh: &UvMesh, target: &dyn Fn(u32, [Vec3; 3]) -> f64, aspect: f64) -> Metrics {
    let n = mesh.triangles.len();
    let mut a3 = Vec::with_capacity(n);
    let mut auv = Vec::with_capacity(n);
    let mut m = Vec::with_capacity(n);
    let (mut sa, mut suv, mut sm) = (0.0, 0.0, 0.0);
    let mut chart_sign: HashMap<u8, f64> = HashMap::new();
    for (k, t) in mesh.triangles.iter().enumerate() {
        let p = t.map(|c| mesh.positions[c.position as usize]);
        let uv = t.map(|c| mesh.uvs[c.uv as usize]);
        let a = area3(p[0], p[1], p[2]);
        let s = signed_area(uv);
        let mt = target(mesh.source_triangle[k], p);
        *chart_sign.entry(mesh.chart[k]).or_insert(0.0) += s;
        sa += a;
        suv += s.abs();
        sm += mt;
        a3.push(a);
        auv.push(s);
        m.push(mt);
    }
    let (mut flipped, mut degenerate, mut outside) = (0, 0, 0);
    let mut ratios: Vec<(f64, f64)> = Vec::with_capacity(n);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    let mut histogram = vec![0.0; RATIO_BINS.len() - 1];
    let (mut l2sum, mut gmax) = (0.0, 0.0f64);
    for k in 0..n {
        let r = (auv[k].abs() / suv) / (m[k] / sm);
        if !(r >= 1e-6) || a3[k] == 0.0 {
            degenerate += 1;
            continue;
        }
        if auv[k] * chart_sign[&mesh.chart[k]] < 0.0 {
            flipped += 1;
        }
        lo = lo.min(r);
        hi = hi.max(r);
        outside += usize::from(!(0.9..=1.1).contains(&r));
        ratios.push((r, m[k] / sm));
        let bin = RATIO_BINS.iter().rposition(|&e| r >= e).unwrap_or(0);
        histogram[bin.min(RATIO_BINS.len() - 2)] += m[k] / sm;
        // Sander stretch of the map UV → surface.
        let t = mesh.triangles[k];
        let q = t.map(|c| mesh.positions[c.position as usize]);
        let uv = t.map(|c| {
            let w = mesh.uvs[c.uv as usize];
            [w[0] * aspect, w[1]]
        });
        let (s1, s2, s3) = (uv[0][0], uv[1][0], uv[2][0]);
        let (t1, t2, t3) = (uv[0][1], uv[1][1], uv[2][1]);
        let area2 = (s2 - s1) * (t3 - t1) - (s3 - s1) * (t2 - t1);
        let mut ss = [0.0; 3];
        let mut st = [0.0; 3];
        for i in 0..3 {
            ss[i] = (q[0][i] * (t2 - t3) + q[1][i] * (t3 - t1) + q[2][i] * (t1 - t2)) / area2;
            st[i] = (q[0][i] * (s3 - s2) + q[1][i] * (s1 - s3) + q[2][i] * (s2 - s1)) / area2;
        }
        let a = ss.iter().map(|x| x * x).sum::<f64>();
        let b = ss.iter().zip(&st).map(|(x, y)| x * y).sum::<f64>();
        let c = st.iter().map(|x| x * x).sum::<f64>();
        let root = ((a - c) * (a - c) + 4.0 * b * b).sqrt();
        let big = (0.5 * (a + c + root)).sqrt();
        l2sum += 0.5 * (a + c) * a3[k];
        gmax = gmax.max(big);
    }
    ratios.sort_by(|x, y| x.0.total_cmp(&y.0));
    let quantile = |q: f64| {
        let mut acc = 0.0;
        for &(r, w) in &ratios {
            acc += w;
            if acc >= q {
                return r;
            }
        }
        ratios.last().map_or(f64::NAN, |x| x.0)
    };
    let norm = (suv * aspect / sa).sqrt();
    Metrics {
        triangles: n,
        flipped,
        degenerate,
        ratio_range: (lo, hi),
        ratio_p01_p99: (quantile(0.01), quantile(0.99)),
        outside_10_percent: outside,
        histogram,
        l2: (l2sum / sa).sqrt() * norm,
        linf: gmax * norm,
        seam_length: seam_length(mesh),
        area: sa,
        uv_area: suv,
    }
}

/// The total surface length of the seam edges (see the module documentation).
pub fn seam_length(mesh: &UvMesh) -> f64 {
    // Edge (lo, hi) of positions → the UVs (of lo, of hi) of the first triangle and a flag.
    let mut edges: HashMap<(u32, u32), ([u64; 4], u8)> = HashMap::new();
    let mut len = 0.0;
    let key = |mesh: &UvMesh, a: super::Corner, b: super::Corner| {
        let (ua, ub) = (mesh.uvs[a.uv as usize], mesh.uvs[b.uv as usize]);
        [
            ua[0].to_bits(),
            ua[1].to_bits(),
            ub[0].to_bits(),
            ub[1].to_bits(),
        ]
    };
    let length = |mesh: &UvMesh, a: u32, b: u32| {
        let (p, q) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    for t in &mesh.triangles {
        for k in 0..3 {
            let (mut a, mut b) = (t[k], t[(k + 1) % 3]);
            if a.position > b.position {
                std::mem::swap(&mut a, &mut b);
            }
            let uvk = key(mesh, a, b);
            match edges.get_mut(&(a.position, b.position)) {
                None => {
                    edges.insert((a.position, b.position), (uvk, 1));
                }
                Some(e) => {
                    e.1 += 1;
                    if e.0 != uvk {
                        len += length(mesh, a.position, b.position);
                    }
                }
            }
        }
    }
    // Edges with one triangle only: the rim of the UV layout where the surface continues
    // elsewhere (cannot happen on a closed mesh) — counted as seams too.
    for (&(a, b), e) in &edges {
        if e.1 == 1 {
            len += length(mesh, a, b);
        }
    }
    len
}

/// The target measure of uniform texel density over the surface: the triangle's area.
pub fn surface_target(_: u32, p: [Vec3; 3]) -> f64 {
    area3(p[0], p[1], p[2])
}
