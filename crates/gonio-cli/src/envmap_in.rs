//! Environment-map input (`.hdr`, `.exr`, `.pfm` lat-long images) for every command, and its
//! pbrt-v4 export.
//!
//! The image is read by [`gonio::image`], its luminance becomes the diagram of an
//! [`gonio::envmap::EnvironmentMap`] (frame: θ from +z with the image's top row at the zenith, the
//! image's centre column along +x; see the library's `envmap` documentation), and every command
//! works on that diagram as on any other: `info`, `sample` (which adds the radiance columns
//! `r,g,b`), `pdf`, `invert`, `check`, `plot`, `bench`. The diagram's values are luminance in the
//! image's unit, so powers are in that unit × sr.

use crate::args::ConvertArgs;
use crate::input::{read_regular, FileKind};
use crate::output::Output;
use anyhow::Context;
use gonio::baselines::equal_area::equal_area_square_to_sphere;
use gonio::envmap::{EnvOptions, EnvironmentMap, Lookup, Weight};
use gonio::image::{Image, ImageFormat};
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

/// Whether an input name is an image (by its extension: `.hdr`, `.pic`, `.exr`, `.pfm`).
pub fn is_image_name(name: &str) -> bool {
    ImageFormat::from_path(Path::new(name)).is_some()
}

/// `--weight`: what an environment map's density is proportional to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum WeightArg {
    /// Rec. 709 luminance 0.2126 R + 0.7152 G + 0.0722 B.
    Luminance,
    /// The red channel.
    Red,
    /// The green channel.
    Green,
    /// The blue channel.
    Blue,
}

/// `--lookup`: how an environment map's radiance is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LookupArg {
    /// The pixel that holds the direction.
    Nearest,
    /// Bilinear between pixel centres (continuous across the seam and at the poles).
    Bilinear,
}

/// The environment-map options of this run, as given (None: not given).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EnvCliOptions {
    /// `--weight`.
    pub weight: Option<WeightArg>,
    /// `--lookup`.
    pub lookup: Option<LookupArg>,
    /// `--mis-compensation`.
    pub mis_compensation: bool,
}

impl EnvCliOptions {
    /// The first option given, by name (for refusing them where the input is not an environment
    /// map: they would be ignored).
    pub fn given(&self) -> Option<&'static str> {
        let o = self;
        if o.weight.is_some() {
            Some("--weight")
        } else if o.lookup.is_some() {
            Some("--lookup")
        } else if o.mis_compensation {
            Some("--mis-compensation")
        } else {
            None
        }
    }

    /// The library's options of these `--weight`, `--lookup` and `--mis-compensation`.
    pub fn library(&self) -> EnvOptions {
        let o = self;
        EnvOptions {
            weight: match o.weight {
                None | Some(WeightArg::Luminance) => Weight::Luminance,
                Some(WeightArg::Red) => Weight::Channel(0),
                Some(WeightArg::Green) => Weight::Channel(1),
                Some(WeightArg::Blue) => Weight::Channel(2),
            },
            lookup: match o.lookup {
                None | Some(LookupArg::Nearest) => Lookup::Nearest,
                Some(LookupArg::Bilinear) => Lookup::Bilinear,
            },
            mis_compensation: o.mis_compensation,
        }
    }
}

/// Reads an image file and builds its environment map with this run's options
/// (`options`); the reader's and the map's warnings go to standard error. (`load::load`
/// wraps it into its `Loaded`.)
pub fn load_envmap(name: &str, options: &EnvCliOptions) -> anyhow::Result<EnvironmentMap> {
    load_envmap_timed(name, options).map(|(env, _)| env)
}

/// [`load_envmap`] and the wall-clock time its map took to build (weights and sphere map, the
/// image already decoded).
pub fn load_envmap_timed(
    name: &str,
    options: &EnvCliOptions,
) -> anyhow::Result<(EnvironmentMap, std::time::Duration)> {
    let bytes = read_regular(Path::new(name), name, FileKind::Image)?;
    let format = ImageFormat::sniff(&bytes).or_else(|| ImageFormat::from_path(Path::new(name)));
    let image = Image::from_bytes(&bytes, format).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
    drop(bytes);
    let start = std::time::Instant::now();
    let env = EnvironmentMap::with_options(image, options.library())
        .map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
    let took = start.elapsed();
    for w in env.warnings() {
        eprintln!("gonio: warning: {name}: {w}");
    }
    Ok((env, took))
}

/// What `gonio info --json` reports of an environment map (key `envmap`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct EnvInfo {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// `luminance`, `red`, `green`, `blue` or `custom`.
    pub weight: &'static str,
    /// `nearest` or `bilinear`.
    pub lookup: &'static str,
    /// Whether the weight is MIS-compensated.
    pub mis_compensation: bool,
    /// ∫ weight dω over the sphere (image unit × sr).
    pub weight_power: f64,
    /// Bytes held beyond the image.
    pub memory_bytes_beyond_image: usize,
    /// Bytes its float32 environment map would hold beyond the image (`null` if it has none).
    pub float32_memory_bytes_beyond_image: Option<usize>,
    /// What was repaired or ignored while reading and building.
    pub warnings: Vec<String>,
}

impl EnvInfo {
    /// The report of `env`.
    pub fn of(env: &EnvironmentMap) -> Self {
        let o = env.options();
        EnvInfo {
            width: env.image().width(),
            height: env.image().height(),
            weight: o.weight.name(),
            lookup: o.lookup.name(),
            mis_compensation: o.mis_compensation,
            weight_power: env.power(),
            memory_bytes_beyond_image: env.memory_bytes_beyond_image(),
            float32_memory_bytes_beyond_image: env.float32_memory_bytes_beyond_image().ok(),
            warnings: env.warnings().to_vec(),
        }
    }
}

