//! Environment maps on generated images: the frame, the uniform sky, single bright pixels at the
//! pole, on the seam and at the horizon, continuity, the peers, MIS compensation.

use super::*;
use crate::check::Status;
use crate::check::{run_battery, BatteryOptions};
use crate::sampler::spherical;
use crate::sampler::Batches;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn random_image(w: usize, h: usize, seed: u64) -> Image {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let rgb = (0..w * h * 3)
        .map(|_| rng.gen::<f32>() * 2.0 + 0.05)
        .collect();
    Image::new(w, h, rgb).unwrap()
}

fn one_bright(w: usize, h: usize, x: usize, y: usize, background: f32) -> Image {
    let mut img = Image::constant(w, h, [background; 3]).unwrap();
    img.set_pixel(x, y, [1000.0, 500.0, 250.0]);
    img
}

fn random_dirs(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let z: f64 = rng.gen_range(-1.0..1.0);
            let p: f64 = rng.gen_range(0.0..TAU);
            let r = (1.0 - z * z).sqrt();
            [r * p.cos(), r * p.sin(), z]
        })
        .collect()
}

#[test]
fn the_frame_centre_column_is_plus_x_top_row_is_zenith() {
    assert_eq!(image_direction(0.5, 0.5), [1.0, 0.0, 6.123233995736766e-17]);
    let d = image_direction(0.25, 0.5);
    assert!((d[1] - 1.0).abs() < 1e-15 && d[0].abs() < 1e-15);
    let d = image_direction(0.75, 0.5);
    assert!((d[1] + 1.0).abs() < 1e-15);
    assert_eq!(image_direction(0.3, 0.0)[2], 1.0);
    assert_eq!(image_direction(0.3, 1.0)[2], -1.0);
    // Each pixel centre's direction reads that pixel back (nearest), for an odd and an even width.
    for (w, h) in [(16, 8), (15, 7)] {
        let mut img = Image::constant(w, h, [0.0; 3]).unwrap();
        for y in 0..h {
            for x in 0..w {
                img.set_pixel(x, y, [(x + w * y) as f32 + 1.0, 0.0, 0.0]);
            }
        }
        let env = EnvironmentMap::new(img).unwrap();
        for y in 0..h {
            for x in 0..w {
                let d = image_direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                assert_eq!(env.eval(d)[0], (x + w * y) as f32 + 1.0, "({x}, {y})");
                assert_eq!(
                    env.eval_with(d, Lookup::Bilinear)[0],
                    (x + w * y) as f32 + 1.0
                );
            }
        }
        // The diagram's meridians are the column centres, sorted by φ, each with its column.
        for (i, &phi) in env.diagram().phi().iter().enumerate() {
            let c = ((phi_to_s(phi) * w as f64) as usize).min(w - 1);
            assert!((column_phi(c, w) - phi).abs() < 1e-12);
            assert_eq!(
                env.diagram().value(i, 1),
                f64::from(luminance(env.image().pixel(c, 0)))
            );
        }
    }
}

#[test]
fn a_constant_sky_is_exactly_uniform() {
    let env = EnvironmentMap::new(Image::constant(20, 10, [0.5, 0.5, 0.5]).unwrap()).unwrap();
    let uniform = 1.0 / (4.0 * PI);
    let mut seq = Xoshiro256PlusPlus::seed_from_u64(7);
    for _ in 0..2000 {
        let s = env.sample([seq.gen(), seq.gen()]);
        assert!((s.pdf - uniform).abs() < 1e-12 * uniform, "{}", s.pdf);
        assert_eq!(s.radiance, [0.5; 3]);
    }
    for d in random_dirs(2000, 3) {
        assert!((env.pdf(d) - uniform).abs() < 1e-12 * uniform);
    }
    let (lo, hi) = env.map().ratio_bound();
    assert!(
        (lo - 1.0).abs() < 1e-9 && (hi - 1.0).abs() < 1e-9,
        "{lo} {hi}"
    );
    // The power is the luminance times 4π.
    assert!((env.power() - 0.5 * 4.0 * PI).abs() < 1e-9);
}

