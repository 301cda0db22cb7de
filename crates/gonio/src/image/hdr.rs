//! Radiance RGBE (`.hdr`) reader.
//!
//! * Header: a first line beginning `#?` (`#?RADIANCE`, `#?RGBE`), variable lines up to an empty
//!   line; `FORMAT=32-bit_rle_rgbe` (or no FORMAT line) is read, `32-bit_rle_xyze` is refused as
//!   unsupported. Other variables (`EXPOSURE`, `GAMMA`, `PRIMARIES`, comments) are ignored, as
//!   pbrt-v4 and Mitsuba 3 ignore them: values are the file's.
//! * Resolution line: `±A n ±B m`, A ≠ B ∈ {X, Y}. The first axis is the slow one (n scanlines of
//!   m pixels). `-Y` runs from the top row down, `+Y` from the bottom up, `+X` from the left,
//!   `-X` from the right; an X-first line stores columns as scanlines. All eight orientations
//!   are read into the same top-to-bottom, left-to-right [`Image`].
//! * Scanlines, each either **new-style run-length** (bytes 2, 2, then the length, for lengths
//!   8..=32767; then each of the four components as runs: a count c > 128 repeats the next byte
//!   c − 128 times, 0 < c ≤ 128 copies c bytes) or **flat / old-style** (4 bytes per pixel, where
//!   a pixel 1, 1, 1, n repeats the previous pixel n·256^k times, k counting consecutive repeat
//!   pixels), decided per scanline as Radiance's `freadcolrs` does.
//! * Conversion: e = 0 is black, else each component is c·2^(e − 136) (no +0.5 offset, as the
//!   readers of pbrt-v4 and Mitsuba 3 do), exact in `f32`.
//!
//! Every scanline takes at least 4 bytes, so the pixel buffer is allocated only once the file
//! holds at least 4 bytes per scanline after the header, and an image of more than 2²⁰ pixels
//! must not declare more than [`MAX_PIXELS_PER_BYTE`] pixels per byte of scanline data; a run that passes the end of its
//! scanline, a zero count, a repeat with no previous pixel and a length that disagrees with the
//! resolution line are errors with their scanline and byte offset.

use super::{check_size, Image, ImageError};

const FORMAT: &str = "Radiance HDR";

/// The most pixels a byte of scanline data may declare: twice what new-style run-length encoding
/// can pack (127 pixels in 8 bytes); images of at most [`MIN_UNCHECKED_PIXELS`] are not checked.
pub const MAX_PIXELS_PER_BYTE: usize = 32;

/// Images of at most 2²⁰ pixels (12 MiB of `f32` RGB) are read whatever their compression.
pub const MIN_UNCHECKED_PIXELS: usize = 1 << 20;

