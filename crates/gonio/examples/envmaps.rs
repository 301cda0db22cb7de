//! Environment-map experiments (docs/ENVMAPS.md): build time and memory of a 2048 × 1024 map on
//! one thread, and direct illumination of a diffuse and a glossy surface under the shared maps,
//! light sampling alone and MIS with BSDF sampling, HDS vs the lat-long piecewise-constant and
//! the pbrt-v4-style equal-area piecewise-constant peers, iid and Owen-scrambled Sobol' points,
//! with the image's radiance read both ways: `Lookup::Nearest` (piecewise constant per pixel, the
//! lat-long peer's density then matches the integrand) and `Lookup::Bilinear` (the interpolant of
//! the diagram, which the HDS density follows).
//!
//! `cargo run --release -p gonio --example envmaps [-- --full]` (set GONIO_ENVMAPS to the maps'
//! folder): the default run takes the first map and 8 replicates, `--full` every map and 32.
//! Each sampler runs its fastest path: the batch calls (the HDS map's SIMD kernels; the peers'
//! scalar loops) and the batch radiance lookup `EnvironmentMap::eval_batch_with`.

mod common;

use gonio::envmap::{luminance, EnvironmentMap, Lookup};
use gonio::image::Image;
use gonio::sampler::normalize;
use gonio::sequence::{Random, Sobol};
use gonio::vector::{cross, dot};
use gonio::Batches;
use gonio::{Point2, Sampler, Vec3};
use std::f64::consts::PI;
use std::time::Instant;