#[test]
fn sample_pdf_invert_agree_on_a_random_map() {
    let env = EnvironmentMap::new(random_image(24, 12, 11)).unwrap();
    let mut seq = Xoshiro256PlusPlus::seed_from_u64(5);
    for _ in 0..5000 {
        let u = [seq.gen(), seq.gen()];
        let s = env.sample(u);
        assert!((env.pdf(s.direction) - s.pdf).abs() <= 1e-10 * s.pdf);
        let back = env.invert(s.direction).unwrap();
        assert!(
            (back[0] - u[0]).abs() < 1e-8 && (back[1] - u[1]).abs() < 1e-8,
            "{u:?} {back:?}"
        );
        assert_eq!(s.radiance, env.eval(s.direction));
    }
}

#[test]
fn the_density_is_continuous_at_the_seam_and_the_poles() {
    for lookup in [Lookup::Nearest, Lookup::Bilinear] {
        let env = EnvironmentMap::with_options(
            random_image(16, 8, 2),
            EnvOptions {
                lookup,
                ..EnvOptions::default()
            },
        )
        .unwrap();
        // Across the seam (the image's left and right edges, φ = π).
        for t in [0.1, 0.37, 0.5, 0.81] {
            let a = env.pdf(image_direction(1e-9, t));
            let b = env.pdf(image_direction(1.0 - 1e-9, t));
            assert!((a - b).abs() < 1e-6 * a, "seam at t = {t}: {a} vs {b}");
            let (ra, rb) = (
                env.eval_with(image_direction(1e-9, t), Lookup::Bilinear),
                env.eval_with(image_direction(1.0 - 1e-9, t), Lookup::Bilinear),
            );
            assert!((ra[0] - rb[0]).abs() < 1e-5, "{ra:?} {rb:?}");
        }
        // Near each pole the density and the bilinear radiance hardly depend on φ.
        for t in [1e-9, 1.0 - 1e-9] {
            let p: Vec<f64> = (0..16)
                .map(|k| env.pdf(image_direction(k as f64 / 16.0, t)))
                .collect();
            let (lo, hi) = p
                .iter()
                .fold((f64::MAX, 0f64), |a, &x| (a.0.min(x), a.1.max(x)));
            assert!(hi - lo < 1e-6 * hi, "pole t = {t}: {lo}..{hi}");
            let r: Vec<f32> = (0..16)
                .map(|k| env.eval_with(image_direction(k as f64 / 16.0, t), Lookup::Bilinear)[1])
                .collect();
            let (lo, hi) = r
                .iter()
                .fold((f32::MAX, 0f32), |a, &x| (a.0.min(x), a.1.max(x)));
            assert!(hi - lo < 1e-4 * hi, "pole t = {t}: {lo}..{hi}");
        }
    }
}

#[test]
fn bilinear_radiance_is_the_diagrams_interpolant() {
    let env = EnvironmentMap::new(random_image(12, 6, 9)).unwrap();
    for d in random_dirs(3000, 4) {
        let (t, p) = spherical(d);
        let y = f64::from(luminance(env.eval_with(d, Lookup::Bilinear)));
        let want = env.diagram().interpolate(t, p);
        assert!(
            (y - want).abs() < 1e-5 * want.max(1.0),
            "{d:?}: {y} vs {want}"
        );
    }
}

#[test]
fn single_bright_pixels_pass_the_check_battery() {
    // At the pole (top row), on the seam (first column), at the horizon (the row below
    // the equator), and anywhere: the map passes the whole battery (chi-square, round trip, pdf
    // consistency, normalisation, ratio, flux), one fixed seed each.
    let (w, h) = (32, 16);
    let cases = [("pole", 5, 0), ("seam left", 0, 6), ("horizon", 11, h / 2)];
    for (k, (name, x, y)) in cases.into_iter().enumerate() {
        let env = EnvironmentMap::new(one_bright(w, h, x, y, 0.01)).unwrap();
        // Most of the light is in the bright pixel, and most samples land on it.
        let d = image_direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
        assert!(env.pdf(d) > 100.0 * env.pdf([0.0, 0.0, if y < h / 2 { -1.0 } else { 1.0 }]));
        let report = run_battery(&env, &BatteryOptions::quick().with_seed(100 + k as u64));
        assert!(report.passed, "{name}: {report:#?}");
    }
}

