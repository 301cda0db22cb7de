//! The C ABI called from Rust, as a C caller would: statuses, messages, NULL pointers, batches
//! against single points, and sharing a sampler between threads.

use super::test_support::{last_error, IES};
use super::*;
use gonio::Batches;
use gonio::Diagram;
use std::ffi::CStr;
use std::ptr::{null, null_mut};

fn read_ies(text: &str, name: &CStr) -> (GonioStatus, *mut GonioDiagram) {
    let mut d = null_mut();
    let st = unsafe {
        gonio_diagram_read_memory(
            text.as_ptr(),
            text.len(),
            GONIO_FORMAT_IES,
            name.as_ptr(),
            &mut d,
        )
    };
    (st, d)
}

fn build(d: *const GonioDiagram, method: GonioMethod) -> *mut GonioSampler {
    let mut s = null_mut();
    let st = unsafe { gonio_sampler_build(d, method, GONIO_DOMAIN_AUTO, &mut s) };
    assert_eq!(st, GONIO_OK, "{}", last_error());
    s
}

#[test]
fn reads_builds_samples_and_inverts() {
    let (st, d) = read_ies(IES, c"down.ies");
    assert_eq!(st, GONIO_OK, "{}", last_error());
    let mut flux = 0.0;
    assert_eq!(unsafe { gonio_diagram_flux(d, &mut flux) }, GONIO_OK);
    let want = Diagram::from_degrees(&[90.0, 135.0, 180.0], &[0.0], &[vec![0.0, 60.0, 100.0]])
        .unwrap()
        .integral();
    assert!((flux - want).abs() <= 1e-12 * want, "{flux} vs {want}");
    let mut dom = -1;
    assert_eq!(unsafe { gonio_diagram_domain(d, &mut dom) }, GONIO_OK);
    assert_eq!(dom, GONIO_DOMAIN_SPHERE, "photometric files get the sphere");

    let s = build(d, GONIO_METHOD_HDS);
    unsafe { gonio_diagram_free(d) }; // the sampler does not borrow the diagram
    let mut smp = GonioSample::default();
    assert_eq!(unsafe { gonio_sample(s, 0.3, 0.6, &mut smp) }, GONIO_OK);
    let [x, y, z] = smp.direction;
    let mut pdf = 0.0;
    assert_eq!(unsafe { gonio_pdf(s, x, y, z, &mut pdf) }, GONIO_OK);
    assert!((pdf - smp.pdf).abs() <= 1e-12 * smp.pdf && smp.pdf > 0.0);
    // The direction may be given unnormalised.
    let mut pdf2 = 0.0;
    assert_eq!(
        unsafe { gonio_pdf(s, 3.0 * x, 3.0 * y, 3.0 * z, &mut pdf2) },
        GONIO_OK
    );
    assert!((pdf2 - pdf).abs() <= 1e-12 * pdf);
    let (mut u, mut v) = (0.0, 0.0);
    assert_eq!(
        unsafe { gonio_invert(s, x, y, z, &mut u, &mut v) },
        GONIO_OK
    );
    assert!(
        (u - 0.3).abs() < 1e-9 && (v - 0.6).abs() < 1e-9,
        "({u}, {v})"
    );
    // Straight up, this downlight has density 0: in the domain, but without preimage; a batch
    // writes NaN there and goes on.
    assert_eq!(
        unsafe { gonio_invert(s, 0.0, 0.0, 1.0, &mut u, &mut v) },
        GONIO_ERR_ZERO_DENSITY
    );
    assert!(last_error().contains("density is 0"), "{}", last_error());
    let dirs = [0.0, 0.0, 1.0, x, y, z];
    let mut uv = [0.0; 4];
    assert_eq!(
        unsafe { gonio_invert_batch(s, dirs.as_ptr(), 2, uv.as_mut_ptr()) },
        GONIO_OK
    );
    assert!(uv[0].is_nan() && uv[1].is_nan(), "{uv:?}");
    assert!(
        (uv[2] - 0.3).abs() < 1e-9 && (uv[3] - 0.6).abs() < 1e-9,
        "{uv:?}"
    );
    let mut t = 0.0;
    assert_eq!(unsafe { gonio_target_pdf(s, x, y, z, &mut t) }, GONIO_OK);
    assert!(t > 0.0);
    let m = unsafe { CStr::from_ptr(gonio_sampler_method(s)) };
    assert_eq!(m.to_str().unwrap(), "hds");
    // The HDS map states its guaranteed pdf/target range, and the target's power is the flux.
    let (mut lo, mut hi, mut power) = (0.0, 0.0, 0.0);
    assert_eq!(
        unsafe { gonio_sampler_ratio_bound(s, &mut lo, &mut hi) },
        GONIO_OK
    );
    assert!(
        lo > 0.0 && lo <= 1.0 && hi >= 1.0 && hi.is_finite(),
        "[{lo}, {hi}]"
    );
    let ratio = pdf / t;
    assert!(
        ratio >= lo * (1.0 - 1e-12) && ratio <= hi * (1.0 + 1e-12),
        "{ratio} outside [{lo}, {hi}]"
    );
    assert_eq!(
        unsafe { gonio_sampler_target_power(s, &mut power) },
        GONIO_OK
    );
    assert!((power - want).abs() <= 1e-9 * want, "{power} vs {want}");
    unsafe { gonio_sampler_free(s) };
}