fn frame(n: Vec3) -> (Vec3, Vec3) {
    let a = if n[0].abs() > 0.9 {
        [0.0, 1.0, 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let t = normalize(cross(n, a)).unwrap();
    (t, cross(n, t))
}

/// A surface: normal n and either diffuse (e = 0) or a normalised Phong lobe of exponent e about
/// the mirror direction r of a fixed view direction.
#[derive(Clone, Copy)]
struct Surface {
    n: Vec3,
    r: Vec3,
    e: f64,
}

impl Surface {
    fn f_cos(&self, d: Vec3) -> f64 {
        let c = dot(self.n, d);
        if c <= 0.0 {
            return 0.0;
        }
        if self.e == 0.0 {
            c / PI
        } else {
            let a = dot(self.r, d).max(0.0);
            (self.e + 2.0) / (2.0 * PI) * a.powf(self.e) * c
        }
    }
    /// BSDF sampling: cosine about n, or the Phong lobe about r; (direction, pdf).
    fn sample(&self, u: Point2) -> (Vec3, f64) {
        let (axis, ex) = if self.e == 0.0 {
            (self.n, 1.0)
        } else {
            (self.r, self.e)
        };
        let ct = (1.0 - u[0]).powf(1.0 / (ex + 1.0));
        let st = (1.0 - ct * ct).max(0.0).sqrt();
        let p = 2.0 * PI * u[1];
        let (t, b) = frame(axis);
        let d = [0, 1, 2].map(|k| st * p.cos() * t[k] + st * p.sin() * b[k] + ct * axis[k]);
        (d, self.pdf(d))
    }
    fn pdf(&self, d: Vec3) -> f64 {
        if self.e == 0.0 {
            dot(self.n, d).max(0.0) / PI
        } else {
            (self.e + 1.0) / (2.0 * PI) * dot(self.r, d).max(0.0).powf(self.e)
        }
    }
}

/// Midpoint rule on k × k points per pixel with the radiance read by `lookup` (the nearest-pixel
/// radiance is constant per pixel; the bilinear one has its kinks on pixel centres, which are
/// cell boundaries for even k).
fn reference(env: &EnvironmentMap, s: &Surface, lookup: Lookup, k: usize) -> f64 {
    let (w, h) = (env.image().width(), env.image().height());
    let (nt, np) = (h * k, w * k);
    let mut sum = 0.0;
    let (mut dirs, mut rgb) = (vec![[0.0; 3]; np], vec![[0.0f32; 3]; np]);
    for i in 0..nt {
        let t = (i as f64 + 0.5) / nt as f64;
        let st = (PI * t).sin();
        for (j, d) in dirs.iter_mut().enumerate() {
            *d = gonio::envmap::image_direction((j as f64 + 0.5) / np as f64, t);
        }
        // `eval_with` of each direction, bit for bit, on the batch path.
        env.eval_batch_with(&dirs, lookup, &mut rgb);
        for (d, c) in dirs.iter().zip(&rgb) {
            let f = s.f_cos(*d);
            if f > 0.0 {
                sum += f * f64::from(luminance(*c)) * st;
            }
        }
    }
    sum * (PI / nt as f64) * (2.0 * PI / np as f64)
}

/// Reused buffers of [`estimate`].
#[derive(Default)]
struct Scratch {
    dirs: Vec<Vec3>,
    pdf: Vec<f64>,
    rgb: Vec<[f32; 3]>,
    bsdf_dirs: Vec<Vec3>,
    bsdf_pdf: Vec<f64>,
    light_pdf: Vec<f64>,
    bsdf_rgb: Vec<[f32; 3]>,
}

/// Each sampler's fastest path: the batch calls (`sample_batch_split`, `pdf_batch`: the SIMD
/// kernels for the HDS map, a loop over the scalar calls for the peers, which have no other) and
/// the one batch radiance lookup `eval_batch_with` for every sampler's directions.
#[allow(clippy::too_many_arguments)]
fn estimate(
    env: &EnvironmentMap,
    lookup: Lookup,
    light: &dyn Sampler,
    s: &Surface,
    mis: bool,
    pts: &[Point2],
    pts2: &[Point2],
    b: &mut Scratch,
) -> f64 {
    let n = pts.len();
    b.dirs.resize(n, [0.0; 3]);
    b.pdf.resize(n, 0.0);
    b.rgb.resize(n, [0.0; 3]);
    light.sample_batch_split(pts, &mut b.dirs, &mut b.pdf);
    env.eval_batch_with(&b.dirs, lookup, &mut b.rgb);
    if mis {
        b.bsdf_dirs.resize(n, [0.0; 3]);
        b.bsdf_pdf.resize(n, 0.0);
        b.light_pdf.resize(n, 0.0);
        b.bsdf_rgb.resize(n, [0.0; 3]);
        for ((d, p), &u) in b.bsdf_dirs.iter_mut().zip(&mut b.bsdf_pdf).zip(pts2) {
            (*d, *p) = s.sample(u);
        }
        light.pdf_batch(&b.bsdf_dirs, &mut b.light_pdf);
        env.eval_batch_with(&b.bsdf_dirs, lookup, &mut b.bsdf_rgb);
    }
    let mut sum = 0.0;
    for k in 0..n {
        let (d, p) = (b.dirs[k], b.pdf[k]);
        if p > 0.0 {
            let f = s.f_cos(d);
            if f > 0.0 {
                let l = f64::from(luminance(b.rgb[k]));
                let w = if mis { p / (p + s.pdf(d)) } else { 1.0 };
                sum += w * f * l / p;
            }
        }
        if mis {
            let (d, pb) = (b.bsdf_dirs[k], b.bsdf_pdf[k]);
            if pb > 0.0 {
                let f = s.f_cos(d);
                if f > 0.0 {
                    let l = f64::from(luminance(b.bsdf_rgb[k]));
                    sum += pb / (pb + b.light_pdf[k]) * f * l / pb;
                }
            }
        }
    }
    sum / n as f64
}

/// Median of 5 timings (after one warm-up) of `f` over `n` items, in ns per item.
fn ns_per(n: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut t: Vec<f64> = (0..5)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e9 / n as f64
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[2]
}

/// One thread's cost per point of each part of light sampling on 2¹⁸ iid points: the HDS map's
/// SIMD batch (`sample_batch_split`), the scalar `sample`, the batch and the scalar radiance
/// lookups (nearest), `sample_batch_rgb` (both together), `pdf_batch`, and the peers' batch calls.
fn speed(name: &str, env: &EnvironmentMap, ll: &dyn Sampler, pb: &dyn Sampler) {
    let n = 1 << 18;
    let mut u = vec![[0.0; 2]; n];
    Random::new(7).fill(0, &mut u);
    let (mut d, mut p, mut c) = (vec![[0.0; 3]; n], vec![0.0; n], vec![[0.0f32; 3]; n]);
    let t_batch = ns_per(n, || env.sample_batch_split(&u, &mut d, &mut p));
    let t_scalar = ns_per(n, || {
        for k in 0..n {
            let s = Sampler::sample(env, u[k]);
            (d[k], p[k]) = (s.direction, s.pdf);
        }
    });
    let t_eval_batch = ns_per(n, || env.eval_batch(&d, &mut c));
    let t_eval = ns_per(n, || {
        for k in 0..n {
            c[k] = env.eval(d[k]);
        }
    });
    let t_rgb = ns_per(n, || env.sample_batch_rgb(&u, &mut d, &mut p, &mut c));
    let t_pdf = ns_per(n, || env.pdf_batch(&d, &mut p));
    let t_ll = ns_per(n, || ll.sample_batch_split(&u, &mut d, &mut p));
    let t_pb = ns_per(n, || pb.sample_batch_split(&u, &mut d, &mut p));
    // The float32 environment map: its float32 map alone, with the radiance, its pdf.
    let f32env = env.clone().into_float32().unwrap();
    let u0: Vec<f32> = u.iter().map(|q| q[0] as f32).collect();
    let u1: Vec<f32> = u.iter().map(|q| q[1] as f32).collect();
    let (mut x, mut y, mut z, mut q) = (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
    let t32 = ns_per(n, || {
        f32env
            .map()
            .sample_soa(&u0, &u1, [&mut x, &mut y, &mut z], &mut q)
    });
    let t32_rgb = ns_per(n, || {
        f32env.sample_soa(&u0, &u1, [&mut x, &mut y, &mut z], &mut q, &mut c)
    });
    let t32_pdf = ns_per(n, || f32env.pdf_soa([&x, &y, &z], &mut q));
    eprintln!(
        "{name} speed (ns per point, one thread, 2^18 iid points, median of 5): HDS sample batch {t_batch:.0}, scalar {t_scalar:.0}; eval batch {t_eval_batch:.0}, scalar {t_eval:.0}; sample_batch_rgb {t_rgb:.0}; pdf batch {t_pdf:.0}; float32 map sample {t32:.0}, with radiance {t32_rgb:.0}, pdf {t32_pdf:.0}; lat-long sample {t_ll:.0}; pbrt-v4 style sample {t_pb:.0}"
    );
}

fn main() {
    // Build time and memory of a 2048 × 1024 map, one thread.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let big = common::random_sky(2048, 1024);
    let mut times = Vec::new();
    let mut mem = 0;
    for _ in 0..5 {
        let img = big.clone();
        let t = Instant::now();
        let env = pool.install(|| EnvironmentMap::new(img).unwrap());
        times.push(t.elapsed().as_secs_f64() * 1e3);
        mem = env.memory_bytes_beyond_image();
    }
    times.sort_by(f64::total_cmp);
    println!(
        "build 2048x1024 on one thread: median {:.1} ms (min {:.1}, max {:.1}); memory beyond the image {} bytes = {:.2} bytes/pixel",
        times[2], times[0], times[4], mem, mem as f64 / (2048.0 * 1024.0)
    );
    let Some(dir) = common::envmaps_dir() else {
        return;
    };
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "hdr"))
        .collect();
    files.sort();
    let view = normalize([0.3, -0.4, 1.0]).unwrap();
    let normals = [[0.0, 0.0, 1.0], normalize([1.0, 0.3, 0.4]).unwrap()];
    let counts = [64usize, 256, 1024, 4096];
    // The default run is short (the first map, 8 replicates); `--full` is the docs' run.
    let full = std::env::args().any(|a| a == "--full");
    let reps = if full { 32u64 } else { 8 };
    if !full {
        files.truncate(1);
        eprintln!(
            "short run: {:?}, {reps} replicates (`-- --full`: every map, 32 replicates)",
            files
        );
    }
    println!("map,radiance,surface,normal,estimator,points,sampler,ns_per_sample,rmse@64,rmse@256,rmse@1024,rmse@4096,slope,rel_rmse@4096,rel_rmse@4096_equal_time");
    // Buffers reused by every estimate (grown once, outside the timed calls after the first).
    let mut scratch = Scratch::default();
    for f in &files {
        let name = f.file_stem().unwrap().to_string_lossy().to_string();
        let env = EnvironmentMap::new(Image::read(f).unwrap()).unwrap();
        let t = Instant::now();
        let ll = env.latlong_peer().unwrap();
        let t_ll = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let pb = env.pbrt_v4_peer(None).unwrap();
        let t_pb = t.elapsed().as_secs_f64() * 1e3;
        eprintln!(
            "{name}: peers built in {t_ll:.0} ms (lat-long), {t_pb:.0} ms (pbrt-v4 style, {}^2)",
            pb.resolution()
        );
        speed(&name, &env, &ll, &pb);
        let samplers: [(&str, &dyn Sampler); 3] =
            [("hds", &env), ("latlong-pc", &ll), ("pbrt-v4-pc", &pb)];
        for (ni, &n) in normals.iter().enumerate() {
            for (sname, e) in [("diffuse", 0.0), ("glossy", 200.0)] {
                let r = {
                    let d = dot(view, n);
                    normalize([0, 1, 2].map(|k| 2.0 * d * n[k] - view[k])).unwrap()
                };
                let surf = Surface { n, r, e };
                for (lk, lookup) in [("nearest", Lookup::Nearest), ("bilinear", Lookup::Bilinear)] {
                    let refv = if lookup == Lookup::Nearest {
                        reference(&env, &surf, lookup, 4)
                    } else {
                        // The bilinear integrand is not constant per pixel: 8 × 8 points, and the
                        // change from 4 × 4 as the reference's own error estimate.
                        let r8 = reference(&env, &surf, lookup, 8);
                        let r4 = reference(&env, &surf, lookup, 4);
                        eprintln!(
                        "{name} {sname} normal {ni} bilinear reference {r8:.6e}, |4x4 - 8x8| / 8x8 = {:.1e}",
                        (r4 - r8).abs() / r8
                    );
                        r8
                    };
                    for mis in [false, true] {
                        for qmc in [false, true] {
                            // Per-sample cost of each sampler in this configuration, for equal time.
                            let mut rows = Vec::new();
                            for (lname, light) in samplers {
                                let mut rmse = Vec::new();
                                let mut ns = 0.0;
                                for &c in &counts {
                                    let mut se = 0.0;
                                    for rep in 0..reps {
                                        let mut p1 = vec![[0.0; 2]; c];
                                        let mut p2 = vec![[0.0; 2]; c];
                                        if qmc {
                                            Sobol::owen(1000 + rep).fill(0, &mut p1);
                                            Sobol::owen(5000 + rep).fill(0, &mut p2);
                                        } else {
                                            Random::new(1000 + rep).fill(0, &mut p1);
                                            Random::new(5000 + rep).fill(0, &mut p2);
                                        }
                                        let t = Instant::now();
                                        let v = estimate(
                                            &env,
                                            lookup,
                                            light,
                                            &surf,
                                            mis,
                                            &p1,
                                            &p2,
                                            &mut scratch,
                                        );
                                        if c == 4096 {
                                            ns += t.elapsed().as_secs_f64() * 1e9 / c as f64;
                                        }
                                        se += (v - refv) * (v - refv);
                                    }
                                    rmse.push((se / reps as f64).sqrt());
                                }
                                ns /= reps as f64;
                                // Least-squares slope of log RMSE against log N.
                                let xs: Vec<f64> =
                                    counts.iter().map(|&c| (c as f64).ln()).collect();
                                let ys: Vec<f64> =
                                    rmse.iter().map(|r| r.max(1e-300).ln()).collect();
                                let (mx, my) =
                                    (xs.iter().sum::<f64>() / 4.0, ys.iter().sum::<f64>() / 4.0);
                                let slope = xs
                                    .iter()
                                    .zip(&ys)
                                    .map(|(x, y)| (x - mx) * (y - my))
                                    .sum::<f64>()
                                    / xs.iter().map(|x| (x - mx) * (x - mx)).sum::<f64>();
                                rows.push((lname, ns, rmse, slope));
                            }
                            let ns_hds = rows[0].1;
                            for (lname, ns, rmse, slope) in rows {
                                // Equal time: at the HDS map's time budget for 4096 samples, a sampler
                                // that costs ns per sample draws 4096·ns_hds/ns samples; its RMSE there
                                // follows its measured slope.
                                let eq = rmse[3] * (ns_hds / ns).powf(slope);
                                println!(
                                "{name},{lk},{sname},{ni},{},{},{lname},{ns:.0},{:.3e},{:.3e},{:.3e},{:.3e},{slope:.2},{:.3e},{:.3e}",
                                if mis { "mis" } else { "light" },
                                if qmc { "sobol" } else { "iid" },
                                rmse[0], rmse[1], rmse[2], rmse[3], rmse[3] / refv, eq / refv
                            );
                            }
                        }
                    }
                }
            }
        }
    }
}