#[test]
fn an_all_black_map_is_a_clear_error() {
    let black = Image::constant(8, 4, [0.0; 3]).unwrap();
    let e = EnvironmentMap::new(black).unwrap_err();
    assert!(matches!(e, EnvMapError::Black { .. }), "{e}");
    assert!(e.to_string().contains("black"));
    // A channel that is zero everywhere, and custom weights that are.
    let red = Image::constant(8, 4, [1.0, 0.0, 0.0]).unwrap();
    let opts = EnvOptions {
        weight: Weight::Channel(1),
        ..EnvOptions::default()
    };
    assert!(matches!(
        EnvironmentMap::with_options(red.clone(), opts),
        Err(EnvMapError::Black { .. })
    ));
    let opts = EnvOptions {
        weight: Weight::Channel(3),
        ..EnvOptions::default()
    };
    assert!(matches!(
        EnvironmentMap::with_options(red.clone(), opts),
        Err(EnvMapError::BadOption(_))
    ));
    let opts = EnvOptions {
        weight: Weight::Custom(vec![1.0; 31]),
        ..EnvOptions::default()
    };
    assert!(matches!(
        EnvironmentMap::with_options(red, opts),
        Err(EnvMapError::BadOption(_))
    ));
}

#[test]
fn negative_pixels_are_weighted_zero_with_a_warning() {
    let mut img = Image::constant(8, 4, [1.0; 3]).unwrap();
    img.set_pixel(2, 2, [-1.0, -1.0, -1.0]);
    let env = EnvironmentMap::new(img).unwrap();
    assert_eq!(env.warnings().len(), 1);
    assert_eq!(env.eval(image_direction(2.5 / 8.0, 2.5 / 4.0)), [-1.0; 3]);
}

#[test]
fn the_peers_keep_the_contract() {
    let env = EnvironmentMap::new(random_image(32, 16, 21)).unwrap();
    let ll = env.latlong_peer().unwrap();
    let pbrt = env.pbrt_v4_peer(Some(24)).unwrap();
    for (k, s) in [&ll as &dyn Sampler, &pbrt].into_iter().enumerate() {
        let mut seq = Xoshiro256PlusPlus::seed_from_u64(40 + k as u64);
        for _ in 0..3000 {
            let u = [seq.gen(), seq.gen()];
            let smp = s.sample(u);
            assert!(
                (s.pdf(smp.direction) - smp.pdf).abs() <= 1e-9 * smp.pdf,
                "{}",
                s.name()
            );
            let back = s.invert(smp.direction).unwrap();
            assert!(
                (back[0] - u[0]).abs() < 1e-7 && (back[1] - u[1]).abs() < 1e-7,
                "{} {u:?} {back:?}",
                s.name()
            );
        }
        if k > 0 {
            // The pbrt-v4 peer is the crate's PiecewiseConstant, checked in tests/samplers.rs.
            continue;
        }
        let report = run_battery(s, &BatteryOptions::quick().with_seed(7 + k as u64));
        assert!(
            report.chi_square.status != Status::Fail && report.normalisation.status != Status::Fail,
            "{}: {report:#?}",
            s.name()
        );
    }
    // The lat-long density on a pixel is weight · sin θ_centre / (2π² sin θ) / mean: exact value.
    let d = image_direction(3.5 / 32.0, 5.25 / 16.0);
    let (c, r) = (3, 5);
    let mut f = 0.0;
    let mut total = 0.0;
    for y in 0..16 {
        let st = (PI * (y as f64 + 0.5) / 16.0).sin();
        for x in 0..32 {
            let v = f64::from(luminance(env.image().pixel(x, y))) * st;
            total += v;
            if (x, y) == (c, r) {
                f = v;
            }
        }
    }
    let want = f / (total / 512.0) / (2.0 * PI * PI * d[0].hypot(d[1]));
    assert!((ll.pdf(d) - want).abs() < 1e-9 * want);
}