#[test]
fn options_reach_the_factory() {
    let (_, d) = read_ies(IES, c"down.ies");
    let mut o = GonioBuildOptions {
        tolerance: 1.0,
        resolution: 1,
        seed: 1,
        sphere_layout: 9,
    };
    assert_eq!(unsafe { gonio_build_options_default(&mut o) }, GONIO_OK);
    assert_eq!(o.tolerance, 0.0);
    assert_eq!(o.sphere_layout, GONIO_SPHERE_LAYOUT_SPLIT);
    let mut s = null_mut();
    // A resolution the piecewise-constant method refuses shows that the option arrives.
    o.resolution = usize::MAX;
    let st = unsafe { gonio_sampler_build_with(d, GONIO_METHOD_PIECEWISE_CONSTANT, 0, &o, &mut s) };
    assert_eq!(st, GONIO_ERR_BUILD, "{}", last_error());
    assert!(last_error().contains("resolution"), "{}", last_error());
    o.resolution = 0;
    o.tolerance = 2.0;
    let st = unsafe { gonio_sampler_build_with(d, GONIO_METHOD_HDS, 0, &o, &mut s) };
    assert_eq!(st, GONIO_ERR_BUILD);
    o.tolerance = 0.0;
    o.sphere_layout = 5;
    let st = unsafe { gonio_sampler_build_with(d, GONIO_METHOD_HDS, 0, &o, &mut s) };
    assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
    // The Lambert layout needs a diagram on both sides of the horizon: refused, so it arrived.
    o.sphere_layout = GONIO_SPHERE_LAYOUT_LAMBERT;
    let st = unsafe { gonio_sampler_build_with(d, GONIO_METHOD_HDS, 0, &o, &mut s) };
    assert_eq!(st, GONIO_ERR_BUILD);
    assert!(last_error().contains("Lambert"), "{}", last_error());
    o.sphere_layout = GONIO_SPHERE_LAYOUT_SPLIT;
    let st = unsafe { gonio_sampler_build_with(d, GONIO_METHOD_HDS, 0, &o, &mut s) };
    assert_eq!(st, GONIO_OK, "{}", last_error());
    let st = unsafe { gonio_sampler_build_with(d, GONIO_METHOD_HDS, 0, null(), &mut s) };
    assert_eq!(st, GONIO_ERR_NULL_POINTER);
    // Uniform states no bound.
    let u = build(d, GONIO_METHOD_UNIFORM);
    let (mut lo, mut hi) = (0.0, 0.0);
    assert_eq!(
        unsafe { gonio_sampler_ratio_bound(u, &mut lo, &mut hi) },
        GONIO_ERR_UNSUPPORTED
    );
    unsafe {
        gonio_sampler_free(u);
        gonio_sampler_free(s);
        gonio_diagram_free(d);
    }
}

