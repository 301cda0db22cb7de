//! Fuzz target: the family blob reader (docs/TABLES.md, "Families") must never panic or read out
//! of bounds; a family it accepts must give a BRDF table `TabulatedBrdf::new` accepts or a typed
//! error, and each slice map read back must sample with finite unit directions and finite
//! densities ≥ 0. As in the `tables` target, the first input byte picks a seed family to mutate
//! (the rest XOR-ed into it at the positions it names, the checksum resealed), so that the fuzzer
//! reaches the content checks past the checksum.
#![no_main]

use gonio::brdf::{self, BrdfSampler, SamplerOptions, Symmetry, TabulatedBrdf};
use gonio::mapping::blob::{self, Precision, ReadMap};
use libfuzzer_sys::fuzz_target;

#[path = "../common/blob_case.rs"]
#[allow(dead_code)] // the checks of a read map: a family's slices are checked here
mod blob_case;

/// The blobs the mutations start from.
fn seeds() -> Vec<Vec<u8>> {
    let iso = TabulatedBrdf::from_fn(
        Symmetry::Isotropic,
        3,
        vec![0.0, 0.7, 1.5707963267948966],
        vec![0.0],
        vec![0.0, 0.5, 1.0, 1.5707963267948966],
        vec![0.0, 2.0, 4.0],
        |ti, _, to, po| {
            [
                1.0 + ti.cos() * to.cos() + 0.5 * po.cos(),
                0.5,
                if ti > 1.0 { 0.0 } else { 2.0 },
            ]
        },
    )
    .unwrap();
    let aniso = TabulatedBrdf::from_fn(
        Symmetry::Anisotropic,
        1,
        vec![0.0, 1.5707963267948966],
        vec![0.0, 3.0],
        vec![0.0, 0.8, 1.5707963267948966],
        vec![0.0, 2.0, 4.0],
        |ti, pi, to, po| {
            [if ti > 1.0 && pi > 1.0 {
                0.0
            } else {
                1.0 + to.cos() + 0.3 * (po - pi).cos()
            }; 3]
        },
    )
    .unwrap();
    let mut v = Vec::new();
    for t in [iso, aniso] {
        let s = BrdfSampler::new(t, &SamplerOptions::default()).unwrap();
        for p in [Precision::F32, Precision::F64] {
            v.push(s.tables(p).unwrap());
        }
    }
    v
}

/// The directions and densities, widened to f64, that the map `$f` gives the points (`$u`, `$v`)
/// rounded to its element type `$t`; its pdf batch at them asserted finite and ≥ 0.
macro_rules! sampled {
    ($f:expr, $t:ty, $u:expr, $v:expr) => {{
        let u: Vec<$t> = $u.iter().map(|&x| x as $t).collect();
        let v: Vec<$t> = $v.iter().map(|&x| x as $t).collect();
        let n = u.len();
        let mut o: [Vec<$t>; 4] = std::array::from_fn(|_| vec![0.0; n]);
        let [x, y, z, p] = &mut o;
        $f.sample_soa(&u, &v, [x, y, z], p);
        let mut q: Vec<$t> = vec![0.0; n];
        $f.pdf_soa([&o[0], &o[1], &o[2]], &mut q);
        assert!(q.iter().all(|p| p.is_finite() && *p >= 0.0));
        (0..n)
            .map(|k| [0, 1, 2, 3].map(|c| o[c][k] as f64))
            .collect::<Vec<[f64; 4]>>()
    }};
}

fn exercise(bytes: &[u8], data: &[u8]) {
    let Ok(fam) = blob::read_family(bytes) else {
        return;
    };
    let _ = brdf::from_tables(bytes);
    let mut u: Vec<f64> = vec![0.0, 1.0, 0.5, 1.0, 0.0];
    let mut v: Vec<f64> = vec![0.0, 1.0, 0.5, 0.0, 1.0];
    for c in data.chunks_exact(2).take(8) {
        u.push(c[0] as f64 / 255.0);
        v.push(c[1] as f64 / 255.0);
    }
    for s in fam.slices.iter().flatten() {
        let dirs = match s {
            ReadMap::F32(f) => sampled!(f, f32, u, v),
            ReadMap::F64(f) => sampled!(f, f64, u, v),
        };
        for d in dirs {
            assert!(d[3].is_finite() && d[3] >= 0.0, "pdf {d:?}");
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-3, "direction {d:?}");
        }
    }
}

fuzz_target!(|data: &[u8]| {
    exercise(data, data);
    if let Some((b, rest)) = blob_case::mutated(seeds, data) {
        exercise(&b, rest);
    }
});