/// Reads a Radiance RGBE image from the bytes of a `.hdr` file.
///
/// # Errors
/// A typed [`ImageError`] naming the header line or the scanline and byte offset.
pub fn read_hdr(bytes: &[u8]) -> Result<Image, ImageError> {
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let header_err = |line: usize, offset: usize, message: String| {
        super::header_error(FORMAT, bytes, line, offset, message)
    };
    let next_line = |pos: &mut usize, line_no: &mut usize| -> Result<(usize, String), ImageError> {
        let start = *pos;
        *line_no += 1;
        match bytes[start..].iter().position(|&b| b == b'\n') {
            Some(k) => {
                *pos = start + k + 1;
                let raw = &bytes[start..start + k];
                let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
                Ok((start, String::from_utf8_lossy(raw).into_owned()))
            }
            None => Err(ImageError::Header {
                format: FORMAT,
                line: *line_no,
                column: super::column_of(bytes, start),
                offset: start,
                message: "the file ends inside the header (no empty line and resolution line)"
                    .into(),
            }),
        }
    };
    let (off, first) = next_line(&mut pos, &mut line_no)?;
    if !first.starts_with("#?") {
        return Err(header_err(
            line_no,
            off,
            "a Radiance file begins with \"#?\" (e.g. #?RADIANCE)".into(),
        ));
    }
    loop {
        let (off, line) = next_line(&mut pos, &mut line_no)?;
        if line.trim().is_empty() {
            break;
        }
        if let Some(f) = line.strip_prefix("FORMAT=") {
            let f = f.trim();
            if f == "32-bit_rle_xyze" {
                return Err(ImageError::Unsupported {
                    format: FORMAT,
                    message: format!("pixel format {f} (only 32-bit_rle_rgbe is read)"),
                });
            }
            if f != "32-bit_rle_rgbe" {
                return Err(header_err(
                    line_no,
                    off,
                    format!("unknown pixel format {f:?} (expected 32-bit_rle_rgbe)"),
                ));
            }
        }
    }
    let (off, res) = next_line(&mut pos, &mut line_no)?;
    let orient = parse_resolution(&res).map_err(|(at, m)| header_err(line_no, off + at, m))?;
    let (width, height) = orient.size();
    check_size(FORMAT, width, height)?;
    let (slow, fast) = (orient.slow.count, orient.fast.count);
    let present = bytes.len();
    let min_needed = pos.saturating_add(slow.saturating_mul(4));
    if present < min_needed {
        return Err(ImageError::Truncated {
            format: FORMAT,
            what: "the scanlines (at least 4 bytes each)",
            needed: min_needed,
            present,
            row: (present.saturating_sub(pos)) / 4,
        });
    }
    // Plausibility of the declared size against the bytes present, before allocating: new-style
    // run-length packs at most 127 pixels of one component into 2 bytes (15.9 pixels a byte); only
    // the obsolete old-style repeat codes pack more (a 786 KB file of one pixel and two repeat
    // codes per scanline once declared 33.5 million pixels, 402 MB of pixels and 2.4 GB in `info`).
    let data = present - pos;
    let plausible = data
        .saturating_mul(MAX_PIXELS_PER_BYTE)
        .max(MIN_UNCHECKED_PIXELS);
    if width * height > plausible {
        return Err(header_err(
            line_no,
            off,
            format!(
                "{width} × {height} pixels from {data} bytes of scanlines is more than \
                 {MAX_PIXELS_PER_BYTE} pixels a byte (run-length encoding packs at most 15.9): \
                 refused as implausible before allocating {} bytes",
                (width * height).saturating_mul(12)
            ),
        ));
    }
    let mut rgb = vec![0f32; width * height * 3];
    let mut line = vec![[0u8; 4]; fast];
    for s in 0..slow {
        read_scanline(bytes, &mut pos, &mut line, s)?;
        for (k, px) in line.iter().enumerate() {
            let (x, y) = orient.place(s, k);
            let dst = 3 * (y * width + x);
            rgb[dst..dst + 3].copy_from_slice(&rgbe_to_f32(*px));
        }
    }
    let mut warnings = Vec::new();
    if pos < present {
        warnings.push(format!(
            "{} bytes after the last scanline (from byte {pos}) were ignored",
            present - pos
        ));
    }
    Ok(Image::from_parts(width, height, rgb, warnings))
}

/// Converts one RGBE pixel to linear RGB: c·2^(e − 136), exactly.
#[inline]
pub(crate) fn rgbe_to_f32(p: [u8; 4]) -> [f32; 3] {
    if p[3] == 0 {
        return [0.0; 3];
    }
    let f = 2f64.powi(i32::from(p[3]) - 136);
    [
        (f64::from(p[0]) * f) as f32,
        (f64::from(p[1]) * f) as f32,
        (f64::from(p[2]) * f) as f32,
    ]
}

#[derive(Debug, Clone, Copy)]
struct Axis {
    /// `true` for X, `false` for Y.
    is_x: bool,
    /// `+` sign.
    plus: bool,
    count: usize,
}

#[derive(Debug, Clone, Copy)]
struct Orientation {
    slow: Axis,
    fast: Axis,
}

impl Orientation {
    fn size(&self) -> (usize, usize) {
        if self.slow.is_x {
            (self.slow.count, self.fast.count)
        } else {
            (self.fast.count, self.slow.count)
        }
    }

    /// Image (x, y from the top) of pixel k of scanline s.
    #[inline]
    fn place(&self, s: usize, k: usize) -> (usize, usize) {
        // Along X, + runs left to right; along Y (Radiance's Y points up), - runs top to bottom.
        let coord = |a: Axis, i: usize| {
            if a.is_x == a.plus {
                i
            } else {
                a.count - 1 - i
            }
        };
        let (a, b) = (coord(self.slow, s), coord(self.fast, k));
        if self.slow.is_x {
            (a, b)
        } else {
            (b, a)
        }
    }
}

