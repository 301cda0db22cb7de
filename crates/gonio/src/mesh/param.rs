//! The parameterisation: UV of a vertex = the inverse map of its direction from the centre.
//!
//! [`parameterise`] checks the mesh ([`super::star::find_center`]), builds the density diagram
//! ([`Density`]) on a (θ, φ) grid, the [`crate::SphereMap`] of that diagram (split layout), and the
//! UVs. The split layout's seams are the horizon z = c_z of the centre: the lower hemisphere maps
//! onto the rectangle u < P_lower, the upper one onto u > P_lower, and the horizon onto both
//! rectangles' rims. Triangles that cross the plane z = c_z are cut along it (new vertices on the
//! edges, shared by both neighbours; the pieces fan-triangulated), so every output triangle lies in
//! one chart and the vertices on the cut get one UV per chart.
//!
//! Inside a chart the map is not smooth everywhere: the concentric stage switches branch along the
//! square's diagonals, which map to four meridians per hemisphere
//! ([`TextureMap::kink_azimuths`]), and the disk centres (the poles) are cone points where a
//! straight-edged triangle spanning an angle Δ around the pole has its UV area off by Δ / sin Δ.
//! The HDS layout is therefore also cut along vertical planes through the centre
//! ([`TextureMap::cut_planes`]): every kink meridian, and more in between until neighbouring
//! half-planes are at most [`POLE_SECTOR`] apart. These cuts are like the horizon's (shared new
//! vertices on the input's edges, exactly on the surface, attributes interpolated) but make no
//! seam: both sides get the same UV. The poles and the square's corners (kink meridians on the
//! horizon) become vertices, and every output triangle lies inside one branch of the map.
//!
//! Each chart is made orientation-preserving: where the inverse map of a hemisphere turns a
//! counter-clockwise triangle (seen from outside) clockwise in the square, the texture coordinate
//! of that chart is v ↦ 1 − v ([`TextureMap`] applies the same flip in [`TextureMap::direction`],
//! so baking and lookup agree). Outward-facing meshes get counter-clockwise UV triangles.
//!
//! The compared layouts ([`Layout`]) go through the same cutter with their own seam planes.

use super::star::{find_center, solid_angle, StarCheck};
use super::{Corner, Mesh, MeshError, VertexProperty, NO_INDEX};
use crate::baselines::equal_area::equal_area_sphere_to_square;
use crate::diagram::Diagram;
use crate::mapping::SphereMap;
use crate::sampler::{spherical, Point2, Sampler, Vec3};
use crate::vector::{add, cross, dot, scale, sub};
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

/// The texel density per steradian the map is built from.
#[derive(Debug, Clone, PartialEq)]
pub enum Density {
    /// Uniform texel density over the surface: the diagram is the surface's area per steradian
    /// r²/cos α, measured from the mesh.
    Surface,
    /// Uniform texel density per steradian.
    SolidAngle,
    /// A positive weight per input vertex times `Surface`: texel density per unit area ∝ weight.
    VertexWeight(Vec<f64>),
    /// A diagram of weights over directions (θ from +z of the mesh frame) times `Surface`.
    Diagram(Diagram),
}

/// The layout of the square: the HDS inverse map, or one of the compared classical layouts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// The inverse HDS map of the density diagram (split layout): two charts.
    Hds,
    /// u = φ/2π, v = θ/π (θ from +z): one chart cut along φ = 0 (and at x = 0, y = 0 so the poles
    /// are vertices).
    LatLong,
    /// Six cube faces, gnomonic, in a 3 × 2 grid of tiles.
    Cube,
    /// Clarberg's equal-area octahedral map: eight charts (octants).
    Octahedral,
}

