//! Environment maps at the C boundary: an equirectangular HDR image (`.hdr`, `.exr`, `.pfm`)
//! read into a [`GonioEnvMap`] (the library's [`EnvironmentMap`] with default options: the HDS
//! sphere map of the image's luminance), sampled, evaluated and inverted one point at a time or
//! in a batch. Same rules as the rest of the ABI: status codes, the thread-local message, NULL
//! pointers refused, panics caught, outputs written only on success.

use super::{
    check_in, check_len, check_out, guard, in_square, invert_error, path_of, r, read_bounded,
    too_large, unit, w, Failure, GonioStatus, GONIO_ERR_BUILD, GONIO_ERR_PARSE,
    GONIO_MAX_FILE_BYTES,
};
use gonio::envmap::EnvironmentMap;
use gonio::image::{Image, ImageError, ImageFormat};
use std::ffi::{c_char, CStr};
use std::path::Path;

/// An environment light read from an equirectangular image (opaque). Created by
/// [`gonio_envmap_read_path`] or [`gonio_envmap_read_memory`], released by [`gonio_envmap_free`].
/// Immutable: may be used from any number of threads at once.
pub struct GonioEnvMap {
    inner: EnvironmentMap,
}

/// Decodes image bytes and builds the map, with the messages of the CLI.
fn build_env(
    name: &str,
    bytes: &[u8],
    format: Option<ImageFormat>,
) -> Result<GonioEnvMap, Failure> {
    let image = Image::from_bytes(bytes, format).map_err(|e| {
        let msg = match e {
            ImageError::Io { .. } => e.to_string(),
            other => format!("{name}: {other}"),
        };
        Failure::new(GONIO_ERR_PARSE, msg)
    })?;
    let inner = EnvironmentMap::new(image)
        .map_err(|e| Failure::new(GONIO_ERR_BUILD, format!("{name}: {e}")))?;
    Ok(GonioEnvMap { inner })
}

/// Reads an equirectangular environment map (Radiance `.hdr`, OpenEXR `.exr` or `.pfm`) from a
/// path; the format is chosen by the file's first bytes, else by its extension. Files larger than
/// [`GONIO_MAX_FILE_BYTES`] and anything that is not a regular file are refused
/// (`GONIO_ERR_IO`); a file that does not decode is
/// [`GONIO_ERR_PARSE`], an all-black image [`GONIO_ERR_BUILD`]. On success `*out` receives a new
/// handle that the caller releases with [`gonio_envmap_free`].
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string; `out` must be NULL or valid for writing a
/// pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_read_path(
    path: *const c_char,
    out: *mut *mut GonioEnvMap,
) -> GonioStatus {
    guard(|| {
        check_out(out, "out")?;
        if path.is_null() {
            return Err(Failure::null("path"));
        }
        let raw = CStr::from_ptr(path);
        let owned = path_of(raw)?;
        let lossy = raw.to_string_lossy();
        let name: &str = &lossy;
        let bytes = read_bounded(&owned, name)?;
        let format = ImageFormat::sniff(&bytes).or_else(|| ImageFormat::from_path(Path::new(name)));
        let e = build_env(name, &bytes, format)?;
        w(out, Box::into_raw(Box::new(e)), "out")
    })
}

/// Reads an environment map from `len` bytes at `data`, the format announced by the first bytes
/// (`#?` Radiance, `PF` PFM, the OpenEXR magic number). `name` (may be NULL, then `"<memory>"`)
/// is used in messages. More than [`GONIO_MAX_FILE_BYTES`] bytes are refused. On success `*out`
/// receives a new handle that the caller releases with [`gonio_envmap_free`].
///
/// # Safety
/// `data` must be NULL or valid for reading `len` bytes; `name` NULL or a NUL-terminated string;
/// `out` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_read_memory(
    data: *const u8,
    len: usize,
    name: *const c_char,
    out: *mut *mut GonioEnvMap,
) -> GonioStatus {
    guard(|| {
        check_out(out, "out")?;
        if data.is_null() && len > 0 {
            return Err(Failure::null("data"));
        }
        let name = if name.is_null() {
            "<memory>"
        } else {
            super::c_str(name, "name")?
        };
        if len as u64 > GONIO_MAX_FILE_BYTES {
            return Err(too_large(name, len as u64));
        }
        if len == 0 {
            return Err(Failure::new(
                GONIO_ERR_PARSE,
                format!("{name}: the input is empty (0 bytes)"),
            ));
        }
        let bytes = std::slice::from_raw_parts(data, len);
        let e = build_env(name, bytes, None)?;
        w(out, Box::into_raw(Box::new(e)), "out")
    })
}

