//! Family blobs (docs/TABLES.md, "Families"): a tabulated BRDF's slice maps, incident grid and
//! table written by `BrdfSampler::tables` and read back by `blob::read_family` /
//! `brdf::from_tables`. Read back, the table is the writer's exactly and every slice samples,
//! evaluates and inverts bit for bit as the writer's slice map (float32 and f64); a corrupted
//! family (every byte flipped in turn, every truncation, flips with the checksum recomputed,
//! forged counts) is refused with a typed error, never a panic.

use gonio::brdf::{self, Analytic, BrdfSampler, SamplerOptions, Symmetry, TabulatedBrdf};
use gonio::mapping::blob::{self, Precision, ReadMap, TablesError};
use std::f64::consts::FRAC_PI_2;

fn points(n: usize) -> (Vec<f64>, Vec<f64>) {
    let radical = |mut i: u64, base: u64| {
        let (mut f, mut r) = (1.0, 0.0);
        while i > 0 {
            f /= base as f64;
            r += f * (i % base) as f64;
            i /= base;
        }
        r
    };
    let mut u: Vec<f64> = (1..=n as u64).map(|i| radical(i, 2)).collect();
    let mut v: Vec<f64> = (1..=n as u64).map(|i| radical(i, 3)).collect();
    for (a, b) in [(0.0, 0.0), (1.0, 1.0), (0.5, 0.5), (0.0, 1.0), (1.0, 0.0)] {
        u.push(a);
        v.push(b);
    }
    (u, v)
}

fn tables() -> Vec<(String, TabulatedBrdf)> {
    let mut out: Vec<(String, TabulatedBrdf)> = Analytic::families()
        .into_iter()
        .map(|a| (a.name().to_string(), a.table(7, 8).unwrap()))
        .collect();
    // A table whose grazing slice holds no reflectance (that slice has no map).
    let dark = TabulatedBrdf::from_fn(
        Symmetry::Isotropic,
        1,
        brdf::uniform_theta(5, 90.0),
        vec![0.0],
        brdf::uniform_theta(6, 90.0),
        brdf::uniform_phi(6),
        |ti, _, to, _| {
            if ti > 1.2 {
                [0.0; 3]
            } else {
                [1.0 + to.cos(); 3]
            }
        },
    )
    .unwrap();
    out.push(("dark grazing slice".into(), dark));
    out
}

/// Asserts that the maps `$w` (the writer's) and `$f` (read back) sample, evaluate and invert
/// the points (`$u`, `$v`), rounded to their element type `$t`, to the same bits.
macro_rules! assert_same_bits {
    ($what:expr, $w:expr, $f:expr, $u:expr, $v:expr, $t:ty) => {{
        #[allow(clippy::unnecessary_cast)] // the f64 expansion
        let (u, v): (Vec<$t>, Vec<$t>) = (
            $u.iter().map(|&x| x as $t).collect(),
            $v.iter().map(|&x| x as $t).collect(),
        );
        let (n, what, t) = (u.len(), $what, stringify!($t));
        let same = |a: &[$t], b: &[$t]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        let mut a: [Vec<$t>; 4] = std::array::from_fn(|_| vec![0.0; n]);
        let mut b = a.clone();
        let [x, y, z, p] = &mut a;
        $w.sample_soa(&u, &v, [x, y, z], p);
        let [x, y, z, p] = &mut b;
        $f.sample_soa(&u, &v, [x, y, z], p);
        for k in 0..4 {
            assert!(same(&a[k], &b[k]), "{what}: {t} sample column {k}");
        }
        let d = [&a[0][..], &a[1][..], &a[2][..]];
        let (mut pa, mut pb): (Vec<$t>, Vec<$t>) = (vec![0.0; n], vec![0.0; n]);
        $w.pdf_soa(d, &mut pa);
        $f.pdf_soa(d, &mut pb);
        assert!(same(&pa, &pb), "{what}: {t} pdf");
        let mut ia: [Vec<$t>; 2] = std::array::from_fn(|_| vec![0.0; n]);
        let mut ib = ia.clone();
        let [iu, iv] = &mut ia;
        $w.invert_soa(d, [iu, iv]);
        let [iu, iv] = &mut ib;
        $f.invert_soa(d, [iu, iv]);
        for k in 0..2 {
            assert!(same(&ia[k], &ib[k]), "{what}: {t} invert {k}");
        }
    }};
}

/// Bit-identity of the slice `read` read back against the writer's slice map `map`.
fn same_slice(what: &str, map: &gonio::HemisphereMap, read: &ReadMap) {
    let (u, v) = points(500);
    match read {
        ReadMap::F32(f) => assert_same_bits!(what, map.float32_map().unwrap(), f, u, v, f32),
        ReadMap::F64(f) => assert_same_bits!(what, map.float64_map(), f, u, v, f64),
    }
}

