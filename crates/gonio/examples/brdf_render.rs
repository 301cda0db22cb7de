//! Issue 26's rendered picture: a sphere of each analytic material under a shared environment map,
//! lit by **BRDF sampling only**, every method (hds, cosine, ggx-fit, piecewise-constant) at
//! **equal time**, with the RMSE of each image against a converged reference.
//!
//! `cargo run --release -p gonio --example brdf_render [-- MAP BUDGET_US REF_N FILTER]`
//! (defaults: `sunset`, 64 µs per pixel, 256 reference samples per strategy, 8; the maps are found
//! as the tests find them: `$GONIO_ENVMAPS`, else `shared/data/envmaps` beside the workspace).
//! The map is read with `gonio::image`, **box-filtered** over FILTER × FILTER pixels in memory
//! (default 8: 1024 × 512 → 128 × 64; 1 keeps it as it is) and evaluated with `gonio::envmap`
//! (nearest pixel). Unfiltered, the sunset's sun (≈ 6e-5 sr) is hit about once per image at these
//! sample counts, and every method's RMSE is then the luck of those few hits, not its sampling.
//! Writes `docs/brdf/brdf_render.png` and prints the table of docs/BRDF.md.
//!
//! * **Materials** (`Analytic::families()`), each table made in memory by the project's own writer
//!   and read back by its reader: Lambert, isotropic GGX and Lambert + GGX through a MERL
//!   `.binary` (read with the default resampling 46 × 46 × 90), anisotropic GGX through a UTIA
//!   `.bin` (6 × 48 incident slices, no data beyond 75°), Ashikhmin–Shirley through gonio's JSON
//!   (10 × 24 incident × 10 × 24 outgoing nodes, 10° × 15°).
//! * **Camera**: orthographic, at +x looking along −x (world = the environment map's frame, z up),
//!   image right = +y, image up = +z; a unit sphere at the origin fills the 96 × 96 pixels; one
//!   ray through each pixel centre; pixels off the sphere are black and not counted.
//! * **Shading frame** at the hit point p: z = n = p (the normal), x = t = normalize(ẑ × n) (the
//!   tangent along the parallels, eastwards), y = n × t. The view direction (to the camera, +x) is
//!   passed as ω_i and the light direction is sampled as ω_o; the estimate is
//!   (1/N) Σ w(ω_o)·L_env(ω_o) with w = f_r(ω_i, ω_o)·cos θ_o / pdf per channel (the analytic
//!   BRDFs are reciprocal, so this is the reflected radiance). The sphere is convex: no occlusion.
//! * **Equal time**: each method's time per sample (one full shading sample: sampling, the
//!   table's f_r, the map's radiance) is measured first on a 4-sample pass over the sphere (median
//!   of 3), and each gets ⌊budget / time⌋ samples per pixel (at least 1).
//! * **Reference**: multiple importance sampling (balance heuristic) of the environment map's own
//!   HDS sphere map and the HDS BRDF sampler, REF_N samples of each per pixel; **converged** is
//!   checked with two independent halves: the reference's own RMSE is estimated as
//!   RMSE(half A, half B)/2 and printed beside the methods' RMSEs.
//! * **RMSE**: over the sphere's pixels and the three channels, divided by the reference's mean
//!   (relative RMSE). Random points: xoshiro256++ per pixel and method, fixed seeds.
//! * **Picture**: rows = materials (in the order above), columns = reference, hds, cosine,
//!   ggx-fit, piecewise-constant; each row exposed so that its reference's mean luminance is 0.35,
//!   then the sRGB transfer curve.

#[path = "../tests/common/corpus.rs"]
mod corpus;

use gonio::brdf::{
    read_any, write_json, write_merl, write_utia_dirs, Analytic, BrdfMethod, BrdfSampler,
    CosineBrdf, GgxFit, MerlOptions, PerSliceConstant, SamplerOptions, TabulatedBrdf,
};
use gonio::envmap::{luminance, EnvironmentMap};
use gonio::image::Image;
use gonio::vector::dot;
use gonio::{Point2, Vec3};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::time::Instant;

const SIZE: usize = 96;

