//! The structure-of-arrays batch calls of the `Sampler` trait (`sample_batch_soa`,
//! `pdf_batch_soa`, `invert_batch_soa` and their `_f32` twins), reached through `&dyn Sampler`:
//! the defaults equal the scalar methods bit for bit (f64) and the scalar methods widened and
//! rounded once (f32); the HDS maps' overrides equal `SoaSampler` bit for bit (f64) and their
//! float32 map's calls (`Float32Map`, f32); the parallel
//! helpers equal the serial calls; unequal slices panic.

// Columns of the structure-of-arrays outputs are indexed by component on purpose.
#![allow(clippy::needless_range_loop)]

use gonio::batch::Soa as Job;
use gonio::mapping::batch::SoaSampler;
use gonio::mapping::Float32Map;
use gonio::synthetic::{example_luminaire, random_hemisphere, Family};
use gonio::Batches;
use gonio::{Diagram, Domain, HemisphereMap, Method, Sampler, SphereLayout, SphereMap};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// 700 points: two full stack chunks of 256 and a partial one.
const N: usize = 700;

fn points(seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut r = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut u: Vec<f64> = (0..N).map(|_| r.gen::<f64>()).collect();
    let mut v: Vec<f64> = (0..N).map(|_| r.gen::<f64>()).collect();
    // The corners and edges of the square.
    for (k, (a, b)) in [(0.0, 0.0), (1.0, 1.0), (0.0, 1.0), (1.0, 0.5), (0.5, 0.0)]
        .into_iter()
        .enumerate()
    {
        u[k] = a;
        v[k] = b;
    }
    (u, v)
}

/// Unit directions over the whole sphere (both hemispheres), the poles and the horizon among them.
fn directions(seed: u64) -> [Vec<f64>; 3] {
    let mut r = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut d: [Vec<f64>; 3] = [vec![], vec![], vec![]];
    for k in 0..N {
        let p = match k {
            0 => [0.0, 0.0, 1.0],
            1 => [0.0, 0.0, -1.0],
            2 => [1.0, 0.0, 0.0],
            3 => [0.0, -1.0, 0.0],
            _ => {
                let z: f64 = r.gen_range(-1.0..=1.0);
                let phi: f64 = r.gen_range(0.0..std::f64::consts::TAU);
                let s = (1.0 - z * z).max(0.0).sqrt();
                [s * phi.cos(), s * phi.sin(), z]
            }
        };
        for c in 0..3 {
            d[c].push(p[c]);
        }
    }
    d
}

fn f32s(v: &[f64]) -> Vec<f32> {
    v.iter().map(|&x| x as f32).collect()
}

