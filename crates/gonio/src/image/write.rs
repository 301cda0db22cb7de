//! Writers for `.hdr` (run-length or flat scanlines) and `.pfm`, for generated maps, tests and
//! the CLI's conversions.

use super::Image;

/// The RGBE encoding of a linear RGB value: the largest component v is written as
/// mantissa·2^(e − 136) with the mantissa in 128..=255 (rounded down, so the decoded value never
/// exceeds the input); values below 2^−128 are black, negative values are written as 0.
pub fn f32_to_rgbe(rgb: [f32; 3]) -> [u8; 4] {
    let c = rgb.map(|v| if v > 0.0 { f64::from(v) } else { 0.0 });
    let m = c[0].max(c[1]).max(c[2]);
    if !(m >= 2f64.powi(-128)) {
        return [0; 4];
    }
    // The exponent e with 128 ≤ m·2^(136 − e) < 256.
    let mut e = m.log2().floor() as i32 + 129;
    let mant = |e: i32| m * 2f64.powi(136 - e);
    while mant(e) >= 256.0 {
        e += 1;
    }
    while mant(e) < 128.0 {
        e -= 1;
    }
    let e = e.clamp(1, 255);
    let f = 2f64.powi(136 - e);
    let q = |v: f64| (v * f).floor().min(255.0) as u8;
    [q(c[0]), q(c[1]), q(c[2]), e as u8]
}

fn header(img: &Image) -> Vec<u8> {
    format!(
        "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {} +X {}\n",
        img.height(),
        img.width()
    )
    .into_bytes()
}

/// The bytes of a Radiance `.hdr` file with flat scanlines (4 bytes per pixel), `-Y H +X W`.
pub fn write_hdr_flat(img: &Image) -> Vec<u8> {
    let mut out = header(img);
    for p in img.rgb().chunks_exact(3) {
        out.extend_from_slice(&f32_to_rgbe([p[0], p[1], p[2]]));
    }
    out
}

/// The bytes of a Radiance `.hdr` file with new-style run-length scanlines (flat ones where the
/// width is outside 8..=32767, as the format requires), `-Y H +X W`.
pub fn write_hdr(img: &Image) -> Vec<u8> {
    let w = img.width();
    if !(8..=0x7fff).contains(&w) {
        return write_hdr_flat(img);
    }
    let mut out = header(img);
    let mut comp = vec![0u8; w];
    for row in img.rgb().chunks_exact(3 * w) {
        let px: Vec<[u8; 4]> = row
            .chunks_exact(3)
            .map(|p| f32_to_rgbe([p[0], p[1], p[2]]))
            .collect();
        out.extend_from_slice(&[2, 2, (w >> 8) as u8, (w & 0xff) as u8]);
        for ch in 0..4 {
            for (c, p) in comp.iter_mut().zip(&px) {
                *c = p[ch];
            }
            encode_runs(&comp, &mut out);
        }
    }
    out
}

/// Run-length codes of one component: runs of 3 or more equal bytes (up to 127) as c > 128,
/// the rest as literals of up to 128 bytes.
fn encode_runs(data: &[u8], out: &mut Vec<u8>) {
    let mut i = 0;
    let mut lit_start = 0;
    let flush = |out: &mut Vec<u8>, from: usize, to: usize| {
        let mut a = from;
        while a < to {
            let n = (to - a).min(128);
            out.push(n as u8);
            out.extend_from_slice(&data[a..a + n]);
            a += n;
        }
    };
    while i < data.len() {
        let mut run = 1;
        while i + run < data.len() && data[i + run] == data[i] && run < 127 {
            run += 1;
        }
        if run >= 3 {
            flush(out, lit_start, i);
            out.push(128 + run as u8);
            out.push(data[i]);
            i += run;
            lit_start = i;
        } else {
            i += run;
        }
    }
    flush(out, lit_start, data.len());
}

/// The bytes of a PFM file: `PF` (RGB), or `Pf` (the first channel only) when `grey`; rows bottom
/// to top; little-endian (scale −1) unless `big_endian` (scale 1).
pub fn write_pfm(img: &Image, grey: bool, big_endian: bool) -> Vec<u8> {
    let (w, h) = (img.width(), img.height());
    let mut out = format!(
        "{}\n{w} {h}\n{}\n",
        if grey { "Pf" } else { "PF" },
        if big_endian { "1.0" } else { "-1.0" }
    )
    .into_bytes();
    for y in (0..h).rev() {
        for x in 0..w {
            let p = img.pixel(x, y);
            let vals: &[f32] = if grey { &p[..1] } else { &p[..] };
            for v in vals {
                out.extend_from_slice(&if big_endian {
                    v.to_be_bytes()
                } else {
                    v.to_le_bytes()
                });
            }
        }
    }
    out
}
