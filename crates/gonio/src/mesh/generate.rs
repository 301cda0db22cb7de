//! Generated star-shaped test meshes: a geodesic sphere of frequency n (each of the icosahedron's
//! 20 faces cut into n² triangles, 20 n² triangles and 10 n² + 2 vertices) whose vertex in unit
//! direction ω is moved to r(ω) ω for a shape's radius function r. Every such mesh is star-shaped
//! from the origin: the triangle (r_a ω_a, r_b ω_b, r_c ω_c) has det = r_a r_b r_c det(ω_a, ω_b, ω_c)
//! > 0. Triangles are counter-clockwise seen from outside.
//!
//! Shapes ([`Shape`]): ellipsoids, superquadrics (superellipsoids), spheres displaced by a
//! band-limited random field (spherical-harmonic-like, an asteroid), and a head-like blob; and, for
//! the error paths, a bent (non-star-shaped) banana.

use super::Mesh;
use rand::{Rng, SeedableRng};
use std::collections::HashMap;

/// A radius function of direction.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// The ellipsoid with semi-axes (a, b, c) along x, y, z.
    Ellipsoid([f64; 3]),
    /// |x/a|^p + |y/b|^p + |z/c|^p = 1 (p = 2: the ellipsoid; large p: a rounded box).
    Superquadric {
        /// Semi-axes.
        axes: [f64; 3],
        /// Exponent p ≥ 1.
        exponent: f64,
    },
    /// r = 1 + amplitude · Σ_k a_k sin(k_k·ω + φ_k) / √K over K random plane waves with |k| ≤
    /// `max_frequency` (fixed seed): a smooth random relief, like an asteroid's low-degree
    /// spherical-harmonic shape.
    Asteroid {
        /// Relief amplitude (keep below ~0.4 so r > 0).
        amplitude: f64,
        /// Largest wave number.
        max_frequency: f64,
        /// Seed of the waves.
        seed: u64,
    },
    /// An ellipsoidal head with a nose, two ears and a chin (Gaussian bumps).
    Head,
}

fn normalise(p: [f64; 3]) -> [f64; 3] {
    let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    [p[0] / l, p[1] / l, p[2] / l]
}

fn bump(d: [f64; 3], c: [f64; 3], width: f64) -> f64 {
    let c = normalise(c);
    let dot = d[0] * c[0] + d[1] * c[1] + d[2] * c[2];
    (-(1.0 - dot) / (width * width)).exp()
}

impl Shape {
    /// The radius in unit direction `d`.
    pub fn radius(&self, d: [f64; 3]) -> f64 {
        match self {
            Shape::Ellipsoid(a) => {
                1.0 / ((d[0] / a[0]).powi(2) + (d[1] / a[1]).powi(2) + (d[2] / a[2]).powi(2)).sqrt()
            }
            Shape::Superquadric { axes, exponent } => {
                let s: f64 = (0..3).map(|k| (d[k] / axes[k]).abs().powf(*exponent)).sum();
                s.powf(-1.0 / exponent)
            }
            Shape::Asteroid {
                amplitude,
                max_frequency,
                seed,
            } => {
                let waves = asteroid_waves(*max_frequency, *seed);
                let s: f64 = waves
                    .iter()
                    .map(|(k, ph, a)| a * (k[0] * d[0] + k[1] * d[1] + k[2] * d[2] + ph).sin())
                    .sum();
                1.0 + amplitude * s / (waves.len() as f64).sqrt()
            }
            Shape::Head => {
                let base = Shape::Ellipsoid([0.8, 0.95, 1.15]).radius(d);
                base + 0.25 * bump(d, [1.0, 0.0, 0.05], 0.18)
                    + 0.12 * bump(d, [0.0, 1.0, 0.1], 0.2)
                    + 0.12 * bump(d, [0.0, -1.0, 0.1], 0.2)
                    + 0.1 * bump(d, [0.6, 0.0, -0.8], 0.3)
            }
        }
    }
}

/// The asteroid's waves (wave vector, phase, amplitude), 24 of them.
fn asteroid_waves(max_frequency: f64, seed: u64) -> Vec<([f64; 3], f64, f64)> {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..24)
        .map(|_| {
            let dir = loop {
                let v: [f64; 3] = [
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                ];
                let l = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                if l > 1e-3 && l <= 1.0 {
                    break normalise(v);
                }
            };
            let k: f64 = rng.gen_range(0.5..=max_frequency.max(0.5));
            (
                [dir[0] * k, dir[1] * k, dir[2] * k],
                rng.gen_range(0.0..std::f64::consts::TAU),
                rng.gen_range(0.3..1.0),
            )
        })
        .collect()
}

