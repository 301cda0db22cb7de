//! Output destinations and number formatting.
//!
//! Where `-o OUT` writes, by what OUT is (symbolic links followed; see `docs/CLI.md`):
//!
//! * `-` or no `-o`: standard output;
//! * a path that does not exist, or a regular file: a temporary file `.NAME.gonio-tmp-PID-K` in
//!   the same folder, renamed onto OUT only when the command succeeds ([`Output::finish`]), so a
//!   failed or interrupted command never leaves a partial or truncated file behind. An existing
//!   file keeps its permission bits; a new one gets the usual `0666 & !umask`. A regular file with
//!   more than one hard link is not replaced: on success the finished temporary file is copied
//!   into it (the links stay intact);
//! * a character or block device, a FIFO or a socket (`/dev/null`, `/dev/stdout`, a named pipe):
//!   written directly, never replaced and no temporary file;
//! * a symbolic link: written through to its target as above (a link to a missing file, or a
//!   directory, is refused);
//! * a file that is also an input of the command (same device and inode, see
//!   [`crate::input::is_input`]) is refused before anything is written.
//!
//! The temporary file is removed on every error path (dropping an unfinished [`Output`]) and on
//! SIGINT, SIGTERM and SIGHUP ([`crate::cleanup`]).

use crate::cleanup::{register, TempGuard};
use crate::input::{is_input, kind_of};
use anyhow::{bail, Context};
use std::fs::{File, Metadata, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Buffer size of every output writer.
const BUF: usize = 1 << 20;

/// How a file output is completed.
enum Pending {
    /// Rename the temporary file onto the destination.
    Rename {
        tmp: PathBuf,
        dst: PathBuf,
        _guard: TempGuard,
    },
    /// Copy the temporary file into the (hard-linked) destination, then remove it.
    CopyInto {
        tmp: PathBuf,
        dst: PathBuf,
        _guard: TempGuard,
    },
}

impl Pending {
    fn tmp(&self) -> &Path {
        match self {
            Pending::Rename { tmp, .. } | Pending::CopyInto { tmp, .. } => tmp,
        }
    }
}

/// Where a command writes: standard output, a device or FIFO, or a file (through a temporary
/// file).
pub struct Output {
    writer: BufWriter<Box<dyn Write>>,
    /// The destination as the user named it, for messages.
    shown: String,
    /// How a file output is completed; `None` for direct writes.
    pending: Option<Pending>,
}

/// What an existing destination is (symbolic links followed).
enum Dest {
    /// Nothing there yet.
    New(PathBuf),
    /// A regular file, with its metadata.
    Regular(PathBuf, Metadata),
    /// A device, FIFO or socket: written directly.
    Direct(PathBuf),
}

fn destination(p: &Path, shown: &str) -> anyhow::Result<Dest> {
    let link = match std::fs::symlink_metadata(p) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Dest::New(p.to_path_buf())),
        Err(e) => bail!("cannot write {shown}: {e}"),
    };
    let (path, meta) = if link.file_type().is_symlink() {
        let meta = match std::fs::metadata(p) {
            Ok(m) => m,
            Err(e) if e.kind() == io::ErrorKind::NotFound => bail!(
                "{shown}: is a symbolic link to a missing file; refused (gonio writes through a \
                 link only to an existing file)"
            ),
            Err(e) => bail!("cannot write {shown}: {e}"),
        };
        // A regular file is replaced through its real path (the temporary file goes next to it);
        // anything else is opened through the link itself (`/dev/stdout` may lead to a pipe,
        // which has no path).
        let path = if meta.is_file() {
            std::fs::canonicalize(p)
                .with_context(|| format!("cannot write {shown}: cannot resolve the link"))?
        } else {
            p.to_path_buf()
        };
        (path, meta)
    } else {
        (p.to_path_buf(), link)
    };
    if let Some(input) = is_input(&meta) {
        bail!("{shown}: is the same file as the input {input}; refused, nothing written");
    }
    if meta.is_dir() {
        bail!("{shown}: is a directory");
    }
    if meta.is_file() {
        Ok(Dest::Regular(path, meta))
    } else {
        Ok(Dest::Direct(path))
    }
}

