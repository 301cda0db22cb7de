//! The table blob (docs/TABLES.md): a map written and read back samples, evaluates and inverts bit
//! for bit as the map that wrote it, for every input kind (generated diagrams on the hemisphere
//! and both sphere layouts, the corpus's photometric files, environment maps) in f32 and f64;
//! and a corrupted blob is refused with a typed error: every byte flipped in turn, every
//! truncation, forged headers with huge counts, and flips with the checksum recomputed (which
//! reach the field and content checks) — never a panic.

#[path = "../../../fuzz/common/blob_case.rs"]
#[allow(dead_code)] // the fuzz targets' mutation is not used here
mod blob_case;
#[path = "common/corpus.rs"]
mod corpus;

use gonio::envmap::EnvironmentMap;
use gonio::image::Image;
use gonio::mapping::blob::{self, Frame, MapTables, Precision, ReadMap, TablesError, Target};
use gonio::synthetic::{random_hemisphere, Family};
use gonio::Batches;
use gonio::{Diagram, HemisphereMap, MapRef, Sampler, SphereLayout, SphereMap};

/// Radical inverse in `base`.
fn radical(mut i: u64, base: u64) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r
}

/// `n` Halton points, then the square's corners and edge midpoints.
fn points(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut u: Vec<f64> = (0..n as u64).map(|i| radical(i + 1, 2)).collect();
    let mut v: Vec<f64> = (0..n as u64).map(|i| radical(i + 1, 3)).collect();
    for (a, b) in [
        (0.0, 0.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (1.0, 1.0),
        (0.5, 0.0),
        (0.0, 0.5),
        (1.0, 0.5),
        (0.5, 1.0),
        (0.5, 0.5),
    ] {
        u.push(a);
        v.push(b);
    }
    (u, v)
}

/// Extra directions: the poles, the seam, the horizon, a non-finite one.
fn extra_dirs() -> Vec<[f64; 3]> {
    vec![
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [1.0, -1e-9, 0.3],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.6, 0.0, -0.8],
        [0.0, 0.0, 0.0],
    ]
}

fn bits32(a: &[f32]) -> Vec<u32> {
    a.iter().map(|x| x.to_bits()).collect()
}
fn bits64(a: &[f64]) -> Vec<u64> {
    a.iter().map(|x| x.to_bits()).collect()
}

