//! The C ABI under abuse (issue 25): NaN points, FIFOs, huge and oddly named files, empty
//! memory, methods without inverse, tiny numbers in messages.

use super::test_support::{diagram_of, last_error, IES};
use super::*;
use std::ffi::CString;
use std::path::PathBuf;
use std::ptr::{null, null_mut};

fn sampler(method: GonioMethod) -> *mut GonioSampler {
    let d = diagram_of(IES, GONIO_FORMAT_IES);
    let mut s = null_mut();
    let st = unsafe { gonio_sampler_build(d, method, GONIO_DOMAIN_AUTO, &mut s) };
    assert_eq!(st, GONIO_OK, "{}", last_error());
    unsafe { gonio_diagram_free(d) };
    s
}

/// A scratch directory of this test process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gonio-capi-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn nan_and_outside_points_are_invalid_arguments_with_the_row() {
    for method in [
        GONIO_METHOD_HDS,
        GONIO_METHOD_BILINEAR,
        GONIO_METHOD_REJECTION,
    ] {
        let s = sampler(method);
        let mut smp = GonioSample::default();
        for (u, v) in [(f64::NAN, 0.5), (0.5, f64::NAN), (1.5, 0.5), (0.5, -1e-300)] {
            let st = unsafe { gonio_sample(s, u, v, &mut smp) };
            assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT, "({u}, {v})");
            assert!(
                last_error().contains("outside the unit square"),
                "{}",
                last_error()
            );
        }
        assert!(last_error().contains("-1e-300"), "{}", last_error());
        // A batch names the first bad point.
        let mut u = vec![0.5f64; 2 * 600];
        u[2 * 517 + 1] = f64::NAN;
        let (mut dirs, mut pdfs) = (vec![0.0; 3 * 600], vec![0.0; 600]);
        let st =
            unsafe { gonio_sample_batch(s, u.as_ptr(), 600, dirs.as_mut_ptr(), pdfs.as_mut_ptr()) };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(last_error().contains("point #517"), "{}", last_error());
        let uf: Vec<f32> = u.iter().map(|&x| x as f32).collect();
        let (mut df, mut pf) = (vec![0.0f32; 3 * 600], vec![0.0f32; 600]);
        let st = unsafe {
            gonio_sample_batch_f32(s, uf.as_ptr(), 600, df.as_mut_ptr(), pf.as_mut_ptr())
        };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(last_error().contains("point #517"), "{}", last_error());
        unsafe { gonio_sampler_free(s) };
    }
}

