//! Tabulated BRDFs at the C boundary (issue 26): a MERL `.binary`, UTIA `.bin` or gonio BRDF JSON
//! file read into a [`GonioBrdf`] (the library's `TabulatedBrdf`, the format recognised from the
//! content), a [`GonioBrdfSampler`] of one of four methods built from it, and `eval`, `sample`,
//! `pdf`, `invert` one pair of directions at a time or in a batch. Same rules as the rest of the
//! ABI: status codes, the thread-local message, NULL pointers refused, panics caught, outputs
//! written only on success (a batch checks every input before it writes any output).
//!
//! Directions are in the local shading frame (z the normal, x the tangent), both pointing away
//! from the surface, as any finite non-zero vector (normalised internally); f_r is in 1/sr.

use super::{
    check_in, check_len, check_memory_len, check_out, guard, in_square, path_of, r, read_bounded,
    unit, w, Failure, GonioStatus, GONIO_ERR_BUILD, GONIO_ERR_IO, GONIO_ERR_OUTSIDE_DOMAIN,
    GONIO_ERR_PARSE, GONIO_ERR_ZERO_DENSITY,
};
use gonio::brdf::{
    read_any, BrdfError, BrdfMethod, BrdfSample, BrdfSampler, CosineBrdf, GgxFit, MerlOptions,
    MerlRaw, PerSliceConstant, SamplerOptions, Symmetry, TabulatedBrdf, MAX_VALUES, UTIA_SIZE,
};
use gonio::Vec3;
use std::ffi::{c_char, CStr};

/// The format of a BRDF file: one of the `GONIO_BRDF_FORMAT_*` constants.
pub type GonioBrdfFormat = i32;
/// MERL binary (`.binary`): three int32 dimensions, then three planes of float64.
pub const GONIO_BRDF_FORMAT_MERL: GonioBrdfFormat = 1;
/// UTIA raw float64 (`.bin`, exactly 3 × 288 × 288 doubles).
pub const GONIO_BRDF_FORMAT_UTIA: GonioBrdfFormat = 2;
/// gonio's self-describing BRDF table (JSON with `"format": "gonio-brdf"`).
pub const GONIO_BRDF_FORMAT_JSON: GonioBrdfFormat = 3;

/// A BRDF sampling method: one of the `GONIO_BRDF_METHOD_*` constants.
pub type GonioBrdfMethod = i32;
/// The HDS map of the slice diagram blended between the tabulated incident directions (exact pdf,
/// bijective, continuous in u and in ω_i, closed-form inverse).
pub const GONIO_BRDF_METHOD_HDS: GonioBrdfMethod = 0;
/// Cosine-weighted sampling, pdf = cos θ_o / π.
pub const GONIO_BRDF_METHOD_COSINE: GonioBrdfMethod = 1;
/// GGX visible-normal sampling (Heitz 2018) with the roughness fitted to the table; reflections
/// below the horizon are zero-weight samples.
pub const GONIO_BRDF_METHOD_GGX_FIT: GonioBrdfMethod = 2;
/// A piecewise-constant image of the nearest tabulated slice (discontinuous in ω_i).
pub const GONIO_BRDF_METHOD_PIECEWISE_CONSTANT: GonioBrdfMethod = 3;

/// Options of [`gonio_brdf_read_path`] and [`gonio_brdf_read_memory`]. Fill it with
/// [`gonio_brdf_read_options_default`], then change fields (the struct may gain fields).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GonioBrdfReadOptions {
    /// MERL resampling: polar nodes 0°…90°, incident and outgoing (≥ 2; default 46, 2° steps).
    pub merl_theta: usize,
    /// MERL resampling: nodes of the relative azimuth φ_o − φ_i in [0°, 360°) (≥ 1; default 90).
    pub merl_phi: usize,
}

/// Options of [`gonio_brdf_sampler_build`]. Fill it with
/// [`gonio_brdf_sampler_options_default`], then change fields (the struct may gain fields).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GonioBrdfSamplerOptions {
    /// HDS and piecewise-constant: polar nodes 0°…90° of the slices' outgoing grid when the
    /// table's own grid cannot be used (≥ 2; default 46).
    pub theta_o: usize,
    /// The same grid's azimuth nodes (≥ 1; default 90).
    pub phi_o: usize,
    /// Piecewise-constant: pixels per side of each slice's image (1…4096; default 128).
    pub resolution: usize,
}

/// What [`gonio_brdf_info`] reports about a read file.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GonioBrdfInfo {
    /// The file's format, a `GONIO_BRDF_FORMAT_*` constant.
    pub format: GonioBrdfFormat,
    /// 1 when the table depends on the incident azimuth, 0 when it is isotropic.
    pub anisotropic: i32,
    /// 1 or 3 (R, G, B).
    pub channels: usize,
    /// Incident polar nodes of the table.
    pub theta_i: usize,
    /// Incident azimuth nodes (1 for isotropic tables).
    pub phi_i: usize,
    /// Outgoing polar nodes.
    pub theta_o: usize,
    /// Outgoing azimuth nodes (of φ_o − φ_i for isotropic tables).
    pub phi_o: usize,
    /// Bytes held by the table.
    pub table_bytes: usize,
    /// MERL only (else NaN): the resampling error of the density, the mean over θ_i = 0°, 30°,
    /// 60°, 75°, 85° of ∫ |p_table − p_file| dω_o (0 = identical, 2 = disjoint).
    pub merl_resampling_error: f64,
    /// MERL only (else 0): stored values marked as no data (negative).
    pub merl_no_data: usize,
}

/// One BRDF sample: the outgoing direction, its exact density and the weight per channel.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GonioBrdfSample {
    /// The unit outgoing direction `[x, y, z]` (local frame).
    pub direction: [f64; 3],
    /// Density of the method at `direction`, per steradian (equal to [`gonio_brdf_pdf`] there).
    pub pdf: f64,
    /// f_r·cos θ_o / pdf per channel (R, G, B; a one-channel table repeats it); 0 where the pdf
    /// is 0 or the direction lies below the horizon.
    pub weight: [f64; 3],
}

