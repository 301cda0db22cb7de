//! One loader for diagram files: bytes of a native JSON diagram, an IES LM-63 or a EULUMDAT file
//! in, the [`Diagram`] (and, for photometric files, the file as read with its header and
//! warnings) out. The CLI, the C ABI and the Python package all read files through [`load`]; each
//! words the [`LoadError`] in its own way.
//!
//! The format is the caller's: a hint from the file name ([`InputKind::from_extension`]), a
//! format the caller names, or what the content shows ([`InputKind::detect`]).

pub mod file;

use crate::photometry::{self, FileFormat, ParseError, Photometry, TiltResolver, Warning};
use crate::{Diagram, DiagramError};
use std::fmt;
use std::path::Path;

/// Where a diagram came from: one of the file formats [`load`] reads, or a source that is not a
/// file (the built-in example, an environment map image, arrays handed in by a caller).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InputKind {
    /// The built-in example luminaire ([`crate::synthetic::example_luminaire`]; candela).
    Example,
    /// A native JSON diagram (units as given).
    Json,
    /// An IES LM-63 file (candela).
    Ies,
    /// An EULUMDAT file (candela after scaling).
    Eulumdat,
    /// An environment map image (luminance, or the image's unit).
    EnvMap,
    /// Arrays of angles and values handed in by a caller.
    Arrays,
}

impl InputKind {
    /// Short lowercase name: `example`, `json`, `ies`, `ldt`, `envmap`, `arrays`.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Example => "example",
            InputKind::Json => "json",
            InputKind::Ies => "ies",
            InputKind::Eulumdat => "ldt",
            InputKind::EnvMap => "envmap",
            InputKind::Arrays => "arrays",
        }
    }

    /// The name messages give the format: `JSON`, `IES LM-63`, `EULUMDAT`, `the example`,
    /// `an environment map image`, `arrays`.
    pub fn label(self) -> &'static str {
        match self {
            InputKind::Example => "the example",
            InputKind::Json => "JSON",
            InputKind::Ies => "IES LM-63",
            InputKind::Eulumdat => "EULUMDAT",
            InputKind::EnvMap => "an environment map image",
            InputKind::Arrays => "arrays",
        }
    }

    /// True for IES and EULUMDAT input and the example (candela too): the diagram's values are
    /// candela and its power is luminous flux in lumens.
    pub fn is_photometric(self) -> bool {
        matches!(
            self,
            InputKind::Example | InputKind::Ies | InputKind::Eulumdat
        )
    }

    /// The file format a name's extension stands for (`.json`, `.ies`, `.ldt`, any letter case);
    /// `None` for any other extension or none.
    pub fn from_extension(name: &str) -> Option<Self> {
        match lowercase_extension(name).as_deref() {
            Some("json") => Some(InputKind::Json),
            Some("ies") => Some(InputKind::Ies),
            Some("ldt") => Some(InputKind::Eulumdat),
            _ => None,
        }
    }

    /// The format the content shows: JSON when its first non-blank character (after a UTF-8
    /// byte-order mark) is `{`, else what [`FileFormat::detect`] says.
    pub fn detect(bytes: &[u8]) -> Option<Self> {
        let body = strip_bom(bytes);
        if body.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{') {
            return Some(InputKind::Json);
        }
        match FileFormat::detect(bytes)? {
            FileFormat::Ies => Some(InputKind::Ies),
            FileFormat::Eulumdat => Some(InputKind::Eulumdat),
        }
    }
}

/// A file read by [`load`].
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The format it was read as ([`InputKind::Json`], [`InputKind::Ies`] or
    /// [`InputKind::Eulumdat`]).
    pub kind: InputKind,
    /// The diagram, in the gonio frame (θ from +z, φ from +x toward +y).
    pub diagram: Diagram,
    /// The photometric file as read (header, keywords, warnings), for IES and EULUMDAT input.
    pub photometry: Option<Box<Photometry>>,
}

impl Loaded {
    /// What the reader tolerated (empty for JSON).
    pub fn warnings(&self) -> &[Warning] {
        self.photometry.as_deref().map_or(&[], |p| &p.warnings)
    }
}

/// Why [`load`] could not read a file. Each consumer words it (the CLI, the C ABI and Python
/// prefix the file name and location their own way).
#[derive(Debug, Clone, PartialEq)]
pub enum LoadError {
    /// `kind` is not a file format [`load`] reads (the example, an image, arrays).
    NotAFileFormat(InputKind),
    /// A JSON file is not UTF-8 text.
    NotUtf8(std::str::Utf8Error),
    /// The JSON text could not be read (1-based line and column; serde's own trailing
    /// ` at line L column C` removed, see [`strip_serde_location`]).
    Json {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// The JSON text holds a diagram that is not valid.
    Diagram(DiagramError),
    /// The photometric file could not be read (its line and column inside).
    Parse(ParseError),
    /// The photometric file was read but its distribution cannot be expanded into a diagram.
    Expand {
        /// Why.
        error: DiagramError,
        /// The file's `TILT factor at 0° is 0` warning, when that is the reason there is no
        /// light.
        tilt_zero: Option<Warning>,
    },
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadError::NotAFileFormat(k) => write!(f, "{} is not a file format", k.label()),
            LoadError::NotUtf8(e) => write!(f, "the file is not UTF-8 text ({e})"),
            LoadError::Json {
                line,
                column,
                message,
            } => write!(f, "{line}:{column}: {message}"),
            LoadError::Diagram(d) => write!(f, "invalid diagram: {d}"),
            LoadError::Parse(e) => write!(f, "{e}"),
            LoadError::Expand { error, .. } => {
                write!(f, "cannot expand the distribution: {error}")
            }
        }
    }
}

