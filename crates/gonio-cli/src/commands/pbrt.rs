//! `gonio convert FILE OUT.exr|OUT.pfm --to pbrt-v4`: the equal-area image that pbrt-v4's
//! `GoniometricLight` reads, and the scene line that uses it.
//!
//! # What pbrt-v4 does with the image
//!
//! pbrt-v4's goniometric light evaluates its intensity in a light-space direction w as the
//! **nearest pixel** of a square single-channel image at `EqualAreaSphereToSquare(w)` — Clarberg's
//! octahedral equal-area map (the inner diamond of the square is the hemisphere z ≥ 0, the four
//! corners fold onto z < 0) — pixel (⌊u·N⌋, ⌊v·N⌋) with y counted from the top row. Its
//! `GoniometricLight::Create` puts a y↔z swap in front of the light's transform, so the image's +z
//! is the light's +y. With `"float power" Φ`, pbrt scales the image so that 4π·mean(pixels) = Φ.
//!
//! # What gonio writes
//!
//! * The image's directions are gonio's frame (θ from +z, φ from +x toward +y): the luminaire's
//!   zenith (γ = 180°) is +z of the image, hence **+y of the pbrt light**, its nadir (γ = 0°) is −y,
//!   the C0 plane is +x and C90 is +z of the pbrt light. pbrt's world is left-handed, so C angles
//!   still run counter-clockwise seen from above, as photometry has them.
//! * Each pixel holds the **average** of the file's intensity (candela; the diagram's own unit for
//!   a JSON diagram) over the pixel's solid angle: the map has constant Jacobian 4π, so the average
//!   over the pixel's square is the average over its solid angle, computed with
//!   [`SUPERSAMPLING`]² stratified points (cell midpoints). The command reports an estimate of the
//!   quadrature error (the largest difference between the [`SUPERSAMPLING`]² and the
//!   (`SUPERSAMPLING`/2)² averages of a pixel) and the image's power against the file's flux.
//! * The printed snippet `LightSource "goniometric" "string filename" "OUT" "float power" Φ` uses
//!   the file's flux Φ in lumens ([`gonio::Diagram::integral`]).
//!
//! EXR: one `Y` channel of 32-bit floats, lossless. PFM: `Pf` (greyscale), little-endian, rows
//! from the bottom up, as the format prescribes (pbrt flips them when reading).

use crate::args::ConvertArgs;
use crate::load::load;
use crate::output::Output;
use anyhow::Context;
use gonio::baselines::equal_area::equal_area_square_to_sphere;
use gonio::sampler::spherical;
use gonio::Diagram;
use rayon::prelude::*;
use std::io::Write;

/// Default image resolution (pixels per side): 512² pixels of 4π/512² ≈ 4.8·10⁻⁵ sr, about
/// 0.4° × 0.4°.
pub const DEFAULT_RESOLUTION: usize = 512;

/// Largest accepted resolution (pixels per side): 8192² f32 pixels are 256 MiB.
pub const MAX_RESOLUTION: usize = 8192;

/// Points per pixel side of the stratified average (so `SUPERSAMPLING`² intensity evaluations per
/// pixel).
pub const SUPERSAMPLING: usize = 8;

/// The image format written, by the output's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// OpenEXR, one `Y` channel of f32.
    Exr,
    /// Portable float map, greyscale (`Pf`).
    Pfm,
}

/// An equal-area octahedral image: `pixels[y * resolution + x]` is pbrt's pixel (x, y), y counted
/// from the top row, covering u ∈ [x/N, (x+1)/N], v ∈ [y/N, (y+1)/N] of the square.
#[derive(Debug, Clone)]
pub struct EqualAreaImage {
    /// Pixels per side N.
    pub resolution: usize,
    /// Average intensity of each pixel, row-major.
    pub pixels: Vec<f32>,
    /// Largest |average with SUPERSAMPLING² points − average with (SUPERSAMPLING/2)² points| over
    /// all pixels: an estimate of the quadrature error of a pixel, in the diagram's unit.
    pub error_estimate: f64,
}