impl Layout {
    /// The layout's name as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Layout::Hds => "hds",
            Layout::LatLong => "latlong",
            Layout::Cube => "cube",
            Layout::Octahedral => "octahedral",
        }
    }
    /// The width/height of the texture the layout is meant for (1 for square layouts).
    pub fn native_aspect(self) -> f64 {
        match self {
            Layout::Hds | Layout::Octahedral => 1.0,
            Layout::LatLong => 2.0,
            Layout::Cube => 1.5,
        }
    }
    fn planes(self) -> Vec<Vec3> {
        let s = std::f64::consts::FRAC_1_SQRT_2;
        match self {
            Layout::Hds => vec![[0.0, 0.0, 1.0]],
            Layout::LatLong => vec![[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
            Layout::Octahedral => vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            Layout::Cube => vec![
                [s, -s, 0.0],
                [s, s, 0.0],
                [s, 0.0, -s],
                [s, 0.0, s],
                [0.0, s, -s],
                [0.0, s, s],
            ],
        }
    }
    fn charts(self) -> usize {
        match self {
            Layout::Hds => 2,
            Layout::LatLong => 4,
            Layout::Cube => 6,
            Layout::Octahedral => 8,
        }
    }
}

/// Options of [`parameterise`].
#[derive(Debug, Clone, PartialEq)]
pub struct UvOptions {
    /// The wanted texel density (HDS layout only).
    pub density: Density,
    /// The centre; `None`: found ([`find_center`]).
    pub center: Option<[f64; 3]>,
    /// The layout.
    pub layout: Layout,
    /// The density diagram's grid (parallels from 0 to π, meridians over [0, 2π)); `None`: chosen
    /// from the triangle count, about 20 triangles per cell, between 9 × 16 and 181 × 360.
    pub grid: Option<(usize, usize)>,
    /// Refine the map until pdf/target is within 1 ± tolerance (see
    /// [`crate::SphereMap::with_tolerance`]); `None`: the map on the diagram's grid.
    pub tolerance: Option<f64>,
}

impl Default for UvOptions {
    fn default() -> Self {
        UvOptions {
            density: Density::Surface,
            center: None,
            layout: Layout::Hds,
            grid: None,
            tolerance: Some(0.01),
        }
    }
}

/// A mesh with texture coordinates: the input's positions (and the cut's new ones appended), one
/// UV per vertex and chart, the input's normals (and interpolated ones for new vertices).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UvMesh {
    /// Positions: the input's, in order, then the vertices the seam cut created.
    pub positions: Vec<[f64; 3]>,
    /// Texture coordinates in [0, 1]².
    pub uvs: Vec<[f64; 2]>,
    /// Normals: the input's, then interpolated ones at cut vertices.
    pub normals: Vec<[f64; 3]>,
    /// Triangles as corners.
    pub triangles: Vec<[Corner; 3]>,
    /// The chart of each triangle (layout-specific numbering).
    pub chart: Vec<u8>,
    /// The input triangle each output triangle is (a piece of).
    pub source_triangle: Vec<u32>,
    /// The input's vertex properties, extended to the new vertices by linear interpolation.
    pub vertex_properties: Vec<VertexProperty>,
}

/// The map of texture coordinates: the HDS sphere map with each chart's orientation fixed.
#[derive(Debug, Clone)]
pub struct TextureMap {
    map: SphereMap,
    p_lower: f64,
    /// v ↦ 1 − v in the lower (0) and upper (1) chart.
    flip: [bool; 2],
}

impl TextureMap {
    /// The map of `diagram` (split layout; refined to `tolerance` when given).
    pub fn new(diagram: &Diagram, tolerance: Option<f64>) -> Result<Self, MeshError> {
        let map = match tolerance {
            Some(t) => SphereMap::with_tolerance(diagram, t)?,
            None => SphereMap::new(diagram)?,
        };
        let p_lower = map.lower_probability().unwrap_or(0.5);
        let mut tm = TextureMap {
            map,
            p_lower,
            flip: [false, false],
        };
        for chart in 0..2 {
            if (chart == 0 && p_lower <= 0.0) || (chart == 1 && p_lower >= 1.0) {
                continue;
            }
            // A small triangle counter-clockwise seen from outside, around a direction inside the
            // chart: its image must be counter-clockwise.
            let z = if chart == 0 { -0.9 } else { 0.9 };
            let d0 = normalize([0.3, 0.2, z]);
            let e1 = normalize(cross([0.0, 0.0, 1.0], d0));
            let e2 = cross(d0, e1);
            let eps = 1e-3;
            let tri = [
                d0,
                normalize(add(d0, scale(e1, eps))),
                normalize(add(d0, scale(e2, eps))),
            ];
            let uv = tri.map(|d| tm.uv(d, chart).unwrap_or([0.0; 2]));
            if signed_area(uv) < 0.0 {
                tm.flip[chart] = true;
            }
        }
        Ok(tm)
    }

    /// The underlying sphere map (its `invert` gives the unflipped square point).
    pub fn sphere_map(&self) -> &SphereMap {
        &self.map
    }

    /// The seam u = P_lower between the lower chart (u < P_lower) and the upper one.
    pub fn seam(&self) -> f64 {
        self.p_lower
    }

    /// Whether chart 0 (lower) / 1 (upper) has v flipped.
    pub fn flipped(&self) -> [bool; 2] {
        self.flip
    }

