//! High-dynamic-range images: the readers of environment maps (Radiance RGBE `.hdr`, PFM,
//! OpenEXR) and small writers for `.hdr` and `.pfm`.
//!
//! Every reader returns an [`Image`]: `width × height` RGB pixels of `f32`, row-major, **row 0 the
//! top of the picture** (as it is displayed), column 0 its left edge, whatever order the file
//! stores them in (a Radiance resolution line `+Y`, a PFM's bottom-to-top rows). Single-channel
//! files (PFM `Pf`, EXR `Y`) give R = G = B. Values are linear, as the file holds them.
//!
//! Hostile input: every reader checks its sizes against [`max_pixels`] and against the bytes
//! present before it allocates, refuses non-finite values, and returns a typed [`ImageError`]
//! that says where (byte offset, header line, scanline) — never a panic. What it repairs (trailing
//! bytes ignored, an alpha channel dropped) is a warning in [`Image::warnings`].

mod hdr;
mod openexr;
mod pfm;
mod write;

pub use hdr::{read_hdr, MAX_PIXELS_PER_BYTE, MIN_UNCHECKED_PIXELS};
pub use openexr::{max_exr_decoded_bytes, read_exr, MAX_EXR_DECODED_BYTES};
pub use pfm::read_pfm;
pub use write::{write_hdr, write_hdr_flat, write_pfm};

use std::path::Path;

/// The default largest number of pixels an image may have: 2²⁷ ≈ 134 million (16384 × 8192, the
/// size of the largest skies HDRI libraries publish), 1.5 GiB of RGB `f32`. Larger images are
/// refused with [`ImageError::BadSize`] before anything is allocated. The limit in force is
/// [`max_pixels`]: this default, the environment variable `GONIO_MAX_PIXELS` when it holds a
/// whole number at the first read, or what [`set_max_pixels`] set.
pub const MAX_PIXELS: usize = 1 << 27;

static PIXEL_LIMIT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// The pixel limit in force (see [`MAX_PIXELS`]).
pub fn max_pixels() -> usize {
    use std::sync::atomic::Ordering::Relaxed;
    match PIXEL_LIMIT.load(Relaxed) {
        0 => {
            let n = std::env::var("GONIO_MAX_PIXELS")
                .ok()
                .and_then(|v| v.trim().parse::<usize>().ok())
                .filter(|&n| n > 0)
                .unwrap_or(MAX_PIXELS);
            // A concurrent `set_max_pixels` wins.
            let _ = PIXEL_LIMIT.compare_exchange(0, n, Relaxed, Relaxed);
            PIXEL_LIMIT.load(Relaxed)
        }
        n => n,
    }
}

/// Sets the pixel limit of every reader from now on (process-wide; at least 1). Returns the
/// previous limit.
pub fn set_max_pixels(limit: usize) -> usize {
    let before = max_pixels();
    PIXEL_LIMIT.store(limit.max(1), std::sync::atomic::Ordering::Relaxed);
    before
}

/// Largest width or height accepted on either axis.
pub const MAX_SIDE: usize = 1 << 16;

/// The file formats the readers know.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// Radiance RGBE (`.hdr`, `.pic`).
    Hdr,
    /// Portable float map (`.pfm`).
    Pfm,
    /// OpenEXR (`.exr`).
    Exr,
}

impl ImageFormat {
    /// The format a file name's extension names (`hdr`/`pic`, `pfm`, `exr`, any letter case).
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "hdr" | "pic" | "rgbe" => Some(Self::Hdr),
            "pfm" => Some(Self::Pfm),
            "exr" => Some(Self::Exr),
            _ => None,
        }
    }

    /// The format the first bytes announce (`#?` Radiance, `PF`/`Pf` PFM, the OpenEXR magic
    /// number 76 2f 31 01).
    pub fn sniff(bytes: &[u8]) -> Option<Self> {
        if bytes.starts_with(b"#?") {
            Some(Self::Hdr)
        } else if bytes.starts_with(b"PF") || bytes.starts_with(b"Pf") {
            Some(Self::Pfm)
        } else if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
            Some(Self::Exr)
        } else {
            None
        }
    }

    /// Short name, as messages print it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Hdr => "Radiance HDR",
            Self::Pfm => "PFM",
            Self::Exr => "OpenEXR",
        }
    }
}

