//! Baking a spherical texture into the map's square, and a preview render.
//!
//! Images are row-major RGB float buffers, row 0 at the **top**. A texel (x, y) of an N × N baked
//! texture has texture coordinate ((x + ½)/N, 1 − (y + ½)/N), so that OBJ's `vt` (v up) addresses
//! it as usual.
//!
//! An **equirectangular** image of W × H pixels is read in the project's one lat-long frame, that
//! of the environment maps ([`crate::envmap`], docs/ENVMAPS.md): row y at θ = π(y + ½)/H (from +z,
//! the top row), column x at s = (x + ½)/W with φ = π − 2πs, so the centre column looks along +x
//! and φ decreases to the right ([`crate::envmap::phi_to_s`]).

use super::param::TextureMap;
use super::UvMesh;
use crate::sampler::{spherical, Vec3};
use crate::vector::{cross, dot, sub};
use std::f64::consts::{PI, TAU};

/// An RGB float image, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width × height` RGB triples, row-major.
    pub rgb: Vec<[f32; 3]>,
}

/// Bilinear lookup of the equirectangular image `img` in unit direction `d` (wrapping in φ,
/// clamped in θ).
pub fn sample_equirect(img: &Image, d: Vec3) -> [f32; 3] {
    let (t, p) = spherical(d);
    let x = crate::envmap::phi_to_s(p) * img.width as f64 - 0.5;
    let y = (t / PI * img.height as f64 - 0.5).clamp(0.0, (img.height - 1) as f64);
    let x0 = x.floor();
    let fx = (x - x0) as f32;
    let y0 = y.floor().min((img.height.saturating_sub(2)) as f64);
    let fy = ((y - y0) as f32).clamp(0.0, 1.0);
    let w = img.width as i64;
    let xi = |k: i64| ((x0 as i64 + k).rem_euclid(w)) as usize;
    let yi = |k: usize| (y0 as usize + k).min(img.height - 1);
    let px = |xx: usize, yy: usize| img.rgb[yy * img.width + xx];
    let mut out = [0.0f32; 3];
    for c in 0..3 {
        let a = px(xi(0), yi(0))[c] * (1.0 - fx) + px(xi(1), yi(0))[c] * fx;
        let b = px(xi(0), yi(1))[c] * (1.0 - fx) + px(xi(1), yi(1))[c] * fx;
        out[c] = a * (1.0 - fy) + b * fy;
    }
    out
}

/// A checkerboard over directions: `n` squares along the equator and n/2 from pole to pole (θ, φ
/// cells), light and dark grey.
pub fn checker_direction(d: Vec3, n: usize) -> [f32; 3] {
    let (t, p) = spherical(d);
    let n = n.max(2) as f64;
    let i = (p / TAU * n).floor() as i64 + (t / PI * n * 0.5).floor() as i64;
    if i.rem_euclid(2) == 0 {
        [0.9, 0.9, 0.9]
    } else {
        [0.15, 0.15, 0.15]
    }
}

/// A checkerboard in texture space: `nu` × `nv` cells of the unit square (each cell covers the
/// same surface area under the `surface` density; with the split layout's two charts side by side,
/// nu = 2 nv gives cells about square on the surface), with the charts tinted (the lower chart,
/// u < `seam`, blue) so the seam shows.
pub fn checker_uv(uv: [f64; 2], nu: usize, nv: usize, seam: f64) -> [f32; 3] {
    let (nu, nv) = (nu.max(1) as f64, nv.max(1) as f64);
    let i = (uv[0] * nu).floor() as i64 + (uv[1] * nv).floor() as i64;
    let light = i.rem_euclid(2) == 0;
    match (uv[0] < seam, light) {
        (true, true) => [0.8, 0.85, 1.0],
        (true, false) => [0.1, 0.15, 0.35],
        (false, true) => [1.0, 0.9, 0.75],
        (false, false) => [0.35, 0.2, 0.1],
    }
}

/// Bakes `source` (a function of the unit direction from the centre) into the N × N square
/// texture of `map`, averaging 2 × 2 samples per texel.
pub fn bake(map: &TextureMap, resolution: usize, source: &dyn Fn(Vec3) -> [f32; 3]) -> Image {
    let n = resolution.max(1);
    let mut rgb = vec![[0.0f32; 3]; n * n];
    for y in 0..n {
        for x in 0..n {
            let mut acc = [0.0f32; 3];
            for (sx, sy) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
                let uv = [(x as f64 + sx) / n as f64, 1.0 - (y as f64 + sy) / n as f64];
                let c = source(map.direction(uv));
                for k in 0..3 {
                    acc[k] += 0.25 * c[k];
                }
            }
            rgb[y * n + x] = acc;
        }
    }
    Image {
        width: n,
        height: n,
        rgb,
    }
}