/// The lines `gonio info` adds for an environment map.
pub fn info_lines(env: &EnvironmentMap) -> String {
    let img = env.image();
    let (w, h) = (img.width(), img.height());
    let mut s = String::new();
    let o = env.options();
    let weight = match o.weight {
        Weight::Luminance => "Rec. 709 luminance",
        Weight::Channel(0) => "red channel",
        Weight::Channel(1) => "green channel",
        Weight::Channel(_) => "blue channel",
        Weight::Custom(_) => "custom",
    };
    let lookup = match o.lookup {
        Lookup::Nearest => "nearest pixel",
        Lookup::Bilinear => "bilinear between pixel centres",
    };
    let mis = if o.mis_compensation {
        ", MIS compensation (weight − mean, clamped at 0)"
    } else {
        ""
    };
    s += &format!(
        "image            {w} × {h} pixels (RGB), weight: {weight}{mis}, radiance lookup: {lookup}\n"
    );
    s += &format!(
        "weight power     {} (image unit × sr)\n",
        gonio::decimal::shortest(env.power())
    );
    s += &format!(
        "memory           {} bytes beyond the image ({:.2} per pixel)\n",
        env.memory_bytes_beyond_image(),
        env.memory_bytes_beyond_image() as f64 / (w * h) as f64
    );
    if let Ok(b) = env.float32_memory_bytes_beyond_image() {
        s += &format!(
            "float32 map      {b} bytes beyond the image ({:.2} per pixel; Float32EnvironmentMap, gonio.EnvMap(precision=\"float32\"), gonio_envmap_into_float32)\n",
            b as f64 / (w * h) as f64
        );
    }
    s += "envmap frame     top row = zenith +z, centre column = +x, φ decreasing to the right (Mitsuba 3 local = (y, z, x); pbrt-v4 light space = gonio)\n";
    for wn in env.warnings() {
        s += &format!("warning          {wn}\n");
    }
    s
}

/// The equal-area octahedral RGB image of `env` at `n` pixels per side: pixel (x, y) (y from the
/// top) is the mean of the map's radiance at the midpoints of 4 × 4 strata of the square cell
/// [x/n, (x+1)/n] × [y/n, (y+1)/n], mapped by `EqualAreaSquareToSphere` (pbrt-v4's light space
/// is gonio's frame).
pub fn render_equal_area(env: &EnvironmentMap, n: usize) -> Vec<f32> {
    const S: usize = 4;
    let rows: Vec<Vec<f32>> = (0..n)
        .into_par_iter()
        .map(|y| {
            let mut row = Vec::with_capacity(3 * n);
            for x in 0..n {
                let mut sum = [0f64; 3];
                for j in 0..S {
                    for i in 0..S {
                        let u = ((x * S + i) as f64 + 0.5) / (n * S) as f64;
                        let v = ((y * S + j) as f64 + 0.5) / (n * S) as f64;
                        let r = env.eval(equal_area_square_to_sphere([u, v]));
                        for c in 0..3 {
                            sum[c] += f64::from(r[c]);
                        }
                    }
                }
                row.extend(sum.map(|v| (v / (S * S) as f64) as f32));
            }
            row
        })
        .collect();
    rows.concat()
}

/// `gonio convert IN.hdr OUT.exr|OUT.pfm --to pbrt-v4 [--resolution N]`: the square equal-area
/// image pbrt-v4's `ImageInfiniteLight` reads, and the scene line that uses it.
pub fn convert_pbrt(
    a: &ConvertArgs,
    ext: Option<&str>,
    options: &EnvCliOptions,
) -> anyhow::Result<()> {
    let out_name = a.output.display().to_string();
    let env = &load_envmap(&a.input, options)?;
    let (w, h) = (env.image().width(), env.image().height());
    let n = a
        .resolution
        .unwrap_or_else(|| ((w * h) as f64).sqrt().round() as usize);
    if !(1..=8192).contains(&n) {
        anyhow::bail!("--resolution {n} is outside 1..=8192");
    }
    let pixels = render_equal_area(env, n);
    let img = Image::new(n, n, pixels).map_err(|e| anyhow::anyhow!("{e}"))?;
    let bytes = match ext {
        Some("exr") => {
            use exr::prelude::*;
            let p = img.rgb();
            let channels = SpecificChannels::rgb(|q: Vec2<usize>| {
                let k = 3 * (q.y() * n + q.x());
                (p[k], p[k + 1], p[k + 2])
            });
            let mut buf = std::io::Cursor::new(Vec::new());
            exr::image::Image::from_channels((n, n), channels)
                .write()
                .to_buffered(&mut buf)
                .map_err(|e| anyhow::anyhow!("cannot encode the EXR image: {e}"))?;
            buf.into_inner()
        }
        Some("pfm") => gonio::image::write_pfm(&img, false, false),
        _ => anyhow::bail!("{out_name}: --to pbrt-v4 writes .exr or .pfm"),
    };
    let mut out = Output::create(Some(&a.output))?;
    out.write_all(&bytes)
        .with_context(|| format!("cannot write {out_name}"))?;
    out.finish()?;
    let text = format!(
        "# {input} -> {out_name}: {n}x{n} equal-area octahedral RGB image for pbrt-v4's ImageInfiniteLight\n\
         # pixels: mean radiance over each pixel's cell (4x4 points); pbrt-v4's light space is gonio's frame\n\
         # (+z = the image's top row, +x = its centre column)\n\
         LightSource \"infinite\" \"string filename\" \"{file}\"\n",
        input = a.input,
        file = out_name.replace('\\', "\\\\").replace('"', "\\\""),
    );
    crate::output::print(&text)
}
