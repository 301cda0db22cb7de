//! # gonio-capi — the C ABI of gonio
//!
//! A shared (`libgonio_capi.so`) and a static (`libgonio_capi.a`) library with the header
//! `include/gonio.h`, generated from this file by cbindgen. It reads IES LM-63, EULUMDAT and
//! native JSON diagrams, builds a sampler of any method and domain through the library's factory,
//! and samples, evaluates the pdf, inverts and evaluates the target density one point at a time or
//! in batches (f64 and f32, array-of-structs and structure-of-arrays). `docs/C_API.md` is the
//! user's guide; the rules in short:
//!
//! * **Handles** are opaque: a [`GonioDiagram`] (a read file) and a [`GonioSampler`]. Each is
//!   created by one function and released by its `*_free` function (which accepts NULL). A sampler
//!   does not borrow the diagram it was built from: the diagram may be freed first.
//! * **Errors**: every function that can fail returns a [`GonioStatus`] ([`GONIO_OK`] = 0) and
//!   leaves a message for [`gonio_last_error_message`] in a thread-local buffer: the same text as
//!   the `gonio` CLI prints, e.g. `lamp.ies:12:5: expected a number, found "x"`.
//! * **No panic crosses the boundary**: each entry point catches one and returns
//!   [`GONIO_ERR_PANIC`] (a bug of gonio; the message says where).
//! * **Pointers** are checked for NULL and for the alignment of their type before use; outputs are
//!   written only on success, except that batch functions may have written part of their output
//!   when they fail. A batch reads the inputs of a chunk of 256 elements before it writes their
//!   outputs, so an output may overwrite its own or an earlier element's input (in place).
//! * **Threads**: a [`GonioSampler`] and a [`GonioDiagram`] are immutable after creation; any
//!   number of threads may use one handle at the same time. Freeing must not race with use.
//! * **Frames and units**: directions are `[x, y, z]` in gonio's frame (θ from +z, φ from +x toward
//!   +y; for photometric files the luminaire's nadir γ = 0° is −z and the C0 plane is +x), given
//!   as any finite non-zero vector (normalised internally); densities are per steradian; flux is
//!   in lumens for photometric files (candela × sr).
#![warn(missing_docs)]

use gonio::input::{InputKind, LoadError};
use gonio::mapping::SphereLayout;
use gonio::photometry::{DirTiltResolver, NoTiltFiles, Photometry};
use gonio::sampler::{BuildOptions, Method, Sample, Vec3};
use gonio::{Diagram, Domain, InvertError, Sampler};
use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::io::Read;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------------------------------------
// Status codes and enumerations (plain integers at the boundary, so that no value a C caller
// passes can be an invalid Rust enum).

/// The result of every fallible function: [`GONIO_OK`] or one of the `GONIO_ERR_*` codes.
pub type GonioStatus = i32;
/// Success.
pub const GONIO_OK: GonioStatus = 0;
/// A pointer argument was NULL (or not aligned for its type).
pub const GONIO_ERR_NULL_POINTER: GonioStatus = 1;
/// An argument is out of range: an unknown enumeration value, a length whose byte size overflows,
/// a zero or non-finite direction.
pub const GONIO_ERR_INVALID_ARGUMENT: GonioStatus = 2;
/// A file could not be opened or read.
pub const GONIO_ERR_IO: GonioStatus = 3;
/// The file's content is not a valid photometric file or diagram; the message has
/// `file:line:column`.
pub const GONIO_ERR_PARSE: GonioStatus = 4;
/// The sampler could not be built for this diagram (e.g. a hemisphere domain for a diagram that
/// extends below the horizon, or no power to sample).
pub const GONIO_ERR_BUILD: GonioStatus = 5;
/// The method has no inverse (rejection sampling), or the sampler has no ratio bound.
pub const GONIO_ERR_UNSUPPORTED: GonioStatus = 6;
/// The direction lies outside the sampler's domain (e.g. below the horizon of a hemisphere
/// sampler), so it has no point of the square.
pub const GONIO_ERR_OUTSIDE_DOMAIN: GonioStatus = 7;
/// An internal error of gonio (a caught panic). Please report it with the message.
pub const GONIO_ERR_PANIC: GonioStatus = 8;
/// The direction lies in the sampler's domain, but the density is 0 there, so no point of the
/// square maps to it (e.g. below the horizon of a luminaire that emits no light downwards).
pub const GONIO_ERR_ZERO_DENSITY: GonioStatus = 9;

/// The format of a photometric file or diagram: one of the `GONIO_FORMAT_*` constants.
pub type GonioFormat = i32;
/// By the path's extension: `.ies`, `.ldt` or `.json` in any letter case (paths only).
pub const GONIO_FORMAT_AUTO: GonioFormat = 0;
/// IES LM-63 (1986 to 2019).
pub const GONIO_FORMAT_IES: GonioFormat = 1;
/// EULUMDAT.
pub const GONIO_FORMAT_EULUMDAT: GonioFormat = 2;
/// gonio's native JSON diagram (`theta_deg`, `phi_deg`, `values`).
pub const GONIO_FORMAT_JSON: GonioFormat = 3;

/// A sampling method: one of the `GONIO_METHOD_*` constants.
pub type GonioMethod = i32;
/// The Havran–Dmitriev–Seidel mapping (bijective, continuous, exact pdf, closed-form inverse).
pub const GONIO_METHOD_HDS: GonioMethod = 0;
/// A piecewise-constant image over an equal-area map (as pbrt-v4's goniometric light).
pub const GONIO_METHOD_PIECEWISE_CONSTANT: GonioMethod = 1;
/// Marginal–conditional inversion of the bilinear target itself.
pub const GONIO_METHOD_BILINEAR: GonioMethod = 2;
/// Rejection sampling against the maximum (no inverse).
pub const GONIO_METHOD_REJECTION: GonioMethod = 3;
/// Uniform directions that ignore the diagram.
pub const GONIO_METHOD_UNIFORM: GonioMethod = 4;

/// The part of the sphere a sampler covers: one of the `GONIO_DOMAIN_*` constants.
pub type GonioDomain = i32;
/// The diagram's own policy: the sphere for photometric files; for a JSON diagram the hemisphere
/// when its last parallel lies at θ ≤ 90°, else the sphere (as the `gonio` CLI).
pub const GONIO_DOMAIN_AUTO: GonioDomain = 0;
/// The upper hemisphere z ≥ 0 (2π sr).
pub const GONIO_DOMAIN_HEMISPHERE: GonioDomain = 1;
/// The whole sphere (4π sr).
pub const GONIO_DOMAIN_SPHERE: GonioDomain = 2;

/// One sample: a unit direction in gonio's frame and the exact density of the sampler there.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GonioSample {
    /// The unit direction `[x, y, z]`.
    pub direction: [f64; 3],
    /// Density of the sampler at `direction`, per steradian (equal to `gonio_pdf` there).
    pub pdf: f64,
}

