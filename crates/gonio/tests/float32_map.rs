//! The float32 map's contract (`gonio::mapping::Float32Map`, issue 24 item 5), against its
//! exact evaluation (`Float32Map::exact`: the same f32 tables widened to f64, run through the f64
//! kernels):
//!
//! (a) the pdf of a sample is the exact density of the float32 map at the sample's direction to
//!     8 f32 ulps, plus a conditioning term where the density is steep;
//! (b) `pdf_soa` at the sample's direction agrees with the sample's pdf to the same bound;
//! (c) the round trip holds to 1e-5;
//! (d) the bits do not depend on the backend, the slice length or the number of threads;
//! (e) pdf/target of the float32 map stays within the f64 map's guaranteed ratio bound widened by
//!     a stated f32 margin.
//!
//! The conditioning term of (a), (b): the largest change of the exact density when the direction
//! moves by δ = 2⁻²⁰ rad in polar angle or azimuth (the f32 round-off of a direction and of its
//! disk position is a few 2⁻²⁴; the float32 kernels compute them in f32). Fixed seeds throughout;
//! no statistical assertions.

mod common;

use gonio::batch::Soa;
use gonio::mapping::simd::Backend;
use gonio::mapping::{Float32Exact, Float32Map};
use gonio::synthetic::{example_luminaire, random_hemisphere, Family};
use gonio::{HemisphereMap, Sampler, SphereLayout, SphereMap};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// One map under test: the float32 map, its exact evaluation and the f64 map it came from.
struct Case {
    name: String,
    f32map: Float32Map,
    exact: Float32Exact,
    f64map: Box<dyn Sampler>,
    bound: (f64, f64),
    hemisphere: bool,
    split: bool,
}

fn case(name: &str, f32map: Float32Map, f64map: Box<dyn Sampler>, bound: (f64, f64)) -> Case {
    Case {
        name: name.into(),
        exact: f32map.exact(),
        f32map,
        f64map,
        bound,
        hemisphere: false,
        split: false,
    }
}

fn hemisphere_case(name: &str, m: HemisphereMap) -> Case {
    let (f, bound) = (m.float32_map().unwrap(), m.ratio_bound());
    Case {
        hemisphere: true,
        ..case(name, f, Box::new(m), bound)
    }
}

fn sphere_case(name: &str, m: SphereMap) -> Case {
    let (f, bound) = (m.float32_map().unwrap(), m.ratio_bound());
    Case {
        split: m.layout() == SphereLayout::Split,
        ..case(name, f, Box::new(m), bound)
    }
}

/// The example diagram (split sphere and Lambert sphere), synthetic hemispheres of every kind the
/// batch tests use.
fn cases() -> Vec<Case> {
    let mut v = vec![
        sphere_case(
            "example split",
            SphereMap::new(&example_luminaire()).unwrap(),
        ),
        sphere_case(
            "example lambert",
            SphereMap::with_layout(&example_luminaire(), SphereLayout::Lambert).unwrap(),
        ),
    ];
    let cases = common::MAP_CASES
        .into_iter()
        .chain([(Family::UniformRandom, 25, 24, false, 6)]);
    for (fam, n, m, irr, seed) in cases {
        let d = random_hemisphere(fam, n, m, irr, seed);
        v.push(hemisphere_case(
            &format!("{fam:?} {n}x{m} irregular={irr}"),
            HemisphereMap::new(&d).unwrap(),
        ));
    }
    v
}

/// `n` points of the square (fixed seed), as f32.
fn points(seed: u64, n: usize) -> (Vec<f32>, Vec<f32>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n).map(|_| (rng.gen::<f32>(), rng.gen::<f32>())).unzip()
}

/// One f32 ulp of `x` (the spacing of f32 values at |x|).
fn ulp32(x: f64) -> f64 {
    let x = (x as f32).abs();
    if x == 0.0 {
        return f32::from_bits(1) as f64;
    }
    (f32::from_bits(x.to_bits() + 1) - x) as f64
}

/// Sample, pdf and inverse of the float32 map on one backend.
struct Run32 {
    dir: [Vec<f32>; 3],
    pdf: Vec<f32>,
    pdf_of_dir: Vec<f32>,
    inv: [Vec<f32>; 2],
}

