//! Reading input files safely: only regular files, never more than a documented size, never
//! blocking on a FIFO or a device.
//!
//! * [`read_regular`] reads a whole file (IES, EULUMDAT, JSON, TILT): it looks at the file's
//!   metadata (following symbolic links) *before* opening it and refuses anything that is not a
//!   regular file (FIFO, character or block device such as `/dev/zero`, socket, directory); it
//!   opens with `O_NONBLOCK | O_NOCTTY`, so a FIFO swapped in between the check and the open
//!   cannot block, checks the open file again (`fstat`), refuses a file larger than the limit
//!   before reading a byte, and never reads more than the limit even if the file grows;
//! * [`open_regular`] does the same checks for the CSV inputs, which are streamed;
//! * every file opened here is remembered by device and inode ([`is_input`]), so that
//!   [`crate::output::Output`] can refuse to write over an input;
//! * [`TiltFiles`] serves `TILT=<file>` names: a plain file name, resolved (symbolic links
//!   followed) to a regular file inside the IES file's folder, at most the library's TILT limit.

pub use gonio::input::file::FileKind;
use gonio::photometry::{DirTiltResolver, TiltResolver};
use std::fs::{File, Metadata};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Identity of a file: (device, inode) on Unix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileId {
    dev: u64,
    ino: u64,
}

impl FileId {
    /// The identity of the file `meta` describes (`None` where the platform has none).
    pub fn of(meta: &Metadata) -> Option<Self> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            Some(FileId {
                dev: meta.dev(),
                ino: meta.ino(),
            })
        }
        #[cfg(not(unix))]
        {
            let _ = meta;
            None
        }
    }
}

/// Every file opened for reading in this run: identity and the name the user gave.
static INPUTS: Mutex<Vec<(FileId, String)>> = Mutex::new(Vec::new());

fn remember(meta: &Metadata, shown: &str) {
    if let Some(id) = FileId::of(meta) {
        let mut v = INPUTS.lock().unwrap_or_else(|e| e.into_inner());
        if !v.iter().any(|(i, _)| *i == id) {
            v.push((id, shown.to_string()));
        }
    }
}

/// The name of the input that is the same file as `meta` (same device and inode), if any.
pub fn is_input(meta: &Metadata) -> Option<String> {
    let id = FileId::of(meta)?;
    INPUTS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .iter()
        .find(|(i, _)| *i == id)
        .map(|(_, n)| n.clone())
}

/// What a non-regular file is, in words (the library's one wording).
pub fn kind_of(meta: &Metadata) -> &'static str {
    gonio::input::file::file_type_name(meta)
}

/// Opens `path` for reading if it is a regular file (symbolic links followed), through the
/// library's one file reader ([`gonio::input::file::open_regular`]); `shown` names it in
/// messages. Never blocks on a FIFO. The file is remembered as an input.
pub fn open_regular(path: &Path, shown: &str) -> anyhow::Result<(File, Metadata)> {
    let (file, meta) = gonio::input::file::open_regular(path, shown)?;
    remember(&meta, shown);
    Ok((file, meta))
}

/// Reads the whole regular file `path` of kind `kind` under the library's limit for that kind
/// ([`gonio::input::file::read_file_with_meta`]: the same checks and messages as the C ABI and
/// Python); the file is remembered as an input.
pub fn read_regular(path: &Path, shown: &str, kind: FileKind) -> anyhow::Result<Vec<u8>> {
    let (bytes, meta) = gonio::input::file::read_file_with_meta(path, shown, kind)?;
    remember(&meta, shown);
    Ok(bytes)
}

/// The `TILT=<file>` resolver of the CLI: [`DirTiltResolver::locate`] (a plain name, resolved with
/// symbolic links to a regular file inside the IES file's folder), then [`read_regular`] with
/// [`FileKind::Tilt`].
#[derive(Debug, Clone)]
pub struct TiltFiles {
    dir: PathBuf,
}

impl TiltFiles {
    /// TILT files next to an IES file in `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }
}

impl TiltResolver for TiltFiles {
    fn resolve(&self, name: &str) -> Result<Vec<u8>, String> {
        let path = DirTiltResolver::new(&self.dir).locate(name)?;
        read_regular(&path, &path.display().to_string(), FileKind::Tilt).map_err(|e| {
            // The message names the file already; the library prefixes `TILT file NAME: `.
            let m = format!("{e:#}");
            let p = format!("{}: ", path.display());
            m.strip_prefix(&p).map(str::to_string).unwrap_or(m)
        })
    }
}

/// Longest message text taken from a reader (e.g. serde_json's, which quotes strings of the file
/// in full), in characters.
pub const MAX_MESSAGE_CHARS: usize = 300;

/// A reader's message made safe to print: control characters escaped (`\n`, `\u{1b}`), at most
/// [`MAX_MESSAGE_CHARS`] characters (then `…`).
pub fn tame(message: &str) -> String {
    let mut out = String::new();
    for (k, c) in message.chars().enumerate() {
        if k == MAX_MESSAGE_CHARS {
            out.push('…');
            break;
        }
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    out
}