/// A layout of the HDS map on the sphere: one of the `GONIO_SPHERE_LAYOUT_*` constants.
pub type GonioSphereLayout = i32;
/// Two hemisphere maps side by side on the square, split by power (the default).
pub const GONIO_SPHERE_LAYOUT_SPLIT: GonioSphereLayout = 0;
/// One map with the whole-sphere Lambert lift.
pub const GONIO_SPHERE_LAYOUT_LAMBERT: GonioSphereLayout = 1;

/// Options of [`gonio_sampler_build_with`]; each method reads those that apply to it. Fill it
/// with [`gonio_build_options_default`], then change fields. (The struct may gain fields in later
/// versions; always start from the defaults.)
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GonioBuildOptions {
    /// HDS: the requested relative accuracy of the pdf/target bound, in (0, 1); 0 for none (the
    /// default). Validated; see `BuildOptions::tolerance` in the library for what it achieves.
    pub tolerance: f64,
    /// Piecewise-constant: pixels per side of the image (default 0 = the library's default).
    pub resolution: usize,
    /// Rejection: seed of the proposal stream (default 0).
    pub seed: u64,
    /// HDS on the sphere: a `GONIO_SPHERE_LAYOUT_*` constant (default split).
    pub sphere_layout: GonioSphereLayout,
}

// ---------------------------------------------------------------------------------------------
// Handles.

/// A read photometric file or diagram (opaque). Created by [`gonio_diagram_read_path`] or
/// [`gonio_diagram_read_memory`], released by [`gonio_diagram_free`]. Immutable: may be used from
/// any number of threads at once.
pub struct GonioDiagram {
    /// The name used in messages (the path, or the name given to `read_memory`).
    name: String,
    /// The distribution in gonio's frame.
    diagram: Diagram,
    /// The file as read, for IES and EULUMDAT input.
    photometry: Option<Photometry>,
    /// The reader's warnings, formatted as the CLI prints them.
    warnings: Vec<CString>,
}

/// A sampler of any method and domain (opaque). Created by [`gonio_sampler_build`], released by
/// [`gonio_sampler_free`]. Immutable: may be shared between threads and used from all of them at
/// once (every function taking `const GonioSampler *` is thread-safe).
pub struct GonioSampler {
    inner: Box<dyn Sampler>,
}

// ---------------------------------------------------------------------------------------------
// Errors.

/// Largest file [`gonio_diagram_read_path`] and [`gonio_diagram_read_memory`] read: 64 MiB, the
/// cap of every gonio front end (CLI, Python, C), checked against the size before reading.
pub const GONIO_MAX_FILE_BYTES: u64 = 64 << 20;

/// An error on its way to the caller: a status code and the message.
#[derive(Debug)]
struct Failure {
    status: GonioStatus,
    message: String,
}

impl Failure {
    fn new(status: GonioStatus, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
        }
    }
    fn null(what: &str) -> Self {
        Self::new(
            GONIO_ERR_NULL_POINTER,
            format!("{what} is NULL or not aligned for its type"),
        )
    }
    fn invalid(message: impl Into<String>) -> Self {
        Self::new(GONIO_ERR_INVALID_ARGUMENT, message)
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    // A NUL inside the message would cut it; replace it visibly.
    let c = CString::new(message.replace('\0', "\\0")).unwrap_or_default();
    // During thread teardown the buffer may be gone: then the message is lost, nothing else.
    let _ = LAST_ERROR.try_with(|e| *e.borrow_mut() = c);
}

/// Runs an entry point: catches a panic, records the message of a failure, returns the status.
fn guard(f: impl FnOnce() -> Result<(), Failure>) -> GonioStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => GONIO_OK,
        Ok(Err(e)) => {
            set_last_error(&e.message);
            e.status
        }
        Err(payload) => {
            let msg = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last_error(&format!("internal error: {msg}"));
            GONIO_ERR_PANIC
        }
    }
}

/// The message of the last failed call on the calling thread, as UTF-8 text without a trailing
/// newline (an empty string when no call has failed on this thread yet).
///
/// The pointer stays valid until the next failing gonio call on the same thread; copy the text to
/// keep it. Never NULL. Calls that succeed leave the message unchanged.
#[no_mangle]
pub extern "C" fn gonio_last_error_message() -> *const c_char {
    const GONE: &CStr = c"the error message is unavailable (thread teardown)";
    catch_unwind(|| LAST_ERROR.try_with(|e| e.borrow().as_ptr()))
        .ok()
        .and_then(Result::ok)
        .unwrap_or(GONE.as_ptr())
}

/// The version of gonio, e.g. `"0.1.0"` (a static string, never NULL).
#[no_mangle]
pub extern "C" fn gonio_version() -> *const c_char {
    static VERSION: &CStr =
        match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
            Ok(c) => c,
            Err(_) => c"unknown",
        };
    VERSION.as_ptr()
}

// ---------------------------------------------------------------------------------------------
// Pointer helpers.

/// A shared reference from a pointer that must be non-NULL and aligned.
///
/// # Safety
/// A non-NULL `p` must point to a live `T`.
unsafe fn r<'a, T>(p: *const T, what: &str) -> Result<&'a T, Failure> {
    if p.is_null() || !p.is_aligned() {
        return Err(Failure::null(what));
    }
    Ok(&*p)
}

/// Writes through an output pointer that must be non-NULL and aligned.
///
/// # Safety
/// A non-NULL `p` must be valid for writing a `T`.
unsafe fn w<T>(p: *mut T, value: T, what: &str) -> Result<(), Failure> {
    if p.is_null() || !p.is_aligned() {
        return Err(Failure::null(what));
    }
    p.write(value);
    Ok(())
}

/// Checks an output pointer before any work is done.
fn check_out<T>(p: *mut T, what: &str) -> Result<(), Failure> {
    if p.is_null() || !p.is_aligned() {
        return Err(Failure::null(what));
    }
    Ok(())
}

/// A C string argument as UTF-8.
///
/// # Safety
/// A non-NULL `p` must point to a NUL-terminated string.
unsafe fn c_str<'a>(p: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if p.is_null() {
        return Err(Failure::null(what));
    }
    CStr::from_ptr(p)
        .to_str()
        .map_err(|e| Failure::invalid(format!("{what} is not UTF-8 text ({e})")))
}

/// A path argument from its bytes: any bytes on Unix; UTF-8 elsewhere.
fn path_of(raw: &CStr) -> Result<PathBuf, Failure> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        Ok(PathBuf::from(std::ffi::OsStr::from_bytes(raw.to_bytes())))
    }
    #[cfg(not(unix))]
    {
        raw.to_str()
            .map(PathBuf::from)
            .map_err(|e| Failure::invalid(format!("path is not UTF-8 text ({e})")))
    }
}

// ---------------------------------------------------------------------------------------------
// Reading.