/// A pixel on the sphere: the shading frame (t, b, n) and ω_i = the view direction in it.
#[derive(Clone, Copy)]
struct Hit {
    index: usize,
    t: Vec3,
    b: Vec3,
    n: Vec3,
    wi: Vec3,
}

impl Hit {
    fn world(&self, d: Vec3) -> Vec3 {
        [0, 1, 2].map(|k| d[0] * self.t[k] + d[1] * self.b[k] + d[2] * self.n[k])
    }
    fn local(&self, d: Vec3) -> Vec3 {
        [dot(d, self.t), dot(d, self.b), dot(d, self.n)]
    }
}

fn hits() -> Vec<Hit> {
    let view = [1.0, 0.0, 0.0];
    let mut out = Vec::new();
    for py in 0..SIZE {
        for px in 0..SIZE {
            let a = 2.0 * (px as f64 + 0.5) / SIZE as f64 - 1.0;
            let c = 1.0 - 2.0 * (py as f64 + 0.5) / SIZE as f64;
            let r2 = a * a + c * c;
            if r2 >= 1.0 {
                continue;
            }
            let n = [(1.0 - r2).sqrt(), a, c];
            let l = (n[0] * n[0] + n[1] * n[1]).sqrt();
            let t = if l > 1e-12 {
                [-n[1] / l, n[0] / l, 0.0]
            } else {
                [1.0, 0.0, 0.0]
            };
            let b = [
                n[1] * t[2] - n[2] * t[1],
                n[2] * t[0] - n[0] * t[2],
                n[0] * t[1] - n[1] * t[0],
            ];
            let mut h = Hit {
                index: py * SIZE + px,
                t,
                b,
                n,
                wi: [0.0; 3],
            };
            h.wi = h.local(view);
            out.push(h);
        }
    }
    out
}

fn radiance(env: &EnvironmentMap, d: Vec3) -> [f64; 3] {
    env.eval(d).map(f64::from)
}

/// One BRDF-sampling estimate's term: w·L for the point `u`.
#[inline]
fn shade_one(m: &dyn BrdfMethod, env: &EnvironmentMap, h: &Hit, u: Point2) -> [f64; 3] {
    let s = m.sample(h.wi, u);
    if s.weight == [0.0; 3] {
        return [0.0; 3];
    }
    let l = radiance(env, h.world(s.direction));
    [s.weight[0] * l[0], s.weight[1] * l[1], s.weight[2] * l[2]]
}

