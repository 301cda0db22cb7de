//! Environment maps at the C boundary: an equirectangular HDR image (`.hdr`, `.exr`, `.pfm`)
//! read into a [`GonioEnvMap`] (the library's [`EnvironmentMap`]: the HDS sphere map of the
//! image's luminance, a channel or the caller's weights, optionally MIS-compensated, see
//! [`GonioEnvOptions`]), sampled, evaluated and inverted one point at a time or in a batch, with
//! the reader's and the builder's warnings. Same rules as the rest of the ABI: status codes, the
//! thread-local message, NULL pointers refused, panics caught, outputs written only on success.

use super::{
    check_in, check_len, check_memory_len, check_out, guard, in_square, invert_error, path_of, r,
    read_bounded, unit, w, Failure, GonioStatus, GONIO_ERR_BUILD, GONIO_ERR_PARSE,
};
use gonio::envmap::{
    EnvMapError, EnvOptions, EnvironmentMap, Float32EnvironmentMap, Lookup, Weight,
};
use gonio::image::{Image, ImageError, ImageFormat};
use std::ffi::{c_char, CStr, CString};
use std::path::Path;

/// What an environment map's density is proportional to: one of the `GONIO_ENV_WEIGHT_*`
/// constants.
pub type GonioEnvWeight = i32;
/// Rec. 709 luminance Y = 0.2126 R + 0.7152 G + 0.0722 B (the default).
pub const GONIO_ENV_WEIGHT_LUMINANCE: GonioEnvWeight = 0;
/// One channel of the image, [`GonioEnvOptions::channel`] (0 = R, 1 = G, 2 = B).
pub const GONIO_ENV_WEIGHT_CHANNEL: GonioEnvWeight = 1;
/// The caller's weights [`GonioEnvOptions::custom_weights`], W × H values row-major (row 0 at
/// the top of the image), finite and ≥ 0.
pub const GONIO_ENV_WEIGHT_CUSTOM: GonioEnvWeight = 2;

/// How [`gonio_envmap_eval`] (and the radiance of a sample) reads the image: one of the
/// `GONIO_ENV_LOOKUP_*` constants.
pub type GonioEnvLookup = i32;
/// The pixel that holds the direction (the default).
pub const GONIO_ENV_LOOKUP_NEAREST: GonioEnvLookup = 0;
/// Bilinear between pixel centres, continuous across the seam and at the poles (the
/// interpolant the density follows; docs/ENVMAPS.md).
pub const GONIO_ENV_LOOKUP_BILINEAR: GonioEnvLookup = 1;

/// Options of [`gonio_envmap_read_path_with`] and [`gonio_envmap_read_memory_with`] (the
/// library's `EnvOptions`). Fill it with [`gonio_envmap_options_default`], then change fields.
/// (The struct may gain fields in later versions; always start from the defaults.)
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GonioEnvOptions {
    /// A `GONIO_ENV_WEIGHT_*` constant (default luminance).
    pub weight: GonioEnvWeight,
    /// With [`GONIO_ENV_WEIGHT_CHANNEL`]: 0 = R, 1 = G, 2 = B (default 0; ignored otherwise).
    pub channel: u32,
    /// With [`GONIO_ENV_WEIGHT_CUSTOM`]: `custom_len` floats, W × H row-major from the top row,
    /// copied during the call (default NULL; ignored otherwise).
    pub custom_weights: *const f32,
    /// The number of floats at `custom_weights`; must equal the image's W × H.
    pub custom_len: usize,
    /// A `GONIO_ENV_LOOKUP_*` constant (default nearest).
    pub lookup: GonioEnvLookup,
    /// 1: MIS compensation (the weight minus its solid-angle mean, clamped at 0; use it only
    /// with MIS, see docs/ENVMAPS.md); 0: the plain weight (the default). Other values are
    /// refused.
    pub mis_compensation: i32,
}

/// An environment light read from an equirectangular image (opaque). Created by
/// [`gonio_envmap_read_path`], [`gonio_envmap_read_memory`] or their `_with` forms, released by
/// [`gonio_envmap_free`]. Immutable: may be used from any number of threads at once.
pub struct GonioEnvMap {
    inner: EnvironmentMap,
    /// The reader's and the builder's warnings, `NAME: warning: message`.
    warnings: Vec<CString>,
}

impl GonioEnvMap {
    /// The environment map.
    pub(crate) fn inner(&self) -> &EnvironmentMap {
        &self.inner
    }
}

/// The library's options from the C struct; the custom weights are copied.
///
/// # Safety
/// `o.custom_weights` must be NULL or valid for reading `o.custom_len` floats when the weight is
/// [`GONIO_ENV_WEIGHT_CUSTOM`].
unsafe fn env_options_of(o: &GonioEnvOptions) -> Result<EnvOptions, Failure> {
    let weight = match o.weight {
        GONIO_ENV_WEIGHT_LUMINANCE => Weight::Luminance,
        GONIO_ENV_WEIGHT_CHANNEL => {
            if o.channel > 2 {
                return Err(Failure::invalid(format!(
                    "channel {} does not exist (0 = R, 1 = G, 2 = B)",
                    o.channel
                )));
            }
            Weight::Channel(o.channel as usize)
        }
        GONIO_ENV_WEIGHT_CUSTOM => {
            if o.custom_weights.is_null() || !o.custom_weights.is_aligned() {
                return Err(Failure::null("custom_weights"));
            }
            if o.custom_len > isize::MAX as usize / std::mem::size_of::<f32>() {
                return Err(Failure::invalid(format!(
                    "custom_len = {} is too large",
                    o.custom_len
                )));
            }
            Weight::Custom(std::slice::from_raw_parts(o.custom_weights, o.custom_len).to_vec())
        }
        other => {
            return Err(Failure::invalid(format!(
                "unknown weight {other}; expected GONIO_ENV_WEIGHT_LUMINANCE, _CHANNEL or _CUSTOM"
            )))
        }
    };
    let lookup = match o.lookup {
        GONIO_ENV_LOOKUP_NEAREST => Lookup::Nearest,
        GONIO_ENV_LOOKUP_BILINEAR => Lookup::Bilinear,
        other => {
            return Err(Failure::invalid(format!(
                "unknown lookup {other}; expected GONIO_ENV_LOOKUP_NEAREST or _BILINEAR"
            )))
        }
    };
    let mis_compensation = match o.mis_compensation {
        0 => false,
        1 => true,
        other => {
            return Err(Failure::invalid(format!(
                "mis_compensation is {other}; expected 0 or 1"
            )))
        }
    };
    Ok(EnvOptions {
        weight,
        lookup,
        mis_compensation,
    })
}

