//! Every corpus file sampled over the sphere with the HDS map: the pdf at every measured node of a
//! type C file is the file's candela value times one constant (issue: "node values are kept
//! exactly"), samples pass a chi-square test, and the inverse round-trips.
//!
//! Significance: one chi-square test per file, family level α = 0.01 with the Šidák correction over
//! all files; fixed seeds.

mod common;

use gonio::check::{chi_square_test, ChiSquareOptions};
use gonio::photometry::{read, DirTiltResolver, FileFormat, PhotometricType, Photometry};
use gonio::{Sampler, SphereMap};
use rand::{Rng, SeedableRng};
use std::path::Path;

fn load(path: &Path) -> Photometry {
    let bytes = std::fs::read(path).unwrap();
    let fmt = FileFormat::from_path_extension(path).unwrap();
    read(&bytes, fmt, &DirTiltResolver::new(path.parent().unwrap()))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn pdf_at_measured_nodes_is_candela_times_one_constant() {
    let dir = common::corpus_dir();
    let mut files = 0;
    for path in common::corpus_files(&dir) {
        let p = load(&path);
        if p.photometric_type != PhotometricType::C {
            continue;
        }
        files += 1;
        let map = SphereMap::new(&p.to_diagram().unwrap()).unwrap();
        let (nv, nh) = (p.vertical_angles_deg.len(), p.horizontal_angles_deg.len());
        // (pdf, candela, where) at every measured node and its mirror images
        let mut nodes = Vec::new();
        for (h, &c) in p.horizontal_angles_deg.iter().enumerate() {
            let closing =
                h == nh - 1 && nh > 1 && (c - p.horizontal_angles_deg[0] - 360.0).abs() < 1e-9;
            if closing && p.raw_values[..nv] != p.raw_values[h * nv..(h + 1) * nv] {
                continue; // a closing plane that differs from the first is not kept (warned)
            }
            for (k, &g) in p.vertical_angles_deg.iter().enumerate() {
                if g <= 0.0 || g >= 180.0 {
                    continue; // poles
                }
                let cd = p.raw_values[h * nv + k] * p.intensity_scale;
                for img in common::images(p.symmetry, c) {
                    let (gr, cr) = (g.to_radians(), img.to_radians());
                    // the photometric frame: γ = 0 is −z, C = 0 along +x
                    let om = [gr.sin() * cr.cos(), gr.sin() * cr.sin(), -gr.cos()];
                    nodes.push((map.pdf(om), cd, g, img));
                }
            }
        }
        // The constant from the brightest node; every node must match it. The tolerance is 1e-9
        // relative plus 1e-12 of the peak, for the round-off of the node's direction vector.
        let &(pk, ck, ..) = nodes
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .expect("a file has nodes");
        let k = pk / ck;
        for &(pdf, cd, g, c) in &nodes {
            assert!(
                (pdf - k * cd).abs() <= 1e-9 * k * cd + 1e-12 * pk,
                "{}: node γ = {g}°, C = {c}°: pdf {pdf} vs {} × {cd} cd",
                path.display(),
                k
            );
        }
    }
    assert!(files >= 30, "only {files} type C files");
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn every_file_samples_correctly() {
    let dir = common::corpus_dir();
    let files = common::corpus_files(&dir);
    let k = files.len();
    for (i, path) in files.iter().enumerate() {
        let p = load(path);
        let map = SphereMap::new(&p.to_diagram().unwrap()).unwrap();
        let r = chi_square_test(
            &map,
            &ChiSquareOptions {
                samples: 40_000,
                // 16 × 32 equal-solid-angle bins: ~80 samples a bin on average
                resolution: Some([16, 32]),
                seed: 500 + i as u64,
                alpha: 0.01,
                tests: k,
                ..ChiSquareOptions::default()
            },
        );
        assert!(
            r.p_value >= r.threshold && r.zero_expected_hits == 0 && r.invalid_samples == 0,
            "{}: {}",
            path.display(),
            r.message
        );
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(i as u64);
        for _ in 0..2000 {
            let u = [rng.gen::<f64>(), rng.gen::<f64>()];
            let s = map.sample(u);
            assert!((map.pdf(s.direction) - s.pdf).abs() <= 1e-9 * s.pdf);
            if s.pdf > 0.0 {
                let w = map.invert(s.direction).unwrap();
                assert!(
                    (w[0] - u[0]).abs() < 1e-9 && (w[1] - u[1]).abs() < 1e-9,
                    "{}: {u:?} -> {w:?}",
                    path.display()
                );
            }
        }
    }
}