#[test]
fn batches_agree_with_single_points_in_every_layout() {
    let (_, d) = read_ies(IES, c"down.ies");
    let s = build(d, GONIO_METHOD_HDS);
    let n = 300; // more than one chunk
                 // Interior points: on the square's edges a sample may sit on a seam of the density.
    let uv: Vec<f64> = (0..2 * n)
        .map(|i| (((i * 7919) % 1000) as f64 + 0.5) / 1000.0)
        .collect();
    let (mut dirs, mut pdfs) = (vec![0.0; 3 * n], vec![0.0; n]);
    assert_eq!(
        unsafe { gonio_sample_batch(s, uv.as_ptr(), n, dirs.as_mut_ptr(), pdfs.as_mut_ptr()) },
        GONIO_OK
    );
    for i in 0..n {
        let mut one = GonioSample::default();
        unsafe { gonio_sample(s, uv[2 * i], uv[2 * i + 1], &mut one) };
        // The library's batch path may use SIMD and FMA: equal up to round-off, not bit for bit.
        for c in 0..3 {
            assert!(
                (one.direction[c] - dirs[3 * i + c]).abs() <= 1e-14,
                "point {i}"
            );
        }
        assert!((one.pdf - pdfs[i]).abs() <= 1e-13 * pdfs[i], "point {i}");
    }
    // SoA, f64.
    let (u, v): (Vec<f64>, Vec<f64>) = (0..n).map(|i| (uv[2 * i], uv[2 * i + 1])).unzip();
    let (mut x, mut y, mut z, mut p) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let st = unsafe {
        gonio_sample_batch_soa(
            s,
            u.as_ptr(),
            v.as_ptr(),
            n,
            x.as_mut_ptr(),
            y.as_mut_ptr(),
            z.as_mut_ptr(),
            p.as_mut_ptr(),
        )
    };
    assert_eq!(st, GONIO_OK);
    for i in 0..n {
        assert_eq!(
            [x[i], y[i], z[i], p[i]],
            [dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2], pdfs[i]]
        );
    }
    // pdf and invert batches, AoS and SoA.
    let mut pb = vec![0.0; n];
    assert_eq!(
        unsafe { gonio_pdf_batch(s, dirs.as_ptr(), n, pb.as_mut_ptr()) },
        GONIO_OK
    );
    let mut pb2 = vec![0.0; n];
    let st =
        unsafe { gonio_pdf_batch_soa(s, x.as_ptr(), y.as_ptr(), z.as_ptr(), n, pb2.as_mut_ptr()) };
    assert_eq!(st, GONIO_OK);
    assert_eq!(pb, pb2);
    let mut back = vec![0.0; 2 * n];
    assert_eq!(
        unsafe { gonio_invert_batch(s, dirs.as_ptr(), n, back.as_mut_ptr()) },
        GONIO_OK
    );
    for i in 0..n {
        assert!(
            (pb[i] - pdfs[i]).abs() <= 1e-12 * pdfs[i],
            "point {i}: pdf {} of the sample, {} recomputed",
            pdfs[i],
            pb[i]
        );
        if pdfs[i] > 0.0 {
            let e = (back[2 * i] - uv[2 * i])
                .abs()
                .max((back[2 * i + 1] - uv[2 * i + 1]).abs());
            assert!(e < 1e-8, "point {i}: round trip off by {e}");
        }
    }
    // f32: the float32 map's results (inputs rounded first).
    let uvf: Vec<f32> = uv.iter().map(|&a| a as f32).collect();
    let (mut df, mut pf) = (vec![0f32; 3 * n], vec![0f32; n]);
    let st =
        unsafe { gonio_sample_batch_f32(s, uvf.as_ptr(), n, df.as_mut_ptr(), pf.as_mut_ptr()) };
    assert_eq!(st, GONIO_OK);
    for i in 0..n {
        let mut one = GonioSample::default();
        unsafe {
            gonio_sample(
                s,
                f64::from(uvf[2 * i]),
                f64::from(uvf[2 * i + 1]),
                &mut one,
            )
        };
        // The float32 map (its own tables and arithmetic), close to the f64 map: the direction
        // within 4e-7 scaled by min(1, 2π·pdf) (a low density stretches the map; measured
        // 1.6e-7), the pdf within 1e-4 relative (measured 3.2e-5, at a low density where the
        // f32 round-off of the position meets a steep density).
        let q = (one.pdf * std::f64::consts::TAU).min(1.0);
        assert!((f64::from(df[3 * i + 2]) - one.direction[2]).abs() * q <= 4e-7);
        assert!((f64::from(pf[i]) - one.pdf).abs() <= 1e-4 * one.pdf);
    }
    let mut tf = vec![0f32; n];
    assert_eq!(
        unsafe { gonio_target_pdf_batch_f32(s, df.as_ptr(), n, tf.as_mut_ptr()) },
        GONIO_OK
    );
    assert!(tf.iter().all(|t| t.is_finite() && *t >= 0.0));
    // In place: the output may overwrite the input.
    let mut inplace = dirs.clone();
    let st = unsafe { gonio_pdf_batch(s, inplace.as_ptr(), n, inplace.as_mut_ptr()) };
    assert_eq!(st, GONIO_OK);
    assert_eq!(&inplace[..n], &pb[..]);
    unsafe {
        gonio_sampler_free(s);
        gonio_diagram_free(d);
    }
}

