//! Input loading and sampler construction, shared by every command (and by `plot` and `bench`).
//!
//! * [`load`] reads a `.json` (native diagram), `.ies` or `.ldt` file (extension in any letter
//!   case), or the special name [`EXAMPLE`] for the built-in luminaire;
//! * [`build_sampler`] builds the sampler of a [`Method`] for what was loaded (through the
//!   library's factory, [`Method::build`]), on the domain [`domain`] chooses.

use crate::input::{read_regular, tame, FileKind, TiltFiles};
use crate::settings::Settings;
use anyhow::Context;
use gonio::{BuildOptions, Built, Diagram, Domain, Method};
use std::fmt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The input name that loads [`gonio::synthetic::example_luminaire`] instead of a file.
pub const EXAMPLE: &str = "example";

/// An error located in an input file; displayed as `FILE:LINE:COLUMN: message`, like a compiler
/// diagnostic (the binary prints it after the `gonio: error:` prefix every error has). Line and column are 1-based; a column of 0
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

/// The kind of input that was loaded: the library's one kind enum.
pub use gonio::input::InputKind;

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
    /// The environment map, for image input (its diagram is `diagram`).
    pub envmap: Option<Box<gonio::envmap::EnvironmentMap>>,
    /// The build time of the environment map's own HDS map (zero for other inputs).
    pub envmap_build: Duration,
    /// The run's global options it was loaded with (the samplers built for it read
    /// `--tolerance` here).
    pub settings: Settings,
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
    if let Some(kind) = InputKind::from_extension(name) {
        return Ok(kind);
    }
    let ext = gonio::input::lowercase_extension(name);
    match ext.as_deref() {
        Some("hdr" | "pic" | "exr" | "pfm") => Ok(InputKind::EnvMap),
        Some(e) => anyhow::bail!(
            "{name}: unknown input format `.{e}`; expected .json, .ies, .ldt or `{EXAMPLE}`"
        ),
        None => anyhow::bail!(
            "{name}: the file name has no extension; expected .json, .ies, .ldt or `{EXAMPLE}`"
        ),
    }
}

/// Loads an input: a JSON diagram, an IES or a EULUMDAT file, or [`EXAMPLE`].
///
/// The format comes from the content (see [`InputKind::detect`]), with the extension as a hint: when
/// the content is not recognised the extension decides, and when the two disagree the content
/// wins and a warning says so on standard error.
///
/// Syntax errors come back as a [`LocatedError`] (`FILE:LINE:COLUMN: message`); every other error
/// names the file.
pub fn load(name: &str, settings: &Settings) -> anyhow::Result<Loaded> {
    let settings = *settings;
    if !crate::envmap_in::is_image_name(name) {
        if let Some(opt) = settings.env.given() {
            anyhow::bail!("{name}: {opt} applies to environment maps (.hdr, .exr, .pfm) only");
        }
    }
    if name == EXAMPLE {
        return Ok(Loaded {
            name: name.to_string(),
            kind: InputKind::Example,
            diagram: gonio::synthetic::example_luminaire(),
            photometry: None,
            envmap: None,
            envmap_build: Duration::ZERO,
            settings,
        });
    }
    if crate::envmap_in::is_image_name(name) {
        let (env, took) = crate::envmap_in::load_envmap_timed(name, &settings.env)?;
        return Ok(Loaded {
            name: name.to_string(),
            kind: InputKind::EnvMap,
            diagram: env.diagram(),
            photometry: None,
            envmap: Some(Box::new(env)),
            envmap_build: took,
            settings,
        });
    }
    let bytes = read_file(name)?;
    let hint = input_kind(name).ok();
    let kind = match (InputKind::detect(&bytes), hint) {
        (Some(found), Some(ext)) if found != ext => {
            eprintln!(
                "gonio: warning: {name}: the content is {}, not {} as the extension says; reading it as {}",
                found.label(),
                ext.label(),
                found.label()
            );
            found
        }
        (Some(found), _) => found,
        (None, Some(ext)) => ext,
        (None, None) => {
            if let Some(what) = gonio::photometry::not_text(&bytes) {
                anyhow::bail!("{name}: {what}; save it as UTF-8 or ASCII");
            }
            // The extension's message (unknown or missing), with what the content was not.
            return Err(input_kind(name).expect_err("no hint").context(format!(
                "{name}: the content is not recognisable as JSON, IES LM-63 or EULUMDAT either"
            )));
        }
    };
    if kind == InputKind::Json {
        if let Some(what) = gonio::photometry::not_text(&bytes) {
            anyhow::bail!("{name}: {what}; save it as UTF-8");
        }
    }
    let dir: PathBuf = match Path::new(name).parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let loaded = gonio::input::load(&bytes, kind, &TiltFiles::new(dir))
        .map_err(|e| load_error(name, &bytes, e))?;
    let (diagram, photometry) = (loaded.diagram, loaded.photometry);
    Ok(Loaded {
        name: name.to_string(),
        kind,
        diagram,
        photometry,
        envmap: None,
        envmap_build: Duration::ZERO,
        settings,
    })
}