    /// The texture coordinate of unit direction `d` in `chart` (0: z ≤ 0, 1: z ≥ 0); a direction
    /// on the other side within rounding is moved onto the horizon of that chart.
    pub fn uv(&self, d: Vec3, chart: usize) -> Result<Point2, MeshError> {
        let mut d = d;
        if chart == 0 && d[2] >= 0.0 {
            d = horizon(d, -f64::MIN_POSITIVE);
        } else if chart == 1 && d[2] < 0.0 {
            d = horizon(d, 0.0);
        }
        let mut u = self.map.invert(d).map_err(|e| {
            MeshError::Density(format!(
                "no texture coordinate for direction {d:?} ({e}): the density must be positive wherever the surface is"
            ))
        })?;
        if self.flip[chart.min(1)] {
            u[1] = 1.0 - u[1];
        }
        Ok(u)
    }

    /// The unit direction (from the centre) of texture coordinate `uv`: the forward map, with the
    /// chart's flip undone.
    pub fn direction(&self, uv: Point2) -> Vec3 {
        let chart = if uv[0] < self.p_lower { 0 } else { 1 };
        let mut u = uv;
        if self.flip[chart] {
            u[1] = 1.0 - u[1];
        }
        self.map.sample(u).direction
    }

    /// The map's density of texture area per steradian at unit direction `d`.
    pub fn pdf(&self, d: Vec3) -> f64 {
        self.map.pdf(d)
    }

    /// The azimuths φ ∈ [0, 2π) of the meridians that the diagonals of each chart's square map to,
    /// lower chart first (four per non-empty chart). The concentric stage of the map switches
    /// branch there, so the forward map has a kink along these half-planes (its derivative jumps),
    /// and the square's corners map to where they meet the horizon. The disk azimuth alone decides
    /// the direction's azimuth, so each diagonal is one meridian; it is read at the middle of the
    /// diagonal with the forward map.
    pub fn kink_azimuths(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(8);
        for chart in 0..2 {
            let (u0, w) = if chart == 0 {
                (0.0, self.p_lower)
            } else {
                (self.p_lower, 1.0 - self.p_lower)
            };
            if w <= 0.0 {
                continue;
            }
            for (s, t) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
                let uv = [u0 + w * (0.5 + 0.25 * s), 0.5 + 0.25 * t];
                let d = self.direction(uv);
                let mut phi = d[1].atan2(d[0]);
                if phi < 0.0 {
                    phi += TAU;
                }
                out.push(phi);
            }
        }
        out
    }

    /// The normals of the vertical planes through the centre the mesh is cut along besides the
    /// horizon: one per kink meridian of [`TextureMap::kink_azimuths`] (with its opposite
    /// half-plane), and more, evenly spaced in the gaps, until neighbouring half-planes are at most
    /// [`POLE_SECTOR`] apart. All of them contain the poles, so a triangle around a pole is cut into
    /// sectors with the pole as their shared vertex; the concentric map is smooth inside each.
    pub fn cut_planes(&self) -> Vec<Vec3> {
        let mut a: Vec<f64> = self
            .kink_azimuths()
            .into_iter()
            .map(|p| p.rem_euclid(PI))
            .collect();
        a.sort_by(f64::total_cmp);
        a.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
        if a.len() > 1 && (a[0] + PI - a[a.len() - 1]) < 1e-12 {
            a.pop();
        }
        if a.is_empty() {
            a.push(0.0);
        }
        let mut all = Vec::with_capacity(a.len() * 2);
        for k in 0..a.len() {
            let lo = a[k];
            let hi = if k + 1 < a.len() { a[k + 1] } else { a[0] + PI };
            let n = ((hi - lo) / POLE_SECTOR - 1e-9).ceil().max(1.0) as usize;
            for j in 0..n {
                all.push(lo + (hi - lo) * j as f64 / n as f64);
            }
        }
        all.into_iter().map(|p| [-p.sin(), p.cos(), 0.0]).collect()
    }
}

/// The widest angle (radians, π/8) between neighbouring vertical cut half-planes of the HDS layout
/// ([`TextureMap::cut_planes`]). A sector of angle Δ with its apex at a pole is a straight-edged
/// triangle on the surface but bounded by an arc in the map, so its UV area is off by the factor
/// Δ / sin Δ: 1.026 at π/8.
pub const POLE_SECTOR: f64 = PI / 8.0;