#[test]
fn errors_are_codes_with_located_messages() {
    let bad = "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 100\n0 45 x\n0\n1 2 3\n";
    let (st, d) = read_ies(bad, c"bad.ies");
    assert_eq!(st, GONIO_ERR_PARSE);
    assert!(d.is_null());
    let msg = last_error();
    assert!(msg.starts_with("bad.ies:5:6: "), "{msg}");

    let mut out = null_mut();
    let st = unsafe { gonio_diagram_read_path(null(), GONIO_FORMAT_AUTO, &mut out) };
    assert_eq!(st, GONIO_ERR_NULL_POINTER);
    assert!(last_error().contains("path"));
    let st = unsafe { gonio_diagram_read_path(c"/nonexistent/x.ies".as_ptr(), 0, &mut out) };
    assert_eq!(st, GONIO_ERR_IO);
    assert!(
        last_error().starts_with("cannot read /nonexistent/x.ies: "),
        "{}",
        last_error()
    );
    let st = unsafe { gonio_diagram_read_path(c"/dev/zero.ies".as_ptr(), 0, &mut out) };
    assert_eq!(st, GONIO_ERR_IO, "{}", last_error());
    let st = unsafe { gonio_diagram_read_path(c"lamp.txt".as_ptr(), 0, &mut out) };
    assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
    assert!(last_error().contains("unknown input format `.txt`"));

    let (_, d) = read_ies(IES, c"down.ies");
    let mut s = null_mut();
    assert_eq!(
        unsafe { gonio_sampler_build(d, 5, 0, &mut s) },
        GONIO_ERR_INVALID_ARGUMENT
    );
    assert_eq!(
        unsafe { gonio_sampler_build(d, 0, 3, &mut s) },
        GONIO_ERR_INVALID_ARGUMENT
    );
    // A hemisphere sampler for a diagram that lies below the horizon cannot be built.
    let st =
        unsafe { gonio_sampler_build(d, GONIO_METHOD_BILINEAR, GONIO_DOMAIN_HEMISPHERE, &mut s) };
    assert_eq!(st, GONIO_ERR_BUILD);
    assert!(
        last_error().starts_with("down.ies: cannot build the bilinear sampler: "),
        "{}",
        last_error()
    );
    assert!(s.is_null());

    let s = build(d, GONIO_METHOD_REJECTION);
    let (mut u, mut v) = (0.0, 0.0);
    assert_eq!(
        unsafe { gonio_invert(s, 0.0, 0.0, -1.0, &mut u, &mut v) },
        GONIO_ERR_UNSUPPORTED
    );
    let mut p = 0.0;
    assert_eq!(
        unsafe { gonio_pdf(s, 0.0, 0.0, 0.0, &mut p) },
        GONIO_ERR_INVALID_ARGUMENT
    );
    assert_eq!(
        unsafe { gonio_pdf(s, f64::NAN, 0.0, 1.0, &mut p) },
        GONIO_ERR_INVALID_ARGUMENT
    );
    assert_eq!(
        unsafe { gonio_pdf(null(), 0.0, 0.0, 1.0, &mut p) },
        GONIO_ERR_NULL_POINTER
    );
    assert_eq!(
        unsafe { gonio_pdf(s, 0.0, 0.0, 1.0, null_mut()) },
        GONIO_ERR_NULL_POINTER
    );
    // Misaligned pointers are refused like NULL ones.
    let buf = [0u8; 64];
    let odd = buf.as_ptr().wrapping_add(1) as *mut f64;
    assert_eq!(
        unsafe { gonio_pdf(s, 0.0, 0.0, 1.0, odd) },
        GONIO_ERR_NULL_POINTER
    );
    // Lengths whose byte size overflows are refused before anything is read.
    let st =
        unsafe { gonio_pdf_batch(s, odd.wrapping_sub(0).cast_const(), usize::MAX / 2, &mut p) };
    assert_eq!(st, GONIO_ERR_NULL_POINTER);
    let dirs = [0.0, 0.0, 1.0];
    let st = unsafe { gonio_pdf_batch(s, dirs.as_ptr(), usize::MAX / 8, &mut p) };
    assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
    // A zero direction inside a batch names its index.
    let dirs = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let mut out = [0.0; 2];
    let st = unsafe { gonio_pdf_batch(s, dirs.as_ptr(), 2, out.as_mut_ptr()) };
    assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
    assert!(
        last_error().starts_with("direction #1: "),
        "{}",
        last_error()
    );
    assert!(unsafe { gonio_sampler_method(null()) }.is_null());
    unsafe {
        gonio_sampler_free(s);
        gonio_diagram_free(d);
        gonio_sampler_free(null_mut());
        gonio_diagram_free(null_mut());
    }
}

#[test]
fn a_panic_becomes_a_status_and_the_message_is_per_thread() {
    let st = guard(|| panic!("boom"));
    assert_eq!(st, GONIO_ERR_PANIC);
    assert_eq!(last_error(), "internal error: boom");
    // Another thread has its own (empty) message.
    let other = std::thread::spawn(last_error).join().unwrap();
    assert_eq!(other, "");
    assert_eq!(last_error(), "internal error: boom");
}