impl From<BrdfSample> for GonioBrdfSample {
    fn from(s: BrdfSample) -> Self {
        GonioBrdfSample {
            direction: s.direction,
            pdf: s.pdf,
            weight: s.weight,
        }
    }
}

/// A tabulated BRDF read from a file (opaque). Created by [`gonio_brdf_read_path`] or
/// [`gonio_brdf_read_memory`], released by [`gonio_brdf_free`]. Immutable: may be used from any
/// number of threads at once.
pub struct GonioBrdf {
    table: TabulatedBrdf,
    info: GonioBrdfInfo,
}

/// A BRDF sampler of one method (opaque). Created by [`gonio_brdf_sampler_build`], released by
/// [`gonio_brdf_sampler_free`]; it holds its own copy of the table (the [`GonioBrdf`] may be
/// freed first). Immutable: may be used from any number of threads at once.
pub struct GonioBrdfSampler {
    inner: Inner,
}

impl GonioBrdfSampler {
    /// The HDS sampler, for the "hds" method.
    pub(crate) fn hds(&self) -> Option<&BrdfSampler> {
        match &self.inner {
            Inner::Hds(s) => Some(s),
            _ => None,
        }
    }
}

enum Inner {
    Hds(BrdfSampler),
    Cosine(TabulatedBrdf),
    Ggx(TabulatedBrdf, (f64, f64)),
    /// The piecewise-constant method owns (shares) the HDS sampler whose slices it tabulates.
    Pc(PerSliceConstant<std::sync::Arc<BrdfSampler>>),
}

impl GonioBrdfSampler {
    fn table(&self) -> &TabulatedBrdf {
        match &self.inner {
            Inner::Hds(s) => s.brdf(),
            Inner::Cosine(b) | Inner::Ggx(b, _) => b,
            Inner::Pc(p) => p.sampler().brdf(),
        }
    }

    fn with<R>(&self, f: impl FnOnce(&dyn BrdfMethod) -> R) -> R {
        match &self.inner {
            Inner::Hds(s) => f(s),
            Inner::Cosine(b) => f(&CosineBrdf::new(b)),
            Inner::Ggx(b, (ax, ay)) => f(&GgxFit::with_alpha(b, *ax, *ay)),
            Inner::Pc(p) => f(p),
        }
    }
}

/// Fills `*out` with the default read options (MERL resampled to 46 × 46 × 90 nodes).
///
/// # Safety
/// `out` must be NULL or valid for writing a [`GonioBrdfReadOptions`].
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_read_options_default(
    out: *mut GonioBrdfReadOptions,
) -> GonioStatus {
    guard(|| {
        let d = MerlOptions::default();
        w(
            out,
            GonioBrdfReadOptions {
                merl_theta: d.n_theta,
                merl_phi: d.n_phi,
            },
            "out",
        )
    })
}

/// Fills `*out` with the default sampler options.
///
/// # Safety
/// `out` must be NULL or valid for writing a [`GonioBrdfSamplerOptions`].
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_sampler_options_default(
    out: *mut GonioBrdfSamplerOptions,
) -> GonioStatus {
    guard(|| {
        let d = SamplerOptions::default();
        w(
            out,
            GonioBrdfSamplerOptions {
                theta_o: d.theta_o,
                phi_o: d.phi_o,
                resolution: 128,
            },
            "out",
        )
    })
}

/// The MERL options, validated (NULL: the defaults).
unsafe fn merl_options(options: *const GonioBrdfReadOptions) -> Result<MerlOptions, Failure> {
    if options.is_null() {
        return Ok(MerlOptions::default());
    }
    let o = r(options, "options")?;
    let values = o
        .merl_theta
        .checked_mul(o.merl_theta)
        .and_then(|v| v.checked_mul(o.merl_phi))
        .and_then(|v| v.checked_mul(3));
    if o.merl_theta < 2 || o.merl_phi < 1 || values.is_none_or(|v| v > MAX_VALUES) {
        return Err(Failure::invalid(format!(
            "options: merl_theta = {} and merl_phi = {}: need merl_theta ≥ 2, merl_phi ≥ 1 and at \
             most {MAX_VALUES} values (3 × merl_theta² × merl_phi)",
            o.merl_theta, o.merl_phi
        )));
    }
    Ok(MerlOptions {
        n_theta: o.merl_theta,
        n_phi: o.merl_phi,
    })
}

fn brdf_failure(name: &str, e: BrdfError) -> Failure {
    let status = match e {
        BrdfError::File(_) => GONIO_ERR_IO,
        _ => GONIO_ERR_PARSE,
    };
    Failure::new(status, format!("{name}: {e}"))
}

/// Reads the table and what `gonio_brdf_info` reports.
fn build_brdf(name: &str, bytes: &[u8], merl: &MerlOptions) -> Result<GonioBrdf, Failure> {
    if bytes.is_empty() {
        return Err(Failure::new(
            GONIO_ERR_PARSE,
            format!("{name}: the input is empty (0 bytes)"),
        ));
    }
    let table = read_any(bytes, merl).map_err(|e| brdf_failure(name, e))?;
    let first = gonio::brdf::strip_json_bom(bytes)
        .iter()
        .find(|b| !b.is_ascii_whitespace());
    let (format, merl_resampling_error, merl_no_data) = if first == Some(&b'{') {
        (GONIO_BRDF_FORMAT_JSON, f64::NAN, 0)
    } else if bytes.len() as u64 == UTIA_SIZE {
        (GONIO_BRDF_FORMAT_UTIA, f64::NAN, 0)
    } else {
        let raw = MerlRaw::parse(bytes).map_err(|e| brdf_failure(name, e))?;
        (
            GONIO_BRDF_FORMAT_MERL,
            raw.resampling_error(&table),
            raw.no_data(),
        )
    };
    let info = GonioBrdfInfo {
        format,
        anisotropic: i32::from(table.symmetry() == Symmetry::Anisotropic),
        channels: table.channels(),
        theta_i: table.theta_i().len(),
        phi_i: table.phi_i().len(),
        theta_o: table.theta_o().len(),
        phi_o: table.phi_o().len(),
        table_bytes: table.memory_bytes(),
        merl_resampling_error,
        merl_no_data,
    };
    Ok(GonioBrdf { table, info })
}

