//! The SIMD batch paths (`mapping::batch`) against the scalar reference: equal results within the
//! documented bounds, exact pdf, round trips in f64 and f32, and results that do not depend on the
//! backend (AVX2+FMA and portable are both run explicitly), the block size or the thread count.

// Columns of the structure-of-arrays outputs are indexed by component on purpose.
#![allow(clippy::needless_range_loop)]

mod common;

use gonio::mapping::batch::{invert_soa_par, pdf_soa_par, sample_soa_par, SoaSampler};
use gonio::mapping::simd::{Backend, BatchFloat};
use gonio::synthetic::{example_luminaire, random_hemisphere, Family};
use gonio::Batches;
use gonio::{HemisphereMap, Sampler, SphereLayout, SphereMap};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Builds one map of the test list.
type MakeMap = Box<dyn Fn() -> Box<dyn Probe>>;

/// Every map shape the batch paths handle: uniform and irregular meridians, zero-heavy values, the
/// split sphere (both halves), the Lambert sphere.
fn maps() -> Vec<(String, MakeMap)> {
    let mut v: Vec<(String, MakeMap)> = Vec::new();
    for (fam, n, m, irr, seed) in common::MAP_CASES {
        v.push((
            format!("hemisphere {fam:?} {n}x{m} irregular={irr}"),
            Box::new(move || {
                Box::new(HemisphereMap::new(&random_hemisphere(fam, n, m, irr, seed)).unwrap())
            }),
        ));
    }
    v.push((
        "sphere split".into(),
        Box::new(|| Box::new(SphereMap::new(&example_luminaire()).unwrap())),
    ));
    v.push((
        "sphere lambert".into(),
        Box::new(|| {
            Box::new(SphereMap::with_layout(&example_luminaire(), SphereLayout::Lambert).unwrap())
        }),
    ));
    v
}

/// Object-safe view of a map with both the scalar and the batch paths, in f64 and f32.
trait Probe: Sampler {
    fn sample64(&self, b: Backend, u: &[f64], v: &[f64]) -> [Vec<f64>; 4];
    fn sample32(&self, b: Backend, u: &[f32], v: &[f32]) -> [Vec<f32>; 4];
    fn pdf64(&self, b: Backend, d: &[Vec<f64>]) -> Vec<f64>;
    fn pdf32(&self, b: Backend, d: &[Vec<f32>]) -> Vec<f32>;
    fn inv64(&self, b: Backend, d: &[Vec<f64>]) -> [Vec<f64>; 2];
    fn inv32(&self, b: Backend, d: &[Vec<f32>]) -> [Vec<f32>; 2];
    fn par64(&self, u: &[f64], v: &[f64]) -> ([Vec<f64>; 4], Vec<f64>, [Vec<f64>; 2]);
}

fn sample_t<S: SoaSampler, T: BatchFloat>(s: &S, b: Backend, u: &[T], v: &[T]) -> [Vec<T>; 4] {
    let n = u.len();
    let mut o = [vec![u[0]; n], vec![u[0]; n], vec![u[0]; n], vec![u[0]; n]];
    let [x, y, z, p] = &mut o;
    s.sample_soa_with(b, u, v, [x, y, z], p);
    o
}
fn pdf_t<S: SoaSampler, T: BatchFloat>(s: &S, b: Backend, d: &[Vec<T>]) -> Vec<T> {
    let mut o = d[0].clone();
    s.pdf_soa_with(b, [&d[0], &d[1], &d[2]], &mut o);
    o
}
fn inv_t<S: SoaSampler, T: BatchFloat>(s: &S, b: Backend, d: &[Vec<T>]) -> [Vec<T>; 2] {
    let mut o = [d[0].clone(), d[0].clone()];
    let [u, v] = &mut o;
    s.invert_soa_with(b, [&d[0], &d[1], &d[2]], [u, v]);
    o
}
fn par_t<S: SoaSampler>(s: &S, u: &[f64], v: &[f64]) -> ([Vec<f64>; 4], Vec<f64>, [Vec<f64>; 2]) {
    let n = u.len();
    let mut o = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    let [x, y, z, p] = &mut o;
    sample_soa_par(s, u, v, [x, y, z], p);
    let mut pd = vec![0.0; n];
    pdf_soa_par(s, [&o[0], &o[1], &o[2]], &mut pd);
    let mut w = [vec![0.0; n], vec![0.0; n]];
    let [wu, wv] = &mut w;
    invert_soa_par(s, [&o[0], &o[1], &o[2]], [wu, wv]);
    (o, pd, w)
}