/// `d` moved onto the horizon z = `z` (x, y rescaled to unit length).
fn horizon(d: Vec3, z: f64) -> Vec3 {
    let h = d[0].hypot(d[1]);
    if h > 0.0 {
        [d[0] / h, d[1] / h, z]
    } else {
        [1.0, 0.0, z]
    }
}

/// What [`parameterise`] made.
#[derive(Debug, Clone)]
pub struct UvResult {
    /// The mesh with UVs.
    pub mesh: UvMesh,
    /// The centre and its check.
    pub star: StarCheck,
    /// The texture map (HDS layout).
    pub texture: Option<TextureMap>,
    /// The density diagram the map was built from (HDS layout).
    pub diagram: Option<Diagram>,
    /// Input triangles cut: by a seam, or (HDS layout) by a kink or pole-sector plane.
    pub cut_triangles: usize,
    /// Seconds: star check, density diagram, map build, UVs and cut.
    pub seconds: [f64; 4],
}

fn normalize(a: Vec3) -> Vec3 {
    let l = dot(a, a).sqrt();
    if l > 0.0 {
        scale(a, 1.0 / l)
    } else {
        a
    }
}

/// Twice the signed area of a UV triangle, halved: positive when counter-clockwise.
pub fn signed_area(t: [Point2; 3]) -> f64 {
    0.5 * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]))
}

/// The area of a 3D triangle.
pub fn area3(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    let n = cross(sub(b, a), sub(c, a));
    0.5 * dot(n, n).sqrt()
}

/// The default grid for `triangles` triangles: about 20 per cell, 2 meridians per parallel.
pub fn default_grid(triangles: usize) -> (usize, usize) {
    let n = ((triangles as f64 / 40.0).sqrt().round() as usize).clamp(9, 181);
    (n, (2 * (n - 1)).max(16))
}

/// The density diagram measured from the mesh seen from `center`: at each node of the grid, the
/// tent-weighted (bilinear in θ, φ) mean of the triangles' target measure over their solid angle,
/// Σ w m_f / Σ w Ω_f, with m_f the triangle's area (times its weight for [`Density::VertexWeight`]
/// and [`Density::Diagram`]); for [`Density::SolidAngle`] the constant 1. Nodes no triangle reaches
/// take the mean of their neighbours.
pub fn density_diagram(
    mesh: &Mesh,
    center: Vec3,
    density: &Density,
    grid: (usize, usize),
) -> Result<Diagram, MeshError> {
    if let Density::SolidAngle = density {
        return Ok(Diagram::new(vec![0.0, PI], vec![0.0], vec![1.0, 1.0])?);
    }
    let (nt, np) = grid;
    if nt < 3 || np < 1 || nt * np > 4_000_000 {
        return Err(MeshError::Density(format!(
            "the density grid {nt} × {np} must have 3 to 4e6 nodes and at least 3 parallels"
        )));
    }
    if let Density::VertexWeight(w) = density {
        if w.len() != mesh.positions.len() {
            return Err(MeshError::AttributeShape {
                what: "vertex weights",
                expected: mesh.positions.len(),
                found: w.len(),
            });
        }
        if let Some(i) = w.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
            return Err(MeshError::Density(format!(
                "vertex weight {i} = {} is not a finite positive number",
                w[i]
            )));
        }
    }
    let dt = PI / (nt - 1) as f64;
    let dp = TAU / np as f64;
    let mut num = vec![0.0; nt * np];
    let mut den = vec![0.0; nt * np];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| sub(mesh.positions[i as usize], center));
        let omega = solid_angle(a, b, c).abs();
        let mut m = area3(a, b, c);
        let g = normalize(scale(add(add(a, b), c), 1.0 / 3.0));
        let (th, ph) = spherical(g);
        match density {
            Density::VertexWeight(w) => {
                m *= (w[t[0] as usize] + w[t[1] as usize] + w[t[2] as usize]) / 3.0
            }
            Density::Diagram(d) => m *= d.interpolate(th, ph),
            _ => {}
        }
        let x = (th / dt).min((nt - 1) as f64);
        let j0 = (x.floor() as usize).min(nt - 2);
        let fx = x - j0 as f64;
        let y = ph / dp;
        let i0 = (y.floor() as usize) % np;
        let fy = y - y.floor();
        let i1 = (i0 + 1) % np;
        for (j, wj) in [(j0, 1.0 - fx), (j0 + 1, fx)] {
            for (i, wi) in [(i0, 1.0 - fy), (i1, fy)] {
                let w = wj * wi;
                num[i * nt + j] += w * m;
                den[i * nt + j] += w * omega;
            }
        }
    }
    // The poles are single points: pool their meridians.
    for j in [0, nt - 1] {
        let (sn, sd): (f64, f64) = (0..np).fold((0.0, 0.0), |(a, b), i| {
            (a + num[i * nt + j], b + den[i * nt + j])
        });
        for i in 0..np {
            num[i * nt + j] = sn;
            den[i * nt + j] = sd;
        }
    }
    let mut values: Vec<f64> = num
        .iter()
        .zip(&den)
        .map(|(n, d)| if *d > 0.0 { n / d } else { f64::NAN })
        .collect();
    // Fill empty nodes from their neighbours.
    for _ in 0..(nt + np) {
        let missing: Vec<usize> = (0..values.len()).filter(|&k| values[k].is_nan()).collect();
        if missing.is_empty() {
            break;
        }
        let snapshot = values.clone();
        for k in missing {
            let (i, j) = (k / nt, k % nt);
            let mut s = (0.0, 0);
            for (ii, jj) in [
                ((i + np - 1) % np, j),
                ((i + 1) % np, j),
                (i, j.saturating_sub(1)),
                (i, (j + 1).min(nt - 1)),
            ] {
                let v = snapshot[ii * nt + jj];
                if v.is_finite() {
                    s = (s.0 + v, s.1 + 1);
                }
            }
            if s.1 > 0 {
                values[k] = s.0 / s.1 as f64;
            }
        }
    }
    if values.iter().any(|v| !v.is_finite()) {
        return Err(MeshError::Density(
            "the density diagram has unfilled nodes".into(),
        ));
    }
    let theta = (0..nt).map(|j| j as f64 * dt).collect();
    let phi = (0..np).map(|i| i as f64 * dp).collect();
    Ok(Diagram::new(theta, phi, values)?)
}