/// Writes the default options into `*options`: luminance weight, nearest lookup, no MIS
/// compensation.
///
/// # Safety
/// `options` must be NULL or valid for writing a [`GonioEnvOptions`].
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_options_default(
    options: *mut GonioEnvOptions,
) -> GonioStatus {
    guard(|| {
        let d = EnvOptions::default();
        w(
            options,
            GonioEnvOptions {
                weight: GONIO_ENV_WEIGHT_LUMINANCE,
                channel: 0,
                custom_weights: std::ptr::null(),
                custom_len: 0,
                lookup: match d.lookup {
                    Lookup::Bilinear => GONIO_ENV_LOOKUP_BILINEAR,
                    Lookup::Nearest => GONIO_ENV_LOOKUP_NEAREST,
                },
                mis_compensation: i32::from(d.mis_compensation),
            },
            "options",
        )
    })
}

/// Decodes image bytes and builds the map, with the messages of the CLI. A bad option (a
/// wrong number of custom weights, a negative or non-finite one) is
/// `GONIO_ERR_INVALID_ARGUMENT`, an all-black weight [`GONIO_ERR_BUILD`].
fn build_env(
    name: &str,
    bytes: &[u8],
    format: Option<ImageFormat>,
    options: EnvOptions,
) -> Result<GonioEnvMap, Failure> {
    let image = Image::from_bytes(bytes, format).map_err(|e| {
        let msg = match e {
            ImageError::File(_) => e.to_string(),
            other => format!("{name}: {other}"),
        };
        Failure::new(GONIO_ERR_PARSE, msg)
    })?;
    let inner = EnvironmentMap::with_options(image, options).map_err(|e| match e {
        EnvMapError::BadOption(_) => Failure::invalid(format!("{name}: {e}")),
        _ => Failure::new(GONIO_ERR_BUILD, format!("{name}: {e}")),
    })?;
    let warnings = inner
        .warnings()
        .iter()
        .map(|m| {
            CString::new(format!("{name}: warning: {m}").replace('\0', "\\0")).unwrap_or_default()
        })
        .collect();
    Ok(GonioEnvMap { inner, warnings })
}

/// Reads an equirectangular environment map (Radiance `.hdr`, OpenEXR `.exr` or `.pfm`) from a
/// path; the format is chosen by the file's first bytes, else by its extension. Files larger than
/// the image limit (`gonio_read_limit`) and anything that is not a regular file are refused
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
    guard(|| read_path(path, EnvOptions::default(), out))
}

/// As [`gonio_envmap_read_path`] with `options` (see [`GonioEnvOptions`]); a bad option is
/// `GONIO_ERR_INVALID_ARGUMENT`, checked before the file is read (the number of custom weights
/// after it is decoded).
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string; `options` NULL or a valid
/// [`GonioEnvOptions`] whose `custom_weights`, when used, is valid for reading `custom_len`
/// floats; `out` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_read_path_with(
    path: *const c_char,
    options: *const GonioEnvOptions,
    out: *mut *mut GonioEnvMap,
) -> GonioStatus {
    guard(|| {
        let o = env_options_of(r(options, "options")?)?;
        read_path(path, o, out)
    })
}

/// # Safety
/// As [`gonio_envmap_read_path`].
unsafe fn read_path(
    path: *const c_char,
    options: EnvOptions,
    out: *mut *mut GonioEnvMap,
) -> Result<(), Failure> {
    check_out(out, "out")?;
    if path.is_null() {
        return Err(Failure::null("path"));
    }
    let raw = CStr::from_ptr(path);
    let owned = path_of(raw)?;
    let lossy = raw.to_string_lossy();
    let name: &str = &lossy;
    let bytes = read_bounded(&owned, name, gonio::input::file::FileKind::Image)?;
    let format = ImageFormat::sniff(&bytes).or_else(|| ImageFormat::from_path(Path::new(name)));
    let e = build_env(name, &bytes, format, options)?;
    w(out, Box::into_raw(Box::new(e)), "out")
}

/// Reads an environment map from `len` bytes at `data`, the format announced by the first bytes
/// (`#?` Radiance, `PF` PFM, the OpenEXR magic number). `name` (may be NULL, then `"<memory>"`)
/// is used in messages. More bytes than the image limit (`gonio_read_limit`) are refused. On success `*out`
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
    guard(|| read_memory(data, len, name, EnvOptions::default(), out))
}

/// As [`gonio_envmap_read_memory`] with `options` (see [`GonioEnvOptions`]); a bad option is
/// `GONIO_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// As [`gonio_envmap_read_memory`]; `options` NULL or a valid [`GonioEnvOptions`] whose
/// `custom_weights`, when used, is valid for reading `custom_len` floats.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_read_memory_with(
    data: *const u8,
    len: usize,
    name: *const c_char,
    options: *const GonioEnvOptions,
    out: *mut *mut GonioEnvMap,
) -> GonioStatus {
    guard(|| {
        let o = env_options_of(r(options, "options")?)?;
        read_memory(data, len, name, o, out)
    })
}

/// # Safety
/// As [`gonio_envmap_read_memory`].
unsafe fn read_memory(
    data: *const u8,
    len: usize,
    name: *const c_char,
    options: EnvOptions,
    out: *mut *mut GonioEnvMap,
) -> Result<(), Failure> {
    check_out(out, "out")?;
    if data.is_null() && len > 0 {
        return Err(Failure::null("data"));
    }
    let name = if name.is_null() {
        "<memory>"
    } else {
        super::c_str(name, "name")?
    };
    check_memory_len(name, len, gonio::input::file::FileKind::Image)?;
    if len == 0 {
        return Err(Failure::new(
            GONIO_ERR_PARSE,
            format!("{name}: the input is empty (0 bytes)"),
        ));
    }
    let bytes = std::slice::from_raw_parts(data, len);
    let e = build_env(name, bytes, None, options)?;
    w(out, Box::into_raw(Box::new(e)), "out")
}