/// The MIS estimator (balance heuristic, light sampling with the compensated map + cosine BSDF
/// sampling) of the irradiance-like integral ∫ L(ω) max(0, n·ω)/π dω is unbiased: it matches a
/// deterministic quadrature within 4 standard errors, and so do light sampling alone and MIS
/// without compensation (light sampling alone *with* compensation would miss the directions where
/// its density is 0, of which there are some).
#[test]
fn mis_compensation_stays_unbiased_with_bsdf_sampling() {
    let (w, h) = (24, 12);
    let mut img = random_image(w, h, 77);
    img.set_pixel(5, 3, [40.0, 30.0, 20.0]);
    let plain = EnvironmentMap::new(img.clone()).unwrap();
    let comp = EnvironmentMap::with_options(
        img,
        EnvOptions {
            mis_compensation: true,
            ..EnvOptions::default()
        },
    )
    .unwrap();
    // Some directions have zero light density under compensation.
    assert!(random_dirs(2000, 1).iter().any(|&d| comp.pdf(d) == 0.0));
    let n = normalize([0.3, -0.2, 0.9]).unwrap();
    let f = |d: Vec3| -> f64 {
        let c = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        if c > 0.0 {
            f64::from(luminance(plain.eval(d))) * c / PI
        } else {
            0.0
        }
    };
    // Reference: midpoint rule on a fine (θ, φ) grid aligned with the pixels (nearest lookup is
    // constant on pixels, the cosine is smooth).
    let (nt, np) = (h * 64, w * 64);
    let mut reference = 0.0;
    for i in 0..nt {
        let t = PI * (i as f64 + 0.5) / nt as f64;
        for j in 0..np {
            let s = (j as f64 + 0.5) / np as f64;
            reference += f(image_direction(s, t / PI)) * t.sin();
        }
    }
    reference *= (PI / nt as f64) * (TAU / np as f64);
    // Cosine-weighted BSDF sampling about n.
    let frame = {
        let a = if n[0].abs() > 0.9 {
            [0.0, 1.0, 0.0]
        } else {
            [1.0, 0.0, 0.0]
        };
        let cross = |a: Vec3, b: Vec3| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let t = normalize(cross(n, a)).unwrap();
        (t, cross(n, t))
    };
    let bsdf_sample = |u: Point2| -> (Vec3, f64) {
        let r = u[0].sqrt();
        let p = TAU * u[1];
        let (x, y, z) = (r * p.cos(), r * p.sin(), (1.0 - u[0]).max(0.0).sqrt());
        let (t, b) = frame;
        let d = [0, 1, 2].map(|k| x * t[k] + y * b[k] + z * n[k]);
        (d, z / PI)
    };
    let bsdf_pdf = |d: Vec3| (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]).max(0.0) / PI;
    let count = 100_000;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(2024);
    let mean_se = |xs: &[f64]| {
        let m = xs.iter().sum::<f64>() / xs.len() as f64;
        let v = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (xs.len() - 1) as f64;
        (m, (v / xs.len() as f64).sqrt())
    };
    let estimate = |light: &EnvironmentMap, mis: bool, rng: &mut Xoshiro256PlusPlus| {
        let mut xs = Vec::with_capacity(count);
        for _ in 0..count {
            let s = light.sample([rng.gen(), rng.gen()]);
            let mut x = 0.0;
            if s.pdf > 0.0 {
                let wl = if mis {
                    s.pdf / (s.pdf + bsdf_pdf(s.direction))
                } else {
                    1.0
                };
                x += wl * f(s.direction) / s.pdf;
            }
            if mis {
                let (d, pb) = bsdf_sample([rng.gen(), rng.gen()]);
                if pb > 0.0 {
                    let wb = pb / (pb + light.pdf(d));
                    x += wb * f(d) / pb;
                }
            }
            xs.push(x);
        }
        mean_se(&xs)
    };
    for (name, light, mis) in [
        ("plain, light only", &plain, false),
        ("plain, MIS", &plain, true),
        ("compensated, MIS", &comp, true),
    ] {
        let (m, se) = estimate(light, mis, &mut rng);
        assert!(
            (m - reference).abs() < 4.0 * se,
            "{name}: {m} ± {se} vs {reference}"
        );
    }
}

