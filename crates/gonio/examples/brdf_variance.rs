//! Issue 26's experiment: weight variance E[w²]/E[w]² − 1 of every BRDF sampling method on every
//! analytic family at θ_i = 0°, 30°, 60°, 75°, 85°, per-sample time against the light map, and
//! the memory of a MERL-size table at the default resolution.
//!
//! `cargo run --release -p gonio --example brdf_variance [-- SAMPLES]` (default 200 000 per cell).
//! w is the luminance of f_r·cos θ_o / pdf; the tables are the analytic BRDFs at 2° × 4° (46 polar
//! × 90 azimuth nodes; the anisotropic ones also 90 incident azimuths), φ_i = 20°.

use gonio::brdf::{
    write_merl, Analytic, BrdfMethod, BrdfSampler, CosineBrdf, GgxFit, MerlOptions, MerlRaw,
    PerSliceConstant, SamplerOptions,
};
use gonio::sampler::direction;
use gonio::sequence::{Sequence, SequenceKind};
use gonio::Sampler;
use std::time::Instant;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(200_000);
    let mut us = vec![[0.0; 2]; n];
    Sequence::new(SequenceKind::Random, 26).fill(0, &mut us);
    let thetas = [0.0f64, 30.0, 60.0, 75.0, 85.0];
    println!("family,method,theta_i,mean_w,var_w,ns_per_sample");
    for a in Analytic::families() {
        let t = a.table(46, 90).unwrap();
        let s = BrdfSampler::new(t.clone(), &SamplerOptions::default()).unwrap();
        let cos = CosineBrdf::new(&t);
        let fit = GgxFit::fit(&t);
        let pc = PerSliceConstant::new(&s, 128);
        let methods: [&dyn BrdfMethod; 4] = [&s, &cos, &fit, &pc];
        for m in methods {
            for &th in &thetas {
                let wi = direction(th.to_radians(), 20f64.to_radians());
                let t0 = Instant::now();
                let (mut s1, mut s2) = (0.0, 0.0);
                for u in &us {
                    let r = m.sample(wi, *u);
                    let v = t.scalar(r.weight);
                    s1 += v;
                    s2 += v * v;
                }
                let ns = t0.elapsed().as_secs_f64() * 1e9 / n as f64;
                let mean = s1 / n as f64;
                let var = s2 / n as f64 / (mean * mean) - 1.0;
                println!("{},{},{th},{mean:.6},{var:.3e},{ns:.1}", a.name(), m.name());
            }
        }
        // The light map: one slice's HemisphereMap at the same grid.
        let map = s.slice(10).unwrap();
        let t0 = Instant::now();
        let mut acc = 0.0;
        for u in &us {
            acc += map.sample(*u).pdf;
        }
        std::hint::black_box(acc);
        println!(
            "{},light-map,,,,{:.1}",
            a.name(),
            t0.elapsed().as_secs_f64() * 1e9 / n as f64
        );
        println!(
            "# {}: alpha fitted {:?}, HDS sampler memory {:.2} MB",
            a.name(),
            fit.alpha(),
            s.memory_bytes() as f64 / 1e6
        );
    }
    // A MERL-size file (the database's 90 × 90 × 180 grid) of the two-lobe mix, at the default
    // resampling.
    let mix = Analytic::families()[4];
    let bytes = write_merl(|wi, wo| mix.eval(wi, wo));
    let t0 = Instant::now();
    let raw = MerlRaw::parse(&bytes).unwrap();
    let table = raw.resample(&MerlOptions::default()).unwrap();
    let err = raw.resampling_error(&table);
    let s = BrdfSampler::new(table, &SamplerOptions::default()).unwrap();
    println!(
        "# MERL-size file ({} bytes): read + resample + build {:.2} s, resampling error {err:.4}, HDS sampler memory {:.2} MB",
        bytes.len(),
        t0.elapsed().as_secs_f64(),
        s.memory_bytes() as f64 / 1e6
    );
}