/// The blob of `sampler`'s HDS map in `precision`, read back: its batches equal the writer's
/// (the sampler's `*_batch_soa` for f64, `*_batch_soa_f32` for f32) bit for bit on `n` points,
/// their directions and the extra directions; the f32 blob written again from the map read back
/// is the same bytes. Returns the blob.
fn round_trip<'m>(
    what: &str,
    map: impl Into<MapRef<'m>>,
    precision: Precision,
    frame: Frame,
    target: &Target<'_>,
    n: usize,
) -> Vec<u8> {
    let map = map.into();
    let sampler = map.sampler();
    let bytes = blob::write(map, precision, frame, target).unwrap();
    assert_eq!(bytes.len() % 64, 0);
    let back: MapTables = blob::read(&bytes).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(back.precision, precision);
    assert_eq!(back.frame, frame);
    assert_eq!(back.domain(), sampler.domain(), "{what}");
    let (u, v) = points(n);
    let m = u.len();
    match (&back.map, precision) {
        (ReadMap::F32(f), Precision::F32) => {
            let (u, v): (Vec<f32>, Vec<f32>) = (
                u.iter().map(|&x| x as f32).collect(),
                v.iter().map(|&x| x as f32).collect(),
            );
            let mut a = [vec![0f32; m], vec![0f32; m], vec![0f32; m], vec![0f32; m]];
            let mut b = a.clone();
            {
                let [x, y, z, p] = &mut a;
                sampler.sample_batch_soa_f32(&u, &v, [x, y, z], p);
                let [x, y, z, p] = &mut b;
                f.sample_soa(&u, &v, [x, y, z], p);
            }
            for k in 0..4 {
                assert_eq!(
                    bits32(&a[k]),
                    bits32(&b[k]),
                    "{what}: f32 sample column {k}"
                );
            }
            let mut dirs = [a[0].clone(), a[1].clone(), a[2].clone()];
            for d in extra_dirs() {
                for c in 0..3 {
                    dirs[c].push(d[c] as f32);
                }
            }
            let dm = dirs[0].len();
            let d = [&dirs[0][..], &dirs[1][..], &dirs[2][..]];
            let (mut pa, mut pb) = (vec![0f32; dm], vec![0f32; dm]);
            sampler.pdf_batch_soa_f32(d, &mut pa);
            f.pdf_soa(d, &mut pb);
            assert_eq!(bits32(&pa), bits32(&pb), "{what}: f32 pdf");
            let mut ia = [vec![0f32; dm], vec![0f32; dm]];
            let mut ib = ia.clone();
            {
                let [iu, iv] = &mut ia;
                sampler.invert_batch_soa_f32(d, [iu, iv]);
                let [iu, iv] = &mut ib;
                f.invert_soa_nonzero(d, [iu, iv]);
            }
            assert_eq!(bits32(&ia[0]), bits32(&ib[0]), "{what}: f32 invert u");
            assert_eq!(bits32(&ia[1]), bits32(&ib[1]), "{what}: f32 invert v");
            // The map read back writes the same bytes.
            let again = blob::write_float32(f, frame, target).unwrap();
            assert!(again == bytes, "{what}: rewritten f32 blob differs");
        }
        (ReadMap::F64(f), Precision::F64) => {
            let mut a = [vec![0f64; m], vec![0f64; m], vec![0f64; m], vec![0f64; m]];
            let mut b = a.clone();
            {
                let [x, y, z, p] = &mut a;
                sampler.sample_batch_soa(&u, &v, [x, y, z], p);
                let [x, y, z, p] = &mut b;
                f.sample_soa(&u, &v, [x, y, z], p);
            }
            for k in 0..4 {
                assert_eq!(
                    bits64(&a[k]),
                    bits64(&b[k]),
                    "{what}: f64 sample column {k}"
                );
            }
            let mut dirs = [a[0].clone(), a[1].clone(), a[2].clone()];
            for d in extra_dirs() {
                for c in 0..3 {
                    dirs[c].push(d[c]);
                }
            }
            let dm = dirs[0].len();
            let d = [&dirs[0][..], &dirs[1][..], &dirs[2][..]];
            let (mut pa, mut pb) = (vec![0f64; dm], vec![0f64; dm]);
            sampler.pdf_batch_soa(d, &mut pa);
            f.pdf_soa(d, &mut pb);
            assert_eq!(bits64(&pa), bits64(&pb), "{what}: f64 pdf");
            let mut ia = [vec![0f64; dm], vec![0f64; dm]];
            let mut ib = ia.clone();
            {
                let [iu, iv] = &mut ia;
                sampler.invert_batch_soa(d, [iu, iv]);
                // The read-back sampler's batch (invert, then NaN where the density is 0).
                let [iu, iv] = &mut ib;
                back.invert_batch_soa(d, [iu, iv]);
            }
            assert_eq!(bits64(&ia[0]), bits64(&ib[0]), "{what}: f64 invert u");
            assert_eq!(bits64(&ia[1]), bits64(&ib[1]), "{what}: f64 invert v");
        }
        _ => panic!("{what}: the blob came back in another precision"),
    }
    // The read-back sampler agrees with the writer one point at a time too (the scalar core and
    // the kernels differ only through sin/cos and atan2), and its target is the grid's.
    for k in (0..m).step_by(97) {
        let (s, w) = (back.sample([u[k], v[k]]), sampler.sample([u[k], v[k]]));
        let tol = if precision == Precision::F64 {
            1e-12
        } else {
            1e-5
        };
        // (The float32 map against the f64 map is its own contract, tests/float32_map.rs; here
        // the f64 blob's one-point path against the scalar core.)
        if precision == Precision::F64 {
            for c in 0..3 {
                assert!(
                    (s.direction[c] - w.direction[c]).abs() <= tol,
                    "{what}: {s:?} vs {w:?}"
                );
            }
            assert!(
                (s.pdf - w.pdf).abs() <= 1e-10 * w.pdf,
                "{what}: {s:?} vs {w:?}"
            );
        }
        if let Target::Grid(d) = target {
            let n = s.direction.iter().map(|c| c * c).sum::<f64>().sqrt();
            let (t, p) = gonio::sampler::spherical(s.direction.map(|c| c / n));
            let inside = back.domain() == gonio::Domain::Sphere || s.direction[2] >= 0.0;
            let want = if inside {
                d.interpolate(t, p) / d.integral()
            } else {
                0.0
            };
            let got = back.target_pdf(s.direction);
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "{what}: target {got} vs {want}"
            );
        }
    }
    bytes
}