/// A fresh temporary file next to `dst`, created exclusively (never through an existing name),
/// with permission bits `mode` (before the umask for new files).
fn temporary(dst: &Path, shown: &str, mode: Option<u32>) -> anyhow::Result<(File, PathBuf)> {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let dir = match dst.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let file_name = dst
        .file_name()
        .with_context(|| format!("{shown}: not a file name"))?;
    loop {
        let tmp = dir.join(format!(
            ".{}.gonio-tmp-{}-{}",
            file_name.to_string_lossy(),
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        let mut opts = OpenOptions::new();
        opts.write(true).create_new(true);
        #[cfg(unix)]
        {
            use std::os::unix::fs::OpenOptionsExt;
            opts.mode(0o666);
        }
        match opts.open(&tmp) {
            Ok(f) => {
                #[cfg(unix)]
                if let Some(mode) = mode {
                    use std::os::unix::fs::PermissionsExt;
                    f.set_permissions(std::fs::Permissions::from_mode(mode))
                        .with_context(|| format!("cannot write {shown}"))?;
                }
                #[cfg(not(unix))]
                let _ = mode;
                return Ok((f, tmp));
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e).with_context(|| format!("cannot create {shown}")),
        }
    }
}

fn mode_of(meta: &Metadata) -> Option<u32> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        Some(meta.permissions().mode() & 0o7777)
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        None
    }
}

fn nlink(meta: &Metadata) -> u64 {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        meta.nlink()
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        1
    }
}

/// What identifies a destination for [`check_distinct`]: standard output, an existing file's
/// device and inode, or the canonical folder and name of a file still to be made.
#[derive(Debug, PartialEq, Eq)]
enum Target {
    Stdout,
    #[cfg(unix)]
    Id(u64, u64),
    Path(PathBuf),
}

fn target(p: &Path) -> Target {
    if p.as_os_str() == "-" {
        return Target::Stdout;
    }
    if let Ok(meta) = std::fs::metadata(p) {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            return Target::Id(meta.dev(), meta.ino());
        }
        #[cfg(not(unix))]
        {
            let _ = meta;
            return Target::Path(std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf()));
        }
    }
    // A file to be made: its folder resolved (links, `..`), then its name.
    let parent = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (std::fs::canonicalize(parent), p.file_name()) {
        (Ok(d), Some(name)) => Target::Path(d.join(name)),
        _ => Target::Path(p.to_path_buf()),
    }
}

/// Refuses, before anything is written, a command's outputs that name the same file (or
/// standard output twice) — `gonio bake -o t.png --obj t.png` once wrote the OBJ text over the
/// PNG. Each entry is (the option, the path). Inputs are checked by [`Output::create`], which a
/// command with several outputs calls for all of them before writing any.
pub fn check_distinct(outputs: &[(&str, &Path)]) -> anyhow::Result<()> {
    let targets: Vec<Target> = outputs.iter().map(|(_, p)| target(p)).collect();
    for (i, a) in targets.iter().enumerate() {
        for (j, b) in targets.iter().enumerate().take(i) {
            if a == b {
                bail!(
                    "{} {} and {} {} are the same destination; refused, nothing written",
                    outputs[j].0,
                    outputs[j].1.display(),
                    outputs[i].0,
                    outputs[i].1.display()
                );
            }
        }
    }
    Ok(())
}

impl Output {
    /// Standard output for `None` or `-`; otherwise `path` as described in the module
    /// documentation. Refuses, before anything is written, a path that is an input of this run.
    pub fn create(path: Option<&Path>) -> anyhow::Result<Self> {
        let p = match path {
            None => return Ok(Self::stdout()),
            Some(p) if p.as_os_str() == "-" => return Ok(Self::stdout()),
            Some(p) => p,
        };
        let shown = p.display().to_string();
        let (file, pending) = match destination(p, &shown)? {
            Dest::New(dst) => {
                let (f, tmp) = temporary(&dst, &shown, None)?;
                let guard = register(&tmp);
                (
                    f,
                    Pending::Rename {
                        tmp,
                        dst,
                        _guard: guard,
                    },
                )
            }
            Dest::Regular(dst, meta) => {
                let (f, tmp) = temporary(&dst, &shown, mode_of(&meta))?;
                let guard = register(&tmp);
                let pending = if nlink(&meta) > 1 {
                    Pending::CopyInto {
                        tmp,
                        dst,
                        _guard: guard,
                    }
                } else {
                    Pending::Rename {
                        tmp,
                        dst,
                        _guard: guard,
                    }
                };
                (f, pending)
            }
            Dest::Direct(dst) => {
                let mut opts = OpenOptions::new();
                opts.write(true);
                #[cfg(unix)]
                {
                    use std::os::unix::fs::OpenOptionsExt;
                    opts.custom_flags(libc::O_NOCTTY);
                }
                let f = opts
                    .open(&dst)
                    .with_context(|| format!("cannot write {shown}"))?;
                let meta = f
                    .metadata()
                    .with_context(|| format!("cannot write {shown}"))?;
                if meta.is_file() || meta.is_dir() {
                    bail!(
                        "{shown}: changed into {} while it was opened; refused",
                        kind_of(&meta)
                    );
                }
                return Ok(Output {
                    writer: BufWriter::with_capacity(BUF, Box::new(f)),
                    shown,
                    pending: None,
                });
            }
        };
        Ok(Output {
            writer: BufWriter::with_capacity(BUF, Box::new(file)),
            shown,
            pending: Some(pending),
        })
    }