macro_rules! probe {
    ($t:ty) => {
        impl Probe for $t {
            fn sample64(&self, b: Backend, u: &[f64], v: &[f64]) -> [Vec<f64>; 4] {
                sample_t(self, b, u, v)
            }
            fn sample32(&self, b: Backend, u: &[f32], v: &[f32]) -> [Vec<f32>; 4] {
                sample_t(self, b, u, v)
            }
            fn pdf64(&self, b: Backend, d: &[Vec<f64>]) -> Vec<f64> {
                pdf_t(self, b, d)
            }
            fn pdf32(&self, b: Backend, d: &[Vec<f32>]) -> Vec<f32> {
                pdf_t(self, b, d)
            }
            fn inv64(&self, b: Backend, d: &[Vec<f64>]) -> [Vec<f64>; 2] {
                inv_t(self, b, d)
            }
            fn inv32(&self, b: Backend, d: &[Vec<f32>]) -> [Vec<f32>; 2] {
                inv_t(self, b, d)
            }
            fn par64(&self, u: &[f64], v: &[f64]) -> ([Vec<f64>; 4], Vec<f64>, [Vec<f64>; 2]) {
                par_t(self, u, v)
            }
        }
    };
}
probe!(HemisphereMap);
probe!(SphereMap);

/// Random points of the square plus its corners, edges, centre and the seam lines.
fn points(seed: u64, n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut u: Vec<f64> = (0..n).map(|_| rng.gen()).collect();
    let mut v: Vec<f64> = (0..n).map(|_| rng.gen()).collect();
    for (a, b) in [
        (0.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (1.0, 0.0),
        (0.5, 0.5),
        (0.5, 0.0),
        (1.0, 0.5),
        (0.75, 0.5),
        (0.5, 0.9),
        (1e-17, 0.5),
    ] {
        u.push(a);
        v.push(b);
    }
    (u, v)
}

fn bits64(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}
fn bits32(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// The backends agree bit for bit, in f64 and f32, for sample, pdf and invert; so do odd block
/// offsets (a sub-slice starting at 3) and 1, 2 and 3 threads.
#[test]
fn results_do_not_depend_on_backend_block_or_threads() {
    let backends = Backend::available();
    if backends.len() < 2 {
        println!("SKIPPED part: this CPU has no AVX2+FMA; only the portable backend was run");
    }
    let (u, v) = points(1, 5_003);
    let (u32s, v32s): (Vec<f32>, Vec<f32>) = (
        u.iter().map(|&x| x as f32).collect(),
        v.iter().map(|&x| x as f32).collect(),
    );
    for (name, make) in maps() {
        let m = make();
        let base = m.sample64(Backend::Portable, &u, &v);
        let base32 = m.sample32(Backend::Portable, &u32s, &v32s);
        let p = m.pdf64(Backend::Portable, &base[..3]);
        let w = m.inv64(Backend::Portable, &base[..3]);
        let p32 = m.pdf32(Backend::Portable, &base32[..3]);
        let w32 = m.inv32(Backend::Portable, &base32[..3]);
        for &b in &backends {
            let s = m.sample64(b, &u, &v);
            for k in 0..4 {
                assert_eq!(bits64(&s[k]), bits64(&base[k]), "{name} {b:?} sample f64");
            }
            assert_eq!(
                bits64(&m.pdf64(b, &base[..3])),
                bits64(&p),
                "{name} {b:?} pdf"
            );
            let wb = m.inv64(b, &base[..3]);
            assert_eq!(bits64(&wb[0]), bits64(&w[0]), "{name} {b:?} invert");
            assert_eq!(bits64(&wb[1]), bits64(&w[1]), "{name} {b:?} invert");
            let s32 = m.sample32(b, &u32s, &v32s);
            for k in 0..4 {
                assert_eq!(
                    bits32(&s32[k]),
                    bits32(&base32[k]),
                    "{name} {b:?} sample f32"
                );
            }
            assert_eq!(
                bits32(&m.pdf32(b, &base32[..3])),
                bits32(&p32),
                "{name} pdf f32"
            );
            let wb = m.inv32(b, &base32[..3]);
            assert_eq!(bits32(&wb[0]), bits32(&w32[0]), "{name} {b:?} invert f32");
            assert_eq!(bits32(&wb[1]), bits32(&w32[1]), "{name} {b:?} invert f32");
            // another block alignment
            let s3 = m.sample64(b, &u[3..], &v[3..]);
            assert_eq!(bits64(&s3[0]), bits64(&base[0][3..]), "{name} offset 3");
        }
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (s, pd, wi) = pool.install(|| m.par64(&u, &v));
            for k in 0..4 {
                assert_eq!(bits64(&s[k]), bits64(&base[k]), "{name} {threads} threads");
            }
            assert_eq!(bits64(&pd), bits64(&p), "{name} {threads} threads pdf");
            assert_eq!(
                bits64(&wi[0]),
                bits64(&w[0]),
                "{name} {threads} threads invert"
            );
        }
    }
}

/// f64 batch vs the scalar reference: the pdf of a sample within 1e-12 relative of the scalar
/// pdf() of its direction, the directions within 1e-15 (sin/cos within 2 ulp), the batch pdf of
/// a direction within 1e-12 relative of the scalar pdf and of the sample's pdf (absolute 1e-18
/// where the density is below 1e-6: zero-density rims), the inverse within
/// 1e-12 of the scalar inverse, and the round trip within 1e-10 wherever the scalar one holds.
#[test]
fn f64_batch_matches_the_scalar_reference() {
    let (u, v) = points(2, 20_000);
    for (name, make) in maps() {
        let m = make();
        for b in Backend::available() {
            let s = m.sample64(b, &u, &v);
            let pd = m.pdf64(b, &s[..3]);
            let w = m.inv64(b, &s[..3]);
            let (mut dmax, mut pmax, mut imax, mut rt_fail) = (0.0f64, 0.0f64, 0.0f64, 0);
            for k in 0..u.len() {
                let r = m.sample([u[k], v[k]]);
                // The sample's density is read at the radius of the returned direction (whose
                // sin/cos differ from the scalar ones within 2 ulp), so it is compared with the
                // scalar pdf() of that direction: relative 1e-12, plus 1e-15 /sr absolute for the
                // round-off of densities next to zero (d0 + (d1 − d0)t with d0 ≈ 1, d1 = 0).
                let at = m.pdf([s[0][k], s[1][k], s[2][k]]);
                assert!(
                    (s[3][k] - at).abs() <= 1e-12 * at + 1e-15,
                    "{name} {b:?} pdf at {k}: {} vs pdf() {at}",
                    s[3][k]
                );
                for c in 0..3 {
                    dmax = dmax.max((s[c][k] - r.direction[c]).abs());
                }
                let dir = [s[0][k], s[1][k], s[2][k]];
                let scalar_pdf = m.pdf(dir);
                // Relative to the density, or absolute below 1e-6 (a zero-density rim, where the
                // scalar path's own sample-vs-pdf round-off is of order 1e-15 absolute).
                let scale = scalar_pdf.max(1e-6);
                pmax = pmax.max((pd[k] - scalar_pdf).abs() / scale);
                // The batch pdf of a batch sample is as consistent as the scalar pair (where the
                // scalar pdf of a sample is off by more than 1e-12, e.g. at a zero-density rim,
                // the batch is allowed the same), plus the batch sample's own difference from
                // pdf() at its direction (bounded above).
                let own = (m.pdf(r.direction) - r.pdf).abs() + (s[3][k] - scalar_pdf).abs();
                pmax = pmax.max(((pd[k] - s[3][k]).abs() - own).max(0.0) / scale);
                if let Ok(ws) = m.invert(dir) {
                    imax = imax
                        .max((w[0][k] - ws[0]).abs())
                        .max((w[1][k] - ws[1]).abs());
                    let scalar_rt = (ws[0] - u[k]).abs().max((ws[1] - v[k]).abs()) <= 1e-10;
                    let batch_rt = (w[0][k] - u[k]).abs().max((w[1][k] - v[k]).abs()) <= 1e-10;
                    if scalar_rt && !batch_rt {
                        rt_fail += 1;
                    }
                }
            }
            println!("{name} {b:?}: direction {dmax:.1e}, pdf {pmax:.1e}, invert {imax:.1e}");
            assert!(dmax <= 1e-15, "{name} {b:?}: direction differs by {dmax:e}");
            assert!(
                pmax <= 1e-12,
                "{name} {b:?}: pdf differs by {pmax:e} relative"
            );
            assert!(imax <= 1e-12, "{name} {b:?}: invert differs by {imax:e}");
            assert_eq!(rt_fail, 0, "{name} {b:?}: round trips lost");
        }
    }
}

/// f32 batch (evaluated by the f64 kernels and rounded once; f32 directions renormalised in f64):
/// directions within 2e-6 of the f64 reference (scaled by min(1, 2π·pdf), as the scalar tests do:
/// a low density stretches the map; the nadir of the Lambert layout left out), the pdf of a sample
/// equal to the f32 batch pdf of its direction within 2 f32 ulps in the median and 2e-5 relative
/// to max(pdf, 0.1) at worst (rounding the direction to f32 moves a steep density by up to
/// |d ln D/dx|·ε₃₂), and the round trip within 1e-6 (the issue asks 1e-5) away from the seams of
/// the square, wherever the scalar f64 round trip holds. Measured: directions ≤ 6e-7, pdf median
/// ≤ 0.73 ulp and max ≤ 4e-6, round trip ≤ 2.4e-7.
#[test]
fn f32_batch_is_exact_to_f32() {
    let (u, v) = points(3, 20_000);
    let (u32s, v32s): (Vec<f32>, Vec<f32>) = (
        u.iter().map(|&x| x as f32).collect(),
        v.iter().map(|&x| x as f32).collect(),
    );
    for (name, make) in maps() {
        let m = make();
        for b in Backend::available() {
            let s = m.sample32(b, &u32s, &v32s);
            let pd = m.pdf32(b, &s[..3]);
            let w = m.inv32(b, &s[..3]);
            let (mut dmax, mut pmax, mut rt) = (0.0f64, 0.0f64, 0.0f64);
            let mut rel = Vec::new();
            for k in 0..u.len() {
                let r = m.sample([u32s[k] as f64, v32s[k] as f64]);
                // Scaled by min(1, 2π·pdf) as in tests/mapping.rs: where the density is low the
                // map stretches, and an f32 rounding of u moves the direction further.
                // The Lambert layout's far pole is the whole rim of its disk, where dω/dr is
                // unbounded: directions within 1e-3 of the nadir (1 + z) are left out there.
                let q = if 1.0 + r.direction[2] < 1e-3 {
                    0.0
                } else {
                    (r.pdf * std::f64::consts::TAU).min(1.0)
                };
                for c in 0..3 {
                    dmax = dmax.max((s[c][k] as f64 - r.direction[c]).abs() * q);
                }
                if r.pdf > 0.0 {
                    let e = ((pd[k] - s[3][k]) / s[3][k]).abs() as f64;
                    // worst case relative to max(pdf, 0.1): near zero-valued nodes the density
                    // falls to 0 and only the absolute error is meaningful (1/2π ≈ 0.16 is the
                    // mean density of a hemisphere)
                    pmax = pmax.max((pd[k] - s[3][k]).abs() as f64 / (s[3][k] as f64).max(0.1));
                    rel.push(e / f32::EPSILON as f64);
                    let du = (w[0][k] - u32s[k]).abs().max((w[1][k] - v32s[k]).abs()) as f64;
                    // the sphere's hemisphere seam and the B-disk's azimuth seam (v = ½, u > ½)
                    let seam = (v[k] - 0.5).abs() < 1e-4 && u[k] > 0.5;
                    // Where the map is not injective the scalar f64 round trip fails too (the
                    // Lambert layout's nadir is the whole rim of its disk: the square's edge):
                    // required, as in the f64 test, wherever the scalar one holds.
                    let p = [u32s[k] as f64, v32s[k] as f64];
                    let scalar_rt = m
                        .invert(r.direction)
                        .is_ok_and(|ws| (ws[0] - p[0]).abs().max((ws[1] - p[1]).abs()) <= 1e-10);
                    if !seam && scalar_rt {
                        rt = rt.max(du);
                    }
                }
            }
            rel.sort_by(f64::total_cmp);
            let med = rel[rel.len() / 2];
            println!(
                "{name} {b:?} f32: direction {dmax:.1e}, pdf median {med:.2} ulp, max {pmax:.1e}, round trip {rt:.1e}"
            );
            assert!(
                dmax <= 2e-6,
                "{name} {b:?}: f32 direction differs by {dmax:e}"
            );
            assert!(
                med <= 2.0,
                "{name} {b:?}: f32 pdf median mismatch {med} ulp"
            );
            assert!(pmax <= 2e-5, "{name} {b:?}: f32 pdf differs by {pmax:e}");
            assert!(rt <= 1e-6, "{name} {b:?}: f32 round trip {rt:e}");
        }
    }
}

/// Directions outside the domain: pdf 0, inverse NaN (the scalar `invert` fails there); the AoS
/// adapters report the error.
#[test]
fn outside_the_domain() {
    let m = HemisphereMap::new(&random_hemisphere(Family::Lobes, 19, 36, false, 1)).unwrap();
    let d = [
        vec![0.0, f64::NAN, 0.6],
        vec![0.6, 0.0, 0.0],
        vec![-0.8, 0.0, 0.8],
    ];
    let p = m.pdf64(Backend::detect(), &d);
    assert_eq!(p[0], 0.0);
    let w = m.inv64(Backend::detect(), &d);
    assert!(w[0][0].is_nan() && w[1][1].is_nan() && w[0][2].is_finite());
    let mut out = vec![Ok([0.0, 0.0]); 3];
    m.invert_batch(
        &[[0.0, 0.6, -0.8], [f64::NAN, 0.0, 0.0], [0.6, 0.0, 0.8]],
        &mut out,
    );
    assert!(out[0].is_err() && out[1].is_err() && out[2].is_ok());
}

/// The split sphere's seam in the batch inverse (f64 and f32): directions just below the horizon
/// invert to the lower map's rim, u → P_lower from below; rounding must not carry them to
/// u ≥ P_lower, which `sample` sends to the upper map (its centre, the north pole, 90° away). The
/// scalar inverse guards this; the batch paths in both precisions must too.
#[test]
fn split_seam_holds_in_both_precisions() {
    let m = SphereMap::new(&example_luminaire()).unwrap();
    let p_lower = m.lower_probability().expect("split layout");
    let n = 720;
    let mut d64 = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for k in 0..n {
        let phi = std::f64::consts::TAU * k as f64 / n as f64;
        // z from -1e-30 to -1e-3: the rim of the lower map
        let z = -(10f64).powf(-30.0 + 27.0 * (k % 10) as f64 / 9.0);
        let s = (1.0 - z * z).sqrt();
        d64[0][k] = s * phi.cos();
        d64[1][k] = s * phi.sin();
        d64[2][k] = z;
    }
    let d32: Vec<Vec<f32>> = d64
        .iter()
        .map(|c| c.iter().map(|&x| x as f32).collect())
        .collect();
    let pl32 = p_lower as f32;
    for b in Backend::available() {
        let w = m.inv64(b, &d64);
        let w32 = m.inv32(b, &d32);
        for k in 0..n {
            assert!(
                w[0][k] < p_lower,
                "{b:?} f64: u = {} ≥ P_lower {p_lower}",
                w[0][k]
            );
            assert!(
                w32[0][k] < pl32,
                "{b:?} f32: u = {} ≥ P_lower {pl32}",
                w32[0][k]
            );
        }
        let back = m.sample32(b, &w32[0], &w32[1]);
        for k in 0..n {
            assert!(
                back[2][k] <= 1e-3,
                "{b:?} f32: a direction below the horizon came back at z = {}",
                back[2][k]
            );
        }
    }
}

/// A sphere map of a luminaire that emits only downwards has no upper map: every direction above
/// the horizon has density 0 and no preimage. The batch inverse gives NaN in both coordinates there
/// (not u = 1, which `min(1)` would make of NaN), in every backend, and the AoS adapter reports the
/// scalar path's reason, `ZeroDensity` (issue 16).
#[test]
fn empty_upper_hemisphere_has_no_preimage() {
    use gonio::{Diagram, InvertError};
    let d = Diagram::from_degrees(
        &[90.0, 135.0, 180.0],
        &[0.0, 90.0],
        &[vec![0.0, 60.0, 100.0], vec![0.0, 50.0, 100.0]],
    )
    .unwrap();
    let m = SphereMap::new(&d).unwrap();
    let up = [0.0, 0.0, 1.0];
    let tilted = [0.6, 0.0, 0.8];
    let down = [0.0, -0.6, -0.8];
    assert_eq!(m.invert(up), Err(InvertError::ZeroDensity));
    let dirs = [
        vec![up[0], tilted[0], down[0]],
        vec![up[1], tilted[1], down[1]],
        vec![up[2], tilted[2], down[2]],
    ];
    for b in Backend::available() {
        let w = m.inv64(b, &dirs);
        for k in 0..2 {
            assert!(w[0][k].is_nan() && w[1][k].is_nan(), "{b:?}: {w:?}");
        }
        assert!(w[0][2].is_finite() && w[1][2].is_finite(), "{b:?}: {w:?}");
    }
    let mut out = vec![Ok([0.0, 0.0]); 3];
    m.invert_batch(&[up, tilted, down], &mut out);
    assert_eq!(out[0], Err(InvertError::ZeroDensity));
    assert_eq!(out[1], Err(InvertError::ZeroDensity));
    let p = out[2].unwrap();
    let back = m.sample(p);
    for i in 0..3 {
        assert!((back.direction[i] - down[i]).abs() < 1e-9, "{back:?}");
    }
}

/// Inputs outside the documented domain (NaN, ±∞, points far outside the square, non-unit and
/// zero directions, negative zeros) reach the explicit AVX2 kernels' gathers without a crash or
/// an out-of-bounds read, and every backend returns the same bits for them (the kernels clamp each
/// gather index into its table, and mirror the portable lanes' NaN rules of `min`/`max`).
#[test]
fn hostile_inputs_are_safe_and_backend_independent() {
    let specials = [
        f64::NAN,
        -f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        -0.0,
        0.0,
        1.0,
        -0.5,
        1.5,
        1e300,
        -1e300,
        f64::MIN_POSITIVE,
        1.0 - f64::EPSILON / 2.0,
        0.5,
    ];
    let (mut u, mut v) = (Vec::new(), Vec::new());
    for &a in &specials {
        for &b in &specials {
            u.push(a);
            v.push(b);
        }
    }
    // Directions: the same specials as coordinates (x, y, z), plus long and short vectors.
    let mut d = [Vec::new(), Vec::new(), Vec::new()];
    for &a in &specials {
        for &b in &specials {
            for &c in &[f64::NAN, 0.0, -0.0, 1.0, 0.3, 1e300, f64::INFINITY, -0.2] {
                d[0].push(a);
                d[1].push(b);
                d[2].push(c);
            }
        }
    }
    let backends = Backend::available();
    if backends.len() < 2 {
        println!("SKIPPED part: this CPU has no AVX2+FMA; only the portable backend was run");
    }
    let same = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
    };
    for (name, make) in maps() {
        let m = make();
        let base = m.sample64(Backend::Portable, &u, &v);
        let p = m.pdf64(Backend::Portable, &d);
        let w = m.inv64(Backend::Portable, &d);
        for &b in &backends {
            let s = m.sample64(b, &u, &v);
            for k in 0..4 {
                assert!(same(&s[k], &base[k]), "{name} {b:?} sample column {k}");
            }
            assert!(same(&m.pdf64(b, &d), &p), "{name} {b:?} pdf");
            let wb = m.inv64(b, &d);
            assert!(
                same(&wb[0], &w[0]) && same(&wb[1], &w[1]),
                "{name} {b:?} invert"
            );
        }
    }
}