/// Reads an input file: a regular file of at most the library's limit for diagrams (a `.json`
/// name) or photometric files (see [`crate::input`]).
fn read_file(name: &str) -> anyhow::Result<Vec<u8>> {
    let kind = if name.to_ascii_lowercase().ends_with(".json") {
        FileKind::Diagram
    } else {
        FileKind::Photometry
    };
    read_regular(Path::new(name), name, kind)
}

/// A library [`gonio::input::LoadError`] as the CLI words it: syntax errors as a
/// [`LocatedError`], every other error naming the file.
fn load_error(name: &str, bytes: &[u8], e: gonio::input::LoadError) -> anyhow::Error {
    use gonio::input::LoadError as E;
    match e {
        E::NotUtf8(e) => anyhow::anyhow!("{name}: the file is not UTF-8 text ({e})"),
        E::Json {
            line,
            column,
            message,
        } => LocatedError {
            file: name.to_string(),
            line,
            column,
            message: tame(&message),
        }
        .into(),
        E::Diagram(d) => {
            let text = std::str::from_utf8(bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes))
                .unwrap_or_default();
            match json_path_of(&d).and_then(|path| json_position(text, &path)) {
                Some((line, column)) => LocatedError {
                    file: name.to_string(),
                    line,
                    column,
                    message: format!("invalid diagram: {d}"),
                }
                .into(),
                None => anyhow::anyhow!("{name}: invalid diagram: {d}"),
            }
        }
        E::Parse(e) => LocatedError {
            file: name.to_string(),
            line: e.line,
            column: e.column,
            message: tame(&e.message),
        }
        .into(),
        E::Expand { error, tilt_zero } => {
            // Say why there is no light when the file's TILT factor is the reason.
            let why = tilt_zero
                .map(|w| format!(" (line {}: {})", w.line, w.message))
                .unwrap_or_default();
            anyhow::anyhow!("{name}: cannot expand the distribution: {error}{why}")
        }
        E::NotAFileFormat(k) => anyhow::anyhow!("{name}: {} is not a file format", k.label()),
    }
}

/// One step of a path into a JSON document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JsonStep<'a> {
    /// A member of an object.
    Key(&'a str),
    /// An element of an array.
    Index(usize),
}

/// Where in the native JSON form the value a diagram error names lives.
fn json_path_of(e: &gonio::DiagramError) -> Option<Vec<JsonStep<'static>>> {
    use gonio::DiagramError as E;
    use JsonStep::{Index, Key};
    let axis_key = |axis: &str| {
        if axis == "theta" {
            "theta_deg"
        } else {
            "phi_deg"
        }
    };
    Some(match e {
        E::NonFiniteAngle { axis, index, .. }
        | E::AngleOutOfRange { axis, index, .. }
        | E::NotIncreasing { axis, index, .. } => vec![Key(axis_key(axis)), Index(*index)],
        E::BadValue {
            meridian, parallel, ..
        } => vec![Key("values"), Index(*meridian), Index(*parallel)],
        E::Shape { what, .. } => {
            let row = what
                .strip_prefix("values[")
                .and_then(|r| r.split(']').next())
                .and_then(|r| r.parse::<usize>().ok());
            match row {
                Some(i) => vec![Key("values"), Index(i)],
                None => vec![Key("values")],
            }
        }
        _ => return None,
    })
}