/// The texture coordinate of unit direction `d` in `chart` of a classical layout; `piece` is the
/// direction of the piece's centroid (for the lat–long poles).
fn classic_uv(layout: Layout, d: Vec3, chart: usize, piece: Vec3) -> Point2 {
    match layout {
        Layout::LatLong => {
            let (t, _) = spherical(d);
            let pole = d[0].hypot(d[1]) <= 1e-12;
            let src = if pole { piece } else { d };
            let mut phi = src[1].atan2(src[0]);
            // Charts: 0 (x ≥ 0, y ≥ 0), 1 (x ≤ 0, y ≥ 0), 2 (x ≤ 0, y ≤ 0), 3 (x ≥ 0, y ≤ 0).
            let (lo, hi) = [
                (0.0, 0.5 * PI),
                (0.5 * PI, PI),
                (PI, 1.5 * PI),
                (1.5 * PI, TAU),
            ][chart];
            if phi < 0.0 {
                phi += TAU;
            }
            // Points on a cut take the chart's side: φ ≈ 0 is 2π in chart 3, φ ≈ 2π is 0 in
            // chart 0.
            if chart == 3 && phi < PI {
                phi += TAU;
            }
            if chart == 0 && phi > PI {
                phi -= TAU;
            }
            let phi = phi.clamp(lo, hi);
            [phi / TAU, t / PI]
        }
        Layout::Octahedral => {
            let sx = if chart & 1 == 0 { 1.0 } else { -1.0 };
            let sy = if chart & 2 == 0 { 1.0 } else { -1.0 };
            let sz = if chart & 4 == 0 { 1.0 } else { -1.0 };
            let mut w = [d[0].abs() * sx, d[1].abs() * sy, d[2].abs() * sz];
            if sz < 0.0 && w[2] == 0.0 {
                w[2] = -0.0;
            }
            // The inverse tests z ≥ 0 for the upper side; a lower-chart point on the equator is
            // moved below it by the least amount.
            if sz < 0.0 && w[2] >= 0.0 {
                w[2] = -f64::MIN_POSITIVE;
            }
            equal_area_sphere_to_square(w)
        }
        Layout::Cube => {
            // Tangent bases with e1 × e2 = outward axis.
            let (major, e1, e2): (Vec3, Vec3, Vec3) = match chart {
                0 => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
                1 => ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
                2 => ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
                3 => ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
                4 => ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
                _ => ([0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
            };
            let m = dot(d, major).max(1e-300);
            let a = (dot(d, e1) / m).clamp(-1.0, 1.0);
            let b = (dot(d, e2) / m).clamp(-1.0, 1.0);
            let (col, row) = ((chart % 3) as f64, (chart / 3) as f64);
            [(col + 0.5 * (a + 1.0)) / 3.0, (row + 0.5 * (b + 1.0)) / 2.0]
        }
        Layout::Hds => unreachable!("the HDS layout uses TextureMap"),
    }
}

fn chart_of(layout: Layout, g: Vec3) -> usize {
    match layout {
        Layout::Hds => usize::from(g[2] >= 0.0),
        Layout::LatLong => match (g[0] >= 0.0, g[1] >= 0.0) {
            (true, true) => 0,
            (false, true) => 1,
            (false, false) => 2,
            (true, false) => 3,
        },
        Layout::Octahedral => {
            usize::from(g[0] < 0.0)
                | (usize::from(g[1] < 0.0) << 1)
                | (usize::from(g[2] < 0.0) << 2)
        }
        Layout::Cube => {
            let a = g.map(f64::abs);
            if a[0] >= a[1] && a[0] >= a[2] {
                usize::from(g[0] < 0.0)
            } else if a[1] >= a[2] {
                2 + usize::from(g[1] < 0.0)
            } else {
                4 + usize::from(g[2] < 0.0)
            }
        }
    }
}

/// One polygon corner during the cut: position index and normal index.
type PolyCorner = (u32, u32);

struct Cutter<'a> {
    mesh: &'a Mesh,
    center: Vec3,
    planes: Vec<Vec3>,
    eps: f64,
    out: UvMesh,
    /// New vertex on the edge (lo, hi) for plane k.
    edge_vertex: HashMap<(u32, u32, u8), u32>,
    /// New normal on the edge between normals (lo, hi) at position parameter bits.
    edge_normal: HashMap<(u32, u32, u64), u32>,
    /// Lazily computed signed distances per vertex and plane.
    sdist: Vec<f64>,
}

impl Cutter<'_> {
    fn s(&mut self, v: u32, k: usize) -> f64 {
        let np = self.planes.len();
        let idx = v as usize * np + k;
        if idx >= self.sdist.len() {
            self.sdist.resize((v as usize + 1) * np, f64::NAN);
        }
        let mut s = self.sdist[idx];
        if s.is_nan() {
            s = dot(
                sub(self.out.positions[v as usize], self.center),
                self.planes[k],
            );
            self.sdist[idx] = s;
        }
        s
    }
    fn class(&mut self, v: u32, k: usize) -> i8 {
        let s = self.s(v, k);
        if s > self.eps {
            1
        } else if s < -self.eps {
            -1
        } else {
            0
        }
    }
    fn split_vertex(&mut self, p: PolyCorner, q: PolyCorner, k: usize) -> PolyCorner {
        let (a, b) = if p.0 < q.0 { (p, q) } else { (q, p) };
        let key = (a.0, b.0, k as u8);
        let (sa, sb) = (self.s(a.0, k), self.s(b.0, k));
        let t = sa / (sa - sb);
        let v = match self.edge_vertex.get(&key) {
            Some(&v) => v,
            None => {
                let pa = self.out.positions[a.0 as usize];
                let pb = self.out.positions[b.0 as usize];
                self.out.positions.push(add(pa, scale(sub(pb, pa), t)));
                for prop in &mut self.out.vertex_properties {
                    let (va, vb) = (prop.values[a.0 as usize], prop.values[b.0 as usize]);
                    prop.values.push(va + (vb - va) * t);
                }
                let v = (self.out.positions.len() - 1) as u32;
                self.edge_vertex.insert(key, v);
                // On the plane by construction.
                let np = self.planes.len();
                self.sdist.resize((v as usize + 1) * np, f64::NAN);
                self.sdist[v as usize * np + k] = 0.0;
                v
            }
        };
        let n = if a.1 == NO_INDEX || b.1 == NO_INDEX {
            NO_INDEX
        } else {
            let nkey = (a.1, b.1, t.to_bits());
            match self.edge_normal.get(&nkey) {
                Some(&n) => n,
                None => {
                    let na = self.out.normals[a.1 as usize];
                    let nb = self.out.normals[b.1 as usize];
                    self.out
                        .normals
                        .push(normalize(add(na, scale(sub(nb, na), t))));
                    let n = (self.out.normals.len() - 1) as u32;
                    self.edge_normal.insert(nkey, n);
                    n
                }
            }
        };
        (v, n)
    }
    /// Splits `poly` by plane k into the parts on its positive and negative side.
    fn split(&mut self, poly: &[PolyCorner], k: usize) -> (Vec<PolyCorner>, Vec<PolyCorner>) {
        let (mut pos, mut neg) = (Vec::new(), Vec::new());
        let n = poly.len();
        for i in 0..n {
            let (p, q) = (poly[i], poly[(i + 1) % n]);
            let (cp, cq) = (self.class(p.0, k), self.class(q.0, k));
            if cp >= 0 {
                pos.push(p);
            }
            if cp <= 0 {
                neg.push(p);
            }
            if cp * cq < 0 {
                let x = self.split_vertex(p, q, k);
                pos.push(x);
                neg.push(x);
            }
        }
        (pos, neg)
    }
}