/// The batch calls (the sphere map's SIMD path) against the scalar ones on a random map and a
/// single bright pixel, both lookups: directions within 1e-15, densities within 1e-12 relative
/// (the bounds of `tests/batch.rs`), the radiance exactly `eval` of the batch direction (and the
/// scalar sample's radiance wherever the two directions read the same pixel, all but round-off
/// cases), `pdf_batch` and `invert_batch` within 1e-12 of `pdf` and `invert`.
#[test]
fn batches_agree_with_the_scalar_calls() {
    let mut seq = Xoshiro256PlusPlus::seed_from_u64(17);
    let mut u: Vec<Point2> = (0..3000).map(|_| [seq.gen(), seq.gen()]).collect();
    u.extend([[0.0, 0.0], [1.0, 1.0], [0.5, 0.5], [0.0, 1.0], [1.0, 0.0]]);
    let n = u.len();
    for (img, lookup) in [
        (random_image(24, 12, 11), Lookup::Nearest),
        (one_bright(32, 16, 7, 3, 0.1), Lookup::Bilinear),
    ] {
        let env = EnvironmentMap::with_options(
            img,
            EnvOptions {
                lookup,
                ..EnvOptions::default()
            },
        )
        .unwrap();
        let (mut dirs, mut pdf, mut rgb) = (vec![[0.0; 3]; n], vec![0.0; n], vec![[0.0f32; 3]; n]);
        env.sample_batch_rgb(&u, &mut dirs, &mut pdf, &mut rgb);
        let mut pb = vec![0.0; n];
        env.pdf_batch(&dirs, &mut pb);
        let mut ib = vec![Ok([0.0; 2]); n];
        env.invert_batch(&dirs, &mut ib);
        let mut other_pixel = 0;
        for k in 0..n {
            let s = env.sample(u[k]);
            let dd = (0..3).map(|i| (dirs[k][i] - s.direction[i]).abs());
            assert!(
                dd.fold(0.0, f64::max) <= 1e-15,
                "{k}: {:?} {:?}",
                dirs[k],
                s.direction
            );
            assert!(
                (pdf[k] - s.pdf).abs() <= 1e-12 * s.pdf,
                "{k}: {} {}",
                pdf[k],
                s.pdf
            );
            assert_eq!(rgb[k], env.eval(dirs[k]), "{k}");
            other_pixel += usize::from(rgb[k] != s.radiance);
            let p = env.pdf(dirs[k]);
            assert!((pb[k] - p).abs() <= 1e-12 * p, "{k}: {} {p}", pb[k]);
            let (a, b) = (ib[k].as_ref().unwrap(), env.invert(dirs[k]).unwrap());
            assert!(
                (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) <= 1e-12,
                "{k}: {a:?} {b:?}"
            );
        }
        assert!(
            other_pixel <= 5,
            "{other_pixel} radiances differ from the scalar sample's"
        );
    }
}

/// `eval_batch` (the angles on the SIMD lanes) equals the scalar `eval` bit for bit, both lookups,
/// on every direction of a seeded run of samples, on random directions, on directions exactly at
/// pixel edges and corners (where any difference in the angles' round-off would show as the
/// neighbouring pixel), at the poles and the seam, and on vectors that are not unit, zero or not
/// finite.
#[test]
fn eval_batch_equals_eval_bit_for_bit() {
    let (w, h) = (24usize, 12usize);
    let env = EnvironmentMap::new(random_image(w, h, 29)).unwrap();
    let mut seq = Xoshiro256PlusPlus::seed_from_u64(31);
    let u: Vec<Point2> = (0..4000).map(|_| [seq.gen(), seq.gen()]).collect();
    let (mut dirs, mut pdf, mut rgb) = (
        vec![[0.0; 3]; u.len()],
        vec![0.0; u.len()],
        vec![[0.0f32; 3]; u.len()],
    );
    env.sample_batch_rgb(&u, &mut dirs, &mut pdf, &mut rgb);
    dirs.extend(random_dirs(4000, 37));
    // Pixel edges and corners, exactly as `image_direction` gives them (and their pole rows).
    for r in 0..=h {
        for c in 0..=w {
            dirs.push(image_direction(c as f64 / w as f64, r as f64 / h as f64));
        }
    }
    dirs.extend([
        [0.0, 0.0, 1.0],
        [-0.0, 0.0, -1.0],
        [1e-200, -1e-200, 1.0],
        [-1.0, 1e-300, 0.0],
        [-1.0, -1e-300, 0.0],
        [-1.0, 0.0, 0.0],
        [3.0, -4.0, 12.0],
        [1e300, 1e300, -1e300],
        [1e-310, 0.0, 3e-310],
        [0.0, 0.0, 0.0],
        [f64::NAN, 0.0, 1.0],
        [f64::INFINITY, 0.0, 0.0],
    ]);
    let mut black = 0;
    for lookup in [Lookup::Nearest, Lookup::Bilinear] {
        let mut out = vec![[0.0f32; 3]; dirs.len()];
        env.eval_batch_with(&dirs, lookup, &mut out);
        for (k, d) in dirs.iter().enumerate() {
            let want = env.eval_with(*d, lookup);
            assert_eq!(
                out[k].map(f32::to_bits),
                want.map(f32::to_bits),
                "{lookup:?} {k}: {d:?}"
            );
            black += usize::from(want == [0.0; 3]);
        }
    }
    // The zero and the two non-finite vectors are black (every pixel of the image is not).
    assert_eq!(black, 2 * 3);
    // The map's own lookup, and the radiance `sample_batch_rgb` returned.
    let mut out = vec![[0.0f32; 3]; u.len()];
    env.eval_batch(&dirs[..u.len()], &mut out);
    assert_eq!(out, rgb);
}

