//! Input loading and sampler construction, shared by every command (and by `plot` and `bench`).
//!
//! * [`load`] reads a `.json` (native diagram), `.ies` or `.ldt` file (extension in any letter
//!   case), or the special name [`EXAMPLE`] for the built-in luminaire;
//! * [`build_sampler`] builds the sampler of a [`Method`] for what was loaded (through the
//!   library's factory, [`Method::build`]), on the domain [`domain`] chooses.

use crate::input::{read_regular, tame, TiltFiles, MAX_INPUT_BYTES};
use anyhow::Context;
use gonio::{BuildOptions, Diagram, Domain, Method, Sampler};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// The input name that loads [`gonio::synthetic::example_luminaire`] instead of a file.
pub const EXAMPLE: &str = "example";

/// An error located in an input file; printed as `FILE:LINE:COLUMN: message` (without the
/// `gonio: error:` prefix), like a compiler diagnostic. Line and column are 1-based; a column of 0
/// is left out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LocatedError {
    /// The file as the user named it.
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, 0 when unknown.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for LocatedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.line, self.column) {
            (0, _) => write!(f, "{}: {}", self.file, self.message),
            (l, 0) => write!(f, "{}:{l}: {}", self.file, self.message),
            (l, c) => write!(f, "{}:{l}:{c}: {}", self.file, self.message),
        }
    }
}

impl std::error::Error for LocatedError {}

/// The kind of input that was loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// The built-in example luminaire (candela, whole sphere).
    Example,
    /// A native JSON diagram (units as given).
    Json,
    /// An IES LM-63 file (candela).
    Ies,
    /// An EULUMDAT file (candela after scaling).
    Eulumdat,
}

impl InputKind {
    /// Short lowercase name: `example`, `json`, `ies`, `ldt`.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Example => "example",
            InputKind::Json => "json",
            InputKind::Ies => "ies",
            InputKind::Eulumdat => "ldt",
        }
    }

    /// True for IES and EULUMDAT input (and the example, which is in candela too): the diagram's
    /// values are candela and its power is luminous flux in lumens.
    pub fn is_photometric(self) -> bool {
        !matches!(self, InputKind::Json)
    }
}

/// An input, loaded and validated.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The name the input was given by (a path, or [`EXAMPLE`]).
    pub name: String,
    /// What kind of input it was.
    pub kind: InputKind,
    /// The diagram, in the gonio frame (θ from +z, φ from +x toward +y).
    pub diagram: Diagram,
    /// The photometric file as read, for IES and EULUMDAT input.
    pub photometry: Option<Box<gonio::photometry::Photometry>>,
}

impl Loaded {
    /// The domain every sampler for this input covers (see [`domain`]).
    pub fn domain(&self) -> Domain {
        domain(self)
    }
}

/// The format an input name stands for, from its extension (any letter case).
pub fn input_kind(name: &str) -> anyhow::Result<InputKind> {
    if name == EXAMPLE {
        return Ok(InputKind::Example);
    }
    let ext = Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("json") => Ok(InputKind::Json),
        Some("ies") => Ok(InputKind::Ies),
        Some("ldt") => Ok(InputKind::Eulumdat),
        Some(e) => anyhow::bail!(
            "{name}: unknown input format `.{e}`; expected .json, .ies, .ldt or `{EXAMPLE}`"
        ),
        None => anyhow::bail!(
            "{name}: the file name has no extension; expected .json, .ies, .ldt or `{EXAMPLE}`"
        ),
    }
}

/// Loads an input: a `.json`, `.ies` or `.ldt` file, or [`EXAMPLE`].
///
/// Syntax errors come back as a [`LocatedError`] (`FILE:LINE:COLUMN: message`); every other error
/// names the file.
pub fn load(name: &str) -> anyhow::Result<Loaded> {
    let kind = input_kind(name)?;
    let (diagram, photometry) = match kind {
        InputKind::Example => (gonio::synthetic::example_luminaire(), None),
        InputKind::Json => {
            let bytes = read_file(name)?;
            let text = std::str::from_utf8(&bytes)
                .map_err(|e| anyhow::anyhow!("{name}: the file is not UTF-8 text ({e})"))?;
            (diagram_from_json(name, text)?, None)
        }
        InputKind::Ies | InputKind::Eulumdat => {
            let (p, d) = load_photometry(name, kind)?;
            (d, Some(Box::new(p)))
        }
    };
    Ok(Loaded {
        name: name.to_string(),
        kind,
        diagram,
        photometry,
    })
}