impl EqualAreaImage {
    /// The image's power as pbrt-v4 computes it: 4π · mean of the pixels.
    pub fn power(&self) -> f64 {
        let sum: f64 = self.pixels.iter().map(|&p| f64::from(p)).sum();
        4.0 * std::f64::consts::PI * sum / (self.pixels.len() as f64)
    }
}

/// Renders the equal-area image of `diagram` at `resolution` pixels per side: each pixel the mean
/// of the interpolated diagram over the pixel (see the module documentation). Runs on all rayon
/// threads; the result does not depend on their number.
pub fn render(diagram: &Diagram, resolution: usize) -> EqualAreaImage {
    let n = resolution;
    let rows: Vec<(Vec<f32>, f64)> = (0..n)
        .into_par_iter()
        .map(|y| {
            let mut row = Vec::with_capacity(n);
            let mut err = 0.0f64;
            for x in 0..n {
                let fine = pixel_mean(diagram, n, x, y, SUPERSAMPLING);
                let coarse = pixel_mean(diagram, n, x, y, SUPERSAMPLING / 2);
                err = err.max((fine - coarse).abs());
                row.push(fine as f32);
            }
            (row, err)
        })
        .collect();
    let mut pixels = Vec::with_capacity(n * n);
    let mut error_estimate = 0.0f64;
    for (row, err) in rows {
        pixels.extend_from_slice(&row);
        error_estimate = error_estimate.max(err);
    }
    EqualAreaImage {
        resolution: n,
        pixels,
        error_estimate,
    }
}

/// Mean of the diagram over pixel (x, y) of an N×N image, at the midpoints of s × s strata.
fn pixel_mean(diagram: &Diagram, n: usize, x: usize, y: usize, s: usize) -> f64 {
    let inv = 1.0 / (n * s) as f64;
    let mut sum = 0.0;
    for j in 0..s {
        let v = ((y * s + j) as f64 + 0.5) * inv;
        for i in 0..s {
            let u = ((x * s + i) as f64 + 0.5) * inv;
            let (theta, phi) = spherical(equal_area_square_to_sphere([u, v]));
            sum += diagram.interpolate(theta, phi);
        }
    }
    sum / (s * s) as f64
}

/// The EXR file of an image: one `Y` channel of f32, row 0 at the top.
pub fn encode_exr(image: &EqualAreaImage) -> anyhow::Result<Vec<u8>> {
    use exr::prelude::*;
    let n = image.resolution;
    let pixels = &image.pixels;
    let channels = SpecificChannels::build()
        .with_channel("Y")
        .with_pixel_fn(|p: Vec2<usize>| (pixels[p.y() * n + p.x()],));
    let exr_image = Image::from_channels((n, n), channels);
    let mut buf = std::io::Cursor::new(Vec::new());
    exr_image
        .write()
        .to_buffered(&mut buf)
        .map_err(|e| anyhow::anyhow!("cannot encode the EXR image: {e}"))?;
    Ok(buf.into_inner())
}

/// The PFM file of an image: `Pf`, little-endian (scale −1), rows from the bottom up.
pub fn encode_pfm(image: &EqualAreaImage) -> Vec<u8> {
    let n = image.resolution;
    let mut out = format!("Pf\n{n} {n}\n-1.0\n").into_bytes();
    out.reserve(4 * n * n);
    for y in (0..n).rev() {
        for p in &image.pixels[y * n..(y + 1) * n] {
            out.extend_from_slice(&p.to_le_bytes());
        }
    }
    out
}

/// The image format named by an output path, or an error naming the accepted ones.
pub fn image_format(out_name: &str, ext: Option<&str>) -> anyhow::Result<ImageFormat> {
    match ext {
        Some("exr") => Ok(ImageFormat::Exr),
        Some("pfm") => Ok(ImageFormat::Pfm),
        Some(e) => anyhow::bail!(
            "{out_name}: unknown output format `.{e}` for --to pbrt-v4; expected .exr or .pfm"
        ),
        None => anyhow::bail!(
            "{out_name}: the output name has no extension; --to pbrt-v4 writes .exr or .pfm"
        ),
    }
}

