//! Build time and memory of a 2048 × 1024 environment map on one thread (docs/ENVMAPS.md,
//! "Build and memory"), alone, for profiling:
//!
//! `cargo run --release -p gonio --example envmap_build -- [BUILDS]` (default 5 builds), or under
//! `valgrind --tool=callgrind target/release/examples/envmap_build 1` for instruction counts.
//! A second argument `bound` also computes the ratio bound after each build (it is computed on
//! first use, not by the build): the difference of the two counts is the bound's cost. Then the
//! same for the float32 environment map (`EnvironmentMap::into_float32`).

mod common;

use gonio::envmap::EnvironmentMap;
use std::time::Instant;

fn main() {
    let builds: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("BUILDS must be a count"))
        .unwrap_or(5)
        .max(1);
    let with_bound = std::env::args().nth(2).as_deref() == Some("bound");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let (w, h) = (2048usize, 1024usize);
    let big = common::random_sky(w, h);
    let mut times = Vec::new();
    let mut mem = 0;
    for _ in 0..builds {
        let img = big.clone();
        let t = Instant::now();
        let env = pool.install(|| EnvironmentMap::new(img).unwrap());
        times.push(t.elapsed().as_secs_f64() * 1e3);
        mem = env.memory_bytes_beyond_image();
        if with_bound {
            let (lo, hi) = env.map().ratio_bound();
            println!("ratio bound [{lo:.17e}, {hi:.17e}]");
        }
    }
    times.sort_by(f64::total_cmp);
    // The float32 environment map of the same image: the float64 build, then its float32 map,
    // the float64 tables dropped.
    let mut times32 = Vec::new();
    let mut mem32 = 0;
    for _ in 0..builds {
        let img = big.clone();
        let t = Instant::now();
        let env = pool.install(|| EnvironmentMap::new(img).unwrap().into_float32().unwrap());
        times32.push(t.elapsed().as_secs_f64() * 1e3);
        mem32 = env.memory_bytes_beyond_image();
    }
    times32.sort_by(f64::total_cmp);
    println!(
        "float32 environment map {w}x{h} on one thread, {builds} builds: median {:.1} ms (min {:.1}, max {:.1}); memory beyond the image {mem32} bytes = {:.2} bytes/pixel",
        times32[builds / 2],
        times32[0],
        times32[builds - 1],
        mem32 as f64 / (w * h) as f64
    );
    println!(
        "build {w}x{h} on one thread, {builds} builds: median {:.1} ms (min {:.1}, max {:.1}); memory beyond the image {mem} bytes = {:.2} bytes/pixel",
        times[builds / 2],
        times[0],
        times[builds - 1],
        mem as f64 / (w * h) as f64
    );
}