/// Reads a BRDF file (MERL `.binary`, UTIA `.bin` or gonio BRDF JSON; the format is recognised
/// from the content, not the extension). `options` may be NULL (the defaults). Files larger than
/// the BRDF limit (`gonio_read_limit`) and anything that is not a regular file are refused
/// ([`GONIO_ERR_IO`]); a file that does not decode (wrong size, NaN, no reflectance at all, …) is
/// [`GONIO_ERR_PARSE`] with what and where (byte offset or value index); options out of range are
/// `GONIO_ERR_INVALID_ARGUMENT`. On success `*out` receives a new handle that the caller releases
/// with [`gonio_brdf_free`].
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string; `options` NULL or valid for reading a
/// [`GonioBrdfReadOptions`]; `out` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_read_path(
    path: *const c_char,
    options: *const GonioBrdfReadOptions,
    out: *mut *mut GonioBrdf,
) -> GonioStatus {
    guard(|| {
        check_out(out, "out")?;
        if path.is_null() {
            return Err(Failure::null("path"));
        }
        let merl = merl_options(options)?;
        let raw = CStr::from_ptr(path);
        let owned = path_of(raw)?;
        let lossy = raw.to_string_lossy();
        let bytes = read_bounded(&owned, &lossy, gonio::input::file::FileKind::Brdf)?;
        let b = build_brdf(&lossy, &bytes, &merl)?;
        w(out, Box::into_raw(Box::new(b)), "out")
    })
}

/// Reads a BRDF file from `len` bytes at `data` (any format, as [`gonio_brdf_read_path`]).
/// `name` (may be NULL, then `"<memory>"`) is used in messages; `options` may be NULL. More than
/// the BRDF limit (`gonio_read_limit`) bytes are refused. On success `*out` receives a new handle that the
/// caller releases with [`gonio_brdf_free`].
///
/// # Safety
/// `data` must be NULL or valid for reading `len` bytes; `name` NULL or a NUL-terminated string;
/// `options` NULL or valid for reading a [`GonioBrdfReadOptions`]; `out` NULL or valid for
/// writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_read_memory(
    data: *const u8,
    len: usize,
    name: *const c_char,
    options: *const GonioBrdfReadOptions,
    out: *mut *mut GonioBrdf,
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
        let merl = merl_options(options)?;
        check_memory_len(name, len, gonio::input::file::FileKind::Brdf)?;
        let bytes: &[u8] = if len == 0 {
            &[]
        } else {
            std::slice::from_raw_parts(data, len)
        };
        let b = build_brdf(name, bytes, &merl)?;
        w(out, Box::into_raw(Box::new(b)), "out")
    })
}

/// Releases a BRDF handle. NULL is accepted and ignored.
///
/// # Safety
/// `brdf` must be NULL or a handle from a `gonio_brdf_read_*` function that was not freed yet,
/// and no other thread may be using it.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_free(brdf: *mut GonioBrdf) {
    if !brdf.is_null() {
        let _ =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| drop(Box::from_raw(brdf))));
    }
}

/// Writes the file's format, grid and (MERL) resampling error into `*out`.
///
/// # Safety
/// `brdf` must be NULL or a live handle; `out` NULL or valid for writing a [`GonioBrdfInfo`].
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_info(
    brdf: *const GonioBrdf,
    out: *mut GonioBrdfInfo,
) -> GonioStatus {
    guard(|| {
        let b = r(brdf, "brdf")?;
        w(out, b.info, "out")
    })
}

/// Reads a direction of 3 doubles; `what` names it in messages.
unsafe fn dir_at(p: *const f64, what: &str) -> Result<Vec3, Failure> {
    let d = [p.read(), p.add(1).read(), p.add(2).read()];
    unit(d).map_err(|e| Failure::invalid(format!("{what}: {}", e.message)))
}

/// f_r per channel (1/sr, R, G, B; a one-channel table repeats it) at the incident direction
/// `wi[3]` and the outgoing direction `wo[3]`, by the table's multilinear interpolation; 0 when
/// either lies below the horizon. A zero or non-finite vector is `GONIO_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `brdf` must be NULL or a live handle; `wi` and `wo` NULL or valid for reading 3 doubles; `f`
/// NULL or valid for writing 3 doubles.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_eval(
    brdf: *const GonioBrdf,
    wi: *const f64,
    wo: *const f64,
    f: *mut f64,
) -> GonioStatus {
    guard(|| {
        let b = r(brdf, "brdf")?;
        check_in(wi, "wi")?;
        check_in(wo, "wo")?;
        check_out(f, "f")?;
        let v = b.table.eval(dir_at(wi, "wi")?, dir_at(wo, "wo")?);
        for (k, x) in v.iter().enumerate() {
            f.add(k).write(*x);
        }
        Ok(())
    })
}

fn method_name(m: GonioBrdfMethod) -> Option<&'static str> {
    match m {
        GONIO_BRDF_METHOD_HDS => Some("hds"),
        GONIO_BRDF_METHOD_COSINE => Some("cosine"),
        GONIO_BRDF_METHOD_GGX_FIT => Some("ggx-fit"),
        GONIO_BRDF_METHOD_PIECEWISE_CONSTANT => Some("piecewise-constant"),
        _ => None,
    }
}

