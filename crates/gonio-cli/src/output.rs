//! Output destinations and number formatting.
//!
//! An output file is written to a temporary file in the same directory and renamed over the
//! destination only when the command succeeds ([`Output::finish`]), so a failed command never
//! leaves a partial or truncated file behind. `-` (or no `-o`) is standard output.

use anyhow::Context;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Buffer size of every output writer.
const BUF: usize = 1 << 20;

/// Where a command writes: standard output or a file (through a temporary file).
pub struct Output {
    writer: BufWriter<Box<dyn Write>>,
    /// (temporary file, destination) while a file output is not finished.
    pending: Option<(PathBuf, PathBuf)>,
}

impl Output {
    /// Standard output for `None` or `-`, otherwise a temporary file next to `path`.
    pub fn create(path: Option<&Path>) -> anyhow::Result<Self> {
        match path {
            None => Ok(Self::stdout()),
            Some(p) if p.as_os_str() == "-" => Ok(Self::stdout()),
            Some(p) => {
                let dir = match p.parent() {
                    Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                    _ => PathBuf::from("."),
                };
                let file_name = p
                    .file_name()
                    .with_context(|| format!("{}: not a file name", p.display()))?;
                let tmp = dir.join(format!(
                    ".{}.gonio-tmp-{}",
                    file_name.to_string_lossy(),
                    std::process::id()
                ));
                let f =
                    File::create(&tmp).with_context(|| format!("cannot create {}", p.display()))?;
                Ok(Output {
                    writer: BufWriter::with_capacity(BUF, Box::new(f)),
                    pending: Some((tmp, p.to_path_buf())),
                })
            }
        }
    }

    fn stdout() -> Self {
        Output {
            writer: BufWriter::with_capacity(BUF, Box::new(io::stdout())),
            pending: None,
        }
    }

    /// Flushes, and for a file output renames the temporary file onto the destination.
    pub fn finish(mut self) -> anyhow::Result<()> {
        self.writer.flush().map_err(anyhow::Error::new)?;
        if let Some((tmp, dst)) = self.pending.take() {
            std::fs::rename(&tmp, &dst).with_context(|| {
                let _ = std::fs::remove_file(&tmp);
                format!("cannot write {}", dst.display())
            })?;
        }
        Ok(())
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.writer.write(buf)
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.writer.write_all(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.writer.flush()
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if let Some((tmp, _)) = self.pending.take() {
            let _ = std::fs::remove_file(tmp);
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