/// Reads an input file: a regular file of at most [`MAX_INPUT_BYTES`] (see [`crate::input`]).
fn read_file(name: &str) -> anyhow::Result<Vec<u8>> {
    read_regular(Path::new(name), name, MAX_INPUT_BYTES)
}

/// Parses the native JSON form, turning library errors into CLI errors that name the file.
pub fn diagram_from_json(name: &str, text: &str) -> anyhow::Result<Diagram> {
    Diagram::from_json_str(text).map_err(|e| match e {
        gonio::Error::Json {
            line,
            column,
            message,
        } => LocatedError {
            file: name.to_string(),
            line,
            column,
            message: tame(strip_serde_location(&message)),
        }
        .into(),
        other => anyhow::anyhow!("{name}: invalid diagram: {other}"),
    })
}

/// serde_json messages end in " at line L column C", which the CLI prints in front instead.
fn strip_serde_location(message: &str) -> &str {
    match message.rfind(" at line ") {
        Some(k) => &message[..k],
        None => message,
    }
}

fn load_photometry(
    name: &str,
    kind: InputKind,
) -> anyhow::Result<(gonio::photometry::Photometry, Diagram)> {
    use gonio::photometry::{read, FileFormat};
    let bytes = read_file(name)?;
    let format = if kind == InputKind::Ies {
        FileFormat::Ies
    } else {
        FileFormat::Eulumdat
    };
    let dir: PathBuf = match Path::new(name).parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let p = read(&bytes, format, &TiltFiles::new(dir)).map_err(|e| LocatedError {
        file: name.to_string(),
        line: e.line,
        column: e.column,
        message: tame(&e.message),
    })?;
    let d = p
        .to_diagram()
        .map_err(|e| anyhow::anyhow!("{name}: cannot expand the distribution: {e}"))?;
    Ok((p, d))
}

/// The domain of every sampler built for `loaded`: photometric input (IES, EULUMDAT, the example)
/// always gets the whole sphere; a JSON diagram gets the library's policy,
/// [`Domain::for_diagram`] (the upper hemisphere when its last parallel lies at θ ≤ 90°, the
/// sphere otherwise).
pub fn domain(loaded: &Loaded) -> Domain {
    if loaded.kind.is_photometric() {
        Domain::Sphere
    } else {
        Domain::for_diagram(&loaded.diagram)
    }
}

/// The global `--tolerance` (bits of an `f64`; NaN = none): the HDS map is refined to it.
static TOLERANCE: AtomicU64 = AtomicU64::new(NO_TOLERANCE);
const NO_TOLERANCE: u64 = 0x7ff8_0000_0000_0000;

/// Sets the tolerance every HDS map of this run is refined to (the global `--tolerance`).
pub fn set_tolerance(tolerance: Option<f64>) {
    TOLERANCE.store(
        tolerance.map_or(NO_TOLERANCE, f64::to_bits),
        Ordering::Relaxed,
    );
}

/// The tolerance set by [`set_tolerance`], if any.
pub fn tolerance() -> Option<f64> {
    let t = f64::from_bits(TOLERANCE.load(Ordering::Relaxed));
    (!t.is_nan()).then_some(t)
}

/// The sampler of `method` for `loaded`, built by the library's factory ([`Method::build_with`])
/// on the domain [`domain`] chooses, with the global `--tolerance` (which only the HDS map reads;
/// a warning goes to stderr when refinement did not reach it). Every zone the sampler completed
/// with zero light ([`Sampler::completions`]) is a warning on stderr too.
pub fn build_sampler(method: Method, loaded: &Loaded) -> anyhow::Result<Box<dyn Sampler>> {
    let (sampler, _) = build_sampler_timed(method, loaded)?;
    for c in sampler.completions() {
        eprintln!("gonio: warning: {}: {c}", loaded.name);
    }
    Ok(sampler)
}

/// [`build_sampler`] and the wall-clock time the build took, without the completion warnings
/// (`gonio info` lists them in its report).
pub fn build_sampler_timed(
    method: Method,
    loaded: &Loaded,
) -> anyhow::Result<(Box<dyn Sampler>, Duration)> {
    let start = Instant::now();
    let options = BuildOptions::default().tolerance(tolerance());
    let sampler = method
        .build_with(&loaded.diagram, domain(loaded), &options)
        .with_context(|| match method {
            Method::Hds => format!("{}: cannot build the HDS map", loaded.name),
            m => format!("{}: cannot build the {m} sampler", loaded.name),
        })?;
    let took = start.elapsed();
    if let Some(w) = sampler.refinement().and_then(|r| r.warning()) {
        eprintln!("gonio: warning: {}: {w}", loaded.name);
    }
    Ok((sampler, took))
}