fn run32(m: &Float32Map, b: Backend, u: &[f32], v: &[f32]) -> Run32 {
    let n = u.len();
    let mut dir = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
    let mut pdf = vec![0f32; n];
    {
        let [x, y, z] = &mut dir;
        m.sample_soa_with(b, u, v, [x, y, z], &mut pdf);
    }
    let mut pdf_of_dir = vec![0f32; n];
    m.pdf_soa_with(b, [&dir[0], &dir[1], &dir[2]], &mut pdf_of_dir);
    let mut inv = [vec![0f32; n], vec![0f32; n]];
    {
        let [a, c] = &mut inv;
        m.invert_soa_with(b, [&dir[0], &dir[1], &dir[2]], [a, c]);
    }
    Run32 {
        dir,
        pdf,
        pdf_of_dir,
        inv,
    }
}

/// The exact density of the float32 map at f32 directions (widened).
fn exact_pdf(e: &Float32Exact, dir: &[Vec<f64>; 3]) -> Vec<f64> {
    let mut p = vec![0.0; dir[0].len()];
    e.pdf_soa_with(Backend::Portable, [&dir[0], &dir[1], &dir[2]], &mut p);
    p
}

/// The four moves of a direction by 4 f32 ulps of its disk radius x and of its azimuth φ
/// (outwards and inwards), in the frame of the hemisphere map that serves it (a split sphere's
/// lower side mirrored): the scale of the f32 round-off of the positions the float32 kernels
/// compute (x and φ each to about 2 f32 ulps).
fn moves(split: bool, d: [f64; 3]) -> [[f64; 3]; 4] {
    let lower = split && d[2] < 0.0;
    let z = if lower { -d[2] } else { d[2] };
    let r2 = if z > 0.0 {
        (d[0] * d[0] + d[1] * d[1]) / (1.0 + z)
    } else {
        1.0 - z
    };
    let x = r2.clamp(0.0, 2.0).sqrt();
    let f = d[1].atan2(d[0]);
    let f = if f < 0.0 {
        f + std::f64::consts::TAU
    } else {
        f
    };
    let (dx, df) = (4.0 * ulp32(x), 4.0 * ulp32(f));
    [(dx, 0.0), (-dx, 0.0), (0.0, df), (0.0, -df)].map(|(a, b)| {
        let (x, f) = ((x + a).max(0.0), f + b);
        let r2 = x * x;
        let s = x * (2.0 - r2).max(0.0).sqrt();
        let zz = 1.0 - r2;
        [s * f.cos(), s * f.sin(), if lower { -zz } else { zz }]
    })
}

/// Per direction, the largest change of `eval` over the four [`moves`] (the conditioning term
/// of the contract: |∂p/∂x|·δx + |∂p/∂φ|·δφ at the f32 scale, measured).
fn conditioning(
    split: bool,
    dir: &[Vec<f64>; 3],
    p: &[f64],
    eval: impl Fn(&[Vec<f64>; 3]) -> Vec<f64>,
) -> Vec<f64> {
    let n = p.len();
    let mut worst = vec![0.0f64; n];
    let all: Vec<[[f64; 3]; 4]> = (0..n)
        .map(|k| moves(split, [dir[0][k], dir[1][k], dir[2][k]]))
        .collect();
    for m in 0..4 {
        let moved: [Vec<f64>; 3] = std::array::from_fn(|c| all.iter().map(|a| a[m][c]).collect());
        let q = eval(&moved);
        for k in 0..n {
            worst[k] = worst[k].max((q[k] - p[k]).abs());
        }
    }
    worst
}

fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// (a), (b), (c): exact density of samples, pdf() vs sample(), round trip.
#[test]
fn pdf_is_the_exact_density_and_round_trips() {
    let (u, v) = points(7, 20_000);
    for c in cases() {
        let r = run32(&c.f32map, Backend::detect(), &u, &v);
        let wide: [Vec<f64>; 3] =
            std::array::from_fn(|k| r.dir[k].iter().map(|&x| x as f64).collect());
        let pe = exact_pdf(&c.exact, &wide);
        let cond = conditioning(c.split, &wide, &pe, |d| exact_pdf(&c.exact, d));
        // The exact round trip, to know where the map is injective (where the f64 evaluation of
        // the same map round-trips).
        let (uw, vw): (Vec<f64>, Vec<f64>) = (
            u.iter().map(|&x| x as f64).collect(),
            v.iter().map(|&x| x as f64).collect(),
        );
        let n = u.len();
        let mut ed = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut ep = vec![0.0; n];
        {
            let [x, y, z] = &mut ed;
            c.exact
                .sample_soa_with(Backend::Portable, &uw, &vw, [x, y, z], &mut ep);
        }
        let mut ei = [vec![0.0; n], vec![0.0; n]];
        {
            let [a, b] = &mut ei;
            c.exact
                .invert_soa_with(Backend::Portable, [&ed[0], &ed[1], &ed[2]], [a, b]);
        }
        let (mut ea, mut eb, mut rt) = (Vec::new(), Vec::new(), 0.0f64);
        let mut conditioned = 0usize;
        for k in 0..n {
            let (p, q, x) = (r.pdf[k] as f64, r.pdf_of_dir[k] as f64, pe[k]);
            assert!(p.is_finite() && p >= 0.0, "{}: pdf {p} at {k}", c.name);
            let ulp = ulp32(x.max(p));
            let (da, db) = ((p - x).abs(), (q - p).abs());
            let allowed = 8.0 * ulp + cond[k];
            assert!(
                da <= allowed,
                "{} (a): u ({}, {}): sample pdf {p} vs exact {x} ({:.1} ulp, conditioning {:.1e})",
                c.name,
                u[k],
                v[k],
                da / ulp,
                cond[k]
            );
            assert!(
                db <= allowed,
                "{} (b): u ({}, {}): pdf() {q} vs sample pdf {p} ({:.1} ulp, conditioning {:.1e})",
                c.name,
                u[k],
                v[k],
                db / ulp,
                cond[k]
            );
            if da > 8.0 * ulp || db > 8.0 * ulp {
                conditioned += 1;
            }
            if x > 0.0 {
                ea.push(da / ulp);
                eb.push(db / ulp);
            }
            // (c), where the density is positive, away from the B-disk's azimuth seam
            // (v = ½, u > ½) and, on the split sphere, the hemisphere seam, where the exact map
            // round-trips.
            let exact_rt = (ei[0][k] - uw[k]).abs().max((ei[1][k] - vw[k]).abs()) <= 1e-10;
            let seam = (v[k] - 0.5).abs() < 1e-4 && u[k] > 0.5;
            if p > 0.0 && exact_rt && !seam {
                let e = (r.inv[0][k] - u[k]).abs().max((r.inv[1][k] - v[k]).abs()) as f64;
                assert!(
                    e <= 1e-5,
                    "{} (c): u ({}, {}) round trip ({}, {})",
                    c.name,
                    u[k],
                    v[k],
                    r.inv[0][k],
                    r.inv[1][k]
                );
                rt = rt.max(e);
            }
        }
        let (a50, a999, amax) = (
            quantile(&mut ea, 0.5),
            quantile(&mut ea, 0.999),
            quantile(&mut ea, 1.0),
        );
        let (b50, b999, bmax) = (
            quantile(&mut eb, 0.5),
            quantile(&mut eb, 0.999),
            quantile(&mut eb, 1.0),
        );
        println!(
            "{}: (a) ulp median {a50:.2} 99.9% {a999:.2} max {amax:.1}; (b) median {b50:.2} \
             99.9% {b999:.2} max {bmax:.1}; beyond 8 ulp (conditioned) {conditioned}/{n}; \
             round trip {rt:.1e}",
            c.name
        );
    }
}