impl std::error::Error for LoadError {}

/// serde_json messages end in " at line L column C", which a location in front already says;
/// this removes it.
pub fn strip_serde_location(message: &str) -> &str {
    match message.rfind(" at line ") {
        Some(k) => &message[..k],
        None => message,
    }
}

fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes)
}

/// Reads `bytes` as a file of format `kind` ([`InputKind::Json`], [`InputKind::Ies`] or
/// [`InputKind::Eulumdat`]). A UTF-8 byte-order mark in front of JSON is skipped. TILT files an
/// IES file names are obtained through `tilt` (pass [`photometry::NoTiltFiles`] when none can
/// be read). Never panics.
pub fn load(bytes: &[u8], kind: InputKind, tilt: &dyn TiltResolver) -> Result<Loaded, LoadError> {
    match kind {
        InputKind::Json => {
            let text = std::str::from_utf8(strip_bom(bytes)).map_err(LoadError::NotUtf8)?;
            let diagram = Diagram::from_json_str(text).map_err(|e| match e {
                crate::Error::Json {
                    line,
                    column,
                    message,
                } => LoadError::Json {
                    line,
                    column,
                    message: strip_serde_location(&message).to_string(),
                },
                crate::Error::Diagram(d) => LoadError::Diagram(d),
            })?;
            Ok(Loaded {
                kind,
                diagram,
                photometry: None,
            })
        }
        InputKind::Ies | InputKind::Eulumdat => {
            let format = if kind == InputKind::Ies {
                FileFormat::Ies
            } else {
                FileFormat::Eulumdat
            };
            let p = photometry::read(bytes, format, tilt).map_err(LoadError::Parse)?;
            let diagram = p.to_diagram().map_err(|error| LoadError::Expand {
                error,
                tilt_zero: p
                    .warnings
                    .iter()
                    .find(|w| w.message.starts_with("TILT factor at 0° is 0"))
                    .cloned(),
            })?;
            Ok(Loaded {
                kind,
                diagram,
                photometry: Some(Box::new(p)),
            })
        }
        other => Err(LoadError::NotAFileFormat(other)),
    }
}

/// The extension of the file name `name` in lower case (`"Sky.EXR"` → `"exr"`), if it has one.
pub fn lowercase_extension(name: &str) -> Option<String> {
    Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

/// The member of `all` whose `name` is `text`, by the one rule for every name gonio parses
/// (methods, sequences, plot kinds; issue 25): ASCII letter case and surrounding blanks do not
/// matter. `None` when no member has that name.
///
/// ```
/// use gonio::{input::find_by_name, Method};
/// assert_eq!(find_by_name(Method::ALL, Method::as_str, " HDS "), Some(Method::Hds));
/// ```
pub fn find_by_name<T: Copy>(
    all: impl IntoIterator<Item = T>,
    name: impl Fn(T) -> &'static str,
    text: &str,
) -> Option<T> {
    let t = text.trim();
    all.into_iter().find(|&m| name(m).eq_ignore_ascii_case(t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photometry::NoTiltFiles;

    #[test]
    fn json_with_bom_and_serde_location_stripped() {
        let d = crate::synthetic::example_luminaire();
        let mut bytes = b"\xef\xbb\xbf".to_vec();
        bytes.extend_from_slice(serde_json::to_string(&d.to_json()).unwrap().as_bytes());
        assert_eq!(InputKind::detect(&bytes), Some(InputKind::Json));
        let l = load(&bytes, InputKind::Json, &NoTiltFiles).unwrap();
        assert_eq!(
            serde_json::to_string(&l.diagram.to_json()).unwrap(),
            serde_json::to_string(&d.to_json()).unwrap()
        );
        assert!(l.warnings().is_empty());
        match load(b"{\"theta_deg\": [0,", InputKind::Json, &NoTiltFiles) {
            Err(LoadError::Json { line, message, .. }) => {
                assert_eq!(line, 1);
                assert!(!message.contains(" at line "), "{message}");
            }
            other => panic!("expected a JSON error, got {other:?}"),
        }
    }

    #[test]
    fn kinds_from_names_and_content() {
        assert_eq!(
            InputKind::from_extension("a/B.LDT"),
            Some(InputKind::Eulumdat)
        );
        assert_eq!(InputKind::from_extension("x.Ies"), Some(InputKind::Ies));
        assert_eq!(InputKind::from_extension("x.hdr"), None);
        assert_eq!(InputKind::from_extension("x"), None);
        assert_eq!(
            InputKind::detect(b"IESNA:LM-63-2002\n"),
            Some(InputKind::Ies)
        );
        assert_eq!(
            load(b"", InputKind::Example, &NoTiltFiles).unwrap_err(),
            LoadError::NotAFileFormat(InputKind::Example)
        );
    }
}
