//! Light transport with every sampler: the irradiance a luminaire casts on a floor below it and on
//! a wall beside it, estimated by light tracing, against a converged deterministic reference.
//!
//! The luminaire sits at the origin; its intensity I(ω) (candela) is the diagram interpolated
//! bilinearly in (θ, φ) — the same function every sampler's target is proportional to. The floor
//! is the plane z = −3 m, cut into 1 m² patches over x ∈ [−4, 8), y ∈ [−4, 3); the wall is the
//! plane y = 3 m, cut into 1 m² patches over x ∈ [−4, 8), z ∈ [−3, 1). A sample direction ω with
//! density pdf(ω) carries the flux I(ω)/pdf(ω) to the first plane it hits; the mean over N samples
//! of the flux landing in a patch, divided by its area, is an unbiased estimate of the patch's mean
//! irradiance (wherever pdf > 0 where I > 0). The reference is the midpoint rule with 256 × 256
//! points per patch of E(p) = I(ω_p) cos θ_p / d².
//!
//! A second set of receivers is smooth: 15 points on the floor, each measuring the irradiance
//! weighted by the C¹ kernel (1 − r²/R²)², R = 1 m (normalised), so that the integrand is
//! continuous in the direction and any discontinuity left is the sampler's own. Its reference is
//! the midpoint rule with 512 × 512 points over each kernel's support.
//!
//! For N = 2⁴ … 2²⁰ (the first N points of one stream, iid or Halton), the error is the RMSE over
//! all patches (receivers) divided by their mean. Time is the thread CPU time of the pass
//! (sampling, weighting and splatting) scaled to N.
//!
//! `cargo run --release --example light_transport [-- --quick]` writes
//! `docs/experiments/light_transport_<luminaire>_<patches|smooth>.{csv,md}` and the plots
//! `light_transport_<luminaire>_<patches|smooth>_{error,time}.svg`.

mod common;

use common::room::{patch, reference, rel_rmse, FLOOR_Z, PATCHES};
use common::{loglog_slope, loglog_svg, Series, Table};
use gonio::photometry::{read, DirTiltResolver, FileFormat};
use gonio::sampler::spherical;
use gonio::sequence::{Halton, Random};
use gonio::{Diagram, Domain, Method, Point2, Sampler, Vec3};
use rayon::prelude::*;

/// Radius of the smooth receivers' kernel, metres.
const KERNEL_R: f64 = 1.0;
/// Centres (x, y) of the smooth receivers on the floor.
const RECEIVERS: [(f64, f64); 15] = [
    (-2.0, -2.0),
    (0.0, -2.0),
    (2.0, -2.0),
    (4.0, -2.0),
    (6.0, -2.0),
    (-2.0, 0.0),
    (0.0, 0.0),
    (2.0, 0.0),
    (4.0, 0.0),
    (6.0, 0.0),
    (-2.0, 1.5),
    (0.0, 1.5),
    (2.0, 1.5),
    (4.0, 1.5),
    (6.0, 1.5),
];

/// The C¹ kernel (1 − r²/R²)² normalised to integrate to 1 over the plane.
#[inline]
fn kernel(dx: f64, dy: f64) -> f64 {
    let s = (dx * dx + dy * dy) / (KERNEL_R * KERNEL_R);
    if s < 1.0 {
        (1.0 - s) * (1.0 - s) * 3.0 / (std::f64::consts::PI * KERNEL_R * KERNEL_R)
    } else {
        0.0
    }
}

/// Kernel-weighted irradiance at every smooth receiver by the midpoint rule, k × k points over the
/// kernel's bounding square (the kernel is C¹, so the rule converges as k⁻²).
fn reference_smooth(d: &Diagram, k: usize) -> Vec<f64> {
    RECEIVERS
        .par_iter()
        .map(|&(cx, cy)| {
            let h = 2.0 * KERNEL_R / k as f64;
            let mut sum = 0.0;
            for a in 0..k {
                for b in 0..k {
                    let (dx, dy) = (
                        -KERNEL_R + (a as f64 + 0.5) * h,
                        -KERNEL_R + (b as f64 + 0.5) * h,
                    );
                    let w = kernel(dx, dy);
                    if w == 0.0 {
                        continue;
                    }
                    let p = [cx + dx, cy + dy, FLOOR_Z];
                    let d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
                    let dist = d2.sqrt();
                    let dir = [p[0] / dist, p[1] / dist, p[2] / dist];
                    sum += w * intensity(d, dir) * (-FLOOR_Z / dist) / d2;
                }
            }
            sum * h * h
        })
        .collect()
}

fn intensity(d: &Diagram, w: Vec3) -> f64 {
    let (t, p) = spherical(w);
    d.interpolate(t, p)
}

struct Run {
    method: Method,
    seq: &'static str,
    /// (N, relative RMSE) of the patches
    errors: Vec<(f64, f64)>,
    /// (N, relative RMSE) of the smooth receivers
    smooth: Vec<(f64, f64)>,
    ns_per_sample: f64,
}