/// The unit geodesic sphere of frequency `n` ≥ 1: 20 n² triangles, counter-clockwise seen from
/// outside.
pub fn geodesic_sphere(n: usize) -> Mesh {
    let n = n.max(1);
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let ico: [[f64; 3]; 12] = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let faces: [[usize; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut positions: Vec<[f64; 3]> = Vec::with_capacity(10 * n * n + 2);
    // Vertex keys: an icosahedron vertex, a point k/n along an edge (from its lower vertex), or an
    // interior point (face, i, j); points on edges are computed from the edge, so that both faces
    // share them exactly.
    let mut index: HashMap<(usize, usize, usize, usize), u32> = HashMap::new();
    let mut vertex = |key: (usize, usize, usize, usize), p: [f64; 3]| -> u32 {
        *index.entry(key).or_insert_with(|| {
            positions.push(normalise(p));
            (positions.len() - 1) as u32
        })
    };
    let lerp = |a: [f64; 3], b: [f64; 3], s: f64| -> [f64; 3] {
        [
            a[0] + (b[0] - a[0]) * s,
            a[1] + (b[1] - a[1]) * s,
            a[2] + (b[2] - a[2]) * s,
        ]
    };
    let mut triangles = Vec::with_capacity(20 * n * n);
    for (fi, f) in faces.iter().enumerate() {
        let [a, b, c] = *f;
        // Point (i, j): a + i/n (b − a) + j/n (c − a), i + j ≤ n.
        let mut id = |i: usize, j: usize| -> u32 {
            let k = n - i - j;
            // Corners.
            if i == 0 && j == 0 {
                return vertex((0, a, 0, 0), ico[a]);
            }
            if i == n {
                return vertex((0, b, 0, 0), ico[b]);
            }
            if j == n {
                return vertex((0, c, 0, 0), ico[c]);
            }
            let edge = |p: usize, q: usize, s: usize| {
                let (lo, hi, s) = if p < q { (p, q, s) } else { (q, p, n - s) };
                ((1, lo, hi, s), lerp(ico[lo], ico[hi], s as f64 / n as f64))
            };
            let (key, p) = if j == 0 {
                edge(a, b, i)
            } else if i == 0 {
                edge(a, c, j)
            } else if k == 0 {
                edge(b, c, j)
            } else {
                let p = lerp(lerp(ico[a], ico[b], i as f64 / n as f64), ico[c], 0.0);
                let p = [
                    p[0] + (ico[c][0] - ico[a][0]) * j as f64 / n as f64,
                    p[1] + (ico[c][1] - ico[a][1]) * j as f64 / n as f64,
                    p[2] + (ico[c][2] - ico[a][2]) * j as f64 / n as f64,
                ];
                ((2, fi, i, j), p)
            };
            vertex(key, p)
        };
        for i in 0..n {
            for j in 0..n - i {
                let (p, q, r) = (id(i, j), id(i + 1, j), id(i, j + 1));
                triangles.push([p, q, r]);
                if i + j + 1 < n {
                    let s = id(i + 1, j + 1);
                    triangles.push([q, s, r]);
                }
            }
        }
    }
    let source_face = (0..triangles.len() as u32).collect();
    Mesh {
        positions,
        triangles,
        source_face,
        ..Mesh::default()
    }
}

/// The frequency whose geodesic sphere has about `faces` triangles (20 n² ≈ faces).
pub fn frequency_for_faces(faces: usize) -> usize {
    ((faces as f64 / 20.0).sqrt().round() as usize).max(1)
}

/// The shape as a mesh of frequency `n` (20 n² triangles), star-shaped from the origin.
pub fn shape_mesh(shape: &Shape, n: usize) -> Mesh {
    let mut m = geodesic_sphere(n);
    if let Shape::Asteroid {
        amplitude,
        max_frequency,
        seed,
    } = shape
    {
        // Waves once, not per vertex.
        let waves = asteroid_waves(*max_frequency, *seed);
        let norm = (waves.len() as f64).sqrt();
        for p in &mut m.positions {
            let d = *p;
            let s: f64 = waves
                .iter()
                .map(|(k, ph, a)| a * (k[0] * d[0] + k[1] * d[1] + k[2] * d[2] + ph).sin())
                .sum();
            let r = 1.0 + amplitude * s / norm;
            *p = [d[0] * r, d[1] * r, d[2] * r];
        }
        return m;
    }
    for p in &mut m.positions {
        let r = shape.radius(*p);
        *p = [p[0] * r, p[1] * r, p[2] * r];
    }
    m
}

/// A banana: the ellipsoid (2, 0.5, 0.5) bent along z by z += 1.5 (1 − x²/4)... strongly enough
/// that no point sees every triangle (not star-shaped), for the error path.
pub fn banana(n: usize) -> Mesh {
    let mut m = shape_mesh(&Shape::Ellipsoid([2.0, 0.4, 0.4]), n);
    for p in &mut m.positions {
        // Bend into a horseshoe: the x axis onto a circle of radius 0.7.
        let a = p[0] / 0.7;
        let r = 0.7 + p[2];
        *p = [r * a.sin(), p[1], r * a.cos()];
    }
    m
}

/// The named test shapes of `docs/TEXTURE.md`.
pub fn named_shapes() -> Vec<(&'static str, Shape)> {
    vec![
        ("sphere", Shape::Ellipsoid([1.0, 1.0, 1.0])),
        ("ellipsoid", Shape::Ellipsoid([1.0, 0.7, 0.45])),
        (
            "superquadric",
            Shape::Superquadric {
                axes: [1.0, 0.8, 0.6],
                exponent: 3.0,
            },
        ),
        (
            "asteroid",
            Shape::Asteroid {
                amplitude: 0.3,
                max_frequency: 3.0,
                seed: 7,
            },
        ),
        ("head", Shape::Head),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geodesic_counts_and_closed() {
        for n in [1, 2, 5] {
            let m = geodesic_sphere(n);
            assert_eq!(m.triangles.len(), 20 * n * n);
            assert_eq!(m.positions.len(), 10 * n * n + 2);
            super::super::star::check_closed(&m).unwrap();
        }
    }
}