/// Why an image could not be read. Byte offsets are zero-based from the start of the file; header
/// lines are 1-based; scanlines are counted in file order from 0.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImageError {
    /// The file was not read (not a regular file, over the image limit, missing: the one file
    /// reader's message, [`crate::input::file`]).
    #[error(transparent)]
    File(#[from] crate::input::file::ReadFileError),
    /// Neither the extension nor the first bytes name a known format.
    #[error("not a Radiance .hdr, PFM or OpenEXR file (first bytes {first:02x?})")]
    UnknownFormat {
        /// Up to the first four bytes.
        first: Vec<u8>,
    },
    /// The header is malformed.
    #[error("{format} header, line {line}, column {column} (byte {offset}): {message}")]
    Header {
        /// The format being read.
        format: &'static str,
        /// 1-based header line (for PFM: the token's line).
        line: usize,
        /// 1-based column of `offset` in its line (in bytes).
        column: usize,
        /// Byte offset where the problem was found.
        offset: usize,
        /// What is wrong.
        message: String,
    },
    /// The file uses a variant the reader does not support (e.g. Radiance XYZE).
    #[error("{format}: unsupported: {message}")]
    Unsupported {
        /// The format being read.
        format: &'static str,
        /// What is not supported.
        message: String,
    },
    /// The image's size is zero or too large.
    #[error("{format}: image of {width} × {height} pixels: {message}")]
    BadSize {
        /// The format being read.
        format: &'static str,
        /// Width given.
        width: usize,
        /// Height given.
        height: usize,
        /// Why it was refused.
        message: String,
    },
    /// The pixel data ends before the image does.
    #[error("{format}: the file ends at byte {present} but {what} needs {needed} bytes (scanline {row})")]
    Truncated {
        /// The format being read.
        format: &'static str,
        /// What was being read.
        what: &'static str,
        /// Bytes needed (the offset the data would have to reach).
        needed: usize,
        /// Bytes present in the file.
        present: usize,
        /// The scanline (file order) being read.
        row: usize,
    },
    /// A run-length encoded scanline is malformed.
    #[error("{format}: scanline {row} (byte {offset}): {message}")]
    Scanline {
        /// The format being read.
        format: &'static str,
        /// Scanline in file order.
        row: usize,
        /// Byte offset of the bad code.
        offset: usize,
        /// What is wrong.
        message: String,
    },
    /// A pixel holds NaN or an infinity.
    #[error(
        "{format}: pixel (x {x}, y {y} from the top), channel {channel}, is not finite ({value})"
    )]
    NonFinite {
        /// The format being read.
        format: &'static str,
        /// Column.
        x: usize,
        /// Row from the top.
        y: usize,
        /// Channel index 0..3 (R, G, B).
        channel: usize,
        /// The value.
        value: f32,
    },
    /// The OpenEXR decoder refused the file.
    #[error("OpenEXR: {message}")]
    Exr {
        /// What the `exr` crate said.
        message: String,
    },
}

/// An RGB image of `f32`, row 0 at the top. See the [module documentation](self).
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    width: usize,
    height: usize,
    rgb: Vec<f32>,
    warnings: Vec<String>,
}

/// The header error of `format` at 1-based `line` and byte `offset` of `bytes` (its column
/// found there).
pub(crate) fn header_error(
    format: &'static str,
    bytes: &[u8],
    line: usize,
    offset: usize,
    message: String,
) -> ImageError {
    ImageError::Header {
        format,
        line,
        column: column_of(bytes, offset),
        offset,
        message,
    }
}

/// The 1-based column (in bytes) of `offset` in its line of `bytes` (a header's location).
pub(crate) fn column_of(bytes: &[u8], offset: usize) -> usize {
    let offset = offset.min(bytes.len());
    offset
        - bytes[..offset]
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |k| k + 1)
        + 1
}

impl Image {
    /// An image from `width × height` RGB triples, row-major, row 0 at the top.
    ///
    /// # Errors
    /// [`ImageError::BadSize`] for an empty or too large image or a buffer of the wrong length;
    /// [`ImageError::NonFinite`] for NaN or infinite values.
    pub fn new(width: usize, height: usize, rgb: Vec<f32>) -> Result<Self, ImageError> {
        check_size("image", width, height)?;
        if rgb.len() != width * height * 3 {
            return Err(ImageError::BadSize {
                format: "image",
                width,
                height,
                message: format!("{} values given, {} needed", rgb.len(), width * height * 3),
            });
        }
        let img = Self {
            width,
            height,
            rgb,
            warnings: Vec::new(),
        };
        img.check_finite("image")?;
        Ok(img)
    }