/// `sample_batch_split` (directions and densities in separate slices, what the bindings use)
/// gives `sample_batch`'s values bit for bit, for the HDS maps' own implementation and for the
/// trait's default (a baseline), at lengths around its chunk of 256.
#[test]
fn sample_batch_split_equals_sample_batch() {
    let mut samplers: Vec<(String, Box<dyn Sampler>)> = maps()
        .into_iter()
        .map(|(name, make)| (name, make() as Box<dyn Sampler>))
        .collect();
    samplers.push((
        "piecewise-constant".into(),
        gonio::Method::PiecewiseConstant
            .build_with(
                &example_luminaire(),
                gonio::Domain::Sphere,
                &Default::default(),
            )
            .unwrap()
            .into_boxed(),
    ));
    for (name, s) in &samplers {
        for n in [0, 1, 255, 256, 257, 1000] {
            let (u, v) = points(11, n);
            let pts: Vec<[f64; 2]> = u.iter().zip(&v).map(|(&a, &b)| [a, b]).collect();
            let mut want = vec![gonio::Sample::default(); pts.len()];
            s.sample_batch(&pts, &mut want);
            let (mut dirs, mut pdf) = (vec![[f64::NAN; 3]; pts.len()], vec![f64::NAN; pts.len()]);
            s.sample_batch_split(&pts, &mut dirs, &mut pdf);
            for (k, w) in want.iter().enumerate() {
                assert_eq!(
                    bits64(&dirs[k]),
                    bits64(&w.direction),
                    "{name}, n = {n}: direction {k}"
                );
                assert_eq!(
                    pdf[k].to_bits(),
                    w.pdf.to_bits(),
                    "{name}, n = {n}: pdf {k}"
                );
            }
        }
    }
}
