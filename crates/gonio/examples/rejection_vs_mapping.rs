//! The paper's "comparison with rejection sampling": acceptance rate and time per accepted sample
//! of rejection sampling (uniform proposals under the maximum of the bilinear target) against the
//! time per sample of the HDS map, over random diagrams and over the photometric corpus.
//!
//! `cargo run --release --example rejection_vs_mapping [-- --quick]` writes
//! `docs/experiments/rejection_{family,corpus}.{csv,md}`. The corpus directory is `$GONIO_CORPUS`
//! or `../shared/data/photometry` beside the workspace; without it that table is skipped.
//! Times are thread CPU time per sample, median of 5 runs over the same Halton points.

mod common;

use common::{diagram_set, median, ns_per_item, Table};
use gonio::baselines::Rejection;
use gonio::photometry::{read, DirTiltResolver, FileFormat};
use gonio::sequence::Halton;
use gonio::synthetic::Family;
use gonio::Batches;
use gonio::{Diagram, Domain, HemisphereMap, Sample, Sampler, SphereMap};
use std::hint::black_box;

/// (acceptance, rejection ns per accepted sample, hds ns per sample).
type Comparison = (f64, f64, f64);

/// The [`Comparison`] on one diagram, or None if rejection sampling refuses it.
fn compare(d: &Diagram, pts: &[[f64; 2]]) -> Option<Comparison> {
    let hemi = *d.theta().last()? <= std::f64::consts::FRAC_PI_2;
    let domain = if hemi {
        Domain::Hemisphere
    } else {
        Domain::Sphere
    };
    let rej = Rejection::new(d, domain).ok()?;
    let hds: Box<dyn Sampler> = if hemi {
        Box::new(HemisphereMap::new(d).ok()?)
    } else {
        Box::new(SphereMap::new(d).ok()?)
    };
    let mut out = vec![Sample::default(); pts.len()];
    let t_rej = ns_per_item(5, pts.len(), || {
        rej.sample_batch(black_box(pts), &mut out);
        black_box(&out);
    });
    let t_hds = ns_per_item(5, pts.len(), || {
        hds.sample_batch(black_box(pts), &mut out);
        black_box(&out);
    });
    Some((rej.acceptance_rate(), t_rej, t_hds))
}

fn main() {
    let quick = common::quick();
    let count = if quick { 64 } else { 256 };
    let mut pts = vec![[0.0; 2]; if quick { 1024 } else { 4096 }];
    Halton::with_skip(1).fill(0, &mut pts);
    // every fourth diagram of the 1024-diagram set
    let set = diagram_set(4 * count);
    let results: Vec<(Family, Option<Comparison>)> = set
        .iter()
        .step_by(4)
        .map(|sd| (sd.family, compare(&sd.diagram, &pts)))
        .collect();
    let mut t = Table::new(&[
        "family",
        "diagrams",
        "refused (acceptance < minimum)",
        "acceptance, median",
        "acceptance, min",
        "rejection ns/sample, median",
        "hds ns/sample, median",
        "rejection / hds time, median",
        "rejection / hds time, max",
    ]);
    for f in Family::ALL {
        let sel: Vec<_> = results.iter().filter(|r| r.0 == f).collect();
        let ok: Vec<Comparison> = sel.iter().filter_map(|r| r.1).collect();
        let acc: Vec<f64> = ok.iter().map(|r| r.0).collect();
        let ratio: Vec<f64> = ok.iter().map(|r| r.1 / r.2).collect();
        t.push(vec![
            f.name().into(),
            sel.len().to_string(),
            (sel.len() - ok.len()).to_string(),
            format!("{:.3}", median(&acc)),
            format!("{:.4}", acc.iter().cloned().fold(1.0, f64::min)),
            format!("{:.0}", median(&ok.iter().map(|r| r.1).collect::<Vec<_>>())),
            format!("{:.0}", median(&ok.iter().map(|r| r.2).collect::<Vec<_>>())),
            format!("{:.1}", median(&ratio)),
            format!("{:.1}", ratio.iter().cloned().fold(0.0, f64::max)),
        ]);
    }
    t.save(
        "rejection_family",
        &format!(
            "Rejection sampling vs HDS over {count} random hemisphere diagrams ({})",
            common::machine()
        ),
    );

    let Some(dir) = common::corpus_dir() else {
        println!("corpus not found (set GONIO_CORPUS): skipping the corpus table");
        return;
    };
    let files = common::corpus_files(&dir);
    let mut t = Table::new(&[
        "file",
        "grid N×M",
        "acceptance",
        "rejection ns/sample",
        "hds ns/sample",
        "rejection / hds",
    ]);
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let Some(format) = FileFormat::from_path_extension(&path) else {
            continue;
        };
        let Ok(bytes) = std::fs::read(&path) else {
            continue;
        };
        let tilt = DirTiltResolver::new(path.parent().unwrap());
        let Ok(d) = read(&bytes, format, &tilt)
            .map_err(|_| ())
            .and_then(|p| p.to_diagram().map_err(|_| ()))
        else {
            continue;
        };
        let grid = format!("{}×{}", d.n_parallels(), d.n_meridians());
        match compare(&d, &pts) {
            Some((a, tr, th)) => t.push(vec![
                name,
                grid,
                format!("{a:.4}"),
                format!("{tr:.0}"),
                format!("{th:.0}"),
                format!("{:.1}", tr / th),
            ]),
            None => t.push(vec![
                name,
                grid,
                "refused".into(),
                "—".into(),
                "—".into(),
                "—".into(),
            ]),
        }
    }
    t.save(
        "rejection_corpus",
        "Rejection sampling vs HDS on the photometric corpus (sphere domain unless θ ≤ 90°)",
    );
}
