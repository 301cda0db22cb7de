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
//!   followed) to a regular file inside the IES file's folder, at most [`MAX_TILT_BYTES`].

use anyhow::bail;
use gonio::photometry::{DirTiltResolver, TiltResolver};
use std::fs::{File, Metadata};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Largest input file read (IES, EULUMDAT, JSON): 64 MiB. A larger file is refused before a byte
/// of it is read. The largest real files in the test corpus are under 0.5 MB; a JSON diagram at
/// the node limit ([`gonio::diagram::MAX_NODES`] values, at least 2 bytes each) is larger than
/// this, so it is refused by size before parsing.
pub const MAX_INPUT_BYTES: u64 = gonio::photometry::MAX_FILE_BYTES;

/// Largest TILT file read: 4 MiB (a TILT table of the largest allowed size,
/// [`gonio::photometry::MAX_ANGLES`] angle/factor pairs, fits in well under this).
pub const MAX_TILT_BYTES: u64 = 4 << 20;

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

/// What a non-regular file is, in words.
pub fn kind_of(meta: &Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    if t.is_symlink() {
        return "a symbolic link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_file() {
        "a regular file"
    } else {
        "not a regular file"
    }
}

/// Opens `path` for reading if it is a regular file (symbolic links followed); `shown` names it
/// in messages. Never blocks on a FIFO. The file is remembered as an input.
pub fn open_regular(path: &Path, shown: &str) -> anyhow::Result<(File, Metadata)> {
    let meta = std::fs::metadata(path).map_err(|e| anyhow::anyhow!("cannot read {shown}: {e}"))?;
    if !meta.is_file() {
        bail!(
            "{shown}: is {}; gonio reads only regular files",
            kind_of(&meta)
        );
    }
    let mut opts = std::fs::OpenOptions::new();
    opts.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        opts.custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY);
    }
    let file = opts
        .open(path)
        .map_err(|e| anyhow::anyhow!("cannot read {shown}: {e}"))?;
    let meta = file
        .metadata()
        .map_err(|e| anyhow::anyhow!("cannot read {shown}: {e}"))?;
    if !meta.is_file() {
        bail!(
            "{shown}: is {}; gonio reads only regular files",
            kind_of(&meta)
        );
    }
    remember(&meta, shown);
    Ok((file, meta))
}

/// Reads the whole regular file `path`, refusing it before reading if it is larger than `max`
/// bytes (and never reading more than `max` bytes).
pub fn read_regular(path: &Path, shown: &str, max: u64) -> anyhow::Result<Vec<u8>> {
    let (file, meta) = open_regular(path, shown)?;
    if meta.len() > max {
        bail!(
            "{shown}: the file has {} bytes, more than the limit of {max} bytes ({} MiB); not read",
            meta.len(),
            max >> 20
        );
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| anyhow::anyhow!("cannot read {shown}: {e}"))?;
    if bytes.len() as u64 > max {
        bail!("{shown}: the file grew beyond the limit of {max} bytes while it was read");
    }
    Ok(bytes)
}

/// The `TILT=<file>` resolver of the CLI: [`DirTiltResolver::locate`] (a plain name, resolved with
/// symbolic links to a regular file inside the IES file's folder), then [`read_regular`] with
/// [`MAX_TILT_BYTES`].
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
        read_regular(&path, &path.display().to_string(), MAX_TILT_BYTES).map_err(|e| {
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
