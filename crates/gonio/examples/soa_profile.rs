//! A driver for instruction counting (callgrind) of the HDS map's scalar and SoA batch paths: runs
//! ONE operation over 2¹⁶ Halton points of a "lobes" hemisphere diagram, so that
//! (instructions of a run − instructions of the `setup` run) / 2¹⁶ is the cost per point.
//!
//! ```sh
//! cargo build --release -p gonio --example soa_profile
//! for op in setup scalar-sample scalar-pdf scalar-invert soa-sample-f64 soa-pdf-f64 \
//!           soa-invert-f64 soa-sample-f32 soa-invert-f32 aos-sample-f64 aos-pdf-f64 \
//!           aos-invert-f64; do
//!   valgrind --tool=callgrind --callgrind-out-file=/tmp/cg.$op \
//!     target/release/examples/soa_profile $op 181 361 2>&1 | grep 'refs'
//! done
//! ```
//! Op `par-sample-f64` runs `sample_soa_par` (chunks of 4096 on the rayon pool; set
//! `RAYON_NUM_THREADS=1` for one thread), the path `gonio bench --soa` and the side-by-side script
//! time. Arguments: OP [N M] [portable|avx2]; `portable` or `avx2` forces that backend (else the
//! fastest the CPU has). Environment:
//! `GONIO_PROFILE_COUNT=P` uses P points instead of 2¹⁶;
//! `GONIO_PROFILE_REPEAT=K` runs a batch operation K times and prints its wall-clock time per point
//! (for `perf record`); `GONIO_PROFILE_FAMILY=peaky` uses the side-by-side script's grid (values
//! r⁴ + 10⁻³, r uniform, θ 0…90°, φ 0…360°) instead of the "lobes" diagram.

mod common;

use gonio::mapping::batch::SoaSampler;
use gonio::mapping::simd::Backend;
use gonio::synthetic::{random_hemisphere, Family};
use gonio::Batches;
use gonio::{HemisphereMap, Sampler};
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let op = args.get(1).map_or("setup", |s| s.as_str());
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(181);
    let m: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(361);
    let backend = match args.get(4).map(|s| s.as_str()) {
        Some("portable") => Backend::Portable,
        Some("avx2") => Backend::Avx2Fma,
        _ => Backend::detect(),
    };
    let count: usize = std::env::var("GONIO_PROFILE_COUNT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1 << 16);
    let repeat: usize = std::env::var("GONIO_PROFILE_REPEAT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let diagram = if std::env::var("GONIO_PROFILE_FAMILY").is_ok_and(|f| f == "peaky") {
        peaky(n, m)
    } else {
        random_hemisphere(Family::Lobes, n, m, false, 7)
    };
    let map = HemisphereMap::new(&diagram).unwrap();
    // Inputs of every operation, prepared in the setup (scalar reference directions).
    let common::profile::Inputs {
        pts,
        dirs,
        uv: [u, v],
        uv32: [u32s, v32s],
        d,
        d32,
    } = common::profile::inputs(&map, count);
    let mut o = vec![vec![0.0f64; count]; 4];
    let mut o32 = vec![vec![0.0f32; count]; 4];
    // Outputs of the AoS batch paths (`Sampler::{sample,pdf,invert}_batch`).
    let mut aos = (
        vec![gonio::Sample::default(); count],
        vec![Ok([0.0; 2]); count],
    );
    let mut acc = 0.0;
    let mut best = f64::INFINITY;
    for _ in 0..repeat {
        let t0 = std::time::Instant::now();
        run(
            op,
            &map,
            backend,
            &pts,
            &dirs,
            (&u, &v),
            (&u32s, &v32s),
            (&d, &d32),
            (&mut o, &mut o32),
            (&mut aos.0, &mut aos.1),
            &mut acc,
        );
        best = best.min(t0.elapsed().as_secs_f64());
    }
    if repeat > 1 {
        eprintln!(
            "{op} {n}x{m}: {:.2} ns per point (best of {repeat})",
            best * 1e9 / count as f64
        );
    }
    black_box((acc, &o, &o32));
}

/// The side-by-side script's grid: r⁴ + 10⁻³ on θ 0…90° (N parallels), φ 0…360° (M meridians).
fn peaky(n: usize, m: usize) -> gonio::Diagram {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    let theta: Vec<f64> = (0..n).map(|j| 90.0 * j as f64 / (n - 1) as f64).collect();
    let phi: Vec<f64> = (0..m).map(|i| 360.0 * i as f64 / m as f64).collect();
    let values: Vec<Vec<f64>> = (0..m)
        .map(|_| (0..n).map(|_| rng.gen::<f64>().powi(4) + 1e-3).collect())
        .collect();
    gonio::Diagram::from_degrees(&theta, &phi, &values).unwrap()
}

#[allow(clippy::too_many_arguments)]
fn run(
    op: &str,
    map: &HemisphereMap,
    backend: Backend,
    pts: &[[f64; 2]],
    dirs: &[[f64; 3]],
    (u, v): (&Vec<f64>, &Vec<f64>),
    (u32s, v32s): (&Vec<f32>, &Vec<f32>),
    (d, d32): (&Vec<Vec<f64>>, &Vec<Vec<f32>>),
    (o, o32): (&mut Vec<Vec<f64>>, &mut Vec<Vec<f32>>),
    (samples, points): (
        &mut [gonio::Sample],
        &mut [Result<[f64; 2], gonio::InvertError>],
    ),
    acc: &mut f64,
) {
    match op {
        "setup" => {}
        "scalar-sample" => {
            for &p in pts {
                *acc += map.sample(black_box(p)).pdf;
            }
        }
        "scalar-pdf" => {
            for &w in dirs {
                *acc += map.pdf(black_box(w));
            }
        }
        "scalar-invert" => {
            for &w in dirs {
                *acc += map.invert(black_box(w)).map_or(0.0, |x| x[0]);
            }
        }
        "aos-sample-f64" => map.sample_batch(black_box(pts), samples),
        "aos-pdf-f64" => map.pdf_batch(black_box(dirs), &mut o[0]),
        "aos-invert-f64" => map.invert_batch(black_box(dirs), points),
        "soa-sample-f64" => {
            let [x, y, z, p] = &mut o[..] else {
                unreachable!()
            };
            map.sample_soa_with(backend, black_box(u), v, [x, y, z], p);
        }
        "par-sample-f64" => {
            let [x, y, z, p] = &mut o[..] else {
                unreachable!()
            };
            gonio::mapping::batch::sample_soa_par(map, black_box(u), v, [x, y, z], p);
        }
        "soa-pdf-f64" => map.pdf_soa_with(backend, [black_box(&d[0]), &d[1], &d[2]], &mut o[0]),
        "soa-invert-f64" => {
            let [a, b, ..] = &mut o[..] else {
                unreachable!()
            };
            map.invert_soa_with(backend, [black_box(&d[0]), &d[1], &d[2]], [a, b]);
        }
        "soa-sample-f32" => {
            let [x, y, z, p] = &mut o32[..] else {
                unreachable!()
            };
            map.sample_soa_with(backend, black_box(u32s), v32s, [x, y, z], p);
        }
        "soa-pdf-f32" => {
            map.pdf_soa_with(backend, [black_box(&d32[0]), &d32[1], &d32[2]], &mut o32[0])
        }
        "soa-invert-f32" => {
            let [a, b, ..] = &mut o32[..] else {
                unreachable!()
            };
            map.invert_soa_with(backend, [black_box(&d32[0]), &d32[1], &d32[2]], [a, b]);
        }
        other => {
            eprintln!("unknown operation {other}");
            std::process::exit(2);
        }
    }
}