/// A raw pointer that may cross threads (the ABI's promise that makes this sound is under test).
#[derive(Clone, Copy)]
struct Shared(*const GonioSampler);
unsafe impl Send for Shared {}

#[test]
fn one_sampler_serves_many_threads() {
    let (_, d) = read_ies(IES, c"down.ies");
    let s = build(d, GONIO_METHOD_HDS);
    let shared = Shared(s);
    let handles: Vec<_> = (0..4)
        .map(|t| {
            std::thread::spawn(move || {
                let s = shared;
                let mut worst = 0.0f64;
                for i in 0..500 {
                    let (u, v) = (
                        (i as f64 + 0.5) / 500.0,
                        ((i * 37 + t * 11) % 500) as f64 / 500.0,
                    );
                    let mut smp = GonioSample::default();
                    let mut uv = [0.0; 2];
                    let [x, y, z] = unsafe {
                        assert_eq!(gonio_sample(s.0, u, v, &mut smp), GONIO_OK);
                        smp.direction
                    };
                    let st = unsafe { gonio_invert(s.0, x, y, z, &mut uv[0], &mut uv[1]) };
                    assert_eq!(st, GONIO_OK);
                    if smp.pdf > 0.0 {
                        worst = worst.max((uv[0] - u).abs().max((uv[1] - v).abs()));
                    }
                }
                worst
            })
        })
        .collect();
    for h in handles {
        let worst = h.join().unwrap();
        assert!(worst < 1e-8, "round trip off by {worst}");
    }
    unsafe {
        gonio_sampler_free(s);
        gonio_diagram_free(d);
    }
}

/// A handle around a sampler built in Rust (the test needs the trait call on the same object).
fn handle(s: impl Into<gonio::Built<'static>>) -> *mut GonioSampler {
    Box::into_raw(Box::new(GonioSampler { inner: s.into() }))
}

fn bits<T: Copy + Into<f64>>(v: &[T]) -> Vec<u64> {
    v.iter().map(|&x| x.into().to_bits()).collect()
}

