//! The paper's "results for 1024 tested goniometric diagrams", reproduced: how far the map's exact
//! density p is from the target (the diagram interpolated bilinearly in (θ, φ), normalised), as the
//! ratio p / target, per family and per number of parallels N.
//!
//! Two numbers per diagram: the **guaranteed** range of the ratio over every direction of positive
//! target, computed at build time (`HemisphereMap::ratio_bound`), and a **sampled** check: the ratio
//! at 2¹⁴ directions drawn from the map itself (Halton points), over directions where the target
//! exceeds 1 % of its maximum (as in the reference figures of docs/DERIVATION.md §12.2).
//!
//! `cargo run --release --example diagrams_1024 [-- --quick]` writes
//! `docs/experiments/diagrams_1024_{family,n}.{csv,md}` and `diagrams_1024_median_dev.svg`.

mod common;

use common::{diagram_set, loglog_svg, median, Series, Table, SET_N};
use gonio::sequence::Halton;
use gonio::synthetic::Family;
use gonio::Batches;
use gonio::{HemisphereMap, Sample, Sampler};
use rayon::prelude::*;

struct Row {
    family: Family,
    n: usize,
    bound: (f64, f64),
    sampled: (f64, f64),
    median_dev: f64,
}

/// Fixed-point for ordinary ratios, scientific for the huge bounds of nearly-zero targets.
fn num(x: f64) -> String {
    if x != 0.0 && (x.abs() >= 1e3 || x.abs() < 1e-3) {
        format!("{x:.2e}")
    } else {
        format!("{x:.3}")
    }
}

fn main() {
    let quick = common::quick();
    let count = if quick { 256 } else { 1024 };
    let per = if quick { 1 << 12 } else { 1 << 14 };
    let set = diagram_set(count);
    let mut pts = vec![[0.0; 2]; per];
    Halton::with_skip(1).fill(0, &mut pts);
    let rows: Vec<Row> = set
        .par_iter()
        .map(|sd| {
            let map = HemisphereMap::new(&sd.diagram).expect("valid diagram");
            let mut out = vec![Sample::default(); per];
            map.sample_batch(&pts, &mut out);
            // the target's maximum: the largest node value over the integral
            let tmax = sd.diagram.max_value() / sd.diagram.integral();
            let mut ratios: Vec<f64> = out
                .iter()
                .filter_map(|s| {
                    let t = map.target_pdf(s.direction);
                    (t > 0.01 * tmax).then(|| s.pdf / t)
                })
                .collect();
            ratios.sort_by(f64::total_cmp);
            let devs: Vec<f64> = ratios.iter().map(|r| (r - 1.0).abs()).collect();
            Row {
                family: sd.family,
                n: sd.n,
                bound: map.ratio_bound(),
                sampled: (
                    ratios.first().copied().unwrap_or(f64::NAN),
                    ratios.last().copied().unwrap_or(f64::NAN),
                ),
                median_dev: median(&devs),
            }
        })
        .collect();

    let summarise = |sel: &[&Row]| -> Vec<String> {
        let bmin = sel.iter().map(|r| r.bound.0).fold(f64::INFINITY, f64::min);
        let bmax = sel.iter().map(|r| r.bound.1).fold(0.0, f64::max);
        let bmed_lo = median(&sel.iter().map(|r| r.bound.0).collect::<Vec<_>>());
        let bmed_hi = median(&sel.iter().map(|r| r.bound.1).collect::<Vec<_>>());
        let smin = sel
            .iter()
            .map(|r| r.sampled.0)
            .fold(f64::INFINITY, f64::min);
        let smax = sel.iter().map(|r| r.sampled.1).fold(0.0, f64::max);
        let md: Vec<f64> = sel.iter().map(|r| r.median_dev).collect();
        let worst: Vec<f64> = sel
            .iter()
            .map(|r| (1.0 - r.sampled.0).max(r.sampled.1 - 1.0))
            .collect();
        let within = sel
            .iter()
            .filter(|r| r.bound.0 >= 0.8 && r.bound.1 <= 1.25)
            .count();
        vec![
            sel.len().to_string(),
            format!("{} – {}", num(bmin), num(bmax)),
            format!("{:.0} %", 100.0 * within as f64 / sel.len() as f64),
            format!("{bmed_lo:.3} – {bmed_hi:.3}"),
            format!("{smin:.3} – {smax:.3}"),
            format!("{:.1} %", 100.0 * median(&worst)),
            format!("{:.2} %", 100.0 * median(&md)),
            format!("{:.2} %", 100.0 * md.iter().cloned().fold(0.0, f64::max)),
        ]
    };
    let header = [
        "diagrams",
        "guaranteed bound, worst (min – max)",
        "bound within 0.8 – 1.25",
        "guaranteed bound, median diagram",
        "sampled ratio, worst (target > 1 % max)",
        "sampled max |ratio − 1|, median diagram",
        "median |ratio − 1|, median diagram",
        "median |ratio − 1|, worst diagram",
    ];
    let mut by_family = Table::new(&[&["family"], &header[..]].concat());
    for f in Family::ALL {
        let sel: Vec<&Row> = rows.iter().filter(|r| r.family == f).collect();
        let mut row = vec![f.name().to_string()];
        row.extend(summarise(&sel));
        by_family.push(row);
    }
    let all: Vec<&Row> = rows.iter().collect();
    let mut row = vec!["all".to_string()];
    row.extend(summarise(&all));
    by_family.push(row);
    by_family.save(
        "diagrams_1024_family",
        &format!("p / target over {count} random diagrams, per family"),
    );

    let mut by_n = Table::new(&[&["N"], &header[..]].concat());
    for &n in &SET_N {
        let sel: Vec<&Row> = rows.iter().filter(|r| r.n == n).collect();
        let mut row = vec![n.to_string()];
        row.extend(summarise(&sel));
        by_n.push(row);
    }
    by_n.save(
        "diagrams_1024_n",
        &format!("p / target over {count} random diagrams, per number of parallels N"),
    );

    let series: Vec<Series> = Family::ALL
        .iter()
        .map(|&f| Series {
            label: f.name().to_string(),
            points: SET_N
                .iter()
                .map(|&n| {
                    let md: Vec<f64> = rows
                        .iter()
                        .filter(|r| r.family == f && r.n == n)
                        .map(|r| r.median_dev)
                        .collect();
                    (n as f64, median(&md))
                })
                .collect(),
            dashed: false,
        })
        .collect();
    loglog_svg(
        "diagrams_1024_median_dev",
        "median |p/target − 1| of the median diagram vs N",
        "parallels N",
        "median |p/target − 1|",
        &series,
    );
}