fn kind_of(format: GonioFormat) -> Result<Option<InputKind>, Failure> {
    match format {
        GONIO_FORMAT_AUTO => Ok(None),
        GONIO_FORMAT_IES => Ok(Some(InputKind::Ies)),
        GONIO_FORMAT_EULUMDAT => Ok(Some(InputKind::Eulumdat)),
        GONIO_FORMAT_JSON => Ok(Some(InputKind::Json)),
        other => Err(Failure::invalid(format!(
            "unknown format {other}; expected GONIO_FORMAT_AUTO, _IES, _EULUMDAT or _JSON"
        ))),
    }
}

/// The format of a path by its extension, with the CLI's message when there is none.
fn kind_of_path(name: &str) -> Result<InputKind, Failure> {
    if let Some(kind) = InputKind::from_extension(name) {
        return Ok(kind);
    }
    let ext = Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext {
        Some(e) => Err(Failure::invalid(format!(
            "{name}: unknown input format `.{e}`; expected .json, .ies or .ldt"
        ))),
        None => Err(Failure::invalid(format!(
            "{name}: the file name has no extension; expected .json, .ies or .ldt"
        ))),
    }
}

/// `FILE:LINE:COLUMN: message` as the CLI prints a located error (line 0: the file as a whole;
/// column 0: unknown).
fn located(file: &str, line: usize, column: usize, message: &str) -> String {
    match (line, column) {
        (0, _) => format!("{file}: {message}"),
        (l, 0) => format!("{file}:{l}: {message}"),
        (l, c) => format!("{file}:{l}:{c}: {message}"),
    }
}

/// The message of an input over [`GONIO_MAX_FILE_BYTES`] (the CLI's).
fn too_large(name: &str, len: u64) -> Failure {
    Failure::new(
        GONIO_ERR_IO,
        format!(
            "{name}: the file has {len} bytes, more than the limit of {GONIO_MAX_FILE_BYTES} \
             bytes ({} MiB); not read",
            GONIO_MAX_FILE_BYTES >> 20
        ),
    )
}

/// Reads a regular file of at most [`GONIO_MAX_FILE_BYTES`]. The kind and size are checked
/// before the file is opened (opening a FIFO without a writer would block forever), and again on
/// the open file (it may have been replaced in between).
fn read_bounded(path: &Path, name: &str) -> Result<Vec<u8>, Failure> {
    let io = |e: std::io::Error| Failure::new(GONIO_ERR_IO, format!("cannot read {name}: {e}"));
    let not_regular = || {
        Failure::new(
            GONIO_ERR_IO,
            format!("cannot read {name}: not a regular file"),
        )
    };
    let before = std::fs::metadata(path).map_err(io)?;
    if !before.is_file() {
        return Err(not_regular());
    }
    if before.len() > GONIO_MAX_FILE_BYTES {
        return Err(too_large(name, before.len()));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular());
    }
    if meta.len() > GONIO_MAX_FILE_BYTES {
        return Err(too_large(name, meta.len()));
    }
    let mut bytes = Vec::new();
    file.take(GONIO_MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > GONIO_MAX_FILE_BYTES {
        return Err(too_large(name, bytes.len() as u64));
    }
    Ok(bytes)
}

/// Turns bytes into a diagram handle, with the CLI's messages.
fn parse(
    name: &str,
    bytes: &[u8],
    kind: InputKind,
    tilt_dir: Option<PathBuf>,
) -> Result<GonioDiagram, Failure> {
    let loaded = match tilt_dir {
        Some(dir) => gonio::input::load(bytes, kind, &DirTiltResolver::new(dir)),
        None => gonio::input::load(bytes, kind, &NoTiltFiles),
    }
    .map_err(|e| {
        let msg = match e {
            LoadError::Json {
                line,
                column,
                message,
            } => located(name, line, column, &message),
            LoadError::Parse(e) => located(name, e.line, e.column, &e.message),
            LoadError::Expand { error, .. } => {
                format!("{name}: cannot expand the distribution: {error}")
            }
            other => format!("{name}: {other}"),
        };
        Failure::new(GONIO_ERR_PARSE, msg)
    })?;
    let (diagram, photometry) = (loaded.diagram, loaded.photometry.map(|p| *p));
    let warnings = photometry
        .iter()
        .flat_map(|p| &p.warnings)
        .map(|w| {
            let text = format!("{name}:{}:{}: warning: {}", w.line, w.column, w.message);
            CString::new(text.replace('\0', "\\0")).unwrap_or_default()
        })
        .collect();
    Ok(GonioDiagram {
        name: name.to_string(),
        diagram,
        photometry,
        warnings,
    })
}

/// Reads a photometric file or diagram from a path.
///
/// `format` is one of the `GONIO_FORMAT_*` constants; [`GONIO_FORMAT_AUTO`] picks it by the
/// extension. TILT files that an IES file names are looked up next to it. Files larger than
/// [`GONIO_MAX_FILE_BYTES`] and anything that is not a regular file are refused. On success
/// `*out` receives a new handle that the caller releases with [`gonio_diagram_free`].
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string; `out` must be NULL or valid for writing a
/// pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_read_path(
    path: *const c_char,
    format: GonioFormat,
    out: *mut *mut GonioDiagram,
) -> GonioStatus {
    guard(|| {
        check_out(out, "out")?;
        if path.is_null() {
            return Err(Failure::null("path"));
        }
        // Any bytes are a path on Unix (as in Python); messages show it lossily decoded.
        let raw = CStr::from_ptr(path);
        let owned = path_of(raw)?;
        let lossy = raw.to_string_lossy();
        let name: &str = &lossy;
        let kind = match kind_of(format)? {
            Some(k) => k,
            None => kind_of_path(name)?,
        };
        let bytes = read_bounded(&owned, name)?;
        let dir = match owned.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let d = parse(name, &bytes, kind, Some(dir))?;
        w(out, Box::into_raw(Box::new(d)), "out")
    })
}

/// Reads a photometric file or diagram from `len` bytes at `data`.
///
/// `format` must name the format ([`GONIO_FORMAT_AUTO`] is refused: there is no extension).
/// `name` (may be NULL, then `"<memory>"`) is used in messages, e.g. `name:12:5: …`. TILT files
/// cannot be looked up (an IES file with `TILT=<file>` is refused). On success `*out` receives a
/// new handle that the caller releases with [`gonio_diagram_free`].
///
/// # Safety
/// `data` must be NULL or valid for reading `len` bytes; `name` NULL or a NUL-terminated string;
/// `out` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_read_memory(
    data: *const u8,
    len: usize,
    format: GonioFormat,
    name: *const c_char,
    out: *mut *mut GonioDiagram,
) -> GonioStatus {
    guard(|| {
        check_out(out, "out")?;
        if data.is_null() && len > 0 {
            return Err(Failure::null("data"));
        }
        if len as u64 > GONIO_MAX_FILE_BYTES {
            let name = if name.is_null() {
                "<memory>"
            } else {
                c_str(name, "name")?
            };
            return Err(too_large(name, len as u64));
        }
        let name = if name.is_null() {
            "<memory>"
        } else {
            c_str(name, "name")?
        };
        let kind = kind_of(format)?.ok_or_else(|| {
            Failure::invalid(
                "gonio_diagram_read_memory needs an explicit format, not GONIO_FORMAT_AUTO",
            )
        })?;
        // No bytes (data may then be NULL): the input is empty, whatever the format.
        if len == 0 {
            return Err(Failure::new(
                GONIO_ERR_PARSE,
                format!("{name}: the input is empty (0 bytes)"),
            ));
        }
        let bytes = std::slice::from_raw_parts(data, len);
        let d = parse(name, bytes, kind, None)?;
        w(out, Box::into_raw(Box::new(d)), "out")
    })
}