#[test]
#[allow(clippy::needless_range_loop)] // columns indexed by element on purpose
fn batches_give_the_bits_of_the_trait_soa_calls() {
    use gonio::synthetic::{example_luminaire, random_hemisphere, Family};
    use gonio::{Domain, Method};
    let lum = example_luminaire();
    let zero_heavy = random_hemisphere(Family::ZeroHeavy, 9, 12, true, 4);
    let n = 600; // two full chunks and a partial one
    let uv: Vec<f64> = (0..2 * n)
        .map(|i| (((i * 7919) % 1000) as f64 + 0.5) / 1000.0)
        .collect();
    let (u, v): (Vec<f64>, Vec<f64>) = (0..n).map(|i| (uv[2 * i], uv[2 * i + 1])).unzip();
    // Directions over the whole sphere, of length 2.5 (the batches normalise them).
    let dir: [Vec<f64>; 3] = {
        let mut d: [Vec<f64>; 3] = [vec![], vec![], vec![]];
        for i in 0..n {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let phi = 2.399_963 * i as f64;
            let r = (1.0 - z * z).sqrt();
            for (c, x) in [r * phi.cos(), r * phi.sin(), z].into_iter().enumerate() {
                d[c].push(2.5 * x);
            }
        }
        d
    };
    let unit: [Vec<f64>; 3] = {
        let mut w: [Vec<f64>; 3] = [vec![], vec![], vec![]];
        for i in 0..n {
            let e = gonio::sampler::normalize([dir[0][i], dir[1][i], dir[2][i]]).unwrap();
            for c in 0..3 {
                w[c].push(e[c]);
            }
        }
        w
    };
    let f = |v: &[f64]| -> Vec<f32> { v.iter().map(|&x| x as f32).collect() };
    let dir32 = [f(&dir[0]), f(&dir[1]), f(&dir[2])];
    // The f32 rule: normalised in f64, rounded to f32.
    let unit32: [Vec<f32>; 3] = {
        let mut w: [Vec<f32>; 3] = [vec![], vec![], vec![]];
        for i in 0..n {
            let e = [dir32[0][i], dir32[1][i], dir32[2][i]].map(f64::from);
            let e = gonio::sampler::normalize(e).unwrap();
            for c in 0..3 {
                w[c].push(e[c] as f32);
            }
        }
        w
    };
    let (u32_, v32) = (f(&u), f(&v));
    for (name, s) in [
        (
            "hds sphere",
            Method::Hds.build(&lum, Domain::Sphere).unwrap(),
        ),
        (
            "hds zero-heavy hemisphere",
            Method::Hds.build(&zero_heavy, Domain::Hemisphere).unwrap(),
        ),
        (
            "bilinear",
            Method::Bilinear.build(&lum, Domain::Sphere).unwrap(),
        ),
    ] {
        // The Rust trait calls.
        let mut want = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [wx, wy, wz, wp] = &mut want;
        s.sample_batch_soa(&u, &v, [wx, wy, wz], wp);
        let ur = [&unit[0][..], &unit[1][..], &unit[2][..]];
        let mut wpdf = vec![0.0; n];
        s.pdf_batch_soa(ur, &mut wpdf);
        let (mut wu, mut wv) = (vec![0.0; n], vec![0.0; n]);
        s.invert_batch_soa(ur, [&mut wu, &mut wv]);
        let mut want32 = [vec![0.0f32; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [wx, wy, wz, wp] = &mut want32;
        s.sample_batch_soa_f32(&u32_, &v32, [wx, wy, wz], wp);
        let ur32 = [&unit32[0][..], &unit32[1][..], &unit32[2][..]];
        let mut wpdf32 = vec![0.0f32; n];
        s.pdf_batch_soa_f32(ur32, &mut wpdf32);
        let (mut wu32, mut wv32) = (vec![0.0f32; n], vec![0.0; n]);
        s.invert_batch_soa_f32(ur32, [&mut wu32, &mut wv32]);
        if s.domain() == Domain::Hemisphere {
            assert!(
                wu.iter().any(|x| x.is_nan()),
                "{name}: the lower hemisphere has no preimage"
            );
        }

        let h = handle(s);
        // f64, SoA and AoS.
        let mut o = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [x, y, z, p] = &mut o;
        let st = unsafe {
            gonio_sample_batch_soa(
                h,
                u.as_ptr(),
                v.as_ptr(),
                n,
                x.as_mut_ptr(),
                y.as_mut_ptr(),
                z.as_mut_ptr(),
                p.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK, "{}", last_error());
        for c in 0..4 {
            assert_eq!(bits(&o[c]), bits(&want[c]), "{name}: sample_soa column {c}");
        }
        let (mut dirs, mut pdfs) = (vec![0.0; 3 * n], vec![0.0; n]);
        let st =
            unsafe { gonio_sample_batch(h, uv.as_ptr(), n, dirs.as_mut_ptr(), pdfs.as_mut_ptr()) };
        assert_eq!(st, GONIO_OK);
        for i in 0..n {
            let got = [dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2], pdfs[i]];
            let w = [want[0][i], want[1][i], want[2][i], want[3][i]];
            assert_eq!(bits(&got), bits(&w), "{name}: sample (AoS) #{i}");
        }
        let mut p = vec![0.0; n];
        let st = unsafe {
            gonio_pdf_batch_soa(
                h,
                dir[0].as_ptr(),
                dir[1].as_ptr(),
                dir[2].as_ptr(),
                n,
                p.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK);
        assert_eq!(bits(&p), bits(&wpdf), "{name}: pdf_soa");
        let (mut iu, mut iv) = (vec![0.0; n], vec![0.0; n]);
        let st = unsafe {
            gonio_invert_batch_soa(
                h,
                dir[0].as_ptr(),
                dir[1].as_ptr(),
                dir[2].as_ptr(),
                n,
                iu.as_mut_ptr(),
                iv.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK);
        assert_eq!(
            (bits(&iu), bits(&iv)),
            (bits(&wu), bits(&wv)),
            "{name}: invert_soa"
        );
        let aos: Vec<f64> = (0..3 * n).map(|k| dir[k % 3][k / 3]).collect();
        let mut p = vec![0.0; n];
        assert_eq!(
            unsafe { gonio_pdf_batch(h, aos.as_ptr(), n, p.as_mut_ptr()) },
            GONIO_OK
        );
        assert_eq!(bits(&p), bits(&wpdf), "{name}: pdf (AoS)");
        let mut back = vec![0.0; 2 * n];
        assert_eq!(
            unsafe { gonio_invert_batch(h, aos.as_ptr(), n, back.as_mut_ptr()) },
            GONIO_OK
        );
        let wuv: Vec<f64> = (0..2 * n)
            .map(|k| if k % 2 == 0 { wu[k / 2] } else { wv[k / 2] })
            .collect();
        assert_eq!(bits(&back), bits(&wuv), "{name}: invert (AoS)");

        // f32, SoA and AoS.
        let mut o = [vec![0.0f32; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [x, y, z, p] = &mut o;
        let st = unsafe {
            gonio_sample_batch_soa_f32(
                h,
                u32_.as_ptr(),
                v32.as_ptr(),
                n,
                x.as_mut_ptr(),
                y.as_mut_ptr(),
                z.as_mut_ptr(),
                p.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK);
        for c in 0..4 {
            assert_eq!(
                bits(&o[c]),
                bits(&want32[c]),
                "{name}: sample_soa_f32 column {c}"
            );
        }
        let uvf: Vec<f32> = f(&uv);
        let (mut dirs, mut pdfs) = (vec![0.0f32; 3 * n], vec![0.0f32; n]);
        let st = unsafe {
            gonio_sample_batch_f32(h, uvf.as_ptr(), n, dirs.as_mut_ptr(), pdfs.as_mut_ptr())
        };
        assert_eq!(st, GONIO_OK);
        for i in 0..n {
            let got = [dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2], pdfs[i]];
            let w = [want32[0][i], want32[1][i], want32[2][i], want32[3][i]];
            assert_eq!(bits(&got), bits(&w), "{name}: sample_f32 (AoS) #{i}");
        }
        let mut p = vec![0.0f32; n];
        let st = unsafe {
            gonio_pdf_batch_soa_f32(
                h,
                dir32[0].as_ptr(),
                dir32[1].as_ptr(),
                dir32[2].as_ptr(),
                n,
                p.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK);
        assert_eq!(bits(&p), bits(&wpdf32), "{name}: pdf_soa_f32");
        let (mut iu, mut iv) = (vec![0.0f32; n], vec![0.0f32; n]);
        let st = unsafe {
            gonio_invert_batch_soa_f32(
                h,
                dir32[0].as_ptr(),
                dir32[1].as_ptr(),
                dir32[2].as_ptr(),
                n,
                iu.as_mut_ptr(),
                iv.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK);
        assert_eq!(
            (bits(&iu), bits(&iv)),
            (bits(&wu32), bits(&wv32)),
            "{name}: invert_soa_f32"
        );
        let aos32: Vec<f32> = (0..3 * n).map(|k| dir32[k % 3][k / 3]).collect();
        let mut p = vec![0.0f32; n];
        assert_eq!(
            unsafe { gonio_pdf_batch_f32(h, aos32.as_ptr(), n, p.as_mut_ptr()) },
            GONIO_OK
        );
        assert_eq!(bits(&p), bits(&wpdf32), "{name}: pdf_f32 (AoS)");
        let mut back = vec![0.0f32; 2 * n];
        assert_eq!(
            unsafe { gonio_invert_batch_f32(h, aos32.as_ptr(), n, back.as_mut_ptr()) },
            GONIO_OK
        );
        let wuv: Vec<f32> = (0..2 * n)
            .map(|k| if k % 2 == 0 { wu32[k / 2] } else { wv32[k / 2] })
            .collect();
        assert_eq!(bits(&back), bits(&wuv), "{name}: invert_f32 (AoS)");
        unsafe { gonio_sampler_free(h) };
    }
}

/// The C ABI's float32 SoA batches of an HDS map give its float32 map's bits
/// (`gonio::mapping::Float32Map`: f32 tables and arithmetic), not the f64 map rounded.
#[test]
#[allow(clippy::needless_range_loop)] // columns indexed by element on purpose
fn float32_batches_give_the_float32_maps_bits() {
    use gonio::synthetic::{example_luminaire, random_hemisphere, Family};
    use gonio::{HemisphereMap, SphereMap};
    let n = 600; // two full chunks and a partial one
    let u: Vec<f32> = (0..n)
        .map(|i| ((i * 7919 % 1000) as f32 + 0.5) / 1000.0)
        .collect();
    let v: Vec<f32> = (0..n)
        .map(|i| ((i * 104_729 % 1000) as f32 + 0.5) / 1000.0)
        .collect();
    let hemi = HemisphereMap::new(&random_hemisphere(Family::ZeroHeavy, 9, 12, true, 4)).unwrap();
    let sphere = SphereMap::new(&example_luminaire()).unwrap();
    let cases: [(&str, gonio::mapping::Float32Map, Box<dyn gonio::Sampler>); 2] = [
        ("hemisphere", hemi.float32_map().unwrap(), Box::new(hemi)),
        ("sphere", sphere.float32_map().unwrap(), Box::new(sphere)),
    ];
    for (name, f, s) in cases {
        let h = handle(s);
        let mut o = [vec![0.0f32; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [x, y, z, p] = &mut o;
        let st = unsafe {
            gonio_sample_batch_soa_f32(
                h,
                u.as_ptr(),
                v.as_ptr(),
                n,
                x.as_mut_ptr(),
                y.as_mut_ptr(),
                z.as_mut_ptr(),
                p.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK);
        let mut w = [vec![0.0f32; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        {
            let [x, y, z, p] = &mut w;
            f.sample_soa(&u, &v, [x, y, z], p);
        }
        for c in 0..4 {
            assert_eq!(bits(&o[c]), bits(&w[c]), "{name}: sample column {c}");
        }
        // The C ABI normalises f32 directions in double and rounds them to float first (its one
        // f32 rule): the float32 map is called on those.
        let d: [Vec<f32>; 3] = {
            let mut d: [Vec<f32>; 3] = [vec![], vec![], vec![]];
            for k in 0..n {
                let e = [o[0][k], o[1][k], o[2][k]].map(f64::from);
                let e = gonio::sampler::normalize(e).unwrap();
                for c in 0..3 {
                    d[c].push(e[c] as f32);
                }
            }
            d
        };
        let mut p = vec![0.0f32; n];
        let st = unsafe {
            gonio_pdf_batch_soa_f32(
                h,
                o[0].as_ptr(),
                o[1].as_ptr(),
                o[2].as_ptr(),
                n,
                p.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK);
        let mut wp = vec![0.0f32; n];
        f.pdf_soa([&d[0], &d[1], &d[2]], &mut wp);
        assert_eq!(bits(&p), bits(&wp), "{name}: pdf");
        let (mut iu, mut iv) = (vec![0.0f32; n], vec![0.0f32; n]);
        let st = unsafe {
            gonio_invert_batch_soa_f32(
                h,
                o[0].as_ptr(),
                o[1].as_ptr(),
                o[2].as_ptr(),
                n,
                iu.as_mut_ptr(),
                iv.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK);
        let (mut wu, mut wv) = (vec![0.0f32; n], vec![0.0f32; n]);
        f.invert_soa_nonzero([&d[0], &d[1], &d[2]], [&mut wu, &mut wv]);
        assert_eq!(
            (bits(&iu), bits(&iv)),
            (bits(&wu), bits(&wv)),
            "{name}: invert"
        );
        // And it is the float32 map, not the f64 map rounded: some pdf differs from that.
        let mut r = vec![0.0f64; n];
        let dw: [Vec<f64>; 3] = std::array::from_fn(|c| d[c].iter().map(|&x| x as f64).collect());
        let unit: Vec<[f64; 3]> = (0..n)
            .map(|k| gonio::sampler::normalize([dw[0][k], dw[1][k], dw[2][k]]).unwrap())
            .collect();
        for k in 0..n {
            r[k] = unsafe { &*h }.inner.pdf(unit[k]);
        }
        assert!(
            (0..n).any(|k| (r[k] as f32).to_bits() != p[k].to_bits()),
            "{name}: the float32 batch equals the f64 map rounded everywhere"
        );
        unsafe { gonio_sampler_free(h) };
    }
}

#[test]
fn a_bad_input_in_a_later_chunk_of_a_soa_batch_is_named_and_earlier_chunks_written() {
    use gonio::{Domain, Method};
    let h = handle(
        Method::Hds
            .build(&gonio::synthetic::example_luminaire(), Domain::Sphere)
            .unwrap(),
    );
    let n = 300;
    let mut u = vec![0.5f32; n];
    let v = vec![0.25f32; n];
    u[280] = f32::NAN;
    let mut o = [
        vec![-7.0f32; n],
        vec![-7.0; n],
        vec![-7.0; n],
        vec![-7.0; n],
    ];
    let [x, y, z, p] = &mut o;
    let st = unsafe {
        gonio_sample_batch_soa_f32(
            h,
            u.as_ptr(),
            v.as_ptr(),
            n,
            x.as_mut_ptr(),
            y.as_mut_ptr(),
            z.as_mut_ptr(),
            p.as_mut_ptr(),
        )
    };
    assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
    assert!(last_error().starts_with("point #280: "), "{}", last_error());
    // The first chunk (256 points) is written, the second is not.
    assert!(o[3][..256].iter().all(|&q| q > 0.0));
    assert!(o[3][256..].iter().all(|&q| q == -7.0));
    let zero = [0.0f64; 1];
    let mut out = [0.0f64; 1];
    let st = unsafe {
        gonio_pdf_batch_soa(
            h,
            zero.as_ptr(),
            zero.as_ptr(),
            zero.as_ptr(),
            1,
            out.as_mut_ptr(),
        )
    };
    assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
    assert!(
        last_error().starts_with("direction #0: "),
        "{}",
        last_error()
    );
    unsafe { gonio_sampler_free(h) };
}