/// `name` as a pbrt string literal (quotes and backslashes escaped).
fn pbrt_string(name: &str) -> String {
    let mut s = String::with_capacity(name.len() + 2);
    s.push('"');
    for c in name.chars() {
        if c == '"' || c == '\\' {
            s.push('\\');
        }
        s.push(c);
    }
    s.push('"');
    s
}

/// Runs `gonio convert IN OUT --to pbrt-v4 [--resolution N]`.
pub fn run(
    a: &ConvertArgs,
    ext: Option<&str>,
    settings: &crate::settings::Settings,
) -> anyhow::Result<()> {
    let out_name = a.output.display().to_string();
    let format = image_format(&out_name, ext)?;
    let resolution = a.resolution.unwrap_or(DEFAULT_RESOLUTION);
    if !(1..=MAX_RESOLUTION).contains(&resolution) {
        anyhow::bail!("--resolution {resolution} is outside 1..={MAX_RESOLUTION}");
    }
    let loaded = load(&a.input, settings)?;
    let flux = loaded.diagram.integral();
    if !(flux.is_finite() && flux > 0.0) {
        anyhow::bail!(
            "{}: the distribution has no positive finite power ({flux}); pbrt-v4 needs one",
            a.input
        );
    }
    let image = render(&loaded.diagram, resolution);
    let bytes = match format {
        ImageFormat::Exr => encode_exr(&image)?,
        ImageFormat::Pfm => encode_pfm(&image),
    };
    let mut out = Output::create(Some(&a.output))?;
    out.write_all(&bytes)
        .with_context(|| format!("cannot write {out_name}"))?;
    out.finish()?;

    let power = image.power();
    let unit = if loaded.kind.is_photometric() {
        ("cd", "lm")
    } else {
        ("(diagram unit)", "(diagram unit)·sr")
    };
    let text = format!(
        "# {input} -> {out_name}: {resolution}x{resolution} equal-area image for pbrt-v4's goniometric light\n\
         # pixels: mean intensity over each pixel's solid angle in {cd} ({s}x{s} points per pixel; \
         quadrature error estimate {err:.3e} {cd})\n\
         # image power 4*pi*mean = {power} {lm}; file flux = {flux} {lm} (ratio {ratio:.6})\n\
         # frame: the luminaire's zenith is +y of the light, nadir -y, C0 along +x, C90 along +z\n\
         LightSource \"goniometric\" \"string filename\" {file} \"float power\" {flux}\n",
        input = a.input,
        cd = unit.0,
        lm = unit.1,
        s = SUPERSAMPLING,
        err = image.error_estimate,
        ratio = power / flux,
        file = pbrt_string(&out_name),
    );
    crate::output::print(&text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_diagram_gives_a_constant_image_of_the_right_power() {
        let d = Diagram::from_degrees(&[0.0, 180.0], &[0.0], &[vec![2.0, 2.0]]).unwrap();
        let img = render(&d, 16);
        assert!(img.pixels.iter().all(|&p| (p - 2.0).abs() < 1e-6));
        let want = 4.0 * std::f64::consts::PI * 2.0;
        assert!((img.power() - want).abs() < 1e-6 * want);
        assert!((d.integral() - want).abs() < 1e-9 * want);
    }

    #[test]
    fn pfm_rows_run_bottom_up() {
        let img = EqualAreaImage {
            resolution: 2,
            pixels: vec![1.0, 2.0, 3.0, 4.0],
            error_estimate: 0.0,
        };
        let b = encode_pfm(&img);
        let header = b"Pf\n2 2\n-1.0\n";
        assert_eq!(&b[..header.len()], header);
        let vals: Vec<f32> = b[header.len()..]
            .chunks(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        assert_eq!(vals, vec![3.0, 4.0, 1.0, 2.0]);
    }

    #[test]
    fn pbrt_strings_are_escaped() {
        assert_eq!(pbrt_string(r#"a"b\c.exr"#), r#""a\"b\\c.exr""#);
    }
}
