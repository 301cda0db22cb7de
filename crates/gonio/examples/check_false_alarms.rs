//! False alarms of `gonio check` on correct samplers: the battery exactly as `gonio check FILE
//! --quick --seed S` runs it (HDS sphere map, its claimed bound, the diagram's flux, the round trip
//! on the cell-boundary preimages), for every file of the photometric corpus and seeds 1…S, in one
//! process. Prints one line per failure and a summary: checks run, reported failures, and how
//! many were decided at stage 2 (a first-stage chance failure re-tested).
//!
//! ```sh
//! nice cargo run --release -p gonio --example check_false_alarms -- 50   # 40 files × 50 seeds
//! ```
//! `GONIO_CORPUS` names the corpus (default `../shared/data/photometry`); `--full` uses the
//! default battery instead of the quick one. Results: `docs/CHECKS.md`, "The run of 2,000 checks".

mod common;

use gonio::check::{cell_boundary_points, run_battery, BatteryOptions};
use gonio::photometry::{read, DirTiltResolver, FileFormat};
use gonio::{Sampler, SphereMap};
use std::time::Instant;

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(50);
    let full = std::env::args().any(|a| a == "--full");
    let Some(dir) = common::corpus_dir() else {
        println!("corpus not found (set GONIO_CORPUS): nothing to do");
        return;
    };
    let mut files: Vec<_> = ["ies", "ldt"]
        .iter()
        .flat_map(|sub| std::fs::read_dir(dir.join(sub)).into_iter().flatten())
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    files.sort();
    let mut maps = Vec::new();
    for f in &files {
        let bytes = std::fs::read(f).expect("readable");
        let format = FileFormat::detect(&bytes)
            .or_else(|| FileFormat::from_path_extension(f))
            .expect("a photometric file");
        let parent = f.parent().unwrap().to_path_buf();
        match read(&bytes, format, &DirTiltResolver::new(parent)).map(|p| p.to_diagram()) {
            Ok(Ok(d)) => {
                let map = SphereMap::new(&d).expect("a sphere map");
                let name = f.file_name().unwrap().to_string_lossy().into_owned();
                maps.push((name, d, map));
            }
            other => println!("skipped {} (not loadable: {other:?})", f.display()),
        }
    }
    let t0 = Instant::now();
    let (mut runs, mut failures, mut stage2, mut stage1_fail) = (0u64, 0u64, 0u64, 0u64);
    for seed in 1..=seeds {
        for (name, d, map) in &maps {
            let base = if full {
                BatteryOptions::default()
            } else {
                BatteryOptions::quick()
            };
            let mut opts = base.with_seed(seed);
            opts.ratio.claimed_bound = Some(map.ratio_bound());
            opts.flux_total = map.target_power();
            opts.round_trip.extra_points =
                cell_boundary_points(map, d, if full { 64 } else { 16 });
            let r = run_battery(map as &dyn Sampler, &opts);
            runs += 1;
            let second = r.chi_square_first_stage.is_some() as u64
                + r.flux_first_stage.is_some() as u64;
            stage2 += second;
            stage1_fail += second;
            if !r.passed {
                failures += 1;
                println!("FAIL seed {seed} {name}: {:?}\n{r}", r.failures());
            } else if second > 0 {
                println!("stage 2 decided (pass) seed {seed} {name}");
            }
        }
        println!(
            "seed {seed}: {runs} checks, {failures} failures, {stage1_fail} first-stage failures \
             re-tested, {:.0} s",
            t0.elapsed().as_secs_f64()
        );
    }
    println!(
        "SUMMARY: {runs} {} checks of correct samplers ({} files × {seeds} seeds): {failures} \
         reported failures; {stage2} items decided at stage 2; {:.0} s",
        if full { "default" } else { "quick" },
        maps.len(),
        t0.elapsed().as_secs_f64()
    );
}