fn run(
    s: &dyn Sampler,
    d: &Diagram,
    pts: &[Point2],
    reference: &[f64],
    reference_smooth: &[f64],
    method: Method,
    seq: &'static str,
) -> Run {
    let mut sums = vec![0.0; PATCHES];
    let mut sums_smooth = vec![0.0; RECEIVERS.len()];
    let mut errors = Vec::new();
    let mut smooth = Vec::new();
    let clock = common::CpuClock::start();
    let mut next = 16usize;
    let mut splat_ns = 0.0;
    for (k, &u) in pts.iter().enumerate() {
        let smp = s.sample(u);
        if smp.pdf > 0.0 {
            let w = smp.direction;
            let flux = intensity(d, w) / smp.pdf;
            if let Some(p) = patch(w) {
                sums[p] += flux;
            }
            if w[2] < 0.0 {
                let t = FLOOR_Z / w[2];
                let (x, y) = (t * w[0], t * w[1]);
                for (s, &(cx, cy)) in sums_smooth.iter_mut().zip(&RECEIVERS) {
                    *s += flux * kernel(x - cx, y - cy);
                }
            }
        }
        if k + 1 == next {
            let t = std::time::Instant::now();
            let n = next as f64;
            errors.push((n, rel_rmse(&sums, n, reference)));
            smooth.push((n, rel_rmse(&sums_smooth, n, reference_smooth)));
            next *= 2;
            splat_ns += t.elapsed().as_nanos() as f64;
        }
    }
    let total = clock.ns();
    Run {
        method,
        seq,
        errors,
        smooth,
        ns_per_sample: (total - splat_ns).max(0.0) / pts.len() as f64,
    }
}

fn study(name: &str, title: &str, d: &Diagram, log2_max: u32) {
    let n = 1usize << log2_max;
    let reference = reference(&|w| intensity(d, w), 256);
    let reference_smooth = reference_smooth(d, 512);
    let mut halton = vec![[0.0; 2]; n];
    Halton::with_skip(1).fill(0, &mut halton);
    let mut iid = vec![[0.0; 2]; n];
    Random::new(42).fill(0, &mut iid);
    let samplers: Vec<(Method, gonio::Built)> = Method::ALL
        .iter()
        .filter_map(|&m| {
            let s = m.build(d, Domain::Sphere).ok();
            if s.is_none() {
                println!("{name}: {m} could not be built, skipped");
            }
            s.map(|s| (m, s))
        })
        .collect();
    let jobs: Vec<(usize, &'static str)> = (0..samplers.len())
        .flat_map(|i| [(i, "iid"), (i, "halton")])
        .collect();
    let runs: Vec<Run> = jobs
        .par_iter()
        .map(|&(i, seq)| {
            let pts = if seq == "iid" { &iid } else { &halton };
            run(
                samplers[i].1.as_ref(),
                d,
                pts,
                &reference,
                &reference_smooth,
                samplers[i].0,
                seq,
            )
        })
        .collect();

    for (metric, what) in [
        (
            "patches",
            "patch irradiance, 132 patches of 1 m² (discontinuous integrand)",
        ),
        (
            "smooth",
            "kernel-weighted floor irradiance, 15 receivers (C¹ integrand)",
        ),
    ] {
        let errs = |r: &Run| -> Vec<(f64, f64)> {
            if metric == "patches" {
                r.errors.clone()
            } else {
                r.smooth.clone()
            }
        };
        let mut header = vec!["method".to_string(), "points".into(), "ns/sample".into()];
        header.extend(
            errs(&runs[0])
                .iter()
                .step_by(2)
                .map(|e| format!("N=2^{}", e.0.log2() as u32)),
        );
        header.push("rate (N ≥ 2^8)".into());
        let mut t = Table::new(&header.iter().map(|s| s.as_str()).collect::<Vec<_>>());
        for r in &runs {
            let e = errs(r);
            let mut row = vec![
                r.method.to_string(),
                r.seq.into(),
                format!("{:.0}", r.ns_per_sample),
            ];
            row.extend(e.iter().step_by(2).map(|e| format!("{:.2e}", e.1)));
            let tail: Vec<(f64, f64)> = e.iter().filter(|e| e.0 >= 256.0).copied().collect();
            row.push(format!("N^{:.2}", loglog_slope(&tail)));
            t.push(row);
        }
        t.save(
            &format!("light_transport_{name}_{metric}"),
            &format!("{title}: relative RMSE of the {what} vs N"),
        );
        let series = |time: bool| -> Vec<Series> {
            runs.iter()
                .map(|r| Series {
                    label: format!("{} {}", r.method, r.seq),
                    points: errs(r)
                        .iter()
                        .map(|&(n, e)| (if time { n * r.ns_per_sample * 1e-9 } else { n }, e))
                        .collect(),
                    dashed: r.seq == "iid",
                })
                .collect()
        };
        loglog_svg(
            &format!("light_transport_{name}_{metric}_error"),
            &format!("{title}, {metric}: relative RMSE vs samples"),
            "samples N",
            "relative RMSE",
            &series(false),
        );
        loglog_svg(
            &format!("light_transport_{name}_{metric}_time"),
            &format!("{title}, {metric}: relative RMSE vs CPU time"),
            "seconds (one thread)",
            "relative RMSE",
            &series(true),
        );
    }
}

fn main() {
    let log2_max = if common::quick() { 16 } else { 20 };
    study(
        "example",
        "built-in example luminaire",
        &gonio::synthetic::example_luminaire(),
        log2_max,
    );
    let file = "ldt/isym0_ledil_strada_72x181.ldt";
    match common::corpus_dir().map(|c| c.join(file)) {
        Some(path) if path.is_file() => {
            let bytes = std::fs::read(&path).expect("read the corpus file");
            let ph = read(
                &bytes,
                FileFormat::Eulumdat,
                &DirTiltResolver::new(path.parent().unwrap()),
            )
            .expect("the corpus file parses");
            let d = ph.to_diagram().expect("the corpus file has power");
            study(
                "strada",
                "corpus street light (isym0_ledil_strada_72x181.ldt)",
                &d,
                log2_max,
            );
        }
        _ => println!("corpus file {file} not found (set GONIO_CORPUS): skipped"),
    }
}