    fn stdout() -> Self {
        Output {
            writer: BufWriter::with_capacity(BUF, Box::new(io::stdout())),
            shown: "standard output".into(),
            pending: None,
        }
    }

    /// Flushes; for a file output, puts the finished temporary file in place (rename, or a copy
    /// into a hard-linked file).
    pub fn finish(mut self) -> anyhow::Result<()> {
        let shown = self.shown.clone();
        self.flush()?;
        match self.pending.take() {
            None => Ok(()),
            Some(Pending::Rename { tmp, dst, _guard }) => {
                std::fs::rename(&tmp, &dst).map_err(|e| {
                    let _ = std::fs::remove_file(&tmp);
                    anyhow::anyhow!("cannot write {shown}: {e}")
                })
            }
            Some(Pending::CopyInto { tmp, dst, _guard }) => {
                let copied = (|| -> io::Result<()> {
                    let mut from = File::open(&tmp)?;
                    let mut to = OpenOptions::new().write(true).truncate(true).open(&dst)?;
                    io::copy(&mut from, &mut to)?;
                    to.flush()
                })();
                let _ = std::fs::remove_file(&tmp);
                copied.with_context(|| format!("cannot write {shown}"))
            }
        }
    }
}

impl Output {
    /// An I/O error that names the destination (keeping its kind, so a broken pipe is still
    /// recognised).
    fn named(&self, e: io::Error) -> io::Error {
        io::Error::new(e.kind(), format!("cannot write {}: {e}", self.shown))
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.writer.write(buf).map_err(|e| self.named(e))
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.writer.write_all(buf).map_err(|e| self.named(e))
    }
    fn flush(&mut self) -> io::Result<()> {
        self.writer.flush().map_err(|e| self.named(e))
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if let Some(p) = self.pending.take() {
            let _ = std::fs::remove_file(p.tmp());
        }
    }
}

/// Appends the numbers of one CSV row, comma-separated, in the shortest round-trip form (the
/// text reads back to the same `f64`; exponent form for extreme magnitudes,
/// [`gonio::decimal::shortest`]), and a newline.
pub fn push_csv_row(buf: &mut Vec<u8>, values: &[f64]) {
    for (k, v) in values.iter().enumerate() {
        if k > 0 {
            buf.push(b',');
        }
        if *v == 0.0 || (1e-5..1e16).contains(&v.abs()) || !v.is_finite() {
            // Writing into a Vec cannot fail.
            let _ = write!(buf, "{v}");
        } else {
            let _ = write!(buf, "{v:e}");
        }
    }
    buf.push(b'\n');
}

/// Writes `text` to standard output.
pub fn print(text: &str) -> anyhow::Result<()> {
    let mut out = io::stdout().lock();
    out.write_all(text.as_bytes())?;
    out.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::push_csv_row;

    #[test]
    fn huge_and_tiny_numbers_in_exponent_form() {
        let mut buf = Vec::new();
        push_csv_row(&mut buf, &[1e308, f64::MAX, 5e-324, 0.25, 0.0, -3.0, 1e-7]);
        let text = String::from_utf8(buf).unwrap();
        assert_eq!(text, "1e308,1.7976931348623157e308,5e-324,0.25,0,-3,1e-7\n");
        for (field, v) in text.trim().split(',').zip([1e308, f64::MAX, 5e-324]) {
            assert_eq!(field.parse::<f64>().unwrap(), v);
        }
    }
}