fn both<'m>(what: &str, map: impl Into<MapRef<'m>>, frame: Frame, target: &Target<'_>, n: usize) {
    let map = map.into();
    round_trip(
        &format!("{what} f32"),
        map,
        Precision::F32,
        frame,
        target,
        n,
    );
    round_trip(
        &format!("{what} f64"),
        map,
        Precision::F64,
        frame,
        target,
        n,
    );
}

#[test]
fn generated_diagrams_round_trip_bit_for_bit_on_every_layout() {
    let families = [
        Family::UniformRandom,
        Family::Spiky,
        Family::Lobes,
        Family::Rotational,
        Family::ZeroHeavy,
    ];
    for (k, fam) in families.into_iter().enumerate() {
        let (n, m) = (3 + 7 * k, 1 + 5 * k);
        let d = random_hemisphere(fam, n, m, k % 2 == 1, 40 + k as u64);
        let h = HemisphereMap::new(&d).unwrap();
        both(
            &format!("{} hemisphere", fam.name()),
            &h,
            Frame::Generic,
            &Target::Grid(&d),
            4000,
        );
        // The same values on the whole sphere (θ to 180°), both layouts.
        let theta: Vec<f64> = d.theta().iter().map(|t| t * 2.0).collect();
        let sd = Diagram::new(theta, d.phi().to_vec(), d.values().to_vec()).unwrap();
        for layout in [SphereLayout::Split, SphereLayout::Lambert] {
            let s = SphereMap::with_layout(&sd, layout).unwrap();
            both(
                &format!("{} sphere {layout:?}", fam.name()),
                &s,
                Frame::Generic,
                &Target::Grid(&sd),
                4000,
            );
        }
    }
    // A split sphere with one map only (nothing below the horizon) and the built-in example.
    let up = random_hemisphere(Family::Lobes, 10, 8, false, 7);
    let s = SphereMap::new(&up).unwrap();
    both(
        "upper-only split sphere",
        &s,
        Frame::Generic,
        &Target::None,
        2000,
    );
    let ex = gonio::synthetic::example_luminaire();
    let s = SphereMap::new(&ex).unwrap();
    both(
        "example",
        &s,
        Frame::Photometric,
        &Target::Grid(&ex),
        20_000,
    );
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn every_corpus_file_round_trips_bit_for_bit() {
    use gonio::photometry::{read, DirTiltResolver, FileFormat};
    let dir = corpus::built_corpus_dir();
    let files = corpus::corpus_files(&dir);
    assert!(files.len() >= 30, "{}", files.len());
    for f in files {
        let bytes = std::fs::read(&f).unwrap();
        let fmt = FileFormat::from_path_extension(&f).unwrap();
        let p = read(&bytes, fmt, &DirTiltResolver::new(f.parent().unwrap())).unwrap();
        let d = p.to_diagram().unwrap();
        let s = SphereMap::new(&d).unwrap();
        both(
            &f.display().to_string(),
            &s,
            Frame::Photometric,
            &Target::Grid(&d),
            3000,
        );
    }
}

/// A small generated sky (a sun across the seam, a bright pixel at a pole) round-trips with its
/// image target, in both precisions and both lookups.
#[test]
fn environment_maps_round_trip_with_their_image() {
    let (w, h) = (24usize, 12usize);
    let mut rgb = vec![0.0f32; w * h * 3];
    for r in 0..h {
        for c in 0..w {
            let v = 0.1 + 0.02 * r as f32 + if c == 0 || c == w - 1 { 30.0 } else { 0.0 };
            rgb[3 * (r * w + c)..3 * (r * w + c) + 3].copy_from_slice(&[v, 0.5 * v, 0.25 * v]);
        }
    }
    rgb[0] = 500.0;
    for lookup in [
        gonio::envmap::Lookup::Nearest,
        gonio::envmap::Lookup::Bilinear,
    ] {
        let img = Image::new(w, h, rgb.clone()).unwrap();
        let opts = gonio::envmap::EnvOptions {
            lookup,
            ..Default::default()
        };
        let env = EnvironmentMap::with_options(img, opts).unwrap();
        let t = Target::Image {
            width: w,
            height: h,
            rgb: &rgb,
            lookup,
        };
        for p in [Precision::F32, Precision::F64] {
            let bytes = round_trip(
                &format!("sky {lookup:?}"),
                env.map(),
                p,
                Frame::EnvironmentMap,
                &t,
                3000,
            );
            match blob::read(&bytes).unwrap().target {
                blob::TargetTables::Image {
                    width,
                    height,
                    rgb: back,
                    lookup: l,
                } => {
                    assert_eq!((width, height, l), (w, h, lookup));
                    assert_eq!(bits32(&back), bits32(&rgb));
                }
                other => panic!("{other:?}"),
            }
        }
    }
    // An image that does not fit its size is refused when writing.
    let img = Image::new(w, h, rgb.clone()).unwrap();
    let env = EnvironmentMap::new(img).unwrap();
    let bad = Target::Image {
        width: w,
        height: h + 1,
        rgb: &rgb,
        lookup: Default::default(),
    };
    assert!(matches!(
        blob::write(
            MapRef::Sphere(env.map()),
            Precision::F32,
            Frame::EnvironmentMap,
            &bad
        ),
        Err(TablesError::Target(_))
    ));
}

#[test]
#[cfg_attr(
    not(gonio_envmaps),
    ignore = "shared environment maps not found (set GONIO_ENVMAPS)"
)]
fn the_shared_environment_maps_round_trip() {
    for f in corpus::built_envmaps() {
        let img = Image::read(&f).unwrap();
        let (w, h) = (img.width(), img.height());
        let rgb = img.rgb().to_vec();
        let env = EnvironmentMap::new(img).unwrap();
        let t = Target::Image {
            width: w,
            height: h,
            rgb: &rgb,
            lookup: Default::default(),
        };
        both(
            &f.display().to_string(),
            env.map(),
            Frame::EnvironmentMap,
            &t,
            20_000,
        );
    }
}