/// Releases an environment map handle. NULL is accepted and ignored.
///
/// # Safety
/// `map` must be NULL or a handle from a `gonio_envmap_read_*` function that was not freed yet,
/// and no other thread may be using it.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_free(map: *mut GonioEnvMap) {
    if !map.is_null() {
        let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| drop(Box::from_raw(map))));
    }
}

/// Maps the point (u, v) of the unit square to a unit direction `dir[3]`, its exact density
/// `*pdf` (per steradian, equal to [`gonio_envmap_pdf`] there) and the image's linear RGB
/// radiance `rgb[3]` in that direction. A point outside [0, 1]² or with a NaN coordinate is
/// `GONIO_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `map` must be NULL or a live handle; `dir` and `rgb` NULL or valid for writing 3 doubles /
/// 3 floats; `pdf` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_sample(
    map: *const GonioEnvMap,
    u: f64,
    v: f64,
    dir: *mut f64,
    pdf: *mut f64,
    rgb: *mut f32,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        check_out(dir, "dir")?;
        check_out(pdf, "pdf")?;
        check_out(rgb, "rgb")?;
        let s = m.inner.sample(in_square([u, v])?);
        for k in 0..3 {
            dir.add(k).write(s.direction[k]);
            rgb.add(k).write(s.radiance[k]);
        }
        w(pdf, s.pdf, "pdf")
    })
}

/// The density of [`gonio_envmap_sample`] at direction (x, y, z) (normalised first), per
/// steradian. A zero or non-finite vector is
/// `GONIO_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `map` must be NULL or a live handle; `pdf` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_pdf(
    map: *const GonioEnvMap,
    x: f64,
    y: f64,
    z: f64,
    pdf: *mut f64,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        check_out(pdf, "pdf")?;
        let d = unit([x, y, z])?;
        w(pdf, m.inner.pdf(d), "pdf")
    })
}

/// The point (u, v) of the unit square that [`gonio_envmap_sample`] maps to direction
/// (x, y, z). `GONIO_ERR_ZERO_DENSITY` for a direction where
/// the density is 0 (a black part of the image: no point maps to it).
///
/// # Safety
/// `map` must be NULL or a live handle; `u` and `v` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_invert(
    map: *const GonioEnvMap,
    x: f64,
    y: f64,
    z: f64,
    u: *mut f64,
    v: *mut f64,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        check_out(u, "u")?;
        check_out(v, "v")?;
        let d = unit([x, y, z])?;
        let p = m.inner.invert(d).map_err(invert_error)?;
        w(u, p[0], "u")?;
        w(v, p[1], "v")
    })
}

/// The image's linear RGB radiance `rgb[3]` in direction (x, y, z) (normalised first), by the
/// map's lookup (nearest pixel). A zero or non-finite vector is
/// `GONIO_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `map` must be NULL or a live handle; `rgb` NULL or valid for writing 3 floats.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_eval(
    map: *const GonioEnvMap,
    x: f64,
    y: f64,
    z: f64,
    rgb: *mut f32,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        check_out(rgb, "rgb")?;
        let d = unit([x, y, z])?;
        let c = m.inner.eval(d);
        for (k, x) in c.iter().enumerate() {
            rgb.add(k).write(*x);
        }
        Ok(())
    })
}