/// (d): the same bits on every backend, at odd lengths, and on 1 and 2 threads.
#[test]
fn bits_do_not_depend_on_backend_length_or_threads() {
    let (u, v) = points(8, 4099);
    for c in cases() {
        let runs: Vec<Run32> = Backend::available()
            .into_iter()
            .map(|b| run32(&c.f32map, b, &u, &v))
            .collect();
        let bits = |r: &Run32| -> Vec<u32> {
            r.dir
                .iter()
                .chain([&r.pdf, &r.pdf_of_dir])
                .chain(r.inv.iter())
                .flat_map(|c| c.iter().map(|x| x.to_bits()))
                .collect()
        };
        let want = bits(&runs[0]);
        for (b, r) in Backend::available().into_iter().zip(&runs) {
            assert!(bits(r) == want, "{}: backend {b:?} differs", c.name);
        }
        // Odd lengths: every prefix length around the blocks gives the prefix of the results.
        for len in [1usize, 7, 15, 17, 31, 33, 255, 257] {
            for b in Backend::available() {
                let r = run32(&c.f32map, b, &u[..len], &v[..len]);
                let full = &runs[0];
                for k in 0..len {
                    assert_eq!(
                        r.pdf[k].to_bits(),
                        full.pdf[k].to_bits(),
                        "{} len {len}",
                        c.name
                    );
                    assert_eq!(r.inv[0][k].to_bits(), full.inv[0][k].to_bits());
                    for d in 0..3 {
                        assert_eq!(r.dir[d][k].to_bits(), full.dir[d][k].to_bits());
                    }
                }
            }
        }
        // Threads.
        let big: (Vec<f32>, Vec<f32>) = points(9, 9000);
        let par = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let n = big.0.len();
                let mut d = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
                let mut p = vec![0f32; n];
                {
                    let [x, y, z] = &mut d;
                    c.f32map.batch_par(Soa::Sample {
                        u: &big.0,
                        v: &big.1,
                        dir: [x, y, z],
                        pdf: &mut p,
                    });
                }
                let mut q = vec![0f32; n];
                c.f32map.batch_par(Soa::Pdf {
                    dir: [&d[0], &d[1], &d[2]],
                    pdf: &mut q,
                });
                let mut w = [vec![0f32; n], vec![0f32; n]];
                {
                    let [a, b] = &mut w;
                    c.f32map.batch_par(Soa::Invert {
                        dir: [&d[0], &d[1], &d[2]],
                        uv: [a, b],
                    });
                }
                d.iter()
                    .chain([&p, &q])
                    .chain(w.iter())
                    .flat_map(|c| c.iter().map(|x| x.to_bits()))
                    .collect::<Vec<u32>>()
            })
        };
        assert!(par(1) == par(2), "{}: 1 vs 2 threads", c.name);
    }
}

/// (e): the float32 map's pdf against the f64 map's target t, at the float32 map's samples and
/// at uniform directions: lo·(t − Δt)·(1 − m) ≤ pdf ≤ hi·(t + Δt)·(1 + m), with [lo, hi] the f64
/// map's guaranteed ratio bound, m the stated f32 margin and Δt the change of t over the f32-scale
/// [`moves`] (the float32 map's tables and kernels place the nodes and the direction to that
/// scale). Reports the ratio pdf/t over the directions where Δt ≤ 1e-6·t.
#[test]
fn pdf_over_target_stays_within_the_f64_bound() {
    let margin = 1e-5;
    for c in cases() {
        let (u, v) = points(10, 20_000);
        let r = run32(&c.f32map, Backend::detect(), &u, &v);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let mut dirs: Vec<[f32; 3]> = (0..u.len())
            .map(|k| [r.dir[0][k], r.dir[1][k], r.dir[2][k]])
            .collect();
        for _ in 0..20_000 {
            let z: f64 = if c.hemisphere {
                rng.gen_range(0.0..1.0)
            } else {
                rng.gen_range(-1.0..1.0)
            };
            let f: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
            let s = (1.0 - z * z).sqrt();
            dirs.push([(s * f.cos()) as f32, (s * f.sin()) as f32, z as f32]);
        }
        let d32: [Vec<f32>; 3] = std::array::from_fn(|k| dirs.iter().map(|d| d[k]).collect());
        let wide: [Vec<f64>; 3] =
            std::array::from_fn(|k| d32[k].iter().map(|&x| x as f64).collect());
        let mut p = vec![0f32; dirs.len()];
        c.f32map.pdf_soa([&d32[0], &d32[1], &d32[2]], &mut p);
        let target = |d: &[Vec<f64>; 3]| -> Vec<f64> {
            (0..d[0].len())
                .map(|k| c.f64map.target_pdf([d[0][k], d[1][k], d[2][k]]))
                .collect()
        };
        let t = target(&wide);
        let dt = conditioning(c.split, &wide, &t, target);
        let (lo, hi) = c.bound;
        let (mut rmin, mut rmax, mut flat) = (f64::INFINITY, 0.0f64, 0usize);
        for k in 0..dirs.len() {
            let (pk, tk) = (p[k] as f64, t[k]);
            assert!(
                pk >= lo * (tk - dt[k]) * (1.0 - margin)
                    && pk <= hi * (tk + dt[k]) * (1.0 + margin),
                "{} (e): at {:?} pdf {pk}, target {tk} ± {:.1e}, bound [{lo}, {hi}]",
                c.name,
                dirs[k],
                dt[k]
            );
            if tk > 0.0 && dt[k] <= 1e-6 * tk {
                flat += 1;
                rmin = rmin.min(pk / tk);
                rmax = rmax.max(pk / tk);
            }
        }
        println!(
            "{}: f64 bound [{lo:.6}, {hi:.6}], float32 pdf/target [{rmin:.6}, {rmax:.6}] over \
             {flat} of {} directions (outside the bound by {:.2e} below, {:.2e} above)",
            c.name,
            dirs.len(),
            (lo - rmin).max(0.0) / lo,
            (rmax - hi).max(0.0) / hi
        );
    }
}