/// A blob that reads must sample, evaluate and invert without panicking, with unit directions and
/// finite densities ≥ 0 (the reader's checks are the kernels' preconditions).
fn exercise(t: &MapTables) {
    let (u, v) = points(64);
    for k in 0..u.len() {
        blob_case::assert_sane_sample(t, [u[k], v[k]]);
    }
    for d in extra_dirs() {
        blob_case::assert_sane_direction(t, d);
    }
}

fn small_blobs() -> Vec<(String, Vec<u8>)> {
    let d = random_hemisphere(Family::Lobes, 5, 4, true, 3);
    let h = HemisphereMap::new(&d).unwrap();
    let theta: Vec<f64> = d.theta().iter().map(|t| t * 2.0).collect();
    let sd = Diagram::new(theta, d.phi().to_vec(), d.values().to_vec()).unwrap();
    let s = SphereMap::new(&sd).unwrap();
    let mut out = Vec::new();
    for p in [Precision::F32, Precision::F64] {
        out.push((
            format!("hemisphere {}", p.name()),
            blob::write(MapRef::Hemisphere(&h), p, Frame::Generic, &Target::Grid(&d)).unwrap(),
        ));
        out.push((
            format!("split sphere {}", p.name()),
            blob::write(MapRef::Sphere(&s), p, Frame::Generic, &Target::None).unwrap(),
        ));
    }
    out
}

#[test]
fn every_flipped_byte_is_refused_by_the_checksum() {
    for (what, b) in small_blobs() {
        for k in 0..b.len() {
            let mut c = b.clone();
            c[k] ^= 0x5a;
            match blob::read(&c) {
                Err(_) => {}
                Ok(_) => panic!("{what}: byte {k} flipped was accepted"),
            }
        }
    }
}