/// Samples `n` points `uv[2n]` (u, v interleaved): unit directions into `dirs[3n]`, densities
/// into `pdf[n]`, RGB radiance into `rgb[3n]`, element i as [`gonio_envmap_sample`] gives it. A
/// point outside the unit square (or NaN) stops the batch with
/// `GONIO_ERR_INVALID_ARGUMENT` naming its index; every
/// point is checked before any output is written, and every input is read before any output is
/// written (an output may overlap `uv`). `n = 0` does nothing (the pointers are still checked).
///
/// # Safety
/// `map` must be NULL or a live handle; `uv` NULL or valid for reading 2n doubles; `dirs`,
/// `pdf`, `rgb` NULL or valid for writing 3n doubles, n doubles, 3n floats.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_sample_batch(
    map: *const GonioEnvMap,
    uv: *const f64,
    n: usize,
    dirs: *mut f64,
    pdf: *mut f64,
    rgb: *mut f32,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        check_in(uv, "uv")?;
        check_out(dirs, "dirs")?;
        check_out(pdf, "pdf")?;
        check_out(rgb, "rgb")?;
        check_len::<f64>(n, 3)?;
        if n == 0 {
            return Ok(());
        }
        let pts = std::slice::from_raw_parts(uv, 2 * n).to_vec();
        for (i, p) in pts.chunks_exact(2).enumerate() {
            in_square([p[0], p[1]])
                .map_err(|e| Failure::invalid(format!("point #{i}: {}", e.message)))?;
        }
        for i in 0..n {
            let s = m.inner.sample([pts[2 * i], pts[2 * i + 1]]);
            for k in 0..3 {
                dirs.add(3 * i + k).write(s.direction[k]);
                rgb.add(3 * i + k).write(s.radiance[k]);
            }
            pdf.add(i).write(s.pdf);
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{
        gonio_last_error_message, GONIO_ERR_INVALID_ARGUMENT, GONIO_ERR_IO, GONIO_ERR_NULL_POINTER,
        GONIO_OK,
    };
    use std::ptr::{null, null_mut};

    /// A PFM file (little-endian RGB, rows bottom to top) of `w × h` pixels, `f(col, row)`.
    fn pfm(w: usize, h: usize, f: impl Fn(usize, usize) -> [f32; 3]) -> Vec<u8> {
        let mut b = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
        for row in 0..h {
            for col in 0..w {
                for c in f(col, row) {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
        b
    }

    fn last_error() -> String {
        unsafe { CStr::from_ptr(gonio_last_error_message()) }
            .to_string_lossy()
            .into_owned()
    }

    fn read(bytes: &[u8]) -> (GonioStatus, *mut GonioEnvMap) {
        let mut m = null_mut();
        let st = unsafe {
            gonio_envmap_read_memory(bytes.as_ptr(), bytes.len(), c"sky".as_ptr(), &mut m)
        };
        (st, m)
    }

    #[test]
    fn constant_sky_is_uniform_and_round_trips() {
        let (st, m) = read(&pfm(8, 4, |_, _| [0.5, 1.0, 2.0]));
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let uniform = 1.0 / (4.0 * std::f64::consts::PI);
        for &(u, v) in &[(0.1, 0.2), (0.5, 0.5), (0.93, 0.71), (0.0, 1.0)] {
            let (mut d, mut p, mut c) = ([0.0; 3], 0.0, [0.0f32; 3]);
            let st =
                unsafe { gonio_envmap_sample(m, u, v, d.as_mut_ptr(), &mut p, c.as_mut_ptr()) };
            assert_eq!(st, GONIO_OK, "{}", last_error());
            assert!((p - uniform).abs() < 1e-12, "pdf {p} at ({u}, {v})");
            assert_eq!(c, [0.5, 1.0, 2.0]);
            let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            assert!((norm - 1.0).abs() < 1e-12);
            let mut q = 0.0;
            let st = unsafe { gonio_envmap_pdf(m, d[0], d[1], d[2], &mut q) };
            assert_eq!(st, GONIO_OK);
            assert_eq!(q, p);
            let mut e = [0.0f32; 3];
            let st = unsafe { gonio_envmap_eval(m, d[0], d[1], d[2], e.as_mut_ptr()) };
            assert_eq!(st, GONIO_OK);
            assert_eq!(e, c);
            if v < 1.0 {
                let (mut iu, mut iv) = (0.0, 0.0);
                let st = unsafe { gonio_envmap_invert(m, d[0], d[1], d[2], &mut iu, &mut iv) };
                assert_eq!(st, GONIO_OK, "{}", last_error());
                assert!(
                    (iu - u).abs() < 1e-9 && (iv - v).abs() < 1e-9,
                    "({iu}, {iv})"
                );
            }
        }
        unsafe { gonio_envmap_free(m) };
    }

    #[test]
    fn bright_pixel_batch_agrees_with_single_points() {
        // One bright pixel in a dim sky: the density is far from uniform.
        let bytes = pfm(16, 8, |c, r| {
            if (c, r) == (5, 2) {
                [100.0, 50.0, 10.0]
            } else {
                [0.1, 0.1, 0.1]
            }
        });
        let (st, m) = read(&bytes);
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let n = 50;
        let uv: Vec<f64> = (0..2 * n)
            .map(|k| ((k * 37 + 11) % 101) as f64 / 100.0)
            .collect();
        let (mut dirs, mut pdf, mut rgb) = (vec![0.0; 3 * n], vec![0.0; n], vec![0.0f32; 3 * n]);
        let st = unsafe {
            gonio_envmap_sample_batch(
                m,
                uv.as_ptr(),
                n,
                dirs.as_mut_ptr(),
                pdf.as_mut_ptr(),
                rgb.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let mut max_pdf: f64 = 0.0;
        for i in 0..n {
            let (mut d, mut p, mut c) = ([0.0; 3], 0.0, [0.0f32; 3]);
            let st = unsafe {
                gonio_envmap_sample(
                    m,
                    uv[2 * i],
                    uv[2 * i + 1],
                    d.as_mut_ptr(),
                    &mut p,
                    c.as_mut_ptr(),
                )
            };
            assert_eq!(st, GONIO_OK);
            assert_eq!(&dirs[3 * i..3 * i + 3], &d);
            assert_eq!(pdf[i], p);
            assert_eq!(&rgb[3 * i..3 * i + 3], &c);
            let mut q = 0.0;
            assert_eq!(
                unsafe { gonio_envmap_pdf(m, d[0], d[1], d[2], &mut q) },
                GONIO_OK
            );
            assert!((q - p).abs() <= 1e-9 * p, "pdf {q} vs sample {p}");
            max_pdf = max_pdf.max(p);
        }
        assert!(
            max_pdf > 10.0 / (4.0 * std::f64::consts::PI),
            "max pdf {max_pdf}"
        );
        // A NaN point stops the batch with its index; nothing is written.
        let mut bad = uv.clone();
        bad[2 * 7 + 1] = f64::NAN;
        let mut pdf2 = vec![-1.0; n];
        let st = unsafe {
            gonio_envmap_sample_batch(
                m,
                bad.as_ptr(),
                n,
                dirs.as_mut_ptr(),
                pdf2.as_mut_ptr(),
                rgb.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(last_error().starts_with("point #7: "), "{}", last_error());
        assert!(pdf2.iter().all(|&p| p == -1.0));
        unsafe { gonio_envmap_free(m) };
    }

    #[test]
    fn errors_have_codes_and_messages() {
        let (st, m) = read(&pfm(4, 2, |_, _| [1.0; 3]));
        assert_eq!(st, GONIO_OK);
        let (mut d, mut p, mut c) = ([0.0; 3], 0.0, [0.0f32; 3]);
        let st =
            unsafe { gonio_envmap_sample(m, 1.5, 0.5, d.as_mut_ptr(), &mut p, c.as_mut_ptr()) };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(
            last_error().contains("outside the unit square"),
            "{}",
            last_error()
        );
        let st = unsafe { gonio_envmap_sample(m, 0.5, 0.5, null_mut(), &mut p, c.as_mut_ptr()) };
        assert_eq!(st, GONIO_ERR_NULL_POINTER);
        assert_eq!(last_error(), "dir is NULL or not aligned for its type");
        let st = unsafe { gonio_envmap_pdf(null(), 0.0, 0.0, 1.0, &mut p) };
        assert_eq!(st, GONIO_ERR_NULL_POINTER);
        let st = unsafe { gonio_envmap_pdf(m, 0.0, 0.0, 0.0, &mut p) };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        let st = unsafe { gonio_envmap_eval(m, f64::NAN, 0.0, 1.0, c.as_mut_ptr()) };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        unsafe { gonio_envmap_free(m) };
        unsafe { gonio_envmap_free(null_mut()) };

        // An all-black image cannot be sampled; garbage does not decode; nothing is handed out.
        let (st, m) = read(&pfm(4, 2, |_, _| [0.0; 3]));
        assert_eq!((st, m), (GONIO_ERR_BUILD, null_mut()));
        assert!(last_error().starts_with("sky: "), "{}", last_error());
        let (st, m) = read(b"not an image");
        assert_eq!((st, m), (GONIO_ERR_PARSE, null_mut()));
        let (st, _) = read(&pfm(4, 2, |_, _| [1.0; 3])[..20]);
        assert_eq!(st, GONIO_ERR_PARSE, "{}", last_error());
        let mut m = null_mut();
        let st = unsafe { gonio_envmap_read_memory(null(), 3, null(), &mut m) };
        assert_eq!(st, GONIO_ERR_NULL_POINTER);
        let st = unsafe { gonio_envmap_read_memory(null(), 0, null(), &mut m) };
        assert_eq!(st, GONIO_ERR_PARSE);
        assert_eq!(last_error(), "<memory>: the input is empty (0 bytes)");

        // Paths: a missing file and a directory are I/O errors; a written file reads.
        let st = unsafe { gonio_envmap_read_path(c"/nonexistent/sky.pfm".as_ptr(), &mut m) };
        assert_eq!(st, GONIO_ERR_IO);
        assert!(
            last_error().starts_with("cannot read /nonexistent/sky.pfm: "),
            "{}",
            last_error()
        );
        let st = unsafe { gonio_envmap_read_path(c"/".as_ptr(), &mut m) };
        assert_eq!(st, GONIO_ERR_IO);
        assert!(
            last_error().ends_with("not a regular file"),
            "{}",
            last_error()
        );
        let file = std::env::temp_dir().join(format!("gonio-capi-env-{}.pfm", std::process::id()));
        std::fs::write(&file, pfm(4, 2, |_, _| [1.0; 3])).unwrap();
        let cpath = std::ffi::CString::new(file.to_str().unwrap()).unwrap();
        let st = unsafe { gonio_envmap_read_path(cpath.as_ptr(), &mut m) };
        std::fs::remove_file(&file).ok();
        assert_eq!(st, GONIO_OK, "{}", last_error());
        unsafe { gonio_envmap_free(m) };
    }

    #[test]
    fn size_cap_fifo_and_zero_density() {
        let dir = std::env::temp_dir().join(format!("gonio-capi-env-cap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A sparse file one byte over the cap: refused by its size, nothing read.
        let big = dir.join("big.hdr");
        std::fs::File::create(&big)
            .unwrap()
            .set_len(GONIO_MAX_FILE_BYTES + 1)
            .unwrap();
        let path = std::ffi::CString::new(big.to_str().unwrap()).unwrap();
        let mut m = null_mut();
        let st = unsafe { gonio_envmap_read_path(path.as_ptr(), &mut m) };
        assert_eq!(st, GONIO_ERR_IO);
        assert!(
            last_error().contains("more than the limit of 67108864 bytes"),
            "{}",
            last_error()
        );
        // A FIFO without a writer is refused before it is opened (opening would block).
        let fifo = dir.join("sky.hdr");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        if made {
            let path = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
            let st = unsafe { gonio_envmap_read_path(path.as_ptr(), &mut m) };
            assert_eq!(st, GONIO_ERR_IO);
            assert!(
                last_error().ends_with("not a regular file"),
                "{}",
                last_error()
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
        assert!(m.is_null());

        // The upper half black (PFM rows run bottom to top, so rows 2 and 3 are the top): the
        // zenith has density 0, no point maps to it.
        let (st, m) = read(&pfm(8, 4, |_, r| if r >= 2 { [0.0; 3] } else { [1.0; 3] }));
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let (mut p, mut u, mut v) = (-1.0, 0.0, 0.0);
        assert_eq!(
            unsafe { gonio_envmap_pdf(m, 0.0, 0.0, 1.0, &mut p) },
            GONIO_OK
        );
        assert_eq!(p, 0.0);
        let st = unsafe { gonio_envmap_invert(m, 0.0, 0.0, 1.0, &mut u, &mut v) };
        assert_eq!(st, crate::GONIO_ERR_ZERO_DENSITY, "{}", last_error());
        assert!(unsafe { gonio_envmap_pdf(m, 0.0, 0.0, -1.0, &mut p) } == GONIO_OK && p > 0.0);
        unsafe { gonio_envmap_free(m) };
    }
}