/// Builds a sampler of `method` (a `GONIO_BRDF_METHOD_*` constant) for the table of `brdf`;
/// `options` may be NULL (the defaults). An unknown method or options out of range are
/// `GONIO_ERR_INVALID_ARGUMENT`; a table the HDS sampler cannot map is [`GONIO_ERR_BUILD`]. On
/// success `*out` receives a new handle that the caller releases with
/// [`gonio_brdf_sampler_free`].
///
/// # Safety
/// `brdf` must be NULL or a live handle; `options` NULL or valid for reading a
/// [`GonioBrdfSamplerOptions`]; `out` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_sampler_build(
    brdf: *const GonioBrdf,
    method: GonioBrdfMethod,
    options: *const GonioBrdfSamplerOptions,
    out: *mut *mut GonioBrdfSampler,
) -> GonioStatus {
    guard(|| {
        check_out(out, "out")?;
        let b = r(brdf, "brdf")?;
        if method_name(method).is_none() {
            return Err(Failure::invalid(format!(
                "unknown method {method}; expected GONIO_BRDF_METHOD_HDS, _COSINE, _GGX_FIT or \
                 _PIECEWISE_CONSTANT"
            )));
        }
        let o = if options.is_null() {
            let mut d = GonioBrdfSamplerOptions {
                theta_o: 0,
                phi_o: 0,
                resolution: 0,
            };
            gonio_brdf_sampler_options_default(&mut d);
            d
        } else {
            *r(options, "options")?
        };
        let nodes = o.theta_o.checked_mul(o.phi_o);
        if o.theta_o < 2 || o.phi_o < 1 || nodes.is_none_or(|n| n > 1 << 20) {
            return Err(Failure::invalid(format!(
                "options: theta_o = {} and phi_o = {}: need theta_o ≥ 2, phi_o ≥ 1 and \
                 theta_o × phi_o ≤ 1048576",
                o.theta_o, o.phi_o
            )));
        }
        if method == GONIO_BRDF_METHOD_PIECEWISE_CONSTANT && !(1..=4096).contains(&o.resolution) {
            return Err(Failure::invalid(format!(
                "options: resolution = {} is outside 1…4096",
                o.resolution
            )));
        }
        let hds = || {
            let opts = SamplerOptions {
                theta_o: o.theta_o,
                phi_o: o.phi_o,
                force_resample: false,
            };
            BrdfSampler::new(b.table.clone(), &opts)
                .map_err(|e| Failure::new(GONIO_ERR_BUILD, e.to_string()))
        };
        let inner = match method {
            GONIO_BRDF_METHOD_HDS => Inner::Hds(hds()?),
            GONIO_BRDF_METHOD_COSINE => Inner::Cosine(b.table.clone()),
            GONIO_BRDF_METHOD_GGX_FIT => {
                let alpha = GgxFit::fit(&b.table).alpha();
                Inner::Ggx(b.table.clone(), alpha)
            }
            _ => Inner::Pc(PerSliceConstant::new(
                std::sync::Arc::new(hds()?),
                o.resolution,
            )),
        };
        w(
            out,
            Box::into_raw(Box::new(GonioBrdfSampler { inner })),
            "out",
        )
    })
}

/// Releases a BRDF sampler. NULL is accepted and ignored.
///
/// # Safety
/// `sampler` must be NULL or a handle from [`gonio_brdf_sampler_build`] that was not freed yet,
/// and no other thread may be using it.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_sampler_free(sampler: *mut GonioBrdfSampler) {
    if !sampler.is_null() {
        let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            drop(Box::from_raw(sampler))
        }));
    }
}

/// The sampler's method as a static string (`"hds"`, `"cosine"`, `"ggx-fit"`,
/// `"piecewise-constant"`); NULL for a NULL handle.
///
/// # Safety
/// `sampler` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_sampler_method(
    sampler: *const GonioBrdfSampler,
) -> *const c_char {
    let Ok(s) = r(sampler, "sampler") else {
        return std::ptr::null();
    };
    let name: &'static CStr = match &s.inner {
        Inner::Hds(_) => c"hds",
        Inner::Cosine(_) => c"cosine",
        Inner::Ggx(..) => c"ggx-fit",
        Inner::Pc(_) => c"piecewise-constant",
    };
    name.as_ptr()
}

/// Samples an outgoing direction for the incident direction `wi[3]` at the point (u, v) of the
/// unit square: `*out` receives the direction, its exact density and the weight f_r·cos θ_o / pdf
/// per channel. An incident direction below the horizon gives the documented zero-weight cosine
/// sample. A point outside [0, 1]² (or NaN), a zero or non-finite `wi` are
/// `GONIO_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `wi` NULL or valid for reading 3 doubles; `out` NULL
/// or valid for writing a [`GonioBrdfSample`].
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_sample(
    sampler: *const GonioBrdfSampler,
    wi: *const f64,
    u: f64,
    v: f64,
    out: *mut GonioBrdfSample,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_in(wi, "wi")?;
        check_out(out, "out")?;
        let wi = dir_at(wi, "wi")?;
        let p = in_square([u, v])?;
        let res = s.with(|m| m.sample(wi, p));
        w(out, res.into(), "out")
    })
}

/// The density of [`gonio_brdf_sample`] at the outgoing direction `wo[3]` for the incident
/// direction `wi[3]`, per steradian (0 below the horizon).
///
/// # Safety
/// `sampler` must be NULL or a live handle; `wi`, `wo` NULL or valid for reading 3 doubles;
/// `pdf` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_pdf(
    sampler: *const GonioBrdfSampler,
    wi: *const f64,
    wo: *const f64,
    pdf: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_in(wi, "wi")?;
        check_in(wo, "wo")?;
        check_out(pdf, "pdf")?;
        let (wi, wo) = (dir_at(wi, "wi")?, dir_at(wo, "wo")?);
        w(pdf, s.with(|m| m.pdf(wi, wo)), "pdf")
    })
}

/// Why `invert` found no point.
fn no_preimage(wo: Vec3) -> Failure {
    if wo[2] < 0.0 {
        Failure::new(
            GONIO_ERR_OUTSIDE_DOMAIN,
            "the outgoing direction lies below the horizon: no point of the square maps to it",
        )
    } else {
        Failure::new(
            GONIO_ERR_ZERO_DENSITY,
            "the density is 0 at the outgoing direction: no point of the square maps to it",
        )
    }
}