/// The number of warnings the reader and the builder issued (ignored channels or trailing
/// bytes, negative pixels weighted as 0, MIS compensation that left nothing above the mean).
///
/// # Safety
/// `map` must be NULL or a live handle; `count` NULL or valid for writing a `size_t`.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_warning_count(
    map: *const GonioEnvMap,
    count: *mut usize,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        w(count, m.warnings.len(), "count")
    })
}

/// Warning number `index` (from 0) as `NAME: warning: message` (NAME the path or the name
/// given to `read_memory`). The string belongs to the map handle and lives as long as it.
///
/// # Safety
/// `map` must be NULL or a live handle; `text` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_warning(
    map: *const GonioEnvMap,
    index: usize,
    text: *mut *const c_char,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        super::write_warning(&m.warnings, index, "map", text)
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
/// map's lookup ([`GonioEnvOptions::lookup`]; nearest pixel by default). A zero or non-finite vector is
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

/// The `n` directions `dirs[3n]` (x, y, z interleaved, each normalised in double), all checked
/// before anything is written: a zero or non-finite one is `GONIO_ERR_INVALID_ARGUMENT` naming its
/// index.
///
/// # Safety
/// `dirs` valid for reading 3n doubles.
unsafe fn env_dirs(dirs: *const f64, n: usize) -> Result<Vec<gonio::Vec3>, Failure> {
    let raw = std::slice::from_raw_parts(dirs, 3 * n);
    raw.chunks_exact(3)
        .enumerate()
        .map(|(i, d)| {
            unit([d[0], d[1], d[2]])
                .map_err(|e| Failure::invalid(format!("direction #{i}: {}", e.message)))
        })
        .collect()
}

/// The densities `pdf[n]` of [`gonio_envmap_sample`] at the `n` directions `dirs[3n]` (x, y, z
/// interleaved, normalised first), per steradian: element i as [`gonio_envmap_pdf`]. A zero or
/// non-finite direction stops the batch with `GONIO_ERR_INVALID_ARGUMENT` naming its index, before
/// anything is written (an output may overlap `dirs`). `n = 0` does nothing.
///
/// # Safety
/// `map` must be NULL or a live handle; `dirs` NULL or valid for reading 3n doubles; `pdf` NULL or
/// valid for writing n doubles.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_pdf_batch(
    map: *const GonioEnvMap,
    dirs: *const f64,
    n: usize,
    pdf: *mut f64,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        check_in(dirs, "dirs")?;
        check_out(pdf, "pdf")?;
        check_len::<f64>(n, 3)?;
        let d = env_dirs(dirs, n)?;
        for (i, d) in d.iter().enumerate() {
            pdf.add(i).write(m.inner.pdf(*d));
        }
        Ok(())
    })
}

/// The points `uv[2n]` (u, v interleaved) of the unit square that [`gonio_envmap_sample`] maps to
/// the `n` directions `dirs[3n]`: element i as [`gonio_envmap_invert`], but (NaN, NaN) where the
/// density is 0 (no point maps there) and the batch goes on. A zero or non-finite direction stops
/// the batch with `GONIO_ERR_INVALID_ARGUMENT` naming its index, before anything is written.
///
/// # Safety
/// `map` must be NULL or a live handle; `dirs` NULL or valid for reading 3n doubles; `uv` NULL or
/// valid for writing 2n doubles.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_invert_batch(
    map: *const GonioEnvMap,
    dirs: *const f64,
    n: usize,
    uv: *mut f64,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        check_in(dirs, "dirs")?;
        check_out(uv, "uv")?;
        check_len::<f64>(n, 3)?;
        let d = env_dirs(dirs, n)?;
        for (i, d) in d.iter().enumerate() {
            let p = m.inner.invert(*d).unwrap_or([f64::NAN; 2]);
            uv.add(2 * i).write(p[0]);
            uv.add(2 * i + 1).write(p[1]);
        }
        Ok(())
    })
}

/// The image's linear RGB radiance `rgb[3n]` at the `n` directions `dirs[3n]`: element i as
/// [`gonio_envmap_eval`]. A zero or non-finite direction stops the batch with
/// `GONIO_ERR_INVALID_ARGUMENT` naming its index, before anything is written.
///
/// # Safety
/// `map` must be NULL or a live handle; `dirs` NULL or valid for reading 3n doubles; `rgb` NULL
/// or valid for writing 3n floats.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_eval_batch(
    map: *const GonioEnvMap,
    dirs: *const f64,
    n: usize,
    rgb: *mut f32,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        check_in(dirs, "dirs")?;
        check_out(rgb, "rgb")?;
        check_len::<f64>(n, 3)?;
        let d = env_dirs(dirs, n)?;
        for (i, d) in d.iter().enumerate() {
            for (k, c) in m.inner.eval(*d).into_iter().enumerate() {
                rgb.add(3 * i + k).write(c);
            }
        }
        Ok(())
    })
}