#[test]
fn reading_a_fifo_fails_at_once() {
    let dir = scratch("fifo");
    let fifo = dir.join("pipe.ies");
    let path = CString::new(fifo.to_str().unwrap()).unwrap();
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.map(|s| s.success()).unwrap_or(false) {
        eprintln!("SKIPPED: mkfifo is not available");
        return;
    }
    // Before the fix, open() blocked forever on a FIFO without a writer: run it on a thread and
    // fail after 20 s instead of hanging the suite.
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut d = null_mut();
        let st = unsafe { gonio_diagram_read_path(path.as_ptr(), GONIO_FORMAT_AUTO, &mut d) };
        let _ = tx.send((st, last_error()));
    });
    let (st, msg) = rx
        .recv_timeout(std::time::Duration::from_secs(20))
        .expect("gonio_diagram_read_path blocked on a FIFO");
    assert_eq!(st, GONIO_ERR_IO);
    assert!(msg.contains("not a regular file"), "{msg}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_size_cap_is_checked_before_reading_and_paths_may_be_any_bytes() {
    use std::os::unix::ffi::OsStrExt;
    let dir = scratch("files");
    // A sparse file one byte over the cap: refused by its size, nothing read.
    let big = dir.join("big.ies");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(GONIO_MAX_FILE_BYTES + 1)
        .unwrap();
    let path = CString::new(big.to_str().unwrap()).unwrap();
    let mut d = null_mut();
    let st = unsafe { gonio_diagram_read_path(path.as_ptr(), GONIO_FORMAT_AUTO, &mut d) };
    assert_eq!(st, GONIO_ERR_IO);
    assert!(
        last_error().contains("more than the limit of 67108864 bytes"),
        "{}",
        last_error()
    );
    assert_eq!(GONIO_MAX_FILE_BYTES, gonio::photometry::MAX_FILE_BYTES);
    // A file name that is not UTF-8 (valid on Linux, as in Python).
    let mut name = dir.as_os_str().as_bytes().to_vec();
    name.extend_from_slice(b"/lamp-\xff\xfe.ies");
    let odd = PathBuf::from(std::ffi::OsStr::from_bytes(&name));
    std::fs::write(&odd, IES).unwrap();
    let path = CString::new(name).unwrap();
    let st = unsafe { gonio_diagram_read_path(path.as_ptr(), GONIO_FORMAT_AUTO, &mut d) };
    assert_eq!(st, GONIO_OK, "{}", last_error());
    unsafe { gonio_diagram_free(d) };
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn empty_memory_says_empty() {
    let mut d = null_mut();
    for data in [null(), IES.as_ptr()] {
        let st = unsafe { gonio_diagram_read_memory(data, 0, GONIO_FORMAT_IES, null(), &mut d) };
        assert_eq!(st, GONIO_ERR_PARSE);
        assert!(last_error().contains("is empty"), "{}", last_error());
    }
    let st = unsafe { gonio_diagram_read_memory(null(), 5, GONIO_FORMAT_IES, null(), &mut d) };
    assert_eq!(st, GONIO_ERR_NULL_POINTER);
}

#[test]
fn invert_batch_without_inverse_is_unsupported_for_every_n() {
    let s = sampler(GONIO_METHOD_REJECTION);
    let dirs = [0.0, 0.0, -1.0];
    let mut uv = [0.0; 2];
    for n in [0, 1] {
        let st = unsafe { gonio_invert_batch(s, dirs.as_ptr(), n, uv.as_mut_ptr()) };
        assert_eq!(st, GONIO_ERR_UNSUPPORTED, "n = {n}");
        let (mut u, mut v) = ([0.0f32], [0.0f32]);
        let d = [0.0f32, 0.0, -1.0];
        let st = unsafe {
            gonio_invert_batch_soa_f32(
                s,
                d.as_ptr(),
                d[1..].as_ptr(),
                d[2..].as_ptr(),
                n,
                u.as_mut_ptr(),
                v.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_ERR_UNSUPPORTED, "n = {n}");
    }
    unsafe { gonio_sampler_free(s) };
}

#[test]
fn zero_density_inverse_is_refused_by_every_invertible_method() {
    for method in [
        GONIO_METHOD_HDS,
        GONIO_METHOD_PIECEWISE_CONSTANT,
        GONIO_METHOD_BILINEAR,
    ] {
        let s = sampler(method);
        let (mut u, mut v) = (0.0, 0.0);
        let st = unsafe { gonio_invert(s, 0.0, 0.0, 1.0, &mut u, &mut v) };
        assert_eq!(
            st,
            GONIO_ERR_ZERO_DENSITY,
            "method {method}: {}",
            last_error()
        );
        unsafe { gonio_sampler_free(s) };
    }
}

/// Issue 40's reproducers through the C ABI: huge BRDF values refused by name, a diagram whose
/// power overflows refused by name, `/dev/zero` refused as not a regular file, a PFM whose header
/// ends in "\r\n" refused or read right (never one byte off).
#[test]
fn issue_40_reproducers() {
    // Item 1: a BRDF JSON table of 1.7e308 everywhere.
    let values = vec!["1.7e308"; 3 * 3 * 3 * 4].join(", ");
    let js = format!(
        "{{\"format\": \"gonio-brdf\", \"version\": 1, \"symmetry\": \"isotropic\", \"channels\": 3, \
         \"theta_i_deg\": [0, 45, 90], \"phi_i_deg\": [0], \"theta_o_deg\": [0, 45, 90], \
         \"phi_o_deg\": [0, 90, 180, 270], \"values\": [{values}]}}"
    );
    let mut b = null_mut();
    let name = CString::new("huge.json").unwrap();
    let st =
        unsafe { gonio_brdf_read_memory(js.as_ptr(), js.len(), name.as_ptr(), null(), &mut b) };
    assert_ne!(st, GONIO_OK);
    let e = last_error();
    assert!(e.contains("huge.json") && e.contains("1.7e308"), "{e}");
    // Item 1: a diagram whose power overflows f64.
    let json =
        "{\"theta_deg\": [0, 90, 180], \"phi_deg\": [0], \"values\": [[1e308, 1e308, 1e308]]}";
    let d = diagram_of(json, GONIO_FORMAT_JSON);
    let mut s = null_mut();
    let st = unsafe { gonio_sampler_build(d, GONIO_METHOD_HDS, GONIO_DOMAIN_AUTO, &mut s) };
    assert_eq!(st, GONIO_ERR_BUILD);
    let e = last_error();
    assert!(e.contains("1e308") && e.contains("overflow"), "{e}");
    unsafe { gonio_diagram_free(d) };
    // Item 2: not a regular file.
    let mut m = null_mut();
    let path = CString::new("/dev/zero").unwrap();
    let st = unsafe { gonio_envmap_read_path(path.as_ptr(), &mut m) };
    assert_eq!(st, GONIO_ERR_IO);
    assert!(last_error().contains("regular"), "{}", last_error());
    // Item 5: a PFM header ending in "\r\n".
    let mut pfm = b"PF\n2 2\n-1.0\r\n".to_vec();
    for _ in 0..12 {
        pfm.extend_from_slice(&0.7f32.to_le_bytes());
    }
    let name = CString::new("crlf.pfm").unwrap();
    let st = unsafe { gonio_envmap_read_memory(pfm.as_ptr(), pfm.len(), name.as_ptr(), &mut m) };
    if st == GONIO_OK {
        let mut dir = [0.0f64; 3];
        let (mut pdf, mut rgb) = (0.0, [0.0f32; 3]);
        let st = unsafe {
            gonio_envmap_sample(m, 0.3, 0.6, dir.as_mut_ptr(), &mut pdf, rgb.as_mut_ptr())
        };
        assert_eq!(st, GONIO_OK);
        assert!(rgb.iter().all(|c| (c - 0.7).abs() < 1e-6), "{rgb:?}");
        unsafe { gonio_envmap_free(m) };
    } else {
        assert!(last_error().contains("crlf.pfm"), "{}", last_error());
    }
}