/// The point (u, v) of the unit square that [`gonio_brdf_sample`] maps to the outgoing
/// direction `wo[3]` for the incident direction `wi[3]`. [`GONIO_ERR_OUTSIDE_DOMAIN`] below the
/// horizon, [`GONIO_ERR_ZERO_DENSITY`] where the density is 0.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `wi`, `wo` NULL or valid for reading 3 doubles; `u`,
/// `v` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_invert(
    sampler: *const GonioBrdfSampler,
    wi: *const f64,
    wo: *const f64,
    u: *mut f64,
    v: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_in(wi, "wi")?;
        check_in(wo, "wo")?;
        check_out(u, "u")?;
        check_out(v, "v")?;
        let (wi, wo) = (dir_at(wi, "wi")?, dir_at(wo, "wo")?);
        let p = s
            .with(|m| m.invert(wi, wo))
            .ok_or_else(|| no_preimage(wo))?;
        w(u, p[0], "u")?;
        w(v, p[1], "v")
    })
}

/// The incident directions of a batch: `wi_count` is 1 (one direction for every element) or `n`.
/// Every direction is checked; the message names the index.
unsafe fn incident_batch(wi: *const f64, wi_count: usize, n: usize) -> Result<Vec<Vec3>, Failure> {
    check_in(wi, "wi")?;
    if wi_count != 1 && wi_count != n {
        return Err(Failure::invalid(format!(
            "wi_count = {wi_count}: expected 1 (one incident direction for all) or n = {n}"
        )));
    }
    check_len::<f64>(wi_count, 3)?;
    (0..wi_count)
        .map(|i| dir_at(wi.add(3 * i), &format!("wi #{i}")))
        .collect()
}

/// `n` directions of 3 doubles, each checked (the message names the index).
unsafe fn direction_batch(p: *const f64, n: usize, what: &str) -> Result<Vec<Vec3>, Failure> {
    check_in(p, what)?;
    check_len::<f64>(n, 3)?;
    (0..n)
        .map(|i| dir_at(p.add(3 * i), &format!("{what} #{i}")))
        .collect()
}

fn pick(wi: &[Vec3], i: usize) -> Vec3 {
    wi[if wi.len() == 1 { 0 } else { i }]
}

/// f_r per channel for `n` pairs: incident directions `wi[3·wi_count]` (`wi_count` 1 or n),
/// outgoing directions `wo[3n]`, results into `f[3n]` (R, G, B per element), element i as
/// [`gonio_brdf_eval`] gives it. A zero or non-finite direction stops the batch with
/// `GONIO_ERR_INVALID_ARGUMENT` naming its index; every input is checked and read before any
/// output is written (an output may overlap an input). `n = 0` does nothing.
///
/// # Safety
/// `brdf` must be NULL or a live handle; `wi` NULL or valid for reading 3·wi_count doubles; `wo`
/// valid for reading 3n doubles; `f` valid for writing 3n doubles.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_eval_batch(
    brdf: *const GonioBrdf,
    wi: *const f64,
    wi_count: usize,
    wo: *const f64,
    n: usize,
    f: *mut f64,
) -> GonioStatus {
    guard(|| {
        let b = r(brdf, "brdf")?;
        check_out(f, "f")?;
        let wis = incident_batch(wi, wi_count, n)?;
        let wos = direction_batch(wo, n, "wo")?;
        for (i, &d) in wos.iter().enumerate() {
            let v = b.table.eval(pick(&wis, i), d);
            for (k, x) in v.iter().enumerate() {
                f.add(3 * i + k).write(*x);
            }
        }
        Ok(())
    })
}

/// Samples `n` points `uv[2n]` (u, v interleaved) for the incident directions
/// `wi[3·wi_count]` (`wi_count` 1 or n) into `out[n]`, element i as [`gonio_brdf_sample`] gives
/// it. A point outside the unit square (or NaN) or a bad direction stops the batch with
/// `GONIO_ERR_INVALID_ARGUMENT` naming its index; every input is checked and read before any
/// output is written. `n = 0` does nothing.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `wi` NULL or valid for reading 3·wi_count doubles;
/// `uv` valid for reading 2n doubles; `out` valid for writing n [`GonioBrdfSample`]s.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_sample_batch(
    sampler: *const GonioBrdfSampler,
    wi: *const f64,
    wi_count: usize,
    uv: *const f64,
    n: usize,
    out: *mut GonioBrdfSample,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_in(uv, "uv")?;
        check_out(out, "out")?;
        check_len::<GonioBrdfSample>(n, 1)?;
        let wis = incident_batch(wi, wi_count, n)?;
        let pts = std::slice::from_raw_parts(uv, 2 * n).to_vec();
        for (i, p) in pts.chunks_exact(2).enumerate() {
            in_square([p[0], p[1]])
                .map_err(|e| Failure::invalid(format!("point #{i}: {}", e.message)))?;
        }
        s.with(|m| {
            for i in 0..n {
                let res = m.sample(pick(&wis, i), [pts[2 * i], pts[2 * i + 1]]);
                out.add(i).write(res.into());
            }
        });
        Ok(())
    })
}

/// The densities of `n` pairs into `pdf[n]`: incident directions `wi[3·wi_count]` (`wi_count` 1
/// or n), outgoing directions `wo[3n]`, element i as [`gonio_brdf_pdf`] gives it. Inputs are
/// checked and read before any output is written. `n = 0` does nothing.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `wi` NULL or valid for reading 3·wi_count doubles;
/// `wo` valid for reading 3n doubles; `pdf` valid for writing n doubles.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_pdf_batch(
    sampler: *const GonioBrdfSampler,
    wi: *const f64,
    wi_count: usize,
    wo: *const f64,
    n: usize,
    pdf: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(pdf, "pdf")?;
        let wis = incident_batch(wi, wi_count, n)?;
        let wos = direction_batch(wo, n, "wo")?;
        s.with(|m| {
            for (i, &d) in wos.iter().enumerate() {
                pdf.add(i).write(m.pdf(pick(&wis, i), d));
            }
        });
        Ok(())
    })
}