#[test]
fn flipped_bytes_with_a_valid_checksum_never_panic() {
    // The field and content checks, reached by resealing: every byte of the header, the
    // directory and the tables flipped in turn (three patterns), then sampled if accepted.
    let mut accepted = 0;
    let mut refused = 0;
    for (what, b) in small_blobs() {
        for k in 0..b.len() {
            if (blob::CHECKSUM_OFFSET..blob::CHECKSUM_OFFSET + 8).contains(&k) {
                continue;
            }
            for pat in [0x01u8, 0x80, 0xff] {
                let mut c = b.clone();
                c[k] ^= pat;
                blob_case::reseal(&mut c);
                match std::panic::catch_unwind(|| blob::read(&c)) {
                    Err(_) => panic!("{what}: byte {k} ^ {pat:#x}: the reader panicked"),
                    Ok(Err(_)) => refused += 1,
                    Ok(Ok(t)) => {
                        accepted += 1;
                        if std::panic::catch_unwind(|| exercise(&t)).is_err() {
                            panic!("{what}: byte {k} ^ {pat:#x}: accepted, then sampling panicked");
                        }
                    }
                }
            }
        }
    }
    println!("resealed flips: {refused} refused, {accepted} accepted and sampled without panic");
    assert!(
        refused > 0 && accepted > 0,
        "{refused} refused, {accepted} accepted"
    );
}

#[test]
fn every_truncation_is_refused() {
    for (what, b) in small_blobs() {
        for len in 0..b.len() {
            match blob::read(&b[..len]) {
                Err(TablesError::Truncated { .. }) => {}
                other => panic!("{what}: {len} of {} bytes gave {other:?}", b.len()),
            }
        }
        // And one byte more is refused too (the header states the size).
        let mut longer = b.clone();
        longer.push(0);
        assert!(blob::read(&longer).is_err(), "{what}");
    }
}

#[test]
fn forged_headers_with_huge_counts_are_refused_before_allocating() {
    let (_, b) = small_blobs().remove(0);
    // Slot 0's m, n, K and guide lengths, and the table count, set to huge values, resealed.
    for (at, v) in [
        (96usize, u32::MAX),
        (100, u32::MAX),
        (104, u32::MAX),
        (108, u32::MAX),
        (112, u32::MAX),
        (96, 1 << 21),
        (48, u32::MAX),
        (88, u32::MAX),
        (92, u32::MAX),
    ] {
        let mut c = b.clone();
        c[at..at + 4].copy_from_slice(&v.to_le_bytes());
        blob_case::reseal(&mut c);
        let e = blob::read(&c).expect_err("a forged count");
        let msg = e.to_string();
        assert!(msg.starts_with("table blob: "), "{msg}");
    }
    // A directory entry pointing past the end, and one misaligned.
    for (field, v) in [(8usize, u64::MAX - 7), (8, 65), (16, u64::MAX / 2)] {
        let mut c = b.clone();
        let at = blob::HEADER_BYTES + field;
        c[at..at + 8].copy_from_slice(&v.to_le_bytes());
        blob_case::reseal(&mut c);
        assert!(
            matches!(blob::read(&c), Err(TablesError::Entry { .. })),
            "{field} {v}"
        );
    }
    // κ far from 1 (the fuzz target's first find: a tiny κ overflowed the wedge equation into a
    // NaN direction), and a map whose azimuths do not end at 2π.
    for (at, v) in [(96usize + 40, 1e-40f64), (96 + 40, 3.0)] {
        let mut c = b.clone();
        c[at..at + 8].copy_from_slice(&v.to_le_bytes());
        blob_case::reseal(&mut c);
        assert!(
            matches!(
                blob::read(&c),
                Err(TablesError::Field {
                    field: "map.kappa",
                    ..
                })
            ),
            "{v}"
        );
    }
    // The wrong magic and version are named.
    let mut c = b.clone();
    c[0] = b'X';
    assert_eq!(blob::read(&c).unwrap_err(), TablesError::Magic);
    let mut c = b.clone();
    c[8] = 2;
    blob_case::reseal(&mut c);
    assert_eq!(
        blob::read(&c).unwrap_err(),
        TablesError::Version { found: 2 }
    );
}
