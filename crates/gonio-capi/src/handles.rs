//! Status codes, enumerations, option and handle types, errors (the thread-local message and
//! the panic guard), pointer helpers and reading diagrams (path, memory, free).

use gonio::input::file::{check_size, read_file_with_meta, read_limit, set_read_limit, FileKind};
use gonio::input::{InputKind, LoadError};
use gonio::photometry::{DirTiltResolver, NoTiltFiles, Photometry};
use gonio::Diagram;
use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
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

/// Options of `gonio_sampler_build_with`; each method reads those that apply to it. Fill it
/// with `gonio_build_options_default`, then change fields. (The struct may gain fields in later
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
    pub(crate) name: String,
    /// The distribution in gonio's frame.
    pub(crate) diagram: Diagram,
    /// The file as read, for IES and EULUMDAT input.
    pub(crate) photometry: Option<Photometry>,
    /// The reader's warnings, formatted as the CLI prints them.
    pub(crate) warnings: Vec<CString>,
}

/// A sampler of any method and domain (opaque). Created by `gonio_sampler_build`, released by
/// `gonio_sampler_free`. Immutable: may be shared between threads and used from all of them at
/// once (every function taking `const GonioSampler *` is thread-safe).
pub struct GonioSampler {
    pub(crate) inner: gonio::Built<'static>,
}

// ---------------------------------------------------------------------------------------------
// Errors.

/// The default size limit of photometric files and JSON diagrams (64 MiB), as
/// `gonio_read_limit``(GONIO_FILE_PHOTOMETRY)` gives it unless it was changed; each input kind
/// has its own limit, the same in every gonio front end.
pub const GONIO_MAX_FILE_BYTES: u64 = 64 << 20;

/// An error on its way to the caller: a status code and the message.
#[derive(Debug)]
pub(crate) struct Failure {
    pub(crate) status: GonioStatus,
    pub(crate) message: String,
}

impl Failure {
    pub(crate) fn new(status: GonioStatus, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
        }
    }
    pub(crate) fn null(what: &str) -> Self {
        Self::new(
            GONIO_ERR_NULL_POINTER,
            format!("{what} is NULL or not aligned for its type"),
        )
    }
    pub(crate) fn invalid(message: impl Into<String>) -> Self {
        Self::new(GONIO_ERR_INVALID_ARGUMENT, message)
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

pub(crate) fn set_last_error(message: &str) {
    // A NUL inside the message would cut it; replace it visibly.
    let c = CString::new(message.replace('\0', "\\0")).unwrap_or_default();
    // During thread teardown the buffer may be gone: then the message is lost, nothing else.
    let _ = LAST_ERROR.try_with(|e| *e.borrow_mut() = c);
}

/// Runs an entry point: catches a panic, records the message of a failure, returns the status.
pub(crate) fn guard(f: impl FnOnce() -> Result<(), Failure>) -> GonioStatus {
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
pub(crate) unsafe fn r<'a, T>(p: *const T, what: &str) -> Result<&'a T, Failure> {
    if p.is_null() || !p.is_aligned() {
        return Err(Failure::null(what));
    }
    Ok(&*p)
}

/// Writes through an output pointer that must be non-NULL and aligned.
///
/// # Safety
/// A non-NULL `p` must be valid for writing a `T`.
pub(crate) unsafe fn w<T>(p: *mut T, value: T, what: &str) -> Result<(), Failure> {
    if p.is_null() || !p.is_aligned() {
        return Err(Failure::null(what));
    }
    p.write(value);
    Ok(())
}

/// Checks an output pointer before any work is done.
pub(crate) fn check_out<T>(p: *mut T, what: &str) -> Result<(), Failure> {
    if p.is_null() || !p.is_aligned() {
        return Err(Failure::null(what));
    }
    Ok(())
}

/// Writes warning number `index` of `warnings` to `text` (the string stays owned by the handle
/// that holds the list); `owner` names that handle in the out-of-range message.
///
/// # Safety
/// A non-NULL `text` must be valid for writing a pointer.
pub(crate) unsafe fn write_warning(
    warnings: &[CString],
    index: usize,
    owner: &str,
    text: *mut *const c_char,
) -> Result<(), Failure> {
    check_out(text, "text")?;
    let s = warnings.get(index).ok_or_else(|| {
        Failure::invalid(format!(
            "warning index {index} is out of range (the {owner} has {} warnings)",
            warnings.len()
        ))
    })?;
    w(text, s.as_ptr(), "text")
}

/// A C string argument as UTF-8.
///
/// # Safety
/// A non-NULL `p` must point to a NUL-terminated string.
pub(crate) unsafe fn c_str<'a>(p: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if p.is_null() {
        return Err(Failure::null(what));
    }
    CStr::from_ptr(p)
        .to_str()
        .map_err(|e| Failure::invalid(format!("{what} is not UTF-8 text ({e})")))
}