/// Parameterises `mesh` (see the module documentation).
pub fn parameterise(mesh: &Mesh, options: &UvOptions) -> Result<UvResult, MeshError> {
    mesh.validate()?;
    if let Some(k) = super::star::extent_scale(mesh, options.center) {
        // Scale-free: a mesh of coordinates near 1e100 or 1e-100 (whose areas and volume would
        // overflow or underflow) is parameterised at 2^k times its size, exactly, and scaled back.
        let m = super::star::scaled_mesh(mesh, k)?;
        let mut opts = options.clone();
        opts.center = options.center.map(|c| c.map(|x| super::star::ldexp(x, k)));
        let mut r = parameterise(&m, &opts)?;
        let back = |p: &mut [f64; 3]| *p = p.map(|x| super::star::ldexp(x, -k));
        r.mesh.positions.iter_mut().for_each(back);
        let mut c = r.star.center;
        back(&mut c);
        r.star.center = c;
        return Ok(r);
    }
    let t0 = std::time::Instant::now();
    let star = find_center(mesh, options.center)?;
    let t1 = std::time::Instant::now();
    let (texture, diagram) = if options.layout == Layout::Hds {
        let grid = options
            .grid
            .unwrap_or_else(|| default_grid(mesh.triangles.len()));
        let d = density_diagram(mesh, star.center, &options.density, grid)?;
        (None, Some(d))
    } else {
        (None::<TextureMap>, None)
    };
    let t2 = std::time::Instant::now();
    let texture = match (&diagram, texture) {
        (Some(d), _) => Some(TextureMap::new(d, options.tolerance)?),
        (None, t) => t,
    };
    let t3 = std::time::Instant::now();
    let (uv_mesh, cut) = build_uvs(mesh, &star, options.layout, texture.as_ref())?;
    let t4 = std::time::Instant::now();
    Ok(UvResult {
        mesh: uv_mesh,
        star,
        texture,
        diagram,
        cut_triangles: cut,
        seconds: [
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64(),
            (t3 - t2).as_secs_f64(),
            (t4 - t3).as_secs_f64(),
        ],
    })
}