/// Samples `n` points `uv[2n]` (u, v interleaved): unit directions into `dirs[3n]`, densities
/// into `pdf[n]`, RGB radiance into `rgb[3n]`, through the sphere map's SIMD batch path
/// ([`gonio::envmap::EnvironmentMap::sample_batch_rgb`]): element i as [`gonio_envmap_sample`]
/// gives it up to the batch round-off (directions within 1e-15, densities within 1e-12
/// relative), its radiance exactly [`gonio_envmap_eval`] of its direction. A
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
        // `gonio::batch::CHUNK` points at a time through stack buffers.
        use gonio::batch::CHUNK;
        let mut u = [[0.0f64; 2]; CHUNK];
        let (mut d, mut p, mut c) = ([[0.0f64; 3]; CHUNK], [0.0f64; CHUNK], [[0.0f32; 3]; CHUNK]);
        for (j, chunk) in pts.chunks(2 * CHUNK).enumerate() {
            let len = chunk.len() / 2;
            for (q, x) in u.iter_mut().zip(chunk.chunks_exact(2)) {
                *q = [x[0], x[1]];
            }
            m.inner
                .sample_batch_rgb(&u[..len], &mut d[..len], &mut p[..len], &mut c[..len]);
            for l in 0..len {
                let i = j * CHUNK + l;
                for k in 0..3 {
                    dirs.add(3 * i + k).write(d[l][k]);
                    rgb.add(3 * i + k).write(c[l][k]);
                }
                pdf.add(i).write(p[l]);
            }
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------------
// The float32 environment map.

/// An environment light on its float32 map alone (opaque; the library's
/// `Float32EnvironmentMap`, docs/ENVMAPS.md "The float32 environment map": about 10 bytes per
/// pixel beyond the image, float32 in and out, the float32 map's contract). Made from a
/// [`GonioEnvMap`] by [`gonio_envmap_into_float32`], released by [`gonio_envmap_f32_free`].
/// Immutable: may be used from any number of threads at once.
pub struct GonioEnvMapF32 {
    inner: Float32EnvironmentMap,
}

/// Turns `map` into its float32 environment map: `*out` receives a new handle, released with
/// [`gonio_envmap_f32_free`]. **`map` is consumed**: after the call it is freed, whatever the
/// status (unless `map` or `out` is NULL: then nothing happens). Read its warnings first.
///
/// # Safety
/// `map` must be NULL or a live handle that no other thread is using; `out` NULL or valid for
/// writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_into_float32(
    map: *mut GonioEnvMap,
    out: *mut *mut GonioEnvMapF32,
) -> GonioStatus {
    guard(|| {
        if map.is_null() || !map.is_aligned() {
            return Err(Failure::null("map"));
        }
        check_out(out, "out")?;
        let m = Box::from_raw(map);
        let inner = m
            .inner
            .into_float32()
            .map_err(|e| Failure::new(GONIO_ERR_BUILD, format!("no float32 map: {e}")))?;
        w(
            out,
            Box::into_raw(Box::new(GonioEnvMapF32 { inner })),
            "out",
        )
    })
}

/// Releases a float32 environment map handle. NULL is accepted and ignored.
///
/// # Safety
/// `map` must be NULL or a handle from [`gonio_envmap_into_float32`] that was not freed yet, and
/// no other thread may be using it.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_f32_free(map: *mut GonioEnvMapF32) {
    if !map.is_null() {
        let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| drop(Box::from_raw(map))));
    }
}

/// The bytes the handle holds beyond the image (the float32 map's tables), into `*bytes`.
///
/// # Safety
/// `map` must be NULL or a live handle; `bytes` NULL or valid for writing a `size_t`.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_f32_memory_bytes(
    map: *const GonioEnvMapF32,
    bytes: *mut usize,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        w(bytes, m.inner.memory_bytes_beyond_image(), "bytes")
    })
}

/// `n` floats read from `p` (checked: not NULL, aligned, `n` not too large).
///
/// # Safety
/// `p` valid for reading `n` floats when not NULL.
unsafe fn read_f32(p: *const f32, n: usize, what: &str) -> Result<Vec<f32>, Failure> {
    check_in(p, what)?;
    check_len::<f32>(n, 1)?;
    Ok(if n == 0 {
        Vec::new()
    } else {
        std::slice::from_raw_parts(p, n).to_vec()
    })
}

/// The directions `x[i]`, `y[i]`, `z[i]`, each normalised in double and rounded to float (as the
/// float32 batches of the sampler ABI do); a zero or non-finite one is an error naming its index.
///
/// # Safety
/// Each pointer valid for reading `n` floats when not NULL.
#[allow(clippy::needless_range_loop)] // three columns indexed by the same i
unsafe fn read_dirs_f32(
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
) -> Result<[Vec<f32>; 3], Failure> {
    let mut d = [
        read_f32(x, n, "x")?,
        read_f32(y, n, "y")?,
        read_f32(z, n, "z")?,
    ];
    for i in 0..n {
        let v = [d[0][i], d[1][i], d[2][i]].map(f64::from);
        let e = gonio::sampler::normalize(v).ok_or_else(|| {
            Failure::invalid(format!(
                "direction #{i} {} is not a finite non-zero vector",
                super::fmt_row(&v)
            ))
        })?;
        for c in 0..3 {
            d[c][i] = e[c] as f32;
        }
    }
    Ok(d)
}

/// Samples `n` points (`u[i]`, `v[i]`) of the unit square (float): unit directions into `x`,
/// `y`, `z`, densities (per sr) into `pdf`, the RGB radiance into `rgb[3i..3i+3]`: the float32
/// map's samples (its contract, docs/API.md "Float32 maps") with the radiance of each direction.
/// A point outside [0, 1]² (or NaN) stops the batch with `GONIO_ERR_INVALID_ARGUMENT` naming its
/// index; every input is read and checked before any output is written.
///
/// # Safety
/// `map` must be NULL or a live handle; `u`, `v` NULL or valid for reading `n` floats; `x`, `y`,
/// `z`, `pdf` NULL or valid for writing `n` floats; `rgb` NULL or valid for writing `3n` floats.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gonio_envmap_f32_sample_batch(
    map: *const GonioEnvMapF32,
    u: *const f32,
    v: *const f32,
    n: usize,
    x: *mut f32,
    y: *mut f32,
    z: *mut f32,
    pdf: *mut f32,
    rgb: *mut f32,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        let (u, v) = (read_f32(u, n, "u")?, read_f32(v, n, "v")?);
        for (name, p) in [("x", x), ("y", y), ("z", z), ("pdf", pdf), ("rgb", rgb)] {
            check_out(p, name)?;
        }
        check_len::<f32>(n, 3)?;
        for i in 0..n {
            in_square([f64::from(u[i]), f64::from(v[i])])
                .map_err(|e| Failure::invalid(format!("point #{i}: {}", e.message)))?;
        }
        if n == 0 {
            return Ok(());
        }
        let (mut dx, mut dy, mut dz, mut p) =
            (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
        let mut c = vec![[0f32; 3]; n];
        m.inner
            .sample_soa(&u, &v, [&mut dx, &mut dy, &mut dz], &mut p, &mut c);
        std::slice::from_raw_parts_mut(x, n).copy_from_slice(&dx);
        std::slice::from_raw_parts_mut(y, n).copy_from_slice(&dy);
        std::slice::from_raw_parts_mut(z, n).copy_from_slice(&dz);
        std::slice::from_raw_parts_mut(pdf, n).copy_from_slice(&p);
        std::slice::from_raw_parts_mut(rgb, 3 * n).copy_from_slice(c.as_flattened());
        Ok(())
    })
}