/// The resolution line; an error says where in `text` (a byte index) and what.
fn parse_resolution(text: &str) -> Result<Orientation, (usize, String)> {
    let t: Vec<&str> = text.split_ascii_whitespace().collect();
    // The byte index of a token of `text`.
    let at = |tok: &str| tok.as_ptr() as usize - text.as_ptr() as usize;
    let bad = |i: usize| {
        (
            i,
            format!("expected a resolution line such as \"-Y 512 +X 1024\", found {text:?}"),
        )
    };
    if t.len() != 4 {
        return Err(bad(0));
    }
    let axis = |sign: &str, n: &str| -> Result<Axis, (usize, String)> {
        let b = sign.as_bytes();
        if b.len() != 2 || !(b[0] == b'+' || b[0] == b'-') || !(b[1] == b'X' || b[1] == b'Y') {
            return Err(bad(at(sign)));
        }
        let count: usize = n
            .parse()
            .map_err(|_| (at(n), format!("{n:?} is not a pixel count (in {text:?})")))?;
        Ok(Axis {
            is_x: b[1] == b'X',
            plus: b[0] == b'+',
            count,
        })
    };
    let slow = axis(t[0], t[1])?;
    let fast = axis(t[2], t[3])?;
    if slow.is_x == fast.is_x {
        return Err((at(t[2]), format!("both axes of {text:?} are the same")));
    }
    if slow.count == 0 || fast.count == 0 {
        let z = if slow.count == 0 { t[1] } else { t[3] };
        return Err((at(z), format!("a side of {text:?} is zero")));
    }
    Ok(Orientation { slow, fast })
}

fn truncated(needed: usize, present: usize, row: usize) -> ImageError {
    ImageError::Truncated {
        format: FORMAT,
        what: "the scanline",
        needed,
        present,
        row,
    }
}

/// Reads scanline `row` at `*pos` into `line` (its length is the scanline's).
fn read_scanline(
    bytes: &[u8],
    pos: &mut usize,
    line: &mut [[u8; 4]],
    row: usize,
) -> Result<(), ImageError> {
    let len = line.len();
    let p = *pos;
    let scan_err = |offset: usize, message: String| ImageError::Scanline {
        format: FORMAT,
        row,
        offset,
        message,
    };
    let new_style = (8..=0x7fff).contains(&len)
        && p + 4 <= bytes.len()
        && bytes[p] == 2
        && bytes[p + 1] == 2
        && bytes[p + 2] & 0x80 == 0;
    if new_style {
        let w = (usize::from(bytes[p + 2]) << 8) | usize::from(bytes[p + 3]);
        if w != len {
            return Err(scan_err(
                p,
                format!("run-length scanline of {w} pixels, but the resolution line says {len}"),
            ));
        }
        let mut q = p + 4;
        for ch in 0..4 {
            let mut i = 0;
            while i < len {
                let Some(&c) = bytes.get(q) else {
                    return Err(truncated(q + 1, bytes.len(), row));
                };
                let at = q;
                q += 1;
                if c > 128 {
                    let n = usize::from(c - 128);
                    let Some(&v) = bytes.get(q) else {
                        return Err(truncated(q + 1, bytes.len(), row));
                    };
                    q += 1;
                    if i + n > len {
                        return Err(scan_err(
                            at,
                            format!("a run of {n} passes the end of the scanline (component {ch}, pixel {i} of {len})"),
                        ));
                    }
                    for px in &mut line[i..i + n] {
                        px[ch] = v;
                    }
                    i += n;
                } else {
                    let n = usize::from(c);
                    if n == 0 {
                        return Err(scan_err(
                            at,
                            format!("a zero-length literal (component {ch}, pixel {i})"),
                        ));
                    }
                    if i + n > len {
                        return Err(scan_err(
                            at,
                            format!("{n} literal bytes pass the end of the scanline (component {ch}, pixel {i} of {len})"),
                        ));
                    }
                    if q + n > bytes.len() {
                        return Err(truncated(q + n, bytes.len(), row));
                    }
                    for (px, &v) in line[i..i + n].iter_mut().zip(&bytes[q..q + n]) {
                        px[ch] = v;
                    }
                    q += n;
                    i += n;
                }
            }
        }
        *pos = q;
        return Ok(());
    }
    // Flat or old-style run-length pixels.
    let mut q = p;
    let mut i = 0;
    let mut shift = 0u32;
    while i < len {
        if q + 4 > bytes.len() {
            return Err(truncated(q + 4, bytes.len(), row));
        }
        let px = [bytes[q], bytes[q + 1], bytes[q + 2], bytes[q + 3]];
        let at = q;
        q += 4;
        if px[0] == 1 && px[1] == 1 && px[2] == 1 {
            if i == 0 {
                return Err(scan_err(
                    at,
                    "an old-style repeat code with no pixel before it".into(),
                ));
            }
            if shift > 24 {
                return Err(scan_err(
                    at,
                    "more than four consecutive old-style repeat codes".into(),
                ));
            }
            let n = usize::from(px[3]) << shift;
            if i + n > len {
                return Err(scan_err(
                    at,
                    format!("an old-style repeat of {n} pixels passes the end of the scanline (pixel {i} of {len})"),
                ));
            }
            let prev = line[i - 1];
            for d in &mut line[i..i + n] {
                *d = prev;
            }
            i += n;
            shift += 8;
        } else {
            line[i] = px;
            i += 1;
            shift = 0;
        }
    }
    *pos = q;
    Ok(())
}