/// Releases a diagram handle. NULL is accepted and ignored. Samplers built from the diagram stay
/// valid.
///
/// # Safety
/// `diagram` must be NULL or a handle from a `gonio_diagram_read_*` function that was not freed
/// yet, and no other thread may be using it.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_free(diagram: *mut GonioDiagram) {
    if !diagram.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(diagram))));
    }
}

/// The total power of the distribution: the integral over the sphere of the intensity
/// interpolated bilinearly in (θ, φ), in lumens for photometric files (the `flux` of
/// `gonio info`).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `flux` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_flux(
    diagram: *const GonioDiagram,
    flux: *mut f64,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        w(flux, d.diagram.integral(), "flux")
    })
}

/// The largest intensity of the distribution (candela for photometric files).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `max` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_max_intensity(
    diagram: *const GonioDiagram,
    max: *mut f64,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        w(max, d.diagram.max_value(), "max")
    })
}

/// The intensity of the distribution in a direction (candela for photometric files), interpolated
/// bilinearly in (θ, φ) — the function every sampler's target density is proportional to.
///
/// # Safety
/// `diagram` must be NULL or a live handle; `intensity` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_intensity(
    diagram: *const GonioDiagram,
    x: f64,
    y: f64,
    z: f64,
    intensity: *mut f64,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        check_out(intensity, "intensity")?;
        let dir = unit([x, y, z])?;
        let (theta, phi) = gonio::sampler::spherical(dir);
        w(intensity, d.diagram.interpolate(theta, phi), "intensity")
    })
}

/// The number of warnings the reader issued (0 for JSON diagrams).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `count` NULL or valid for writing a `size_t`.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_warning_count(
    diagram: *const GonioDiagram,
    count: *mut usize,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        w(count, d.warnings.len(), "count")
    })
}

/// Warning number `index` (from 0) as the CLI prints it: `FILE:LINE:COLUMN: warning: message`.
/// The string belongs to the diagram handle and lives as long as it.
///
/// # Safety
/// `diagram` must be NULL or a live handle; `text` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_warning(
    diagram: *const GonioDiagram,
    index: usize,
    text: *mut *const c_char,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        check_out(text, "text")?;
        let s = d.warnings.get(index).ok_or_else(|| {
            Failure::invalid(format!(
                "warning index {index} is out of range (the diagram has {} warnings)",
                d.warnings.len()
            ))
        })?;
        w(text, s.as_ptr(), "text")
    })
}

/// The domain [`GONIO_DOMAIN_AUTO`] stands for with this diagram ([`GONIO_DOMAIN_HEMISPHERE`] or
/// [`GONIO_DOMAIN_SPHERE`]).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `domain` NULL or valid for writing an `int32_t`.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_domain(
    diagram: *const GonioDiagram,
    domain: *mut GonioDomain,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        w(domain, domain_code(auto_domain(d)), "domain")
    })
}

// ---------------------------------------------------------------------------------------------
// Building.

/// The CLI's policy: photometric files always get the sphere, a JSON diagram
/// [`Domain::for_diagram`].
fn auto_domain(d: &GonioDiagram) -> Domain {
    if d.photometry.is_some() {
        Domain::Sphere
    } else {
        Domain::for_diagram(&d.diagram)
    }
}

fn domain_code(d: Domain) -> GonioDomain {
    match d {
        Domain::Hemisphere => GONIO_DOMAIN_HEMISPHERE,
        Domain::Sphere => GONIO_DOMAIN_SPHERE,
    }
}

fn method_of(method: GonioMethod) -> Result<Method, Failure> {
    match method {
        GONIO_METHOD_HDS => Ok(Method::Hds),
        GONIO_METHOD_PIECEWISE_CONSTANT => Ok(Method::PiecewiseConstant),
        GONIO_METHOD_BILINEAR => Ok(Method::Bilinear),
        GONIO_METHOD_REJECTION => Ok(Method::Rejection),
        GONIO_METHOD_UNIFORM => Ok(Method::Uniform),
        other => Err(Failure::invalid(format!(
            "unknown method {other}; expected one of the GONIO_METHOD_* constants (0 to 4)"
        ))),
    }
}

fn domain_of(d: &GonioDiagram, domain: GonioDomain) -> Result<Domain, Failure> {
    match domain {
        GONIO_DOMAIN_AUTO => Ok(auto_domain(d)),
        GONIO_DOMAIN_HEMISPHERE => Ok(Domain::Hemisphere),
        GONIO_DOMAIN_SPHERE => Ok(Domain::Sphere),
        other => Err(Failure::invalid(format!(
            "unknown domain {other}; expected GONIO_DOMAIN_AUTO, _HEMISPHERE or _SPHERE"
        ))),
    }
}

fn options_of(o: &GonioBuildOptions) -> Result<BuildOptions, Failure> {
    let mut b = BuildOptions::default();
    if o.tolerance != 0.0 {
        b = b.tolerance(Some(o.tolerance));
    }
    if o.resolution != 0 {
        b = b.resolution(o.resolution);
    }
    b = b.seed(o.seed);
    b = b.sphere_layout(match o.sphere_layout {
        GONIO_SPHERE_LAYOUT_SPLIT => SphereLayout::Split,
        GONIO_SPHERE_LAYOUT_LAMBERT => SphereLayout::Lambert,
        other => {
            return Err(Failure::invalid(format!(
                "unknown sphere layout {other}; expected GONIO_SPHERE_LAYOUT_SPLIT or _LAMBERT"
            )))
        }
    });
    Ok(b)
}

/// Builds through the library's factory, with the CLI's message on failure.
fn build(
    diagram: *const GonioDiagram,
    method: GonioMethod,
    domain: GonioDomain,
    options: &BuildOptions,
    out: *mut *mut GonioSampler,
) -> Result<(), Failure> {
    check_out(out, "out")?;
    // SAFETY: the caller passes NULL or a live handle (the exported functions' contract).
    let d = unsafe { r(diagram, "diagram")? };
    let m = method_of(method)?;
    let dom = domain_of(d, domain)?;
    let s = m.build_with(&d.diagram, dom, options).map_err(|e| {
        Failure::new(
            GONIO_ERR_BUILD,
            format!("{}: cannot build the {m} sampler: {e}", d.name),
        )
    })?;
    // SAFETY: `out` was checked above.
    unsafe {
        w(
            out,
            Box::into_raw(Box::new(GonioSampler { inner: s })),
            "out",
        )
    }
}