/// Renders `mesh` (orthographic, two views side by side: from +x+y+z-ish and from the opposite
/// side), each pixel coloured by `shade(uv)` times a Lambert term of the triangle's normal; white
/// background. `width` is the whole image (two squares of width/2).
pub fn render_preview(mesh: &UvMesh, width: usize, shade: &dyn Fn([f64; 2]) -> [f32; 3]) -> Image {
    let half = (width / 2).max(8);
    let (w, h) = (2 * half, half);
    let mut rgb = vec![[1.0f32; 3]; w * h];
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    // Bounding sphere.
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &mesh.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let c = [
        0.5 * (lo[0] + hi[0]),
        0.5 * (lo[1] + hi[1]),
        0.5 * (lo[2] + hi[2]),
    ];
    let mut r: f64 = 0.0;
    for p in &mesh.positions {
        r = r.max(((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt());
    }
    let r = r.max(1e-300);
    for view in 0..2 {
        // Camera looking along −dir; right and up vectors.
        let s = if view == 0 { 1.0 } else { -1.0 };
        let dir = norm3([0.8 * s, 0.5 * s, 0.35]);
        let right = norm3(cross([0.0, 0.0, 1.0], dir));
        let up = cross(dir, right);
        let light = norm3([
            dir[0] + 0.3 * up[0],
            dir[1] + 0.3 * up[1],
            dir[2] + 0.3 * up[2],
        ]);
        let project = |p: Vec3| {
            let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            let x = (dot(q, right) / r * 0.48 + 0.5) * half as f64;
            let y = (0.5 - dot(q, up) / r * 0.48) * half as f64;
            (x, y, dot(q, dir))
        };
        for t in &mesh.triangles {
            let p = t.map(|k| mesh.positions[k.position as usize]);
            let uv = t.map(|k| mesh.uvs[k.uv as usize]);
            let nrm = norm3(cross(sub(p[1], p[0]), sub(p[2], p[0])));
            let lambert = dot(nrm, light).abs() as f32 * 0.8 + 0.2;
            let q = p.map(project);
            let area =
                (q[1].0 - q[0].0) * (q[2].1 - q[0].1) - (q[2].0 - q[0].0) * (q[1].1 - q[0].1);
            if area == 0.0 || !area.is_finite() {
                continue;
            }
            let (minx, maxx) = pixel_span(q.map(|v| v.0), half);
            let (miny, maxy) = pixel_span(q.map(|v| v.1), h);
            for py in miny..=maxy {
                for px in minx..=maxx {
                    let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
                    let b0 = ((q[1].0 - x) * (q[2].1 - y) - (q[2].0 - x) * (q[1].1 - y)) / area;
                    let b1 = ((q[2].0 - x) * (q[0].1 - y) - (q[0].0 - x) * (q[2].1 - y)) / area;
                    let b2 = 1.0 - b0 - b1;
                    if b0 < 0.0 || b1 < 0.0 || b2 < 0.0 {
                        continue;
                    }
                    let z = b0 * q[0].2 + b1 * q[1].2 + b2 * q[2].2;
                    let idx = py * w + view * half + px;
                    if z <= depth[idx] {
                        continue;
                    }
                    depth[idx] = z;
                    let u = [
                        b0 * uv[0][0] + b1 * uv[1][0] + b2 * uv[2][0],
                        b0 * uv[0][1] + b1 * uv[1][1] + b2 * uv[2][1],
                    ];
                    let col = shade(u);
                    rgb[idx] = col.map(|v| v * lambert);
                }
            }
        }
    }
    Image {
        width: w,
        height: h,
        rgb,
    }
}

/// The pixels `first..=last` along one axis of a `size`-pixel raster that a triangle whose
/// corners stand at `x` (pixel units) may cover, clamped to the raster.
fn pixel_span(x: [f64; 3], size: usize) -> (usize, usize) {
    let lo = x.into_iter().fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
    let hi = x.into_iter().fold(f64::NEG_INFINITY, f64::max).ceil() as usize;
    (lo, hi.min(size - 1))
}

fn norm3(a: Vec3) -> Vec3 {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

#[cfg(test)]
mod frame_tests {
    use super::*;
    use crate::envmap::{EnvOptions, EnvironmentMap, Lookup};

    /// The bake reads lat-long images in the environment maps' frame: at every pixel centre the
    /// bilinear lookup of `sample_equirect` returns that pixel, and so does the environment map's
    /// own lookup (nearest and bilinear) of the same direction.
    #[test]
    fn equirect_frame_is_the_envmap_frame() {
        let (w, h) = (8usize, 4usize);
        let rgb: Vec<f32> = (0..w * h)
            .flat_map(|i| [1.0 + i as f32, 0.5 * i as f32, 100.0 - i as f32])
            .collect();
        let img = crate::image::Image::new(w, h, rgb.clone()).unwrap();
        let bake_img = Image {
            width: w,
            height: h,
            rgb: rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(),
        };
        let env = EnvironmentMap::with_options(img, EnvOptions::default()).unwrap();
        for y in 0..h {
            for x in 0..w {
                let d = crate::envmap::image_direction(
                    (x as f64 + 0.5) / w as f64,
                    (y as f64 + 0.5) / h as f64,
                );
                let want = bake_img.rgb[y * w + x];
                let got = sample_equirect(&bake_img, d);
                let env_near = env.eval_with(d, Lookup::Nearest);
                for c in 0..3 {
                    assert!((got[c] - want[c]).abs() <= 1e-4 * want[c].abs().max(1.0));
                    assert_eq!(env_near[c], want[c], "pixel ({x}, {y})");
                }
            }
        }
    }
}