/// The cut and the UVs for a checked centre (the last stage of [`parameterise`]); `texture` is
/// needed for [`Layout::Hds`].
pub fn build_uvs(
    mesh: &Mesh,
    star: &StarCheck,
    layout: Layout,
    texture: Option<&TextureMap>,
) -> Result<(UvMesh, usize), MeshError> {
    let center = star.center;
    let mut radius: f64 = 0.0;
    for p in &mesh.positions {
        radius = radius.max(dot(sub(*p, center), sub(*p, center)).sqrt());
    }
    let planes = match (layout, texture) {
        (Layout::Hds, Some(t)) => {
            let mut p = layout.planes();
            p.extend(t.cut_planes());
            p
        }
        _ => layout.planes(),
    };
    let n_charts = layout.charts();
    let mut cutter = Cutter {
        mesh,
        center,
        planes,
        eps: 1e-10 * radius,
        out: UvMesh {
            positions: mesh.positions.clone(),
            normals: mesh.normals.clone(),
            vertex_properties: mesh.vertex_properties.clone(),
            ..UvMesh::default()
        },
        edge_vertex: HashMap::new(),
        edge_normal: HashMap::new(),
        sdist: Vec::new(),
    };
    cutter.sdist = vec![f64::NAN; mesh.positions.len() * cutter.planes.len()];
    cutter
        .out
        .triangles
        .reserve(mesh.triangles.len() + mesh.triangles.len() / 16);
    cutter
        .out
        .uvs
        .reserve(mesh.positions.len() + mesh.positions.len() / 16);
    let mut uv_of: Vec<u32> = vec![NO_INDEX; mesh.positions.len() * n_charts];
    let mut cut = 0usize;
    let has_normals = !mesh.triangle_normals.is_empty();
    let mut pieces: Vec<Vec<PolyCorner>> = Vec::new();
    for (f, t) in cutter.mesh.triangles.iter().enumerate() {
        let nrm = if has_normals {
            cutter.mesh.triangle_normals[f]
        } else {
            [NO_INDEX; 3]
        };
        pieces.clear();
        pieces.push((0..3).map(|k| (t[k], nrm[k])).collect());
        let mut was_cut = false;
        for k in 0..cutter.planes.len() {
            let straddles = |cutter: &mut Cutter, poly: &[PolyCorner]| {
                let (mut has_pos, mut has_neg) = (false, false);
                for c in poly {
                    let cl = cutter.class(c.0, k);
                    has_pos |= cl > 0;
                    has_neg |= cl < 0;
                }
                has_pos && has_neg
            };
            // Most triangles miss most planes: no new vectors for them.
            if !pieces.iter().any(|poly| straddles(&mut cutter, poly)) {
                continue;
            }
            let mut next = Vec::with_capacity(pieces.len() + 1);
            for poly in pieces.drain(..) {
                if straddles(&mut cutter, &poly) {
                    was_cut = true;
                    let (a, b) = cutter.split(&poly, k);
                    for p in [a, b] {
                        if p.len() >= 3 {
                            next.push(p);
                        }
                    }
                } else {
                    next.push(poly);
                }
            }
            pieces = next;
        }
        cut += usize::from(was_cut);
        for poly in &pieces {
            // The chart of the piece: from its centroid direction.
            let mut g = [0.0; 3];
            for c in poly {
                g = add(g, sub(cutter.out.positions[c.0 as usize], center));
            }
            let g = normalize(g);
            let chart = chart_of(layout, g);
            let mut corner_uv: Vec<u32> = Vec::with_capacity(poly.len());
            for c in poly {
                let v = c.0 as usize;
                if uv_of.len() < (v + 1) * n_charts {
                    uv_of.resize((v + 1) * n_charts, NO_INDEX);
                }
                let d = normalize(sub(cutter.out.positions[v], center));
                let pole = layout == Layout::LatLong && d[0].hypot(d[1]) <= 1e-12;
                let cached = uv_of[v * n_charts + chart];
                let id = if cached != NO_INDEX && !pole {
                    cached
                } else {
                    let uv = match layout {
                        Layout::Hds => texture
                            .ok_or_else(|| MeshError::Density("no texture map".into()))?
                            .uv(d, chart)?,
                        _ => classic_uv(layout, d, chart, g),
                    };
                    cutter.out.uvs.push(uv);
                    let id = (cutter.out.uvs.len() - 1) as u32;
                    if !pole {
                        uv_of[v * n_charts + chart] = id;
                    }
                    id
                };
                corner_uv.push(id);
            }
            let corners: Vec<Corner> = poly
                .iter()
                .zip(&corner_uv)
                .map(|(c, &uv)| Corner {
                    position: c.0,
                    uv,
                    normal: c.1,
                })
                .collect();
            triangulate(&mut cutter.out, &corners, chart as u8, f as u32);
        }
    }
    Ok((cutter.out, cut))
}