/// Builds a sampler of `method` (a `GONIO_METHOD_*` constant) on `domain` (a `GONIO_DOMAIN_*`
/// constant; [`GONIO_DOMAIN_AUTO`] for the diagram's own policy) with default options, through
/// the library's factory `Method::build`. On success `*out` receives a new handle that the caller
/// releases with [`gonio_sampler_free`]; it does not borrow `diagram`.
///
/// # Safety
/// `diagram` must be NULL or a live handle; `out` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_build(
    diagram: *const GonioDiagram,
    method: GonioMethod,
    domain: GonioDomain,
    out: *mut *mut GonioSampler,
) -> GonioStatus {
    guard(|| build(diagram, method, domain, &BuildOptions::default(), out))
}

/// Writes the default options into `*options`.
///
/// # Safety
/// `options` must be NULL or valid for writing a [`GonioBuildOptions`].
#[no_mangle]
pub unsafe extern "C" fn gonio_build_options_default(
    options: *mut GonioBuildOptions,
) -> GonioStatus {
    guard(|| {
        let d = BuildOptions::default();
        let layout = match d.sphere_layout {
            SphereLayout::Lambert => GONIO_SPHERE_LAYOUT_LAMBERT,
            _ => GONIO_SPHERE_LAYOUT_SPLIT,
        };
        w(
            options,
            GonioBuildOptions {
                tolerance: d.tolerance.unwrap_or(0.0),
                resolution: 0,
                seed: d.seed,
                sphere_layout: layout,
            },
            "options",
        )
    })
}

/// As [`gonio_sampler_build`] with `options` (through the factory's `Method::build_with`).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `options` NULL or a valid [`GonioBuildOptions`];
/// `out` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_build_with(
    diagram: *const GonioDiagram,
    method: GonioMethod,
    domain: GonioDomain,
    options: *const GonioBuildOptions,
    out: *mut *mut GonioSampler,
) -> GonioStatus {
    guard(|| {
        let o = options_of(r(options, "options")?)?;
        build(diagram, method, domain, &o, out)
    })
}

/// Releases a sampler handle. NULL is accepted and ignored.
///
/// # Safety
/// `sampler` must be NULL or a handle from [`gonio_sampler_build`] that was not freed yet, and no
/// other thread may be using it.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_free(sampler: *mut GonioSampler) {
    if !sampler.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(sampler))));
    }
}

/// The method's name as the CLI's `--method` spells it (`"hds"`, `"piecewise-constant"`, …): a
/// static string; NULL when `sampler` is NULL.
///
/// # Safety
/// `sampler` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_method(sampler: *const GonioSampler) -> *const c_char {
    let Ok(s) = r(sampler, "sampler") else {
        return std::ptr::null();
    };
    match catch_unwind(AssertUnwindSafe(|| s.inner.name())) {
        Ok("hds") => c"hds".as_ptr(),
        Ok("piecewise-constant") => c"piecewise-constant".as_ptr(),
        Ok("bilinear") => c"bilinear".as_ptr(),
        Ok("rejection") => c"rejection".as_ptr(),
        Ok("uniform") => c"uniform".as_ptr(),
        _ => c"unknown".as_ptr(),
    }
}

/// The sampler's domain ([`GONIO_DOMAIN_HEMISPHERE`] or [`GONIO_DOMAIN_SPHERE`]).
///
/// # Safety
/// `sampler` must be NULL or a live handle; `domain` NULL or valid for writing an `int32_t`.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_domain(
    sampler: *const GonioSampler,
    domain: *mut GonioDomain,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        w(domain, domain_code(s.inner.domain()), "domain")
    })
}

// ---------------------------------------------------------------------------------------------
// One point.

/// A direction argument as a unit vector, or an error for a zero or non-finite vector.
fn unit(d: Vec3) -> Result<Vec3, Failure> {
    gonio::sampler::normalize(d).ok_or_else(|| {
        Failure::invalid(format!(
            "the direction {} is not a finite non-zero vector",
            fmt_row(&d)
        ))
    })
}

/// Numbers for a message, `(x, y, z)`, in the shortest form that reads back (exponent form for
/// tiny and huge magnitudes).
fn fmt_row(r: &[f64]) -> String {
    let parts: Vec<String> = r.iter().map(|&x| gonio::decimal::shortest(x)).collect();
    format!("({})", parts.join(", "))
}

/// A point argument, which must lie in the unit square [0, 1]² (NaN does not): the rule of the
/// Python package too (issue 25; before, NaN was "clamped" to a direction of pdf 0).
fn in_square(u: [f64; 2]) -> Result<[f64; 2], Failure> {
    if (0.0..=1.0).contains(&u[0]) && (0.0..=1.0).contains(&u[1]) {
        Ok(u)
    } else {
        Err(Failure::invalid(format!(
            "the point {} is outside the unit square [0, 1]² (or NaN)",
            fmt_row(&u)
        )))
    }
}

/// Maps the point (u, v) of the unit square to a direction and its exact density. A point outside
/// [0, 1]² or with a NaN coordinate is [`GONIO_ERR_INVALID_ARGUMENT`] (as in Python).
///
/// # Safety
/// `sampler` must be NULL or a live handle; `out` NULL or valid for writing a [`GonioSample`].
#[no_mangle]
pub unsafe extern "C" fn gonio_sample(
    sampler: *const GonioSampler,
    u: f64,
    v: f64,
    out: *mut GonioSample,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(out, "out")?;
        let smp = s.inner.sample(in_square([u, v])?);
        w(
            out,
            GonioSample {
                direction: smp.direction,
                pdf: smp.pdf,
            },
            "out",
        )
    })
}

/// The density of the sampler at direction (x, y, z) (normalised first), per steradian; 0
/// outside the domain. A zero or non-finite vector is [`GONIO_ERR_INVALID_ARGUMENT`].
///
/// # Safety
/// `sampler` must be NULL or a live handle; `pdf` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf(
    sampler: *const GonioSampler,
    x: f64,
    y: f64,
    z: f64,
    pdf: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(pdf, "pdf")?;
        let d = unit([x, y, z])?;
        w(pdf, s.inner.pdf(d), "pdf")
    })
}

/// The target density at direction (x, y, z): the diagram interpolated bilinearly in (θ, φ),
/// normalised over the domain, per steradian.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `target_pdf` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf(
    sampler: *const GonioSampler,
    x: f64,
    y: f64,
    z: f64,
    target_pdf: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(target_pdf, "target_pdf")?;
        let d = unit([x, y, z])?;
        w(target_pdf, s.inner.target_pdf(d), "target_pdf")
    })
}

fn invert_error(e: InvertError) -> Failure {
    match e {
        InvertError::Unsupported => Failure::new(GONIO_ERR_UNSUPPORTED, e.to_string()),
        InvertError::OutsideDomain => Failure::new(GONIO_ERR_OUTSIDE_DOMAIN, e.to_string()),
        InvertError::ZeroDensity => Failure::new(GONIO_ERR_ZERO_DENSITY, e.to_string()),
    }
}