/// The batch angles are `math::angles` bit for bit on every backend this CPU has, and within a
/// few ulps of `spherical` (libm's hypot and atan2).
#[test]
fn batch_angles_equal_the_scalar_angles_on_every_backend() {
    use crate::mapping::simd::{dispatch, math, Backend};
    let mut dirs = random_dirs(5000, 41);
    dirs.extend([
        [0.0, 0.0, 1.0],
        [-0.0, -0.0, -1.0],
        [-1.0, 0.0, 0.0],
        [-1.0, -0.0, 0.0],
        [-1.0, -1e-17, 0.0],
        [1.0, -1e-17, 0.0],
        [1e-9, 1e-9, 1.0],
    ]);
    let n = dirs.len();
    let cols: Vec<Vec<f64>> = (0..3)
        .map(|i| dirs.iter().map(|d| d[i]).collect())
        .collect();
    for b in Backend::available() {
        let (mut t, mut p) = (vec![0.0; n], vec![0.0; n]);
        dispatch::angles(b, [&cols[0], &cols[1], &cols[2]], [&mut t, &mut p]);
        for (k, d) in dirs.iter().enumerate() {
            let (ts, ps) = math::angles(*d);
            assert_eq!(
                (t[k].to_bits(), p[k].to_bits()),
                (ts.to_bits(), ps.to_bits()),
                "{b:?} {k}: {d:?}"
            );
            assert!(
                (0.0..=PI).contains(&ts) && (0.0..TAU).contains(&ps),
                "{d:?}"
            );
            let (tl, pl) = crate::sampler::spherical(*d);
            // φ near 0 and 2π is the same azimuth.
            let dp = (ps - pl).abs().min(TAU - (ps - pl).abs());
            assert!(
                (ts - tl).abs() <= 2e-15 && dp <= 2e-15,
                "{k}: {d:?}: ({ts}, {ps}) vs libm ({tl}, {pl})"
            );
        }
    }
}

