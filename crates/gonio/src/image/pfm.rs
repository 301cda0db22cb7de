//! Portable float map (`.pfm`) reader.
//!
//! Header: `PF` (RGB) or `Pf` (greyscale), the width, the height and the scale, separated by
//! white space, then **exactly one** white-space byte (usually a newline) before the data. A
//! negative scale means little-endian floats, a positive one big-endian; its absolute value
//! multiplies every value (as pbrt-v4's reader does; a scale of 1 or −1, by far the most common,
//! changes nothing). Rows are stored **bottom to top**; the [`Image`] has them top to bottom.
//! The byte count width × height × channels × 4 is checked against the bytes present before
//! anything is allocated; bytes after the data are ignored with a warning.

use super::{check_size, Image, ImageError};

const FORMAT: &str = "PFM";

/// Reads a PFM image from the bytes of a `.pfm` file.
///
/// # Errors
/// A typed [`ImageError`] naming the header line and byte offset, or the row that is short.
pub fn read_pfm(bytes: &[u8]) -> Result<Image, ImageError> {
    let mut pos = 0usize;
    let mut line = 1usize;
    let header_err = |line: usize, offset: usize, message: String| {
        super::header_error(FORMAT, bytes, line, offset, message)
    };
    let token =
        |pos: &mut usize, line: &mut usize, what: &str| -> Result<(usize, String), ImageError> {
            while *pos < bytes.len() && bytes[*pos].is_ascii_whitespace() {
                if bytes[*pos] == b'\n' {
                    *line += 1;
                }
                *pos += 1;
            }
            let start = *pos;
            while *pos < bytes.len() && !bytes[*pos].is_ascii_whitespace() && *pos - start < 64 {
                *pos += 1;
            }
            if *pos < bytes.len() && !bytes[*pos].is_ascii_whitespace() {
                return Err(header_err(
                    *line,
                    start,
                    format!("the {what} is longer than 64 characters"),
                ));
            }
            if start == *pos || *pos >= bytes.len() {
                return Err(header_err(
                    *line,
                    start,
                    format!("the file ends before the {what}"),
                ));
            }
            Ok((
                start,
                String::from_utf8_lossy(&bytes[start..*pos]).into_owned(),
            ))
        };
    let (off, magic) = token(&mut pos, &mut line, "magic PF or Pf")?;
    let channels = match magic.as_str() {
        "PF" => 3,
        "Pf" => 1,
        _ => {
            return Err(header_err(
                line,
                off,
                format!("a PFM file begins with PF or Pf, found {magic:?}"),
            ))
        }
    };
    let mut number = |what: &str| -> Result<usize, ImageError> {
        let (off, t) = token(&mut pos, &mut line, what)?;
        t.parse::<usize>()
            .map_err(|_| header_err(line, off, format!("the {what} {t:?} is not a whole number")))
    };
    let width = number("width")?;
    let height = number("height")?;
    let (off, scale_text) = token(&mut pos, &mut line, "scale")?;
    let scale: f32 = scale_text.parse().map_err(|_| {
        header_err(
            line,
            off,
            format!("the scale {scale_text:?} is not a number"),
        )
    })?;
    if !(scale.is_finite() && scale != 0.0) {
        return Err(header_err(
            line,
            off,
            format!("the scale must be a finite non-zero number (its sign gives the byte order), found {scale_text}"),
        ));
    }
    // `token` stopped on a white-space byte (it is not at the end): exactly that one byte follows.
    // A `\r\n` (a header written on Windows) is two bytes: taken as one separator only when the
    // byte count says so (the file is then exactly one byte longer than the data needs), refused
    // when it is ambiguous, so the data is never read one byte off in silence.
    let sep_at = pos;
    pos += 1;
    check_size(FORMAT, width, height)?;
    let row_bytes = width * channels * 4;
    let mut needed = pos + height * row_bytes;
    let mut warnings = Vec::new();
    if bytes[sep_at] == b'\r' && bytes.get(pos) == Some(&b'\n') && bytes.len() > needed {
        if bytes.len() == needed + 1 {
            pos += 1;
            needed += 1;
            warnings.push(format!(
                "the header ends with \"\\r\\n\" (bytes {sep_at}-{pos}) where the format has one \
                 white-space byte; both were taken as the separator, as the file length says"
            ));
        } else {
            return Err(header_err(
                line,
                sep_at,
                format!(
                    "the scale is followed by \"\\r\\n\" (byte {sep_at}) where the format has \
                     exactly one white-space byte, and the file length ({} bytes, {} after the \
                     pixel data) does not say whether the \"\\n\" is data",
                    bytes.len(),
                    bytes.len() - needed
                ),
            ));
        }
    }
    if bytes.len() < needed {
        return Err(ImageError::Truncated {
            format: FORMAT,
            what: "the pixel data",
            needed,
            present: bytes.len(),
            row: (bytes.len().saturating_sub(pos)) / row_bytes,
        });
    }
    let little = scale < 0.0;
    let mul = scale.abs();
    let mut rgb = vec![0f32; width * height * 3];
    for file_row in 0..height {
        let y = height - 1 - file_row;
        let src = &bytes[pos + file_row * row_bytes..pos + (file_row + 1) * row_bytes];
        for x in 0..width {
            for c in 0..3 {
                let k = if channels == 3 { 3 * x + c } else { x };
                let b = [src[4 * k], src[4 * k + 1], src[4 * k + 2], src[4 * k + 3]];
                let v = if little {
                    f32::from_le_bytes(b)
                } else {
                    f32::from_be_bytes(b)
                };
                rgb[3 * (y * width + x) + c] = v * mul;
            }
        }
    }
    if bytes.len() > needed {
        warnings.push(format!(
            "{} bytes after the pixel data (from byte {needed}) were ignored",
            bytes.len() - needed
        ));
    }
    let img = Image::from_parts(width, height, rgb, warnings);
    img.check_finite(FORMAT)?;
    Ok(img)
}