/// The point (u, v) of the unit square that the sampler maps to direction (x, y, z).
/// [`GONIO_ERR_UNSUPPORTED`] for a method without inverse, [`GONIO_ERR_OUTSIDE_DOMAIN`] for a
/// direction outside the domain, [`GONIO_ERR_ZERO_DENSITY`] for a direction in the domain where
/// the density is 0 (no point maps to it).
///
/// # Safety
/// `sampler` must be NULL or a live handle; `u` and `v` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_invert(
    sampler: *const GonioSampler,
    x: f64,
    y: f64,
    z: f64,
    u: *mut f64,
    v: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(u, "u")?;
        check_out(v, "v")?;
        let d = unit([x, y, z])?;
        let p = s.inner.invert(d).map_err(invert_error)?;
        w(u, p[0], "u")?;
        w(v, p[1], "v")
    })
}

/// The guaranteed bound `min ≤ pdf / target_pdf ≤ max` of the sampler over its domain where the
/// target is positive. [`GONIO_ERR_UNSUPPORTED`] when the method states none.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `min` and `max` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_ratio_bound(
    sampler: *const GonioSampler,
    min: *mut f64,
    max: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(min, "min")?;
        check_out(max, "max")?;
        let (lo, hi) = s.inner.ratio_bound().ok_or_else(|| {
            Failure::new(
                GONIO_ERR_UNSUPPORTED,
                format!("the {} sampler states no ratio bound", s.inner.name()),
            )
        })?;
        w(min, lo, "min")?;
        w(max, hi, "max")
    })
}

/// The power of the sampler's target: the integral over its domain of the intensity that
/// `target_pdf` normalises, in lumens for photometric files (candela × sr). For the HDS map it is
/// the power of the diagram as completed for its tables; it equals [`gonio_diagram_flux`] when
/// the completion adds nothing.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `power` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_target_power(
    sampler: *const GonioSampler,
    power: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        w(power, s.inner.target_power(), "power")
    })
}

// ---------------------------------------------------------------------------------------------
// Batches.

/// The two float types of the batch functions.
trait Real: Copy {
    fn to_f64(self) -> f64;
    fn from_f64(x: f64) -> Self;
}
impl Real for f64 {
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }
}
impl Real for f32 {
    #[inline]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    #[inline]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
}

/// K input components of n elements, array-of-structs (one pointer, stride K) or
/// structure-of-arrays (K pointers, stride 1).
struct In<T, const K: usize> {
    ptr: [*const T; K],
    stride: usize,
}

/// K output components of n elements, as [`In`].
struct Out<T, const K: usize> {
    ptr: [*mut T; K],
    stride: usize,
}

/// The byte size of `n · k` values of `T` must fit in an `isize`.
fn check_len<T>(n: usize, k: usize) -> Result<(), Failure> {
    match n
        .checked_mul(k)
        .and_then(|c| c.checked_mul(std::mem::size_of::<T>()))
    {
        Some(b) if b <= isize::MAX as usize => Ok(()),
        _ => Err(Failure::invalid(format!("n = {n} is too large"))),
    }
}

fn check_in<T>(p: *const T, what: &str) -> Result<(), Failure> {
    if p.is_null() || !p.is_aligned() {
        return Err(Failure::null(what));
    }
    Ok(())
}

impl<T: Real, const K: usize> In<T, K> {
    fn aos(p: *const T, n: usize, what: &str) -> Result<Self, Failure> {
        check_in(p, what)?;
        check_len::<T>(n, K)?;
        let mut ptr = [p; K];
        for (c, q) in ptr.iter_mut().enumerate() {
            *q = p.wrapping_add(c);
        }
        Ok(Self { ptr, stride: K })
    }
    fn soa(ps: [(*const T, &str); K], n: usize) -> Result<Self, Failure> {
        for (p, what) in ps {
            check_in(p, what)?;
        }
        check_len::<T>(n, 1)?;
        Ok(Self {
            ptr: ps.map(|(p, _)| p),
            stride: 1,
        })
    }
    /// Element i as f64.
    ///
    /// # Safety
    /// i < n, and the caller's pointers are valid for n elements.
    #[inline]
    unsafe fn get(&self, i: usize) -> [f64; K] {
        let mut v = [0.0; K];
        for (c, x) in v.iter_mut().enumerate() {
            *x = self.ptr[c].add(i * self.stride).read().to_f64();
        }
        v
    }
}

impl<T: Real, const K: usize> Out<T, K> {
    fn aos(p: *mut T, n: usize, what: &str) -> Result<Self, Failure> {
        check_out(p, what)?;
        check_len::<T>(n, K)?;
        let mut ptr = [p; K];
        for (c, q) in ptr.iter_mut().enumerate() {
            *q = p.wrapping_add(c);
        }
        Ok(Self { ptr, stride: K })
    }
    fn soa(ps: [(*mut T, &str); K], n: usize) -> Result<Self, Failure> {
        for (p, what) in ps {
            check_out(p, what)?;
        }
        check_len::<T>(n, 1)?;
        Ok(Self {
            ptr: ps.map(|(p, _)| p),
            stride: 1,
        })
    }
    /// Writes element i.
    ///
    /// # Safety
    /// i < n, and the caller's pointers are valid for n elements.
    #[inline]
    unsafe fn set(&self, i: usize, v: [f64; K]) {
        for (c, x) in v.iter().enumerate() {
            self.ptr[c].add(i * self.stride).write(T::from_f64(*x));
        }
    }
}

/// Points per chunk of a batch: the sampler's own batch path sees this many at a time.
const CHUNK: usize = 256;

/// Samples n points: directions into `dirs` and densities into `pdfs`. A point outside the unit
/// square (or NaN) stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`] naming its index (the
/// chunks before it are written).
///
/// # Safety
/// The views are valid for n elements.
unsafe fn sample_n<T: Real>(
    s: &dyn Sampler,
    n: usize,
    u: &In<T, 2>,
    dirs: &Out<T, 3>,
    pdfs: &Out<T, 1>,
) -> Result<(), Failure> {
    let mut pts = [[0.0; 2]; CHUNK];
    let mut out = [Sample::default(); CHUNK];
    let mut start = 0;
    while start < n {
        let m = CHUNK.min(n - start);
        for (k, p) in pts[..m].iter_mut().enumerate() {
            let i = start + k;
            *p = in_square(u.get(i))
                .map_err(|e| Failure::invalid(format!("point #{i}: {}", e.message)))?;
        }
        s.sample_batch(&pts[..m], &mut out[..m]);
        for (k, o) in out[..m].iter().enumerate() {
            dirs.set(start + k, o.direction);
            pdfs.set(start + k, [o.pdf]);
        }
        start += m;
    }
    Ok(())
}

