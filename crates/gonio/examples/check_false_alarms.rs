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
//! default battery instead of the quick one; `--statistical` runs only the items that can fail a
//! correct sampler by chance — the chi-square test and the flux estimate, each in its two stages,
//! exactly as the battery runs them — with the bin integrals of each file computed once for all
//! seeds (they do not depend on the seed), which is what makes 2,000 checks affordable on a
//! shared 2-core machine. Results: `docs/CHECKS.md`, "The run of 2,000 checks".

mod common;

use gonio::check::{
    bin_integrals, cell_boundary_points, chi_square_two_stage_with_integrals, flux_two_stage,
    run_battery, BatteryOptions, Status,
};
use gonio::photometry::{read, DirTiltResolver, FileFormat};
use gonio::{Sampler, SphereMap};
use std::time::Instant;

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(50);
    let full = std::env::args().any(|a| a == "--full");
    let statistical = std::env::args().any(|a| a == "--statistical");
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
    let base = if full {
        BatteryOptions::default()
    } else {
        BatteryOptions::quick()
    };
    let integrals: Vec<Vec<f64>> = if statistical {
        maps.iter()
            .map(|(_, _, m)| bin_integrals(m, &base.chi_square))
            .collect()
    } else {
        Vec::new()
    };
    let t0 = Instant::now();
    let (mut runs, mut failures, mut stage2) = (0u64, 0u64, 0u64);
    for seed in 1..=seeds {
        for (k, (name, d, map)) in maps.iter().enumerate() {
            let mut opts = base.clone().with_seed(seed);
            opts.ratio.claimed_bound = Some(map.ratio_bound());
            opts.flux_total = map.target_power();
            runs += 1;
            if statistical {
                let (chi, chi1) = chi_square_two_stage_with_integrals(map, &opts, &integrals[k]);
                let (flux, flux1) = flux_two_stage(map, &opts);
                let second = chi1.is_some() as u64 + flux1.is_some() as u64;
                stage2 += second;
                if chi.status == Status::Fail || flux.status == Status::Fail {
                    failures += 1;
                    println!(
                        "FAIL seed {seed} {name}: chi-square {} / flux {}",
                        chi.summary(),
                        flux.summary()
                    );
                } else if let Some(f) = chi1 {
                    println!(
                        "chi-square stage 1 failed, stage 2 passed: seed {seed} {name}: stage 1 p = \
                         {:.3e}, stage 2 p = {:.3e}",
                        f.combined_p_value, chi.combined_p_value
                    );
                } else if second > 0 {
                    println!("flux stage 1 failed, stage 2 passed: seed {seed} {name}");
                }
                continue;
            }
            opts.round_trip.extra_points = cell_boundary_points(map, d, if full { 64 } else { 16 });
            let r = run_battery(map as &dyn Sampler, &opts);
            let second =
                r.chi_square_first_stage.is_some() as u64 + r.flux_first_stage.is_some() as u64;
            stage2 += second;
            if !r.passed {
                failures += 1;
                println!("FAIL seed {seed} {name}: {:?}\n{r}", r.failures());
            } else if second > 0 {
                println!("stage 2 decided (pass) seed {seed} {name}");
            }
        }
        println!(
            "seed {seed}: {runs} checks, {failures} failures, {stage2} first-stage failures \
             re-tested, {:.0} s",
            t0.elapsed().as_secs_f64()
        );
    }
    println!(
        "SUMMARY: {runs} {}{} checks of correct samplers ({} files × {seeds} seeds): {failures} \
         reported failures; {stage2} items decided at stage 2; {:.0} s",
        if full { "default" } else { "quick" },
        if statistical {
            " (statistical items)"
        } else {
            ""
        },
        maps.len(),
        t0.elapsed().as_secs_f64()
    );
}
