//! The one way gonio reads a file from a path, for every input kind and every front end (the
//! CLI, the C ABI, Python, and the library's own `*::read(path)` functions):
//!
//! * only **regular files** (symbolic links followed): a FIFO, a device such as `/dev/zero`, a
//!   socket or a directory is refused by its metadata *before* it is opened, and the file is
//!   opened with `O_NONBLOCK | O_NOCTTY` and checked again (`fstat`), so a FIFO swapped in between
//!   cannot block;
//! * at most the **size limit of its kind** ([`FileKind`], [`read_limit`]): a larger file is
//!   refused before a byte of it is read, and no more than the limit is ever read even if the
//!   file grows; the buffer is reserved fallibly (an allocation failure is an error, not an
//!   abort);
//! * one message per fault, the same text whichever front end words it ([`ReadFileError`]).
//!
//! The limits are large enough for real data (a 16384 × 8192 float RGBA OpenEXR sky is 2 GiB, a
//! MERL table 33 MB, a two-million-triangle PLY tens of MB) and settable for the whole process
//! ([`set_read_limit`]; the C ABI's `gonio_set_read_limit`, Python's `gonio.set_read_limit`).

use std::fs::{File, Metadata};
use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// What a file is read as: each kind has its own size limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FileKind {
    /// IES LM-63 or EULUMDAT (default limit 64 MiB).
    Photometry,
    /// A native JSON diagram (64 MiB).
    Diagram,
    /// A TILT file named by an IES file (4 MiB).
    Tilt,
    /// An image: an environment map (`.hdr`, `.exr`, `.pfm`) or a texture (4 GiB).
    Image,
    /// A tabulated BRDF: MERL, UTIA, gonio BRDF JSON (256 MiB).
    Brdf,
    /// A mesh: OBJ or PLY (2 GiB).
    Mesh,
    /// A table blob (docs/TABLES.md; 4 GiB).
    Tables,
}

impl FileKind {
    /// Every kind, in the order of [`FileKind::name`]'s table.
    pub const ALL: [FileKind; 7] = [
        FileKind::Photometry,
        FileKind::Diagram,
        FileKind::Tilt,
        FileKind::Image,
        FileKind::Brdf,
        FileKind::Mesh,
        FileKind::Tables,
    ];

    /// The kind's name: `photometry`, `diagram`, `tilt`, `image`, `brdf`, `mesh`, `tables`.
    pub fn name(self) -> &'static str {
        match self {
            FileKind::Photometry => "photometry",
            FileKind::Diagram => "diagram",
            FileKind::Tilt => "tilt",
            FileKind::Image => "image",
            FileKind::Brdf => "brdf",
            FileKind::Mesh => "mesh",
            FileKind::Tables => "tables",
        }
    }

    /// The kind of a name as [`FileKind::name`] spells it.
    pub fn from_name(name: &str) -> Option<FileKind> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The default size limit in bytes.
    pub fn default_limit(self) -> u64 {
        match self {
            FileKind::Photometry | FileKind::Diagram => 64 << 20,
            FileKind::Tilt => 4 << 20,
            FileKind::Image | FileKind::Tables => 4 << 30,
            FileKind::Brdf => 256 << 20,
            FileKind::Mesh => 2 << 30,
        }
    }

    fn index(self) -> usize {
        Self::ALL
            .iter()
            .position(|&k| k == self)
            .expect("every kind is listed")
    }
}

/// The process-wide limits, in bytes (0: the kind's default).
static LIMITS: [AtomicU64; 7] = [const { AtomicU64::new(0) }; 7];

/// The size limit of `kind` in bytes: [`set_read_limit`]'s value, else the kind's default.
pub fn read_limit(kind: FileKind) -> u64 {
    match LIMITS[kind.index()].load(Ordering::Relaxed) {
        0 => kind.default_limit(),
        v => v,
    }
}

/// Sets the size limit of `kind` for the whole process (0 restores the default). Reads already
/// under way keep the limit they started with.
pub fn set_read_limit(kind: FileKind, bytes: u64) {
    LIMITS[kind.index()].store(bytes, Ordering::Relaxed);
}

/// Why a file was not read. Each message names the file as the caller showed it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReadFileError {
    /// The file does not exist.
    #[error("cannot read {path}: no such file")]
    NotFound {
        /// The file.
        path: String,
    },
    /// Any other operating-system error (permissions, I/O).
    #[error("cannot read {path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The system's message.
        message: String,
    },
    /// Not a regular file.
    #[error("{path}: is {what}, not a regular file; gonio reads only regular files")]
    NotRegular {
        /// The file.
        path: String,
        /// What it is, in words ("a FIFO (named pipe)", "a directory", …).
        what: &'static str,
    },
    /// Larger than the limit of its kind.
    #[error(
        "{path}: the file has {size} bytes, more than the limit of {limit} bytes for {} files \
         ({} MiB; settable); not read",
        kind.name(),
        limit >> 20
    )]
    TooLarge {
        /// The file.
        path: String,
        /// Its size.
        size: u64,
        /// The limit.
        limit: u64,
        /// Its kind.
        kind: FileKind,
    },
    /// The file grew past the limit while it was read.
    #[error("{path}: the file grew beyond the limit of {limit} bytes while it was read")]
    Grew {
        /// The file.
        path: String,
        /// The limit.
        limit: u64,
    },
    /// No memory for its bytes.
    #[error("{path}: cannot allocate {size} bytes to read it")]
    NoMemory {
        /// The file.
        path: String,
        /// Bytes asked for.
        size: u64,
    },
}

/// What a file that is not regular is, in words.
pub fn file_type_name(meta: &Metadata) -> &'static str {
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