/// Every analytic family and a table with an empty slice, in both precisions: the table comes
/// back exactly, every slice bit for bit, the empty slice as none; writing the read-back
/// sampler's family again gives the same bytes.
#[test]
fn families_round_trip() {
    for (name, table) in tables() {
        let sampler = BrdfSampler::new(table.clone(), &SamplerOptions::default()).unwrap();
        let (count, empty) = sampler.slice_counts();
        if name == "dark grazing slice" {
            assert_eq!(empty, 1, "{name}: the grazing slice is empty");
        }
        for precision in [Precision::F32, Precision::F64] {
            let what = format!("{name} {}", precision.name());
            let bytes = sampler.tables(precision).unwrap();
            assert_eq!(bytes.len() % 64, 0);
            let (back, fam) = brdf::from_tables(&bytes).unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_eq!(back, table, "{what}: the BRDF table");
            assert_eq!(fam.precision, precision);
            assert_eq!(fam.slices.len(), count);
            assert_eq!(fam.anisotropic, table.symmetry() == Symmetry::Anisotropic);
            for (k, s) in fam.slices.iter().enumerate() {
                match (sampler.slice(k), s) {
                    (Some(m), Some(r)) => same_slice(&format!("{what} slice {k}"), m, r),
                    (None, None) => {}
                    _ => panic!("{what}: slice {k} present on one side only"),
                }
            }
            // The table read back builds the same sampler, which writes the same bytes.
            let again = BrdfSampler::new(back, &SamplerOptions::default())
                .unwrap()
                .tables(precision)
                .unwrap();
            assert!(again == bytes, "{what}: rewritten family differs");
            // A family is not a single map, and a single map is not a family.
            assert!(matches!(
                blob::read(&bytes),
                Err(TablesError::Field {
                    field: "layout",
                    ..
                })
            ));
        }
    }
    let single = gonio::HemisphereMap::new(
        &gonio::Diagram::from_degrees(&[0.0, 45.0, 90.0], &[0.0], &[vec![1.0, 1.0, 1.0]]).unwrap(),
    )
    .unwrap();
    let b = blob::write(
        gonio::MapRef::Hemisphere(&single),
        Precision::F32,
        blob::Frame::Generic,
        &blob::Target::None,
    )
    .unwrap();
    assert!(matches!(
        blob::read_family(&b),
        Err(TablesError::Field {
            field: "layout",
            ..
        })
    ));
}

fn recompute_checksum(b: &mut [u8]) {
    let c = blob::checksum(b);
    b[24..32].copy_from_slice(&c.to_le_bytes());
}

/// A small family, corrupted every way: every byte flipped (refused by the checksum), every
/// truncation, and every byte of the header and directory flipped with the checksum recomputed
/// (each reaches the field and content checks): a typed error, or a valid family, never a panic
/// or a read outside the bytes.
#[test]
fn corrupted_families_are_refused() {
    let table = TabulatedBrdf::from_fn(
        Symmetry::Anisotropic,
        1,
        vec![0.0, 0.6, FRAC_PI_2],
        vec![0.0, 3.0],
        vec![0.0, 0.8, FRAC_PI_2],
        vec![0.0, 2.0, 4.0],
        |ti, pi, to, po| [1.0 + ti.cos() * to.cos() + 0.3 * (po - pi).cos(); 3],
    )
    .unwrap();
    let sampler = BrdfSampler::new(table, &SamplerOptions::default()).unwrap();
    for precision in [Precision::F32, Precision::F64] {
        let bytes = sampler.tables(precision).unwrap();
        assert!(brdf::from_tables(&bytes).is_ok());
        for k in 0..bytes.len() {
            let mut b = bytes.clone();
            b[k] ^= 0x5a;
            let r = blob::read_family(&b);
            // Bytes 0-23 fail the magic, version or size checks first; the rest the checksum.
            assert!(
                r.is_err() && (k < 24 || matches!(r, Err(TablesError::Checksum { .. }))),
                "byte {k}"
            );
        }
        for len in 0..bytes.len() {
            assert!(blob::read_family(&bytes[..len]).is_err(), "length {len}");
        }
        let dir_end = 256 + 32 * u32::from_le_bytes(bytes[48..52].try_into().unwrap()) as usize;
        let mut refused = 0;
        for k in 0..dir_end.min(bytes.len()) {
            for flip in [0x01u8, 0x80, 0xff] {
                let mut b = bytes.clone();
                b[k] ^= flip;
                recompute_checksum(&mut b);
                if brdf::from_tables(&b).is_err() {
                    refused += 1;
                }
            }
        }
        // Nearly every header and directory byte matters; the few that do not (low bits of a
        // scale factor, of the grid's values) may still give a valid family.
        assert!(
            refused > 3 * dir_end * 9 / 10,
            "{refused} of {}",
            3 * dir_end
        );
        // Table bytes flipped with the checksum recomputed: never a panic.
        for k in (dir_end..bytes.len()).step_by(3) {
            let mut b = bytes.clone();
            b[k] ^= 0xff;
            recompute_checksum(&mut b);
            let _ = brdf::from_tables(&b);
        }
        // Forged counts: huge incident grids, parallels, meridians.
        for (at, v) in [
            (176usize, u32::MAX),
            (180, u32::MAX),
            (96, u32::MAX),
            (100, u32::MAX),
            (188, 2),
            (184, 7),
            (192, u32::MAX),
        ] {
            let mut b = bytes.clone();
            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
            recompute_checksum(&mut b);
            assert!(blob::read_family(&b).is_err(), "forged field at {at}");
        }
    }
}