/// The density (per sr) at `n` directions `x[i]`, `y[i]`, `z[i]` (float; normalised in double
/// and rounded to float) into `pdf[i]`: the float32 map's. A zero or non-finite direction stops
/// the batch with `GONIO_ERR_INVALID_ARGUMENT` naming its index.
///
/// # Safety
/// `map` must be NULL or a live handle; `x`, `y`, `z` NULL or valid for reading `n` floats; `pdf`
/// NULL or valid for writing `n` floats.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_f32_pdf_batch(
    map: *const GonioEnvMapF32,
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
    pdf: *mut f32,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        let [dx, dy, dz] = read_dirs_f32(x, y, z, n)?;
        check_out(pdf, "pdf")?;
        let mut p = vec![0f32; n];
        m.inner.pdf_soa([&dx, &dy, &dz], &mut p);
        if n > 0 {
            std::slice::from_raw_parts_mut(pdf, n).copy_from_slice(&p);
        }
        Ok(())
    })
}

/// The points (`u[i]`, `v[i]`) of the unit square that the map sends to the directions `x[i]`,
/// `y[i]`, `z[i]` (float; normalised in double and rounded to float); NaN in both where the
/// density is 0. A zero or non-finite direction stops the batch with
/// `GONIO_ERR_INVALID_ARGUMENT` naming its index.
///
/// # Safety
/// `map` must be NULL or a live handle; `x`, `y`, `z` NULL or valid for reading `n` floats; `u`,
/// `v` NULL or valid for writing `n` floats.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_f32_invert_batch(
    map: *const GonioEnvMapF32,
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
    u: *mut f32,
    v: *mut f32,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        let [dx, dy, dz] = read_dirs_f32(x, y, z, n)?;
        check_out(u, "u")?;
        check_out(v, "v")?;
        let (mut uu, mut vv) = (vec![0f32; n], vec![0f32; n]);
        m.inner.invert_soa([&dx, &dy, &dz], [&mut uu, &mut vv]);
        if n > 0 {
            std::slice::from_raw_parts_mut(u, n).copy_from_slice(&uu);
            std::slice::from_raw_parts_mut(v, n).copy_from_slice(&vv);
        }
        Ok(())
    })
}