/// Evaluates a batch function at n directions, a chunk of [`CHUNK`] at a time: the chunk's
/// directions are read and normalised (a zero or non-finite one stops with
/// [`GONIO_ERR_INVALID_ARGUMENT`] naming its index), `f` fills the chunk's results, which are then
/// written. Every input of a chunk is read before any of its outputs is written, so an output may
/// overwrite its own or an earlier element's input (in place).
///
/// # Safety
/// The views are valid for n elements.
unsafe fn eval_n<T: Real, const K: usize>(
    n: usize,
    dirs: &In<T, 3>,
    out: &Out<T, K>,
    mut f: impl FnMut(&[Vec3], &mut [[f64; K]]) -> Result<(), Failure>,
) -> Result<(), Failure> {
    let mut unit_dirs = [[0.0; 3]; CHUNK];
    let mut res = [[0.0; K]; CHUNK];
    let mut start = 0;
    while start < n {
        let m = CHUNK.min(n - start);
        for (k, d) in unit_dirs[..m].iter_mut().enumerate() {
            let i = start + k;
            *d = unit(dirs.get(i))
                .map_err(|e| Failure::invalid(format!("direction #{i}: {}", e.message)))?;
        }
        f(&unit_dirs[..m], &mut res[..m])?;
        for (k, r) in res[..m].iter().enumerate() {
            out.set(start + k, *r);
        }
        start += m;
    }
    Ok(())
}

/// `invert` of a chunk of unit directions through the sampler's batch path: a point, or NaN for a
/// direction outside the domain or of density 0 (no preimage).
fn invert_or_nan(s: &dyn Sampler, dirs: &[Vec3], out: &mut [[f64; 2]]) -> Result<(), Failure> {
    let mut res = [Ok([0.0; 2]); CHUNK];
    let res = &mut res[..dirs.len()];
    s.invert_batch(dirs, res);
    for (o, r) in out.iter_mut().zip(res.iter()) {
        *o = match *r {
            Ok(p) => p,
            Err(InvertError::OutsideDomain | InvertError::ZeroDensity) => [f64::NAN, f64::NAN],
            Err(e @ InvertError::Unsupported) => return Err(invert_error(e)),
        };
    }
    Ok(())
}

// The generic bodies of the batch functions; the exported functions below are one line each
// (written out, not generated by a macro, so that cbindgen sees them).

unsafe fn sample_aos<T: Real>(
    sampler: *const GonioSampler,
    u: *const T,
    n: usize,
    directions: *mut T,
    pdfs: *mut T,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let u = In::<T, 2>::aos(u, n, "u")?;
        let d = Out::<T, 3>::aos(directions, n, "directions")?;
        let p = Out::<T, 1>::aos(pdfs, n, "pdfs")?;
        sample_n(s.inner.as_ref(), n, &u, &d, &p)
    })
}

#[allow(clippy::too_many_arguments)]
unsafe fn sample_soa<T: Real>(
    sampler: *const GonioSampler,
    u: *const T,
    v: *const T,
    n: usize,
    x: *mut T,
    y: *mut T,
    z: *mut T,
    pdfs: *mut T,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let uv = In::<T, 2>::soa([(u, "u"), (v, "v")], n)?;
        let d = Out::<T, 3>::soa([(x, "x"), (y, "y"), (z, "z")], n)?;
        let p = Out::<T, 1>::soa([(pdfs, "pdfs")], n)?;
        sample_n(s.inner.as_ref(), n, &uv, &d, &p)
    })
}

/// A density of a sampler at a chunk of unit directions (pdf or target pdf).
type DensityFn = fn(&dyn Sampler, &[Vec3], &mut [[f64; 1]]);

/// The pdf through the sampler's batch path (the SIMD kernels of the HDS maps).
fn pdf_of(s: &dyn Sampler, dirs: &[Vec3], out: &mut [[f64; 1]]) {
    s.pdf_batch(dirs, out.as_flattened_mut());
}

/// The target density, one direction at a time (no sampler has a batch path for it).
fn target_of(s: &dyn Sampler, dirs: &[Vec3], out: &mut [[f64; 1]]) {
    for (o, d) in out.iter_mut().zip(dirs) {
        *o = [s.target_pdf(*d)];
    }
}

unsafe fn density_aos<T: Real>(
    sampler: *const GonioSampler,
    directions: *const T,
    n: usize,
    out: *mut T,
    f: DensityFn,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::aos(directions, n, "directions")?;
        let o = Out::<T, 1>::aos(out, n, "out")?;
        eval_n(n, &d, &o, |dirs, res| {
            f(s.inner.as_ref(), dirs, res);
            Ok(())
        })
    })
}

unsafe fn density_soa<T: Real>(
    sampler: *const GonioSampler,
    x: *const T,
    y: *const T,
    z: *const T,
    n: usize,
    out: *mut T,
    f: DensityFn,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::soa([(x, "x"), (y, "y"), (z, "z")], n)?;
        let o = Out::<T, 1>::soa([(out, "out")], n)?;
        eval_n(n, &d, &o, |dirs, res| {
            f(s.inner.as_ref(), dirs, res);
            Ok(())
        })
    })
}

unsafe fn invert_aos<T: Real>(
    sampler: *const GonioSampler,
    directions: *const T,
    n: usize,
    uv: *mut T,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::aos(directions, n, "directions")?;
        let o = Out::<T, 2>::aos(uv, n, "uv")?;
        // A method without inverse says so for every n, 0 included (issue 25).
        if s.inner.invert([0.0, 0.0, 1.0]) == Err(InvertError::Unsupported) {
            return Err(invert_error(InvertError::Unsupported));
        }
        eval_n(n, &d, &o, |dirs, res| {
            invert_or_nan(s.inner.as_ref(), dirs, res)
        })
    })
}

#[allow(clippy::too_many_arguments)]
unsafe fn invert_soa<T: Real>(
    sampler: *const GonioSampler,
    x: *const T,
    y: *const T,
    z: *const T,
    n: usize,
    u: *mut T,
    v: *mut T,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        let d = In::<T, 3>::soa([(x, "x"), (y, "y"), (z, "z")], n)?;
        let o = Out::<T, 2>::soa([(u, "u"), (v, "v")], n)?;
        // A method without inverse says so for every n, 0 included (issue 25).
        if s.inner.invert([0.0, 0.0, 1.0]) == Err(InvertError::Unsupported) {
            return Err(invert_error(InvertError::Unsupported));
        }
        eval_n(n, &d, &o, |dirs, res| {
            invert_or_nan(s.inner.as_ref(), dirs, res)
        })
    })
}

/// Samples `n` points of the square given as interleaved pairs `u[2i], u[2i+1]` (double):
/// directions into `directions[3i..3i+3]`, densities (per sr) into `pdfs[i]`.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_sample_batch(
    sampler: *const GonioSampler,
    u: *const f64,
    n: usize,
    directions: *mut f64,
    pdfs: *mut f64,
) -> GonioStatus {
    sample_aos::<f64>(sampler, u, n, directions, pdfs)
}