fn io_error(shown: &str, e: &std::io::Error) -> ReadFileError {
    if e.kind() == std::io::ErrorKind::NotFound {
        ReadFileError::NotFound {
            path: shown.to_string(),
        }
    } else {
        ReadFileError::Io {
            path: shown.to_string(),
            message: e.to_string(),
        }
    }
}

/// Opens `path` for reading if it is a regular file (see the module documentation); `shown`
/// names it in messages. Returns the file and its metadata (of the open file).
///
/// # Errors
/// [`ReadFileError::NotFound`], [`ReadFileError::Io`], [`ReadFileError::NotRegular`].
pub fn open_regular(path: &Path, shown: &str) -> Result<(File, Metadata), ReadFileError> {
    let meta = std::fs::metadata(path).map_err(|e| io_error(shown, &e))?;
    if !meta.is_file() {
        return Err(ReadFileError::NotRegular {
            path: shown.to_string(),
            what: file_type_name(&meta),
        });
    }
    let mut opts = std::fs::OpenOptions::new();
    opts.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        opts.custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY);
    }
    let file = opts.open(path).map_err(|e| io_error(shown, &e))?;
    let meta = file.metadata().map_err(|e| io_error(shown, &e))?;
    if !meta.is_file() {
        return Err(ReadFileError::NotRegular {
            path: shown.to_string(),
            what: file_type_name(&meta),
        });
    }
    Ok((file, meta))
}

/// `size` bytes of kind `kind` (a file's length or a buffer handed in memory) against the kind's
/// limit ([`read_limit`]): the one size check of every front end, with its message.
///
/// # Errors
/// [`ReadFileError::TooLarge`] naming `shown`.
pub fn check_size(shown: &str, size: u64, kind: FileKind) -> Result<(), ReadFileError> {
    let limit = read_limit(kind);
    if size > limit {
        return Err(ReadFileError::TooLarge {
            path: shown.to_string(),
            size,
            limit,
            kind,
        });
    }
    Ok(())
}

/// Reads the whole regular file `path` of kind `kind` under its limit ([`read_limit`]); `shown`
/// names it in messages (usually `path` as the user gave it). Returns the bytes and the open
/// file's metadata (the CLI compares outputs with inputs by it).
///
/// # Errors
/// A [`ReadFileError`]; nothing is read from a file that is not regular or is too large.
pub fn read_file_with_meta(
    path: &Path,
    shown: &str,
    kind: FileKind,
) -> Result<(Vec<u8>, Metadata), ReadFileError> {
    let limit = read_limit(kind);
    let (file, meta) = open_regular(path, shown)?;
    check_size(shown, meta.len(), kind)?;
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(meta.len() as usize)
        .map_err(|_| ReadFileError::NoMemory {
            path: shown.to_string(),
            size: meta.len(),
        })?;
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| io_error(shown, &e))?;
    if bytes.len() as u64 > limit {
        return Err(ReadFileError::Grew {
            path: shown.to_string(),
            limit,
        });
    }
    Ok((bytes, meta))
}

/// [`read_file_with_meta`] without the metadata, the path shown as it is.
///
/// # Errors
/// As [`read_file_with_meta`].
pub fn read_file(path: &Path, kind: FileKind) -> Result<Vec<u8>, ReadFileError> {
    read_file_with_meta(path, &path.display().to_string(), kind).map(|(b, _)| b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("gonio-file-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn regular_files_under_the_limit_are_read_and_others_refused_with_one_message() {
        let d = temp("limits");
        let f = d.join("a.ies");
        std::fs::write(&f, b"hello").unwrap();
        assert_eq!(read_file(&f, FileKind::Photometry).unwrap(), b"hello");
        // A directory, a missing file.
        let e = read_file(&d, FileKind::Image).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("is a directory, not a regular file; gonio reads only regular files"),
            "{e}"
        );
        let e = read_file(&d.join("none"), FileKind::Image).unwrap_err();
        assert!(matches!(e, ReadFileError::NotFound { .. }), "{e}");
        // A sparse file over the limit is refused by its size, before reading.
        let big = d.join("big.pfm");
        let fh = File::create(&big).unwrap();
        fh.set_len(FileKind::Tilt.default_limit() + 1).unwrap();
        let e = read_file(&big, FileKind::Tilt).unwrap_err();
        assert!(
            matches!(
                e,
                ReadFileError::TooLarge {
                    kind: FileKind::Tilt,
                    ..
                }
            ),
            "{e}"
        );
        assert!(
            e.to_string().contains("for tilt files (4 MiB; settable)"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_and_a_device_are_refused_without_blocking() {
        let d = temp("fifo");
        let p = d.join("sky.hdr");
        let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = read_file(&p, FileKind::Image).unwrap_err();
        assert!(e.to_string().contains("is a FIFO (named pipe)"), "{e}");
        let e = read_file(Path::new("/dev/zero"), FileKind::Image).unwrap_err();
        assert!(e.to_string().contains("is a character device"), "{e}");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn limits_are_settable_per_kind() {
        let d = temp("set");
        let f = d.join("m.obj");
        std::fs::write(&f, vec![b'#'; 100]).unwrap();
        set_read_limit(FileKind::Mesh, 99);
        let e = read_file(&f, FileKind::Mesh).unwrap_err();
        set_read_limit(FileKind::Mesh, 0);
        assert!(
            matches!(
                e,
                ReadFileError::TooLarge {
                    limit: 99,
                    size: 100,
                    ..
                }
            ),
            "{e}"
        );
        assert_eq!(read_limit(FileKind::Mesh), 2 << 30);
        assert_eq!(read_file(&f, FileKind::Mesh).unwrap().len(), 100);
        let _ = std::fs::remove_dir_all(&d);
    }
}