/// The float32 map of every corpus file (sphere maps): (a), (b), (d) across backends and the
/// round trip, on fewer points.
#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn corpus_files_keep_the_contract() {
    use gonio::photometry::{read, DirTiltResolver, FileFormat};
    let dir = common::corpus_dir();
    let (u, v) = points(12, 2000);
    let (mut ea, mut eb, mut conditioned, mut files) = (Vec::new(), Vec::new(), 0usize, 0usize);
    for path in common::corpus_files(&dir) {
        files += 1;
        let bytes = std::fs::read(&path).unwrap();
        let fmt = FileFormat::from_path_extension(&path).unwrap();
        let p = read(&bytes, fmt, &DirTiltResolver::new(path.parent().unwrap()))
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let m = SphereMap::new(&p.to_diagram().unwrap()).unwrap();
        let f = m.float32_map().unwrap();
        let e = f.exact();
        let runs: Vec<Run32> = Backend::available()
            .into_iter()
            .map(|b| run32(&f, b, &u, &v))
            .collect();
        let r = &runs[0];
        for o in &runs[1..] {
            assert!(
                o.pdf
                    .iter()
                    .zip(&r.pdf)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
                    && o.inv[0]
                        .iter()
                        .zip(&r.inv[0])
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{}: backends differ",
                path.display()
            );
        }
        let wide: [Vec<f64>; 3] =
            std::array::from_fn(|k| r.dir[k].iter().map(|&x| x as f64).collect());
        let pe = exact_pdf(&e, &wide);
        let cond = conditioning(m.layout() == SphereLayout::Split, &wide, &pe, |d| {
            exact_pdf(&e, d)
        });
        for k in 0..u.len() {
            let (ps, q, x) = (r.pdf[k] as f64, r.pdf_of_dir[k] as f64, pe[k]);
            let ulp = ulp32(x.max(ps));
            let allowed = 8.0 * ulp + cond[k];
            if x > 0.0 {
                ea.push((ps - x).abs() / ulp);
                eb.push((q - ps).abs() / ulp);
            }
            if (ps - x).abs().max((q - ps).abs()) > 8.0 * ulp {
                conditioned += 1;
            }
            assert!(
                (ps - x).abs() <= allowed && (q - ps).abs() <= allowed,
                "{}: u ({}, {}): sample pdf {ps}, pdf() {q}, exact {x}",
                path.display(),
                u[k],
                v[k]
            );
        }
    }
    let n = ea.len();
    println!(
        "{files} corpus files: (a) ulp median {:.2} 99.9% {:.2} max {:.1}; (b) median {:.2} 99.9% \
         {:.2} max {:.1}; beyond 8 ulp (conditioned) {conditioned}/{}",
        quantile(&mut ea, 0.5),
        quantile(&mut ea, 0.999),
        quantile(&mut ea, 1.0),
        quantile(&mut eb, 0.5),
        quantile(&mut eb, 0.999),
        quantile(&mut eb, 1.0),
        files * u.len()
    );
    assert!(n > 0);
}

/// A float32 map is a quarter-to-half of its f64 map's table memory, and errors are typed.
#[test]
fn memory_and_size() {
    let m = HemisphereMap::new(&random_hemisphere(Family::Lobes, 181, 361, false, 2)).unwrap();
    let f = m.float32_map().unwrap();
    let (a, b) = (f.memory_bytes(), m.memory_bytes());
    println!("181x361: float32 map {a} bytes, f64 map {b} bytes");
    assert!(a < b && a * 2 > b / 2, "{a} vs {b}");
}