fn bits64(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn bits32(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// The six SoA calls of one sampler through `&dyn Sampler`, f64 then f32.
struct Soa {
    sample: [Vec<f64>; 4],
    pdf: Vec<f64>,
    inv: [Vec<f64>; 2],
    sample32: [Vec<f32>; 4],
    pdf32: Vec<f32>,
    inv32: [Vec<f32>; 2],
}

fn soa_of(s: &dyn Sampler, u: &[f64], v: &[f64], d: &[Vec<f64>; 3]) -> Soa {
    let n = u.len();
    let mut o: [Vec<f64>; 4] = std::array::from_fn(|_| vec![0.0; n]);
    let [x, y, z, p] = &mut o;
    s.sample_batch_soa(u, v, [x, y, z], p);
    let dr = [&d[0][..], &d[1][..], &d[2][..]];
    let mut pdf = vec![0.0; n];
    s.pdf_batch_soa(dr, &mut pdf);
    let mut inv: [Vec<f64>; 2] = std::array::from_fn(|_| vec![0.0; n]);
    let [iu, iv] = &mut inv;
    s.invert_batch_soa(dr, [iu, iv]);

    let (u32_, v32) = (f32s(u), f32s(v));
    let d32 = [f32s(&d[0]), f32s(&d[1]), f32s(&d[2])];
    let d32r = [&d32[0][..], &d32[1][..], &d32[2][..]];
    let mut o32: [Vec<f32>; 4] = std::array::from_fn(|_| vec![0.0; n]);
    let [x, y, z, p] = &mut o32;
    s.sample_batch_soa_f32(&u32_, &v32, [x, y, z], p);
    let mut pdf32 = vec![0.0f32; n];
    s.pdf_batch_soa_f32(d32r, &mut pdf32);
    let mut inv32: [Vec<f32>; 2] = std::array::from_fn(|_| vec![0.0; n]);
    let [iu, iv] = &mut inv32;
    s.invert_batch_soa_f32(d32r, [iu, iv]);
    Soa {
        sample: o,
        pdf,
        inv,
        sample32: o32,
        pdf32,
        inv32,
    }
}

/// The f32 rule of the defaults: widen, scale to unit length in f64 (one division), as
/// `gonio::batch` documents.
fn widen_unit(d: [f32; 3]) -> [f64; 3] {
    let w = d.map(f64::from);
    let l = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    let s = if l > 0.0 && l.is_finite() {
        1.0 / l
    } else {
        1.0
    };
    w.map(|c| c * s)
}

fn baselines() -> Vec<(String, gonio::Built<'static>)> {
    let hemi = random_hemisphere(Family::ZeroHeavy, 9, 12, true, 4);
    let lum = example_luminaire();
    let mut v = Vec::new();
    for m in [
        Method::PiecewiseConstant,
        Method::Bilinear,
        Method::Uniform,
        Method::Rejection,
    ] {
        v.push((
            format!("{m} hemisphere"),
            m.build(&hemi, Domain::Hemisphere).unwrap(),
        ));
        v.push((
            format!("{m} sphere"),
            m.build(&lum, Domain::Sphere).unwrap(),
        ));
    }
    v
}

#[test]
fn defaults_equal_the_scalar_methods_bit_for_bit() {
    let (u, v) = points(1);
    let d = directions(2);
    for (name, s) in baselines() {
        let got = soa_of(s.as_ref(), &u, &v, &d);
        for k in 0..N {
            let e = s.sample([u[k], v[k]]);
            let want = [e.direction[0], e.direction[1], e.direction[2], e.pdf];
            for c in 0..4 {
                assert_eq!(
                    got.sample[c][k].to_bits(),
                    want[c].to_bits(),
                    "{name} sample #{k}"
                );
            }
            let dk = [d[0][k], d[1][k], d[2][k]];
            assert_eq!(got.pdf[k].to_bits(), s.pdf(dk).to_bits(), "{name} pdf #{k}");
            let inv = s.invert(dk).unwrap_or([f64::NAN; 2]);
            assert_eq!(
                bits64(&[got.inv[0][k], got.inv[1][k]]),
                bits64(&inv),
                "{name} inv #{k}"
            );

            // f32: the scalar method at the widened input, rounded once.
            let e = s.sample([f64::from(u[k] as f32), f64::from(v[k] as f32)]);
            let want = [e.direction[0], e.direction[1], e.direction[2], e.pdf].map(|x| x as f32);
            for c in 0..4 {
                assert_eq!(
                    got.sample32[c][k].to_bits(),
                    want[c].to_bits(),
                    "{name} sample32 #{k}"
                );
            }
            let w = widen_unit(dk.map(|x| x as f32));
            assert_eq!(
                got.pdf32[k].to_bits(),
                (s.pdf(w) as f32).to_bits(),
                "{name} pdf32 #{k}"
            );
            let inv = s.invert(w).unwrap_or([f64::NAN; 2]).map(|x| x as f32);
            assert_eq!(
                bits32(&[got.inv32[0][k], got.inv32[1][k]]),
                bits32(&inv),
                "{name} inv32 #{k}"
            );
        }
    }
}

/// `SoaSampler`'s six calls and the zero-density rule of the trait's inverse.
fn check_hds<S: SoaSampler>(name: &str, map: &S, f32map: &Float32Map, dynamic: &dyn Sampler) {
    let (u, v) = points(3);
    let d = directions(4);
    let got = soa_of(dynamic, &u, &v, &d);
    let n = N;
    let dr = [&d[0][..], &d[1][..], &d[2][..]];

    let mut o: [Vec<f64>; 4] = std::array::from_fn(|_| vec![0.0; n]);
    let [x, y, z, p] = &mut o;
    map.sample_soa(&u, &v, [x, y, z], p);
    for c in 0..4 {
        assert_eq!(
            bits64(&got.sample[c]),
            bits64(&o[c]),
            "{name} sample col {c}"
        );
    }
    let mut pdf = vec![0.0; n];
    map.pdf_soa(dr, &mut pdf);
    assert_eq!(bits64(&got.pdf), bits64(&pdf), "{name} pdf");
    let mut inv: [Vec<f64>; 2] = std::array::from_fn(|_| vec![0.0; n]);
    let [iu, iv] = &mut inv;
    map.invert_soa(dr, [iu, iv]);
    let mut zeros = 0;
    for k in 0..n {
        let want = if pdf[k] == 0.0 {
            zeros += 1;
            [f64::NAN; 2]
        } else {
            [inv[0][k], inv[1][k]]
        };
        assert_eq!(
            bits64(&[got.inv[0][k], got.inv[1][k]]),
            bits64(&want),
            "{name} inv #{k}"
        );
        // Where both give a point, the scalar inverse agrees that there is one.
        assert_eq!(
            got.inv[0][k].is_nan(),
            dynamic.invert([d[0][k], d[1][k], d[2][k]]).is_err()
        );
    }
    if dynamic.domain() == Domain::Hemisphere {
        assert!(
            zeros >= N / 3,
            "{name}: the lower hemisphere has density 0 ({zeros})"
        );
    }

    let (u32_, v32) = (f32s(&u), f32s(&v));
    let d32 = [f32s(&d[0]), f32s(&d[1]), f32s(&d[2])];
    let d32r = [&d32[0][..], &d32[1][..], &d32[2][..]];
    let mut o: [Vec<f32>; 4] = std::array::from_fn(|_| vec![0.0; n]);
    let [x, y, z, p] = &mut o;
    f32map.sample_soa(&u32_, &v32, [x, y, z], p);
    for c in 0..4 {
        assert_eq!(
            bits32(&got.sample32[c]),
            bits32(&o[c]),
            "{name} sample32 col {c}"
        );
    }
    let mut pdf = vec![0.0f32; n];
    f32map.pdf_soa(d32r, &mut pdf);
    assert_eq!(bits32(&got.pdf32), bits32(&pdf), "{name} pdf32");
    let mut inv: [Vec<f32>; 2] = std::array::from_fn(|_| vec![0.0; n]);
    let [iu, iv] = &mut inv;
    f32map.invert_soa(d32r, [iu, iv]);
    for k in 0..n {
        let want = if pdf[k] == 0.0 {
            [f32::NAN; 2]
        } else {
            [inv[0][k], inv[1][k]]
        };
        assert_eq!(
            bits32(&[got.inv32[0][k], got.inv32[1][k]]),
            bits32(&want),
            "{name} inv32 #{k}"
        );
    }
}

#[test]
fn hds_overrides_equal_soa_sampler_bit_for_bit() {
    // Zero-heavy: many directions of density 0 inside the hemisphere too.
    let hemi = random_hemisphere(Family::ZeroHeavy, 9, 12, true, 4);
    let m = HemisphereMap::new(&hemi).unwrap();
    check_hds("hemisphere zero-heavy", &m, m.float32().unwrap(), &m);
    let lobes = random_hemisphere(Family::Lobes, 19, 36, false, 1);
    let m = HemisphereMap::new(&lobes).unwrap();
    check_hds("hemisphere lobes", &m, m.float32().unwrap(), &m);
    // The factory's box reaches the same override.
    let b = Method::Hds.build(&lobes, Domain::Hemisphere).unwrap();
    check_hds(
        "hemisphere lobes (boxed)",
        &m,
        m.float32().unwrap(),
        b.as_ref(),
    );
    let lum = example_luminaire();
    let m = SphereMap::new(&lum).unwrap();
    check_hds("sphere split", &m, m.float32().unwrap(), &m);
    let m = SphereMap::with_layout(&lum, SphereLayout::Lambert).unwrap();
    check_hds("sphere lambert", &m, m.float32().unwrap(), &m);
    // A sphere whose upper half emits nothing (one side's map only).
    let down = Diagram::from_degrees(&[0.0, 90.0, 180.0], &[0.0], &[vec![0.0, 0.0, 2.0]]).unwrap();
    let m = SphereMap::new(&down).unwrap();
    check_hds("sphere lower half only", &m, m.float32().unwrap(), &m);
}

#[test]
fn parallel_helpers_equal_the_serial_calls() {
    let lum = example_luminaire();
    let (u, v) = points(5);
    let d = directions(6);
    let dr = [&d[0][..], &d[1][..], &d[2][..]];
    // Long enough for several rayon tasks of PAR_CHUNK points.
    let rep = 3 * gonio::batch::PAR_CHUNK / N + 1;
    let u: Vec<f64> = u.iter().cycle().take(rep * N).copied().collect();
    let v: Vec<f64> = v.iter().cycle().take(rep * N).copied().collect();
    for s in [
        Method::Hds.build(&lum, Domain::Sphere).unwrap(),
        Method::Bilinear.build(&lum, Domain::Sphere).unwrap(),
    ] {
        let s = s.as_ref();
        let n = u.len();
        let run = |par: bool| {
            let mut o: [Vec<f64>; 4] = std::array::from_fn(|_| vec![0.0; n]);
            let [x, y, z, p] = &mut o;
            if par {
                gonio::sampler::batch_par(
                    s,
                    Job::Sample {
                        u: &u,
                        v: &v,
                        dir: [x, y, z],
                        pdf: p,
                    }
                    .into(),
                );
            } else {
                s.sample_batch_soa(&u, &v, [x, y, z], p);
            }
            let mut pdf = vec![0.0; N];
            let mut inv: [Vec<f64>; 2] = std::array::from_fn(|_| vec![0.0; N]);
            let [iu, iv] = &mut inv;
            if par {
                gonio::sampler::batch_par(
                    s,
                    Job::Pdf {
                        dir: dr,
                        pdf: &mut pdf,
                    }
                    .into(),
                );
                gonio::sampler::batch_par(
                    s,
                    Job::Invert {
                        dir: dr,
                        uv: [iu, iv],
                    }
                    .into(),
                );
            } else {
                s.pdf_batch_soa(dr, &mut pdf);
                s.invert_batch_soa(dr, [iu, iv]);
            }
            let mut all: Vec<u64> = o.iter().flat_map(|c| bits64(c)).collect();
            all.extend(bits64(&pdf));
            all.extend(inv.iter().flat_map(|c| bits64(c)));
            all
        };
        assert_eq!(run(true), run(false), "{}", s.name());
    }
}

#[test]
fn empty_slices_are_fine() {
    let lum = example_luminaire();
    for s in [
        Method::Hds.build(&lum, Domain::Sphere).unwrap(),
        Method::Uniform.build(&lum, Domain::Sphere).unwrap(),
    ] {
        s.sample_batch_soa(&[], &[], [&mut [], &mut [], &mut []], &mut []);
        s.pdf_batch_soa_f32([&[], &[], &[]], &mut []);
        s.invert_batch_soa_f32([&[], &[], &[]], [&mut [], &mut []]);
    }
}

#[test]
#[should_panic(expected = "slices differ in length")]
fn unequal_lengths_panic_in_the_default() {
    let s = Method::Uniform
        .build(&example_luminaire(), Domain::Sphere)
        .unwrap();
    let mut p = [0.0; 2];
    s.pdf_batch_soa([&[0.0; 2], &[0.0; 2], &[1.0; 3]], &mut p);
}

#[test]
#[should_panic(expected = "slices differ in length")]
fn unequal_lengths_panic_in_the_hds_override() {
    let s = Method::Hds
        .build(&example_luminaire(), Domain::Sphere)
        .unwrap();
    let (mut u, mut v) = ([0.0f32; 2], [0.0f32; 1]);
    s.invert_batch_soa_f32([&[0.0; 2], &[0.0; 2], &[1.0; 2]], [&mut u, &mut v]);
}

#[test]
fn the_environment_map_forwards_to_its_sphere_map() {
    use gonio::envmap::EnvironmentMap;
    use gonio::image::Image;
    let (w, h) = (16, 8);
    let rgb: Vec<f32> = (0..w * h * 3)
        .map(|i| 0.1 + ((i * 37) % 11) as f32)
        .collect();
    let env = EnvironmentMap::new(Image::new(w, h, rgb).unwrap()).unwrap();
    let map = env.map();
    check_hds("environment map", map, map.float32().unwrap(), &env);
}