/// Fan-triangulates a convex piece from the apex that maximises the smallest UV area.
fn triangulate(out: &mut UvMesh, corners: &[Corner], chart: u8, source: u32) {
    let n = corners.len();
    let uv = |c: &Corner| out.uvs[c.uv as usize];
    if n == 3 {
        out.triangles.push([corners[0], corners[1], corners[2]]);
        out.chart.push(chart);
        out.source_triangle.push(source);
        return;
    }
    let total: f64 = (1..n - 1)
        .map(|k| signed_area([uv(&corners[0]), uv(&corners[k]), uv(&corners[k + 1])]))
        .sum();
    let sign = if total < 0.0 { -1.0 } else { 1.0 };
    let mut best = (0, f64::NEG_INFINITY);
    for apex in 0..n {
        let mut worst = f64::INFINITY;
        for k in 1..n - 1 {
            let (b, c) = (corners[(apex + k) % n], corners[(apex + k + 1) % n]);
            worst = worst.min(sign * signed_area([uv(&corners[apex]), uv(&b), uv(&c)]));
        }
        if worst > best.1 {
            best = (apex, worst);
        }
    }
    let apex = best.0;
    for k in 1..n - 1 {
        out.triangles.push([
            corners[apex],
            corners[(apex + k) % n],
            corners[(apex + k + 1) % n],
        ]);
        out.chart.push(chart);
        out.source_triangle.push(source);
    }
}