/// Samples `n` points of the square given as arrays `u[i]`, `v[i]` (double): directions
/// into `x[i]`, `y[i]`, `z[i]`, densities (per sr) into `pdfs[i]`.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gonio_sample_batch_soa(
    sampler: *const GonioSampler,
    u: *const f64,
    v: *const f64,
    n: usize,
    x: *mut f64,
    y: *mut f64,
    z: *mut f64,
    pdfs: *mut f64,
) -> GonioStatus {
    sample_soa::<f64>(sampler, u, v, n, x, y, z, pdfs)
}

/// The sampler's density (per sr) at `n` directions given as interleaved triples
/// `directions[3i..3i+3]` (double; normalised first), into `out[i]`. A zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf_batch(
    sampler: *const GonioSampler,
    directions: *const f64,
    n: usize,
    out: *mut f64,
) -> GonioStatus {
    density_aos::<f64>(sampler, directions, n, out, pdf_of)
}

/// The sampler's density (per sr) at `n` directions given as arrays `x[i]`, `y[i]`, `z[i]`
/// (double; normalised first), into `out[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf_batch_soa(
    sampler: *const GonioSampler,
    x: *const f64,
    y: *const f64,
    z: *const f64,
    n: usize,
    out: *mut f64,
) -> GonioStatus {
    density_soa::<f64>(sampler, x, y, z, n, out, pdf_of)
}

/// The target density (per sr) at `n` directions given as interleaved triples
/// `directions[3i..3i+3]` (double; normalised first), into `out[i]`. A zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf_batch(
    sampler: *const GonioSampler,
    directions: *const f64,
    n: usize,
    out: *mut f64,
) -> GonioStatus {
    density_aos::<f64>(sampler, directions, n, out, target_of)
}

/// The target density (per sr) at `n` directions given as arrays `x[i]`, `y[i]`, `z[i]`
/// (double; normalised first), into `out[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf_batch_soa(
    sampler: *const GonioSampler,
    x: *const f64,
    y: *const f64,
    z: *const f64,
    n: usize,
    out: *mut f64,
) -> GonioStatus {
    density_soa::<f64>(sampler, x, y, z, n, out, target_of)
}

/// Inverts `n` directions given as interleaved triples `directions[3i..3i+3]` (double)
/// into interleaved points `uv[2i], uv[2i+1]`. A direction outside the domain or of density 0 gives (NaN, NaN)
/// and the batch goes on; a method without inverse is [`GONIO_ERR_UNSUPPORTED`]; a zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_invert_batch(
    sampler: *const GonioSampler,
    directions: *const f64,
    n: usize,
    uv: *mut f64,
) -> GonioStatus {
    invert_aos::<f64>(sampler, directions, n, uv)
}

/// Inverts `n` directions given as arrays `x[i]`, `y[i]`, `z[i]` (double) into `u[i]`,
/// `v[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gonio_invert_batch_soa(
    sampler: *const GonioSampler,
    x: *const f64,
    y: *const f64,
    z: *const f64,
    n: usize,
    u: *mut f64,
    v: *mut f64,
) -> GonioStatus {
    invert_soa::<f64>(sampler, x, y, z, n, u, v)
}

/// Samples `n` points of the square given as interleaved pairs `u[2i], u[2i+1]` (float; computed in double, results rounded):
/// directions into `directions[3i..3i+3]`, densities (per sr) into `pdfs[i]`.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_sample_batch_f32(
    sampler: *const GonioSampler,
    u: *const f32,
    n: usize,
    directions: *mut f32,
    pdfs: *mut f32,
) -> GonioStatus {
    sample_aos::<f32>(sampler, u, n, directions, pdfs)
}

/// Samples `n` points of the square given as arrays `u[i]`, `v[i]` (float; computed in double, results rounded): directions
/// into `x[i]`, `y[i]`, `z[i]`, densities (per sr) into `pdfs[i]`.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gonio_sample_batch_soa_f32(
    sampler: *const GonioSampler,
    u: *const f32,
    v: *const f32,
    n: usize,
    x: *mut f32,
    y: *mut f32,
    z: *mut f32,
    pdfs: *mut f32,
) -> GonioStatus {
    sample_soa::<f32>(sampler, u, v, n, x, y, z, pdfs)
}

/// The sampler's density (per sr) at `n` directions given as interleaved triples
/// `directions[3i..3i+3]` (float; computed in double, results rounded; normalised first), into `out[i]`. A zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf_batch_f32(
    sampler: *const GonioSampler,
    directions: *const f32,
    n: usize,
    out: *mut f32,
) -> GonioStatus {
    density_aos::<f32>(sampler, directions, n, out, pdf_of)
}

/// The sampler's density (per sr) at `n` directions given as arrays `x[i]`, `y[i]`, `z[i]`
/// (float; computed in double, results rounded; normalised first), into `out[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf_batch_soa_f32(
    sampler: *const GonioSampler,
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
    out: *mut f32,
) -> GonioStatus {
    density_soa::<f32>(sampler, x, y, z, n, out, pdf_of)
}

/// The target density (per sr) at `n` directions given as interleaved triples
/// `directions[3i..3i+3]` (float; computed in double, results rounded; normalised first), into `out[i]`. A zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf_batch_f32(
    sampler: *const GonioSampler,
    directions: *const f32,
    n: usize,
    out: *mut f32,
) -> GonioStatus {
    density_aos::<f32>(sampler, directions, n, out, target_of)
}

/// The target density (per sr) at `n` directions given as arrays `x[i]`, `y[i]`, `z[i]`
/// (float; computed in double, results rounded; normalised first), into `out[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf_batch_soa_f32(
    sampler: *const GonioSampler,
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
    out: *mut f32,
) -> GonioStatus {
    density_soa::<f32>(sampler, x, y, z, n, out, target_of)
}

/// Inverts `n` directions given as interleaved triples `directions[3i..3i+3]` (float; computed in double, results rounded)
/// into interleaved points `uv[2i], uv[2i+1]`. A direction outside the domain or of density 0 gives (NaN, NaN)
/// and the batch goes on; a method without inverse is [`GONIO_ERR_UNSUPPORTED`]; a zero or
/// non-finite direction stops the batch with [`GONIO_ERR_INVALID_ARGUMENT`], naming its index.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
pub unsafe extern "C" fn gonio_invert_batch_f32(
    sampler: *const GonioSampler,
    directions: *const f32,
    n: usize,
    uv: *mut f32,
) -> GonioStatus {
    invert_aos::<f32>(sampler, directions, n, uv)
}

/// Inverts `n` directions given as arrays `x[i]`, `y[i]`, `z[i]` (float; computed in double, results rounded) into `u[i]`,
/// `v[i]`; as the interleaved variant.
///
/// # Safety
/// `sampler` must be NULL or a live handle; every array NULL or valid for its `n` elements.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gonio_invert_batch_soa_f32(
    sampler: *const GonioSampler,
    x: *const f32,
    y: *const f32,
    z: *const f32,
    n: usize,
    u: *mut f32,
    v: *mut f32,
) -> GonioStatus {
    invert_soa::<f32>(sampler, x, y, z, n, u, v)
}

mod brdf;
pub use brdf::*;
mod envmap;
pub use envmap::*;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_abuse;