/// The points of the square of `n` pairs into `uv[2n]` (u, v interleaved): incident directions
/// `wi[3·wi_count]` (`wi_count` 1 or n), outgoing directions `wo[3n]`; NaN, NaN for a direction
/// that no point maps to (below the horizon or of density 0). Inputs are checked and read before
/// any output is written. `n = 0` does nothing.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `wi` NULL or valid for reading 3·wi_count doubles;
/// `wo` valid for reading 3n doubles; `uv` valid for writing 2n doubles.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_invert_batch(
    sampler: *const GonioBrdfSampler,
    wi: *const f64,
    wi_count: usize,
    wo: *const f64,
    n: usize,
    uv: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(uv, "uv")?;
        let wis = incident_batch(wi, wi_count, n)?;
        let wos = direction_batch(wo, n, "wo")?;
        s.with(|m| {
            for (i, &d) in wos.iter().enumerate() {
                let p = m.invert(pick(&wis, i), d).unwrap_or([f64::NAN; 2]);
                uv.add(2 * i).write(p[0]);
                uv.add(2 * i + 1).write(p[1]);
            }
        });
        Ok(())
    })
}

/// f_r per channel from a sampler's own copy of the table (as [`gonio_brdf_eval`]), so that a
/// caller holding only the sampler can evaluate the BRDF (e.g. for light sampling with MIS).
///
/// # Safety
/// `sampler` must be NULL or a live handle; `wi` and `wo` NULL or valid for reading 3 doubles;
/// `f` NULL or valid for writing 3 doubles.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_sampler_eval(
    sampler: *const GonioBrdfSampler,
    wi: *const f64,
    wo: *const f64,
    f: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_in(wi, "wi")?;
        check_in(wo, "wo")?;
        check_out(f, "f")?;
        let v = s.table().eval(dir_at(wi, "wi")?, dir_at(wo, "wo")?);
        for (k, x) in v.iter().enumerate() {
            f.add(k).write(*x);
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{
        gonio_last_error_message, GONIO_ERR_INVALID_ARGUMENT, GONIO_ERR_NULL_POINTER, GONIO_OK,
    };
    use gonio::brdf::{write_json, write_utia_dirs, Analytic};
    use std::ptr::{null, null_mut};

    fn last_error() -> String {
        unsafe { CStr::from_ptr(gonio_last_error_message()) }
            .to_string_lossy()
            .into_owned()
    }

    fn read(bytes: &[u8]) -> (GonioStatus, *mut GonioBrdf) {
        let mut b = null_mut();
        let st = unsafe {
            gonio_brdf_read_memory(bytes.as_ptr(), bytes.len(), c"m".as_ptr(), null(), &mut b)
        };
        (st, b)
    }

    fn build(b: *const GonioBrdf, method: GonioBrdfMethod) -> *mut GonioBrdfSampler {
        let mut s = null_mut();
        let st = unsafe { gonio_brdf_sampler_build(b, method, null(), &mut s) };
        assert_eq!(st, GONIO_OK, "{}", last_error());
        s
    }

    fn mix_json() -> Vec<u8> {
        let a = Analytic::Mix {
            kd: [0.3, 0.4, 0.5],
            alpha: 0.3,
            f0: [0.04; 3],
        };
        write_json(&a.table(10, 24).unwrap()).into_bytes()
    }

    /// Every method: sample's pdf equals pdf(), the weight is f·cos/pdf, invert round-trips (all
    /// but GGX, whose inverse goes through the half vector and holds only where the sample is
    /// above the horizon), batches agree with single calls.
    #[test]
    fn every_method_agrees_with_itself() {
        let (st, b) = read(&mix_json());
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let mut info = GonioBrdfInfo {
            format: 0,
            anisotropic: -1,
            channels: 0,
            theta_i: 0,
            phi_i: 0,
            theta_o: 0,
            phi_o: 0,
            table_bytes: 0,
            merl_resampling_error: 0.0,
            merl_no_data: 7,
        };
        assert_eq!(unsafe { gonio_brdf_info(b, &mut info) }, GONIO_OK);
        assert_eq!(info.format, GONIO_BRDF_FORMAT_JSON);
        assert_eq!((info.anisotropic, info.channels), (0, 3));
        assert_eq!(
            (info.theta_i, info.phi_i, info.theta_o, info.phi_o),
            (10, 1, 10, 24)
        );
        assert!(info.merl_resampling_error.is_nan() && info.merl_no_data == 0);
        let wi = [0.4, 0.1, 0.8];
        let n = 64;
        let uv: Vec<f64> = (0..2 * n)
            .map(|k| ((k * 37 + 5) % 97) as f64 / 97.0)
            .collect();
        for method in 0..4 {
            let s = build(b, method);
            let mut batch = vec![GonioBrdfSample::default(); n];
            let st = unsafe {
                gonio_brdf_sample_batch(s, wi.as_ptr(), 1, uv.as_ptr(), n, batch.as_mut_ptr())
            };
            assert_eq!(st, GONIO_OK, "{}", last_error());
            let mut wos = vec![];
            for i in 0..n {
                let mut one = GonioBrdfSample::default();
                let st = unsafe {
                    gonio_brdf_sample(s, wi.as_ptr(), uv[2 * i], uv[2 * i + 1], &mut one)
                };
                assert_eq!(st, GONIO_OK);
                assert_eq!(one, batch[i]);
                let d = one.direction;
                wos.extend_from_slice(&d);
                let mut p = -1.0;
                assert_eq!(
                    unsafe { gonio_brdf_pdf(s, wi.as_ptr(), d.as_ptr(), &mut p) },
                    GONIO_OK
                );
                if d[2] > 0.0 {
                    // Relative 1e-9, plus 1e-12 /sr absolute: at the horizon the density is ∝ cos θ_o,
                    // which z carries to about 1e-16 only (the mean density is 1/2π).
                    assert!(
                        (p - one.pdf).abs() <= 1e-9 * one.pdf + 1e-12,
                        "method {method}: {p} vs {}",
                        one.pdf
                    );
                    let mut f = [0.0; 3];
                    assert_eq!(
                        unsafe {
                            gonio_brdf_sampler_eval(s, wi.as_ptr(), d.as_ptr(), f.as_mut_ptr())
                        },
                        GONIO_OK
                    );
                    for (fc, wc) in f.iter().zip(one.weight) {
                        let expect = fc * d[2] / one.pdf;
                        assert!((wc - expect).abs() <= 1e-9 * expect.max(1e-300));
                    }
                    if method != GONIO_BRDF_METHOD_GGX_FIT {
                        let (mut u, mut v) = (-1.0, -1.0);
                        let st = unsafe {
                            gonio_brdf_invert(s, wi.as_ptr(), d.as_ptr(), &mut u, &mut v)
                        };
                        assert_eq!(st, GONIO_OK, "{}", last_error());
                        assert!(
                            (u - uv[2 * i]).abs() < 1e-7 && (v - uv[2 * i + 1]).abs() < 1e-7,
                            "method {method}: ({u}, {v}) vs ({}, {})",
                            uv[2 * i],
                            uv[2 * i + 1]
                        );
                    }
                }
            }
            let mut pdf = vec![0.0; n];
            let st = unsafe {
                gonio_brdf_pdf_batch(s, wi.as_ptr(), 1, wos.as_ptr(), n, pdf.as_mut_ptr())
            };
            assert_eq!(st, GONIO_OK);
            let mut inv = vec![0.0; 2 * n];
            let st = unsafe {
                gonio_brdf_invert_batch(s, wi.as_ptr(), 1, wos.as_ptr(), n, inv.as_mut_ptr())
            };
            assert_eq!(st, GONIO_OK);
            for i in 0..n {
                let (mut p, mut u, mut v) = (0.0, f64::NAN, f64::NAN);
                let wo = &wos[3 * i..3 * i + 3];
                unsafe { gonio_brdf_pdf(s, wi.as_ptr(), wo.as_ptr(), &mut p) };
                assert_eq!(pdf[i], p);
                unsafe { gonio_brdf_invert(s, wi.as_ptr(), wo.as_ptr(), &mut u, &mut v) };
                assert!(inv[2 * i] == u || (inv[2 * i].is_nan() && u.is_nan()));
            }
            let name = unsafe { CStr::from_ptr(gonio_brdf_sampler_method(s)) };
            assert_eq!(Some(name.to_str().unwrap()), method_name(method));
            unsafe { gonio_brdf_sampler_free(s) };
        }
        // eval agrees with the library's table, and the batch with single calls.
        let table = gonio::brdf::read_json(std::str::from_utf8(&mix_json()).unwrap()).unwrap();
        let wo = [[0.0, 0.0, 1.0], [-0.5, 0.2, 0.6], [0.3, -0.3, 0.1]];
        let flat: Vec<f64> = wo.iter().flatten().copied().collect();
        let mut f = vec![0.0; 9];
        let st =
            unsafe { gonio_brdf_eval_batch(b, wi.as_ptr(), 1, flat.as_ptr(), 3, f.as_mut_ptr()) };
        assert_eq!(st, GONIO_OK);
        for (k, d) in wo.iter().enumerate() {
            let e = table.eval(
                gonio::sampler::normalize(wi).unwrap(),
                gonio::sampler::normalize(*d).unwrap(),
            );
            assert_eq!(&f[3 * k..3 * k + 3], &e);
        }
        unsafe { gonio_brdf_free(b) };
    }

    #[test]
    fn errors_have_codes_and_messages() {
        let (st, b) = read(&mix_json());
        assert_eq!(st, GONIO_OK);
        let s = build(b, GONIO_BRDF_METHOD_HDS);
        unsafe { gonio_brdf_free(b) }; // the sampler holds its own table
        let wi = [0.0, 0.0, 1.0];
        let mut out = GonioBrdfSample::default();
        let st = unsafe { gonio_brdf_sample(s, wi.as_ptr(), 0.5, f64::NAN, &mut out) };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(
            last_error().contains("outside the unit square"),
            "{}",
            last_error()
        );
        let bad = [0.0, f64::NAN, 1.0];
        let st = unsafe { gonio_brdf_sample(s, bad.as_ptr(), 0.5, 0.5, &mut out) };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(
            last_error().starts_with("wi: the direction"),
            "{}",
            last_error()
        );
        // A batch names the index of the bad element and writes nothing.
        let uv = [0.1, 0.2, 0.3, 1.5, 0.5, 0.5];
        let mut outs = [GonioBrdfSample::default(); 3];
        let st = unsafe {
            gonio_brdf_sample_batch(s, wi.as_ptr(), 1, uv.as_ptr(), 3, outs.as_mut_ptr())
        };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(last_error().starts_with("point #1: "), "{}", last_error());
        assert!(outs.iter().all(|o| *o == GonioBrdfSample::default()));
        let wo = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let mut pdf = [-1.0; 2];
        let st =
            unsafe { gonio_brdf_pdf_batch(s, wi.as_ptr(), 1, wo.as_ptr(), 2, pdf.as_mut_ptr()) };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(last_error().starts_with("wo #1: "), "{}", last_error());
        assert_eq!(pdf, [-1.0; 2]);
        let st =
            unsafe { gonio_brdf_pdf_batch(s, wi.as_ptr(), 2, wo.as_ptr(), 3, pdf.as_mut_ptr()) };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(last_error().starts_with("wi_count = 2"), "{}", last_error());
        // Below the horizon: no preimage; the batch writes NaN.
        let down = [0.3, 0.0, -0.5];
        let (mut u, mut v) = (0.0, 0.0);
        let st = unsafe { gonio_brdf_invert(s, wi.as_ptr(), down.as_ptr(), &mut u, &mut v) };
        assert_eq!(st, GONIO_ERR_OUTSIDE_DOMAIN, "{}", last_error());
        let mut p = -1.0;
        assert_eq!(
            unsafe { gonio_brdf_pdf(s, wi.as_ptr(), down.as_ptr(), &mut p) },
            GONIO_OK
        );
        assert_eq!(p, 0.0);
        let st = unsafe { gonio_brdf_sample(null(), wi.as_ptr(), 0.5, 0.5, &mut out) };
        assert_eq!(st, GONIO_ERR_NULL_POINTER);
        let st = unsafe { gonio_brdf_sample(s, wi.as_ptr(), 0.5, 0.5, null_mut()) };
        assert_eq!(st, GONIO_ERR_NULL_POINTER);
        assert_eq!(last_error(), "out is NULL or not aligned for its type");
        unsafe { gonio_brdf_sampler_free(s) };
        unsafe { gonio_brdf_sampler_free(null_mut()) };
        unsafe { gonio_brdf_free(null_mut()) };
        assert!(unsafe { gonio_brdf_sampler_method(null()) }.is_null());

        // Unknown method and bad options.
        let (_, b) = read(&mix_json());
        let mut s = null_mut();
        let st = unsafe { gonio_brdf_sampler_build(b, 9, null(), &mut s) };
        assert_eq!((st, s), (GONIO_ERR_INVALID_ARGUMENT, null_mut()));
        let mut o = GonioBrdfSamplerOptions {
            theta_o: 0,
            phi_o: 0,
            resolution: 0,
        };
        assert_eq!(
            unsafe { gonio_brdf_sampler_options_default(&mut o) },
            GONIO_OK
        );
        assert_eq!((o.theta_o, o.phi_o, o.resolution), (46, 90, 128));
        o.resolution = 0;
        let st = unsafe {
            gonio_brdf_sampler_build(b, GONIO_BRDF_METHOD_PIECEWISE_CONSTANT, &o, &mut s)
        };
        assert_eq!(st, GONIO_ERR_INVALID_ARGUMENT);
        assert!(last_error().contains("resolution = 0"), "{}", last_error());
        unsafe { gonio_brdf_free(b) };
        let mut ro = GonioBrdfReadOptions {
            merl_theta: 0,
            merl_phi: 0,
        };
        assert_eq!(
            unsafe { gonio_brdf_read_options_default(&mut ro) },
            GONIO_OK
        );
        assert_eq!((ro.merl_theta, ro.merl_phi), (46, 90));
        ro.merl_theta = 1;
        let bytes = mix_json();
        let mut b = null_mut();
        let st =
            unsafe { gonio_brdf_read_memory(bytes.as_ptr(), bytes.len(), null(), &ro, &mut b) };
        assert_eq!((st, b), (GONIO_ERR_INVALID_ARGUMENT, null_mut()));

        // Files that do not decode: typed, located messages; nothing handed out.
        let (st, b) = read(b"");
        assert_eq!((st, b), (GONIO_ERR_PARSE, null_mut()));
        assert_eq!(last_error(), "m: the input is empty (0 bytes)");
        let (st, _) = read(b"not a brdf at all");
        assert_eq!(st, GONIO_ERR_PARSE, "{}", last_error());
        assert!(
            last_error().starts_with("m: not a BRDF file"),
            "{}",
            last_error()
        );
        let text =
            String::from_utf8(mix_json())
                .unwrap()
                .replacen("\"values\":[", "\"values\":[-", 1);
        let (st, _) = read(text.as_bytes());
        assert_eq!(st, GONIO_ERR_PARSE, "{}", last_error());
        // Located by line and column in the JSON text (issue 40; it said "byte 0").
        assert!(
            last_error().starts_with("m: json 1:") && last_error().contains("values[0] = -"),
            "{}",
            last_error()
        );
        let half = &mix_json()[..100];
        let (st, _) = read(half);
        assert_eq!(st, GONIO_ERR_PARSE);
        assert!(last_error().starts_with("m: json "), "{}", last_error());
        let mut b = null_mut();
        let st = unsafe { gonio_brdf_read_path(c"/nonexistent/x.binary".as_ptr(), null(), &mut b) };
        assert_eq!(st, crate::GONIO_ERR_IO);
        let st = unsafe { gonio_brdf_read_path(c"/".as_ptr(), null(), &mut b) };
        assert_eq!(st, crate::GONIO_ERR_IO);
        assert!(
            last_error().contains("not a regular file"),
            "{}",
            last_error()
        );
    }

    /// A UTIA file of an anisotropic lobe, read from a path (the format by content only: the
    /// name has no extension), sampled by HDS with exact pdf.
    #[test]
    fn utia_file_from_a_path() {
        let a = Analytic::AshikhminShirley {
            nu: 20.0,
            nv: 80.0,
            rs: [0.5, 0.4, 0.3],
        };
        let bytes = write_utia_dirs(|wi, wo| a.eval(wi, wo));
        let file = std::env::temp_dir().join(format!("gonio-capi-brdf-{}", std::process::id()));
        std::fs::write(&file, &bytes).unwrap();
        let cpath = std::ffi::CString::new(file.to_str().unwrap()).unwrap();
        let mut b = null_mut();
        let st = unsafe { gonio_brdf_read_path(cpath.as_ptr(), null(), &mut b) };
        std::fs::remove_file(&file).ok();
        assert_eq!(st, GONIO_OK, "{}", last_error());
        let mut info = GonioBrdfInfo {
            format: 0,
            anisotropic: 0,
            channels: 0,
            theta_i: 0,
            phi_i: 0,
            theta_o: 0,
            phi_o: 0,
            table_bytes: 0,
            merl_resampling_error: 0.0,
            merl_no_data: 0,
        };
        unsafe { gonio_brdf_info(b, &mut info) };
        assert_eq!((info.format, info.anisotropic), (GONIO_BRDF_FORMAT_UTIA, 1));
        let s = build(b, GONIO_BRDF_METHOD_HDS);
        let wi = [0.5, 0.5, 0.7];
        for k in 0..20 {
            let (u, v) = ((k as f64 + 0.5) / 20.0, ((k * 7) % 20) as f64 / 20.0 + 0.01);
            let mut o = GonioBrdfSample::default();
            assert_eq!(
                unsafe { gonio_brdf_sample(s, wi.as_ptr(), u, v, &mut o) },
                GONIO_OK
            );
            let mut p = 0.0;
            unsafe { gonio_brdf_pdf(s, wi.as_ptr(), o.direction.as_ptr(), &mut p) };
            assert!((p - o.pdf).abs() <= 1e-9 * o.pdf, "{p} vs {}", o.pdf);
            assert!(o.weight.iter().all(|w| w.is_finite() && *w >= 0.0));
        }
        unsafe { gonio_brdf_sampler_free(s) };
        unsafe { gonio_brdf_free(b) };
    }
}