    /// A `width × height` image of one constant colour.
    ///
    /// # Errors
    /// As [`Image::new`].
    pub fn constant(width: usize, height: usize, rgb: [f32; 3]) -> Result<Self, ImageError> {
        check_size("image", width, height)?;
        Self::new(width, height, rgb.repeat(width * height))
    }

    /// Width in pixels (columns).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels (rows).
    pub fn height(&self) -> usize {
        self.height
    }

    /// The RGB triples, row-major, row 0 at the top.
    pub fn rgb(&self) -> &[f32] {
        &self.rgb
    }

    /// The pixel at column `x`, row `y` from the top.
    ///
    /// # Panics
    /// If `x ≥ width` or `y ≥ height` (a programming error).
    pub fn pixel(&self, x: usize, y: usize) -> [f32; 3] {
        assert!(x < self.width && y < self.height, "pixel out of range");
        let k = 3 * (y * self.width + x);
        [self.rgb[k], self.rgb[k + 1], self.rgb[k + 2]]
    }

    /// Sets the pixel at column `x`, row `y` from the top (for generated images).
    ///
    /// # Panics
    /// If the pixel is out of range or a value is not finite (programming errors).
    pub fn set_pixel(&mut self, x: usize, y: usize, rgb: [f32; 3]) {
        assert!(x < self.width && y < self.height, "pixel out of range");
        assert!(
            rgb.iter().all(|v| v.is_finite()),
            "pixel values must be finite"
        );
        let k = 3 * (y * self.width + x);
        self.rgb[k..k + 3].copy_from_slice(&rgb);
    }

    /// What the reader repaired or ignored (e.g. trailing bytes), one sentence each.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Bytes held by the pixels.
    pub fn memory_bytes(&self) -> usize {
        self.rgb.len() * std::mem::size_of::<f32>()
    }

    pub(crate) fn from_parts(
        width: usize,
        height: usize,
        rgb: Vec<f32>,
        warnings: Vec<String>,
    ) -> Self {
        debug_assert_eq!(rgb.len(), width * height * 3);
        Self {
            width,
            height,
            rgb,
            warnings,
        }
    }

    pub(crate) fn check_finite(&self, format: &'static str) -> Result<(), ImageError> {
        match self.rgb.iter().position(|v| !v.is_finite()) {
            None => Ok(()),
            Some(k) => Err(ImageError::NonFinite {
                format,
                x: (k / 3) % self.width,
                y: k / 3 / self.width,
                channel: k % 3,
                value: self.rgb[k],
            }),
        }
    }

    /// Reads an image file, the format chosen by its first bytes (else by its extension).
    ///
    /// # Errors
    /// [`ImageError::File`] if the file cannot be read, [`ImageError::UnknownFormat`], or the
    /// reader's error.
    pub fn read(path: &Path) -> Result<Self, ImageError> {
        let bytes = crate::input::file::read_file(path, crate::input::file::FileKind::Image)?;
        let format = ImageFormat::sniff(&bytes).or_else(|| ImageFormat::from_path(path));
        Self::from_bytes(&bytes, format)
    }

    /// Decodes the bytes of an image file in `format`, or in the format its first bytes announce
    /// when `format` is `None`.
    ///
    /// # Errors
    /// [`ImageError::UnknownFormat`] or the reader's error.
    pub fn from_bytes(bytes: &[u8], format: Option<ImageFormat>) -> Result<Self, ImageError> {
        match format.or_else(|| ImageFormat::sniff(bytes)) {
            Some(ImageFormat::Hdr) => read_hdr(bytes),
            Some(ImageFormat::Pfm) => read_pfm(bytes),
            Some(ImageFormat::Exr) => read_exr(bytes),
            None => Err(ImageError::UnknownFormat {
                first: bytes.iter().take(4).copied().collect(),
            }),
        }
    }
}

/// Refuses empty and too large sizes (before any allocation).
pub(crate) fn check_size(
    format: &'static str,
    width: usize,
    height: usize,
) -> Result<(), ImageError> {
    let bad = |message: String| ImageError::BadSize {
        format,
        width,
        height,
        message,
    };
    if width == 0 || height == 0 {
        return Err(bad("an image needs at least one pixel on each side".into()));
    }
    if width > MAX_SIDE || height > MAX_SIDE {
        return Err(bad(format!("a side exceeds the limit of {MAX_SIDE}")));
    }
    match width.checked_mul(height) {
        Some(n) if n <= max_pixels() => Ok(()),
        _ => Err(bad(format!(
            "more than the limit of {} pixels (GONIO_MAX_PIXELS or image::set_max_pixels raise it)",
            max_pixels()
        ))),
    }
}

#[cfg(test)]
mod tests;