/// The image's linear RGB radiance at `n` directions `x[i]`, `y[i]`, `z[i]` (float, normalised
/// in double) into `rgb[3i..3i+3]`, by the map's lookup; a float32 sample's direction reads the
/// radiance [`gonio_envmap_f32_sample_batch`] returned with it. A zero or non-finite direction
/// stops the batch with `GONIO_ERR_INVALID_ARGUMENT` naming its index.
///
/// # Safety
/// `map` must be NULL or a live handle; `x`, `y`, `z` NULL or valid for reading `n` floats; `rgb`
/// NULL or valid for writing `3n` floats.
#[no_mangle]
#[allow(clippy::needless_range_loop)] // three columns indexed by the same i
pub unsafe extern "C" fn gonio_envmap_f32_eval_batch(
    map: *const GonioEnvMapF32,
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
    rgb: *mut f32,
) -> GonioStatus {
    guard(|| {
        let m = r(map, "map")?;
        let d = [
            read_f32(x, n, "x")?,
            read_f32(y, n, "y")?,
            read_f32(z, n, "z")?,
        ];
        check_out(rgb, "rgb")?;
        check_len::<f32>(n, 3)?;
        let mut dirs = Vec::with_capacity(n);
        for i in 0..n {
            let v = [d[0][i], d[1][i], d[2][i]].map(f64::from);
            if gonio::sampler::normalize(v).is_none() {
                return Err(Failure::invalid(format!(
                    "direction #{i} {} is not a finite non-zero vector",
                    super::fmt_row(&v)
                )));
            }
            dirs.push(v);
        }
        let mut c = vec![[0f32; 3]; n];
        m.inner.eval_batch(&dirs, &mut c);
        if n > 0 {
            std::slice::from_raw_parts_mut(rgb, 3 * n).copy_from_slice(c.as_flattened());
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
            // The batch path: the documented round-off, the radiance of its own direction.
            for k in 0..3 {
                assert!(
                    (dirs[3 * i + k] - d[k]).abs() <= 1e-15,
                    "{i}: {dirs:?} {d:?}"
                );
            }
            assert!((pdf[i] - p).abs() <= 1e-12 * p, "{i}: {} {p}", pdf[i]);
            let mut e = [0.0f32; 3];
            assert_eq!(
                unsafe {
                    gonio_envmap_eval(
                        m,
                        dirs[3 * i],
                        dirs[3 * i + 1],
                        dirs[3 * i + 2],
                        e.as_mut_ptr(),
                    )
                },
                GONIO_OK
            );
            assert_eq!(&rgb[3 * i..3 * i + 3], &e);
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
            last_error().contains("not a regular file"),
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

    fn read_with(bytes: &[u8], o: *const GonioEnvOptions) -> (GonioStatus, *mut GonioEnvMap) {
        let mut m = null_mut();
        let st = unsafe {
            gonio_envmap_read_memory_with(bytes.as_ptr(), bytes.len(), c"sky".as_ptr(), o, &mut m)
        };
        (st, m)
    }

    fn defaults() -> GonioEnvOptions {
        let mut o = GonioEnvOptions {
            weight: -1,
            channel: 9,
            custom_weights: null(),
            custom_len: 9,
            lookup: -1,
            mis_compensation: -1,
        };
        assert_eq!(unsafe { gonio_envmap_options_default(&mut o) }, GONIO_OK);
        o
    }

    fn warnings(m: *const GonioEnvMap) -> Vec<String> {
        let mut n = usize::MAX;
        assert_eq!(unsafe { gonio_envmap_warning_count(m, &mut n) }, GONIO_OK);
        (0..n)
            .map(|i| {
                let mut t = null();
                assert_eq!(unsafe { gonio_envmap_warning(m, i, &mut t) }, GONIO_OK);
                unsafe { CStr::from_ptr(t) }.to_string_lossy().into_owned()
            })
            .collect()
    }

    fn pdf_at(m: *const GonioEnvMap, d: [f64; 3]) -> f64 {
        let mut p = -1.0;
        let st = unsafe { gonio_envmap_pdf(m, d[0], d[1], d[2], &mut p) };
        assert_eq!(st, GONIO_OK, "{}", last_error());
        p
    }

    #[test]
    fn options_default_and_refused_values() {
        let o = defaults();
        assert_eq!(
            (
                o.weight,
                o.channel,
                o.custom_weights,
                o.custom_len,
                o.lookup,
                o.mis_compensation
            ),
            (
                GONIO_ENV_WEIGHT_LUMINANCE,
                0,
                null(),
                0,
                GONIO_ENV_LOOKUP_NEAREST,
                0
            )
        );
        assert_eq!(
            unsafe { gonio_envmap_options_default(null_mut()) },
            GONIO_ERR_NULL_POINTER
        );
        let sky = pfm(8, 4, |_, _| [0.5, 1.0, 2.0]);
        let cases: [(GonioEnvOptions, GonioStatus, &str); 6] = [
            (
                GonioEnvOptions { weight: 7, ..o },
                GONIO_ERR_INVALID_ARGUMENT,
                "unknown weight 7",
            ),
            (
                GonioEnvOptions {
                    weight: GONIO_ENV_WEIGHT_CHANNEL,
                    channel: 3,
                    ..o
                },
                GONIO_ERR_INVALID_ARGUMENT,
                "channel 3 does not exist",
            ),
            (
                GonioEnvOptions { lookup: 2, ..o },
                GONIO_ERR_INVALID_ARGUMENT,
                "unknown lookup 2",
            ),
            (
                GonioEnvOptions {
                    mis_compensation: 2,
                    ..o
                },
                GONIO_ERR_INVALID_ARGUMENT,
                "mis_compensation is 2",
            ),
            (
                GonioEnvOptions {
                    weight: GONIO_ENV_WEIGHT_CUSTOM,
                    custom_len: 32,
                    ..o
                },
                GONIO_ERR_NULL_POINTER,
                "custom_weights is NULL",
            ),
            (
                GonioEnvOptions {
                    weight: GONIO_ENV_WEIGHT_CUSTOM,
                    custom_weights: [1.0f32; 4].as_ptr(),
                    custom_len: 4,
                    ..o
                },
                GONIO_ERR_INVALID_ARGUMENT,
                "sky: 4 custom weights for an image of 8 × 4 pixels",
            ),
        ];
        for (opt, status, msg) in cases {
            let (st, m) = read_with(&sky, &opt);
            assert_eq!((st, m), (status, null_mut()), "{opt:?}: {}", last_error());
            assert!(last_error().starts_with(msg), "{opt:?}: {}", last_error());
        }
        let (st, m) = read_with(&sky, null());
        assert_eq!((st, m), (GONIO_ERR_NULL_POINTER, null_mut()));
        assert_eq!(last_error(), "options is NULL or not aligned for its type");
        // A custom weight that is negative, and a channel that is 0 everywhere (blue here).
        let mut cw = [1.0f32; 32];
        cw[5] = -1.0;
        let opt = GonioEnvOptions {
            weight: GONIO_ENV_WEIGHT_CUSTOM,
            custom_weights: cw.as_ptr(),
            custom_len: cw.len(),
            ..o
        };
        assert_eq!(read_with(&sky, &opt).0, GONIO_ERR_INVALID_ARGUMENT);
        assert!(
            last_error().contains("pixel (x 5, y 0)"),
            "{}",
            last_error()
        );
        let yellow = pfm(8, 4, |_, _| [1.0, 1.0, 0.0]);
        let opt = GonioEnvOptions {
            weight: GONIO_ENV_WEIGHT_CHANNEL,
            channel: 2,
            ..o
        };
        assert_eq!(read_with(&yellow, &opt), (GONIO_ERR_BUILD, null_mut()));
        assert!(last_error().contains("black"), "{}", last_error());
        // The path form reads the options too.
        let mut m = null_mut();
        let bad = GonioEnvOptions { lookup: 5, ..o };
        let st = unsafe { gonio_envmap_read_path_with(c"/nonexistent.hdr".as_ptr(), &bad, &mut m) };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT, "{}", last_error());
        let st = unsafe { gonio_envmap_read_path_with(c"/nonexistent.hdr".as_ptr(), &o, &mut m) };
        assert_eq!(st, GONIO_ERR_IO, "{}", last_error());
    }

    #[test]
    fn weight_options_change_the_density() {
        let o = defaults();
        // Red on the left half (columns 0..8 of 16), green on the right; the image's centre
        // column looks along +x, its left edge along −x (docs/ENVMAPS.md).
        let sky = pfm(16, 8, |c, _| {
            if c < 8 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            }
        });
        let left = [-0.3, 0.9, 0.1]; // s ≈ 0.3: the left (red) half
        let right = [-0.3, -0.9, 0.1]; // s ≈ 0.7: the right (green) half
        let (st, lum) = read_with(&sky, &o);
        assert_eq!(st, GONIO_OK, "{}", last_error());
        assert!(
            pdf_at(lum, right) > pdf_at(lum, left),
            "green is brighter in luminance"
        );
        let (st, red) = read_with(
            &sky,
            &GonioEnvOptions {
                weight: GONIO_ENV_WEIGHT_CHANNEL,
                ..o
            },
        );
        assert_eq!(st, GONIO_OK, "{}", last_error());
        assert!(pdf_at(red, left) > 0.0);
        assert_eq!(pdf_at(red, right), 0.0);
        // Constant custom weights: the uniform density, whatever the image.
        let cw = vec![3.0f32; 16 * 8];
        let opt = GonioEnvOptions {
            weight: GONIO_ENV_WEIGHT_CUSTOM,
            custom_weights: cw.as_ptr(),
            custom_len: cw.len(),
            ..o
        };
        let (st, uni) = read_with(&sky, &opt);
        assert_eq!(st, GONIO_OK, "{}", last_error());
        drop(cw); // copied during the call
        let uniform = 1.0 / (4.0 * std::f64::consts::PI);
        for d in [left, right, [0.0, 0.0, 1.0], [0.2, -0.1, -0.9]] {
            assert!((pdf_at(uni, d) - uniform).abs() < 1e-12);
        }
        for m in [lum, red, uni] {
            assert!(warnings(m).is_empty());
            unsafe { gonio_envmap_free(m) };
        }
    }

    #[test]
    fn bilinear_lookup_mis_compensation_and_warnings() {
        let o = defaults();
        let sky = pfm(16, 8, |c, r| {
            if (c, r) == (5, 5) {
                [80.0; 3]
            } else {
                [[0.1f32, 0.3, 0.5][c % 3]; 3]
            }
        });
        let (st, near) = read_with(&sky, &o);
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let (st, bil) = read_with(
            &sky,
            &GonioEnvOptions {
                lookup: GONIO_ENV_LOOKUP_BILINEAR,
                ..o
            },
        );
        assert_eq!(st, GONIO_OK, "{}", last_error());
        // Halfway between two pixel centres of one row the bilinear lookup is their mean, the
        // nearest lookup one of them; at a centre both give the pixel.
        let dir = |s: f64, t: f64| gonio::envmap::image_direction(s, t);
        let eval = |m, d: [f64; 3]| {
            let mut c = [0.0f32; 3];
            let st = unsafe { gonio_envmap_eval(m, d[0], d[1], d[2], c.as_mut_ptr()) };
            assert_eq!(st, GONIO_OK, "{}", last_error());
            c
        };
        // PFM rows run bottom to top: file row 5 (the bright pixel's) is image row 2 from the
        // top; image row 1 is dim: its columns 4 and 5 hold 0.3 and 0.5.
        let t = 1.5 / 8.0;
        let (a, b) = (
            eval(near, dir(4.5 / 16.0, t)),
            eval(near, dir(5.5 / 16.0, t)),
        );
        assert_eq!((a, b), ([0.3; 3], [0.5; 3]));
        let close = |c: [f32; 3], x: f32| c.iter().all(|&v| (v - x).abs() < 1e-6);
        let mid = eval(bil, dir(5.0 / 16.0, t));
        assert!(close(mid, 0.4), "{mid:?}");
        let centre = eval(bil, dir(4.5 / 16.0, t));
        assert!(close(centre, 0.3), "{centre:?}");
        // The sample's radiance follows the lookup.
        let (mut d, mut p, mut c) = ([0.0; 3], 0.0, [0.0f32; 3]);
        let st =
            unsafe { gonio_envmap_sample(bil, 0.3, 0.6, d.as_mut_ptr(), &mut p, c.as_mut_ptr()) };
        assert_eq!(st, GONIO_OK);
        assert_eq!(c, eval(bil, d));
        // The density does not depend on the lookup.
        assert!((pdf_at(near, d) - p).abs() <= 1e-9 * p);

        // MIS compensation: dim directions far from the bright pixel get density 0.
        let (st, mis) = read_with(
            &sky,
            &GonioEnvOptions {
                mis_compensation: 1,
                ..o
            },
        );
        assert_eq!(st, GONIO_OK, "{}", last_error());
        assert!(pdf_at(near, [0.0, 0.0, 1.0]) > 0.0);
        assert_eq!(pdf_at(mis, [0.0, 0.0, 1.0]), 0.0);
        assert!(warnings(mis).is_empty());
        // On a constant sky nothing is above the mean: the plain weight, with a warning.
        let (st, flat) = read_with(
            &pfm(8, 4, |_, _| [1.0; 3]),
            &GonioEnvOptions {
                mis_compensation: 1,
                ..o
            },
        );
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let ws = warnings(flat);
        assert_eq!(ws.len(), 1, "{ws:?}");
        assert!(
            ws[0].starts_with("sky: warning: MIS compensation left no pixel above the mean"),
            "{ws:?}"
        );
        // Negative pixels are weighted as 0, with the reader's convention of a warning.
        let neg = pfm(8, 4, |c, r| {
            if (c, r) == (1, 1) {
                [-1.0; 3]
            } else {
                [1.0; 3]
            }
        });
        let (st, negm) = read_with(&neg, &o);
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let ws = warnings(negm);
        assert_eq!(ws, ["sky: warning: 1 pixels have a negative luminance; they are weighted as 0 (their radiance is kept)"]);
        // Warning errors: an index out of range, NULL pointers.
        let mut text = null();
        assert_eq!(
            unsafe { gonio_envmap_warning(negm, 1, &mut text) },
            GONIO_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            last_error(),
            "warning index 1 is out of range (the map has 1 warnings)"
        );
        assert!(text.is_null());
        assert_eq!(
            unsafe { gonio_envmap_warning(negm, 0, null_mut()) },
            GONIO_ERR_NULL_POINTER
        );
        assert_eq!(
            unsafe { gonio_envmap_warning(null(), 0, &mut text) },
            GONIO_ERR_NULL_POINTER
        );
        assert_eq!(
            unsafe { gonio_envmap_warning_count(negm, null_mut()) },
            GONIO_ERR_NULL_POINTER
        );
        for m in [near, bil, mis, flat, negm] {
            unsafe { gonio_envmap_free(m) };
        }
    }

    #[test]
    fn size_cap_fifo_and_zero_density() {
        let dir = std::env::temp_dir().join(format!("gonio-capi-env-cap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A sparse file one byte over the cap: refused by its size, nothing read.
        let big = dir.join("big.hdr");
        std::fs::File::create(&big)
            .unwrap()
            .set_len(gonio::input::file::FileKind::Image.default_limit() + 1)
            .unwrap();
        let path = std::ffi::CString::new(big.to_str().unwrap()).unwrap();
        let mut m = null_mut();
        let st = unsafe { gonio_envmap_read_path(path.as_ptr(), &mut m) };
        assert_eq!(st, GONIO_ERR_IO);
        assert!(
            last_error().contains("more than the limit of 4294967296 bytes for image files"),
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
                last_error().contains("not a regular file"),
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

    /// The float32 environment map through the C ABI: the library's `Float32EnvironmentMap` of
    /// the same image, bit for bit (samples, densities, inverses, radiance), fewer bytes than the
    /// float64 handle, and the ABI's errors (NULL handle, a point outside the square, a zero
    /// direction, each naming its index; outputs untouched on error).
    #[test]
    fn float32_envmap_is_the_librarys_bit_for_bit() {
        let bytes = pfm(32, 16, |c, r| {
            if (c, r) == (21, 4) {
                [900.0, 500.0, 200.0]
            } else {
                [0.1 + 0.01 * c as f32, 0.2, 0.05 * r as f32 + 0.01]
            }
        });
        let (st, m) = read(&bytes);
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let mut b64 = 0usize;
        {
            let env = unsafe { &*m };
            b64 = b64.max(env.inner.memory_bytes_beyond_image());
        }
        let mut f = null_mut();
        assert_eq!(unsafe { gonio_envmap_into_float32(m, &mut f) }, GONIO_OK);
        let lib = gonio::envmap::Float32EnvironmentMap::new(
            Image::from_bytes(&bytes, None).unwrap(),
            EnvOptions::default(),
        )
        .unwrap();
        let n = 1001;
        let u: Vec<f32> = (0..n)
            .map(|i| ((i as f32 + 0.5) * 0.618_034) % 1.0)
            .collect(); // clear of the square's edges, where the map folds
        let v: Vec<f32> = (0..n).map(|i| (i as f32 + 0.5) / n as f32).collect();
        let (mut x, mut y, mut z, mut p) =
            (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
        let mut rgb = vec![0f32; 3 * n];
        let st = unsafe {
            gonio_envmap_f32_sample_batch(
                f,
                u.as_ptr(),
                v.as_ptr(),
                n,
                x.as_mut_ptr(),
                y.as_mut_ptr(),
                z.as_mut_ptr(),
                p.as_mut_ptr(),
                rgb.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let (mut lx, mut ly, mut lz, mut lp) =
            (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
        let mut lrgb = vec![[0f32; 3]; n];
        lib.sample_soa(&u, &v, [&mut lx, &mut ly, &mut lz], &mut lp, &mut lrgb);
        let bits = |a: &[f32]| a.iter().map(|q| q.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&x), bits(&lx));
        assert_eq!(bits(&y), bits(&ly));
        assert_eq!(bits(&z), bits(&lz));
        assert_eq!(bits(&p), bits(&lp));
        assert_eq!(bits(&rgb), bits(lrgb.as_flattened()));
        // pdf, invert and eval of the sampled directions: the library's (which normalises
        // nothing; the ABI normalises in double and rounds, a no-op or an ulp on these).
        let mut q = vec![0f32; n];
        let st = unsafe {
            gonio_envmap_f32_pdf_batch(f, x.as_ptr(), y.as_ptr(), z.as_ptr(), n, q.as_mut_ptr())
        };
        assert_eq!(st, GONIO_OK);
        let (mut iu, mut iv) = (vec![0f32; n], vec![0f32; n]);
        let st = unsafe {
            gonio_envmap_f32_invert_batch(
                f,
                x.as_ptr(),
                y.as_ptr(),
                z.as_ptr(),
                n,
                iu.as_mut_ptr(),
                iv.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_OK);
        let mut c = vec![0f32; 3 * n];
        let st = unsafe {
            gonio_envmap_f32_eval_batch(f, x.as_ptr(), y.as_ptr(), z.as_ptr(), n, c.as_mut_ptr())
        };
        assert_eq!(st, GONIO_OK);
        assert_eq!(bits(&c), bits(&rgb));
        for i in 0..n {
            assert!(
                (q[i] / p[i] - 1.0).abs() < 1e-3,
                "{i}: {} vs {}",
                q[i],
                p[i]
            );
            assert!(
                (iu[i] - u[i]).abs() < 1e-5 && (iv[i] - v[i]).abs() < 1e-5,
                "{i}"
            );
        }
        let mut b32 = 0usize;
        assert_eq!(
            unsafe { gonio_envmap_f32_memory_bytes(f, &mut b32) },
            GONIO_OK
        );
        assert_eq!(b32, lib.memory_bytes_beyond_image());
        assert!(b32 < b64, "{b32} vs {b64}");
        // Errors.
        let bad_u = [0.5f32, 1.5];
        let vv = [0.5f32, 0.5];
        let mut out = [7f32; 6];
        let st = unsafe {
            gonio_envmap_f32_sample_batch(
                f,
                bad_u.as_ptr(),
                vv.as_ptr(),
                2,
                out.as_mut_ptr(),
                out.as_mut_ptr(),
                out.as_mut_ptr(),
                out.as_mut_ptr(),
                out.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(last_error().contains("point #1"), "{}", last_error());
        assert_eq!(out, [7f32; 6]);
        let zx = [1f32, 0.0];
        let zy = [0f32, 0.0];
        let st = unsafe {
            gonio_envmap_f32_pdf_batch(
                f,
                zx.as_ptr(),
                zy.as_ptr(),
                zy.as_ptr(),
                2,
                out.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(last_error().contains("direction #1"), "{}", last_error());
        let st = unsafe {
            gonio_envmap_f32_pdf_batch(
                null(),
                zx.as_ptr(),
                zy.as_ptr(),
                zy.as_ptr(),
                1,
                out.as_mut_ptr(),
            )
        };
        assert_eq!(st, GONIO_ERR_NULL_POINTER);
        let mut g = null_mut();
        assert_eq!(
            unsafe { gonio_envmap_into_float32(null_mut(), &mut g) },
            GONIO_ERR_NULL_POINTER
        );
        unsafe { gonio_envmap_f32_free(f) };
        unsafe { gonio_envmap_f32_free(null_mut()) };
    }
}