/// A path argument from its bytes: any bytes on Unix; UTF-8 elsewhere.
pub(crate) fn path_of(raw: &CStr) -> Result<PathBuf, Failure> {
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

pub(crate) fn kind_of(format: GonioFormat) -> Result<Option<InputKind>, Failure> {
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
pub(crate) fn kind_of_path(name: &str) -> Result<InputKind, Failure> {
    if let Some(kind) = InputKind::from_extension(name) {
        return Ok(kind);
    }
    let ext = gonio::input::lowercase_extension(name);
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
pub(crate) fn located(file: &str, line: usize, column: usize, message: &str) -> String {
    match (line, column) {
        (0, _) => format!("{file}: {message}"),
        (l, 0) => format!("{file}:{l}: {message}"),
        (l, c) => format!("{file}:{l}:{c}: {message}"),
    }
}

/// Bytes handed in memory of `kind`: refused over the kind's limit, as a file would be (the
/// library's check and message).
pub(crate) fn check_memory_len(name: &str, len: usize, kind: FileKind) -> Result<(), Failure> {
    check_size(name, len as u64, kind).map_err(|e| Failure::new(GONIO_ERR_IO, e.to_string()))
}

/// Reads a regular file of `kind` through the library's one file reader
/// ([`gonio::input::file`]: regular files only, never blocking on a FIFO, at most the kind's
/// limit, checked before reading), with its message.
pub(crate) fn read_bounded(path: &Path, name: &str, kind: FileKind) -> Result<Vec<u8>, Failure> {
    read_file_with_meta(path, name, kind)
        .map(|(b, _)| b)
        .map_err(|e| Failure::new(GONIO_ERR_IO, e.to_string()))
}

/// The kinds of input files, each with its own size limit ([`gonio_set_read_limit`]).
pub type GonioFileKind = u32;
/// IES LM-63 and EULUMDAT files (default limit 64 MiB).
pub const GONIO_FILE_PHOTOMETRY: GonioFileKind = 0;
/// Native JSON diagrams (64 MiB).
pub const GONIO_FILE_DIAGRAM: GonioFileKind = 1;
/// TILT files named by IES files (4 MiB).
pub const GONIO_FILE_TILT: GonioFileKind = 2;
/// Images: environment maps (.hdr, .exr, .pfm) (4 GiB).
pub const GONIO_FILE_IMAGE: GonioFileKind = 3;
/// Tabulated BRDFs: MERL, UTIA, gonio BRDF JSON (256 MiB).
pub const GONIO_FILE_BRDF: GonioFileKind = 4;
/// Meshes: OBJ, PLY (2 GiB).
pub const GONIO_FILE_MESH: GonioFileKind = 5;
/// Table blobs (4 GiB).
pub const GONIO_FILE_TABLES: GonioFileKind = 6;

fn file_kind(kind: GonioFileKind) -> Result<FileKind, Failure> {
    FileKind::ALL
        .get(kind as usize)
        .copied()
        .ok_or_else(|| Failure::invalid(format!("file kind {kind}: not a GONIO_FILE_* constant")))
}

/// The size limit in bytes of files of `kind` (one of the `GONIO_FILE_*` constants) that every
/// gonio front end reads (CLI, C, Python): the value [`gonio_set_read_limit`] set, else the
/// default. 0 for an unknown kind.
#[no_mangle]
pub extern "C" fn gonio_read_limit(kind: GonioFileKind) -> u64 {
    file_kind(kind).map(read_limit).unwrap_or(0)
}

/// Sets the size limit in bytes of files of `kind` for the whole process (0 restores the
/// default); a larger file (or buffer handed to a `*_read_memory` function) is refused before it
/// is read, with the library's message. [`GONIO_ERR_INVALID_ARGUMENT`] for an unknown kind.
#[no_mangle]
pub extern "C" fn gonio_set_read_limit(kind: GonioFileKind, bytes: u64) -> GonioStatus {
    guard(|| {
        set_read_limit(file_kind(kind)?, bytes);
        Ok(())
    })
}

/// Turns bytes into a diagram handle, with the CLI's messages.
pub(crate) fn parse(
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
/// the limit of their kind (`gonio_read_limit`) and anything that is not a regular file are refused. On success
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
        let fk = if kind == InputKind::Json {
            FileKind::Diagram
        } else {
            FileKind::Photometry
        };
        let bytes = read_bounded(&owned, name, fk)?;
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
        let name = if name.is_null() {
            "<memory>"
        } else {
            c_str(name, "name")?
        };
        check_memory_len(name, len, FileKind::Photometry)?;
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