/// The ratio bound is not computed by the build but on the first `ratio_bound()` call, and is
/// then bit for bit the build-time computation; threads sharing one map (`Sync`) all see it.
#[test]
fn the_lazy_ratio_bound_is_the_eager_one_and_shared_across_threads() {
    let maps = [
        random_image(64, 32, 7),
        random_image(37, 19, 8),
        one_bright(32, 16, 5, 0, 0.0),
        one_bright(40, 20, 0, 10, 0.01),
    ];
    for img in maps {
        let env = EnvironmentMap::new(img).unwrap();
        let (eager, cached) = env.map().ratio_bound_eager();
        assert!(!cached, "the build computed the bound");
        let bits = |b: (f64, f64)| (b.0.to_bits(), b.1.to_bits());
        let seen: Vec<(u64, u64)> = std::thread::scope(|s| {
            let hs: Vec<_> = (0..4)
                .map(|_| s.spawn(|| bits(env.map().ratio_bound())))
                .collect();
            hs.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert!(
            seen.iter().all(|&b| b == bits(eager)),
            "{seen:?} vs {eager:?}"
        );
        assert!(
            env.map().ratio_bound_eager().1,
            "the bound is kept after first use"
        );
        assert_eq!(
            bits(crate::MapRef::Sphere(env.map()).ratio_bound()),
            bits(eager)
        );
        assert!(eager.0 <= eager.1 && eager.1.is_finite());
    }
    // A luminaire's sphere maps, both layouts; a refined map has its bound from the build.
    let d = Diagram::from_degrees(
        &[0.0, 40.0, 90.0, 130.0, 180.0],
        &[0.0, 120.0, 240.0],
        &[
            vec![1.0, 0.5, 0.3, 2.0, 4.0],
            vec![0.7, 0.2, 0.1, 3.0, 1.0],
            vec![1.0, 0.9, 0.0, 0.5, 2.5],
        ],
    )
    .unwrap();
    for layout in [crate::SphereLayout::Split, crate::SphereLayout::Lambert] {
        let map = SphereMap::with_layout(&d, layout).unwrap();
        let (eager, cached) = map.ratio_bound_eager();
        assert!(!cached);
        let b = map.ratio_bound();
        assert_eq!(
            (b.0.to_bits(), b.1.to_bits()),
            (eager.0.to_bits(), eager.1.to_bits())
        );
    }
    let refined = SphereMap::with_tolerance(&d, 0.05).unwrap();
    assert!(
        refined.ratio_bound_eager().1,
        "a refined map's bound is computed by the build"
    );
}

/// The float32 environment map: its samples, densities and inverses are its float32 map's bit for
/// bit (so the float32 map's tested contract is its own), its radiance is the float64 lookup of
/// the widened direction bit for bit, it keeps the float32 map's contract on maps with bright
/// pixels at the pole, the seam and the horizon, and it holds ≤ 12 bytes per pixel.
#[test]
fn the_float32_environment_map_is_its_float32_map_with_radiance() {
    let images = [
        random_image(64, 32, 9),
        one_bright(48, 24, 0, 0, 0.02),
        one_bright(48, 24, 47, 11, 0.02),
        one_bright(48, 24, 17, 12, 0.02),
    ];
    for (case, img) in images.into_iter().enumerate() {
        for lookup in [Lookup::Nearest, Lookup::Bilinear] {
            let opts = EnvOptions {
                lookup,
                ..EnvOptions::default()
            };
            let env = EnvironmentMap::with_options(img.clone(), opts.clone()).unwrap();
            let reference = env.map().float32_map().unwrap();
            let power = env.power();
            let predicted = env.float32_memory_bytes_beyond_image().unwrap();
            let f32env = env.clone().into_float32().unwrap();
            assert_eq!(f32env.power(), power);
            // Counted without making the float32 map (issue 40), the same bytes.
            assert_eq!(predicted, f32env.memory_bytes_beyond_image());
            let n = 4099;
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(case as u64);
            let u: Vec<f32> = (0..n).map(|_| rng.gen::<f32>()).collect();
            let v: Vec<f32> = (0..n).map(|_| rng.gen::<f32>()).collect();
            let bits = |a: &[f32]| a.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let (mut x, mut y, mut z, mut p) =
                (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
            let mut rgb = vec![[0f32; 3]; n];
            f32env.sample_soa(&u, &v, [&mut x, &mut y, &mut z], &mut p, &mut rgb);
            let (mut x2, mut y2, mut z2, mut p2) =
                (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
            reference.sample_soa(&u, &v, [&mut x2, &mut y2, &mut z2], &mut p2);
            assert_eq!(bits(&x), bits(&x2));
            assert_eq!(bits(&y), bits(&y2));
            assert_eq!(bits(&z), bits(&z2));
            assert_eq!(bits(&p), bits(&p2));
            for k in 0..n {
                let d = [x[k], y[k], z[k]];
                let want = env.eval_with(d.map(f64::from), lookup);
                assert_eq!(rgb[k], want, "case {case}, point {k}");
                assert_eq!(f32env.eval(d), want);
            }
            // The float32 map's contract: pdf at the sample agrees, the inverse round-trips,
            // the density is close to the float64 map's.
            let mut q = vec![0f32; n];
            f32env.pdf_soa([&x, &y, &z], &mut q);
            let (mut iu, mut iv) = (vec![0f32; n], vec![0f32; n]);
            f32env.invert_soa([&x, &y, &z], [&mut iu, &mut iv]);
            for k in 0..n {
                assert!(p[k] > 0.0 && p[k].is_finite());
                assert!(
                    (q[k] / p[k] - 1.0).abs() < 1e-4,
                    "case {case}: {} vs {}",
                    q[k],
                    p[k]
                );
                assert!((iu[k] - u[k]).abs() < 1e-5 && (iv[k] - v[k]).abs() < 1e-5);
                let p64 = env.pdf([x[k], y[k], z[k]].map(f64::from));
                assert!(
                    (f64::from(p[k]) / p64 - 1.0).abs() < 1e-3,
                    "case {case}: {} vs {p64}",
                    p[k]
                );
            }
        }
    }
    // A constant sky is uniform to float32 round-off; a black one is the clear error.
    let sky = Float32EnvironmentMap::new(
        Image::constant(32, 16, [2.0; 3]).unwrap(),
        EnvOptions::default(),
    )
    .unwrap();
    let mut q = [0f32; 3];
    sky.pdf_soa(
        [&[1.0, 0.0, 0.6], &[0.0, 1.0, 0.0], &[0.0, 0.0, 0.8]],
        &mut q,
    );
    let uniform = 1.0 / (4.0 * std::f32::consts::PI);
    assert!(
        q.iter()
            .all(|&p| (p - uniform).abs() <= 4.0 * f32::EPSILON * uniform),
        "{q:?}"
    );
    assert!(matches!(
        Float32EnvironmentMap::new(
            Image::constant(8, 4, [0.0; 3]).unwrap(),
            EnvOptions::default()
        ),
        Err(EnvMapError::Black { .. })
    ));
    // Memory: the float32 tables, ≤ 12 bytes per pixel beyond the image (the float64 map: ≈ 18).
    let (w, h) = (512, 256);
    let env = EnvironmentMap::new(random_image(w, h, 4)).unwrap();
    let b64 = env.memory_bytes_beyond_image() as f64 / (w * h) as f64;
    let predicted = env.float32_memory_bytes_beyond_image().unwrap();
    let f = env.into_float32().unwrap();
    assert_eq!(predicted, f.memory_bytes_beyond_image());
    let b32 = f.memory_bytes_beyond_image() as f64 / (w * h) as f64;
    assert!(b32 <= 12.0 && b64 > 16.0, "{b32} {b64} bytes per pixel");
}

/// Degenerate image sizes (one pixel, one row, one column) build both maps, and their samples
/// keep the contract: unit directions, positive densities that the pdf calls give back.
#[test]
fn tiny_images_build_and_sample_in_both_precisions() {
    for (w, h) in [(1, 1), (1, 2), (2, 1), (3, 1), (1, 3), (3, 2)] {
        let img = random_image(w, h, (w * 10 + h) as u64);
        let env = EnvironmentMap::new(img).unwrap_or_else(|e| panic!("{w}x{h}: {e}"));
        let f = env.clone().into_float32().unwrap();
        let n = 257;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let u: Vec<f32> = (0..n).map(|_| rng.gen::<f32>()).collect();
        let v: Vec<f32> = (0..n).map(|_| rng.gen::<f32>()).collect();
        let (mut x, mut y, mut z, mut p) =
            (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
        let mut rgb = vec![[0f32; 3]; n];
        f.sample_soa(&u, &v, [&mut x, &mut y, &mut z], &mut p, &mut rgb);
        let mut q = vec![0f32; n];
        f.pdf_soa([&x, &y, &z], &mut q);
        for k in 0..n {
            let len = (x[k] * x[k] + y[k] * y[k] + z[k] * z[k]).sqrt();
            assert!((len - 1.0).abs() < 1e-5, "{w}x{h}: |d| = {len}");
            assert!(
                p[k] > 0.0 && (q[k] / p[k] - 1.0).abs() < 1e-4,
                "{w}x{h}: {} {}",
                p[k],
                q[k]
            );
            let s = env.sample([f64::from(u[k]), f64::from(v[k])]);
            assert!(s.pdf > 0.0 && (env.pdf(s.direction) / s.pdf - 1.0).abs() < 1e-9);
        }
    }
}