/// Renders with `spp` BRDF samples per pixel; returns the image (linear RGB, SIZE²) and seconds.
fn render(
    m: &dyn BrdfMethod,
    env: &EnvironmentMap,
    hits: &[Hit],
    spp: usize,
    seed: u64,
) -> (Vec<[f64; 3]>, f64) {
    let mut img = vec![[0.0; 3]; SIZE * SIZE];
    let t0 = Instant::now();
    for h in hits {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(
            seed ^ (h.index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
        );
        let mut acc = [0.0; 3];
        for _ in 0..spp {
            let v = shade_one(m, env, h, [rng.gen(), rng.gen()]);
            for c in 0..3 {
                acc[c] += v[c];
            }
        }
        img[h.index] = acc.map(|a| a / spp as f64);
    }
    (img, t0.elapsed().as_secs_f64())
}

/// The MIS reference (balance heuristic, `n` samples of each strategy per pixel).
fn reference(
    brdf: &TabulatedBrdf,
    hds: &BrdfSampler,
    env: &EnvironmentMap,
    hits: &[Hit],
    n: usize,
    seed: u64,
) -> Vec<[f64; 3]> {
    let mut img = vec![[0.0; 3]; SIZE * SIZE];
    for h in hits {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(
            seed ^ (h.index as u64).wrapping_mul(0xD1B5_4A32_D192_ED03),
        );
        let mut acc = [0.0; 3];
        for _ in 0..n {
            // Light sample.
            let e = env.sample([rng.gen(), rng.gen()]);
            let lo = h.local(e.direction);
            if lo[2] > 0.0 && e.pdf > 0.0 {
                let f = brdf.eval(h.wi, lo);
                let den = e.pdf + hds.pdf(h.wi, lo);
                for c in 0..3 {
                    acc[c] += f[c] * lo[2] * f64::from(e.radiance[c]) / den;
                }
            }
            // BRDF sample.
            let s = hds.sample(h.wi, [rng.gen(), rng.gen()]);
            if s.pdf > 0.0 && s.direction[2] > 0.0 {
                let d = h.world(s.direction);
                let f = brdf.eval(h.wi, s.direction);
                let den = s.pdf + env.pdf(d);
                let l = radiance(env, d);
                for c in 0..3 {
                    acc[c] += f[c] * s.direction[2] * l[c] / den;
                }
            }
        }
        img[h.index] = acc.map(|a| a / n as f64);
    }
    img
}

/// Relative RMSE of `img` against `reference` over the sphere's pixels.
fn rel_rmse(img: &[[f64; 3]], reference: &[[f64; 3]], hits: &[Hit]) -> f64 {
    let (mut se, mut sum) = (0.0, 0.0);
    for h in hits {
        for c in 0..3 {
            let d = img[h.index][c] - reference[h.index][c];
            se += d * d;
            sum += reference[h.index][c];
        }
    }
    let k = 3.0 * hits.len() as f64;
    (se / k).sqrt() / (sum / k)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The materials and the file each table went through.
fn materials() -> Vec<(Analytic, &'static str, TabulatedBrdf)> {
    let merl = MerlOptions::default();
    Analytic::families()
        .into_iter()
        .map(|a| {
            let (format, bytes) = match a.name() {
                "ggx-aniso" => ("UTIA .bin", write_utia_dirs(|wi, wo| a.eval(wi, wo))),
                "ashikhmin-shirley" => (
                    "JSON 10×24×10×24",
                    write_json(&a.table(10, 24).unwrap()).into_bytes(),
                ),
                _ => ("MERL .binary", write_merl(|wi, wo| a.eval(wi, wo))),
            };
            let t = read_any(&bytes, &merl).unwrap();
            (a, format, t)
        })
        .collect()
}

/// The image averaged over `k` × `k` pixel boxes (`k` = 1: unchanged).
fn box_filter(img: &Image, k: usize) -> Image {
    let (w, h) = (img.width() / k, img.height() / k);
    let mut rgb = vec![0f32; 3 * w * h];
    for y in 0..h {
        for x in 0..w {
            let mut acc = [0f64; 3];
            for yy in 0..k {
                for xx in 0..k {
                    let p = img.pixel(x * k + xx, y * k + yy);
                    for c in 0..3 {
                        acc[c] += f64::from(p[c]);
                    }
                }
            }
            for c in 0..3 {
                rgb[3 * (y * w + x) + c] = (acc[c] / (k * k) as f64) as f32;
            }
        }
    }
    Image::new(w, h, rgb).unwrap()
}

fn srgb(x: f64) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let y = if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (y * 255.0 + 0.5) as u8
}

fn write_png(path: &std::path::Path, width: usize, height: usize, rgb: &[u8]) {
    let file = std::fs::File::create(path).unwrap();
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), width as u32, height as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Best);
    let mut w = enc.write_header().unwrap();
    w.write_image_data(rgb).unwrap();
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let map = args.first().map(String::as_str).unwrap_or("sunset");
    let budget_us: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(64.0);
    let ref_n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(256);
    let filter: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(8);
    let Some(dir) = corpus::envmaps_dir() else {
        return;
    };
    let path = dir.join(format!("{map}.hdr"));
    let env = EnvironmentMap::new(box_filter(&Image::read(&path).unwrap(), filter)).unwrap();
    let hits = hits();
    eprintln!(
        "{} box-filtered {filter}×{filter} to {}×{}: {} sphere pixels of {SIZE}², budget {budget_us} µs per pixel, reference {ref_n} + {ref_n} MIS samples",
        path.display(),
        env.image().width(),
        env.image().height(),
        hits.len()
    );
    let names = ["hds", "cosine", "ggx-fit", "piecewise-constant"];
    let cols = 1 + names.len();
    let mut picture = vec![0u8; 3 * cols * SIZE * 5 * SIZE];
    let mut rows = Vec::new();
    for (row, (a, format, t)) in materials().into_iter().enumerate() {
        let t_build = Instant::now();
        let hds = BrdfSampler::new(t.clone(), &SamplerOptions::default()).unwrap();
        let cos = CosineBrdf::new(&t);
        let fit = GgxFit::fit(&t);
        let pc = PerSliceConstant::new(&hds, 128);
        let methods: [&dyn BrdfMethod; 4] = [&hds, &cos, &fit, &pc];
        eprintln!(
            "{} ({format}): samplers built in {:.2} s",
            a.name(),
            t_build.elapsed().as_secs_f64()
        );
        // Reference, two independent halves.
        let t_ref = Instant::now();
        let half = (ref_n / 2).max(1);
        let ra = reference(&t, &hds, &env, &hits, half, 1000 + row as u64);
        let rb = reference(&t, &hds, &env, &hits, half, 2000 + row as u64);
        let refimg: Vec<[f64; 3]> = ra
            .iter()
            .zip(&rb)
            .map(|(x, y)| [0, 1, 2].map(|c| 0.5 * (x[c] + y[c])))
            .collect();
        let ref_err = rel_rmse(&ra, &rb, &hits) / 2.0;
        eprintln!(
            "  reference in {:.1} s, its own relative RMSE ≈ {ref_err:.2e}",
            t_ref.elapsed().as_secs_f64()
        );
        // Time per sample of each method.
        let ns: Vec<f64> = methods
            .iter()
            .map(|m| {
                median(
                    (0..3)
                        .map(|r| {
                            let (_, s) = render(*m, &env, &hits, 4, 77 + r);
                            s * 1e9 / (4 * hits.len()) as f64
                        })
                        .collect(),
                )
            })
            .collect();
        let mut images = vec![refimg.clone()];
        let mut cells = Vec::new();
        for (k, m) in methods.iter().enumerate() {
            let spp = ((budget_us * 1e3 / ns[k]) as usize).max(1);
            let (img, secs) = render(*m, &env, &hits, spp, 5000 + 10 * row as u64 + k as u64);
            let e = rel_rmse(&img, &refimg, &hits);
            eprintln!(
                "  {:<19} {:>7.0} ns/sample, {spp:>4} spp, {:.1} µs/pixel rendered, rel. RMSE {e:.4}",
                m.name(),
                ns[k],
                secs * 1e6 / hits.len() as f64
            );
            cells.push((ns[k], spp, e));
            images.push(img);
        }
        // Row of the picture.
        let mean_y = hits
            .iter()
            .map(|h| {
                let p = refimg[h.index];
                luminance([p[0] as f32, p[1] as f32, p[2] as f32]) as f64
            })
            .sum::<f64>()
            / hits.len() as f64;
        let exposure = 0.35 / mean_y;
        for (col, img) in images.iter().enumerate() {
            for y in 0..SIZE {
                for x in 0..SIZE {
                    let p = img[y * SIZE + x];
                    let o = 3 * ((row * SIZE + y) * cols * SIZE + col * SIZE + x);
                    for c in 0..3 {
                        picture[o + c] = srgb(p[c] * exposure);
                    }
                }
            }
        }
        rows.push((a.name(), format, ref_err, cells));
    }
    let out = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/brdf");
    std::fs::create_dir_all(&out).unwrap();
    let png_path = out.join("brdf_render.png");
    write_png(&png_path, cols * SIZE, 5 * SIZE, &picture);
    eprintln!("wrote {}", png_path.display());
    println!(
        "| material (file) | reference error | {} |",
        names
            .iter()
            .map(|n| format!("{n}: ns/sample, spp, rel. RMSE"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    println!("|---|---|{}", "---|".repeat(names.len()));
    for (name, format, ref_err, cells) in rows {
        println!(
            "| {name} ({format}) | {ref_err:.1e} | {} |",
            cells
                .iter()
                .map(|(ns, spp, e)| format!("{ns:.0}, {spp}, **{e:.4}**"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
    }
}