/// The 1-based (line, column) of the value at `path` in the JSON `text`, if the text has one
/// there (columns count characters).
pub fn json_position(text: &str, path: &[JsonStep]) -> Option<(usize, usize)> {
    let b = text.as_bytes();
    let at = locate(b, skip_ws(b, 0), path)?;
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = before[before.rfind('\n').map_or(0, |k| k + 1)..]
        .chars()
        .count()
        + 1;
    Some((line, col))
}

fn skip_ws(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i].is_ascii_whitespace() {
        i += 1;
    }
    i
}

/// End (exclusive) of the JSON value starting at `i`.
fn skip_value(b: &[u8], i: usize) -> Option<usize> {
    match *b.get(i)? {
        b'"' => {
            let mut k = i + 1;
            while k < b.len() {
                match b[k] {
                    b'\\' => k += 2,
                    b'"' => return Some(k + 1),
                    _ => k += 1,
                }
            }
            None
        }
        open @ (b'{' | b'[') => {
            let close = if open == b'{' { b'}' } else { b']' };
            let mut k = skip_ws(b, i + 1);
            if b.get(k) == Some(&close) {
                return Some(k + 1);
            }
            loop {
                if open == b'{' {
                    k = skip_ws(b, skip_value(b, k)?);
                    if b.get(k) != Some(&b':') {
                        return None;
                    }
                    k = skip_ws(b, k + 1);
                }
                k = skip_ws(b, skip_value(b, k)?);
                match b.get(k)? {
                    b',' => k = skip_ws(b, k + 1),
                    c if *c == close => return Some(k + 1),
                    _ => return None,
                }
            }
        }
        _ => {
            let mut k = i;
            while k < b.len() && !matches!(b[k], b',' | b']' | b'}') && !b[k].is_ascii_whitespace()
            {
                k += 1;
            }
            (k > i).then_some(k)
        }
    }
}

fn locate(b: &[u8], i: usize, path: &[JsonStep]) -> Option<usize> {
    let Some((step, rest)) = path.split_first() else {
        return Some(i);
    };
    match (step, *b.get(i)?) {
        (JsonStep::Key(key), b'{') => {
            let mut k = skip_ws(b, i + 1);
            while b.get(k) == Some(&b'"') {
                let end = skip_value(b, k)?;
                let name = std::str::from_utf8(&b[k + 1..end - 1]).ok()?;
                k = skip_ws(b, end);
                if b.get(k) != Some(&b':') {
                    return None;
                }
                k = skip_ws(b, k + 1);
                if name == *key {
                    return locate(b, k, rest);
                }
                k = skip_ws(b, skip_value(b, k)?);
                if b.get(k) != Some(&b',') {
                    return None;
                }
                k = skip_ws(b, k + 1);
            }
            None
        }
        (JsonStep::Index(n), b'[') => {
            let mut k = skip_ws(b, i + 1);
            for _ in 0..*n {
                k = skip_ws(b, skip_value(b, k)?);
                if b.get(k) != Some(&b',') {
                    return None;
                }
                k = skip_ws(b, k + 1);
            }
            if matches!(b.get(k), None | Some(b']')) {
                return None;
            }
            locate(b, k, rest)
        }
        _ => None,
    }
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

/// The sampler of `method` for `loaded`, built by the library's factory ([`Method::build_with`])
/// on the domain [`domain`] chooses, with the run's `--tolerance` (`loaded.settings`) (which only the HDS map reads;
/// a warning goes to stderr when refinement did not reach it). Every zone the sampler completed
/// with zero light ([`gonio::MapRef::completions`]) is a warning on stderr too.
pub fn build_sampler(method: Method, loaded: &Loaded) -> anyhow::Result<Built<'_>> {
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
) -> anyhow::Result<(Built<'_>, Duration)> {
    let start = Instant::now();
    let options = BuildOptions::default().tolerance(loaded.settings.tolerance);
    // An environment map's HDS map is the one its environment map built (the split sphere map
    // of its weight, the same as the factory's): borrowed, not built a second time (issue 40: a
    // second map cost `info` 18 bytes a pixel of a big sky).
    if let (Method::Hds, Some(env), None, Domain::Sphere) =
        (method, &loaded.envmap, options.tolerance, domain(loaded))
    {
        return Ok((env.map().into(), loaded.envmap_build));
    }
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
