//! `gonio plot`: pictures of a diagram and of a sampler, as PNG or SVG (plotters; the library itself
//! draws nothing).
//!
//! * [`PlotKind::Polar`]: the intensity curves in the planes C0–C180 and C90–C270, as lighting
//!   catalogues draw them;
//! * [`PlotKind::Warp`]: the same Halton points through every stage of the HDS map (square → M_B
//!   disk → M_C star domain → M_D disk → directions), coloured by their stratum of the square;
//! * [`PlotKind::Density`]: the sampler's pdf, a histogram of iid samples and their standardised
//!   difference on the equal-area (φ, cos θ) rectangle;
//! * [`PlotKind::Ratio`]: pdf / target over the domain, with the sampler's guaranteed bound.
//!
//! [`run`] is `gonio plot`: it loads the input, builds the sampler of `--method` and calls
//! [`render`], which other code (and the tests) may call directly with any [`PlotInput`].
//!
//! Every picture carries its own title, axes with units, a colour bar wherever colour encodes a
//! number and a legend wherever several series share axes. Text is drawn with the bundled DejaVu
//! Sans font (`assets/fonts`), so the output does not depend on the fonts of the machine.

mod axis;
pub mod brdf;
mod colour;
mod density;
mod grid;
mod polar;
mod ratio;
mod warp;

use crate::args::PlotArgs;
use crate::load;
use anyhow::{bail, Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::register_font;
use std::fmt;
use std::io::Write;
use std::path::Path;
use std::str::FromStr;
use std::sync::OnceLock;

/// The pictures `gonio plot --kind` draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PlotKind {
    /// Intensity curves in the C0–C180 and C90–C270 planes (polar diagram).
    Polar,
    /// Halton points through the stages of the map.
    Warp,
    /// pdf, histogram of samples, and their difference.
    Density,
    /// pdf / target over the domain with the guaranteed bound.
    Ratio,
}

impl PlotKind {
    /// Every kind, in the order `--kind` lists them.
    pub const ALL: [PlotKind; 4] = [
        PlotKind::Polar,
        PlotKind::Warp,
        PlotKind::Density,
        PlotKind::Ratio,
    ];

    /// The kind's name as `--kind` spells it.
    pub fn as_str(self) -> &'static str {
        match self {
            PlotKind::Polar => "polar",
            PlotKind::Warp => "warp",
            PlotKind::Density => "density",
            PlotKind::Ratio => "ratio",
        }
    }

    /// A good picture size in pixels (width, height) for this kind.
    pub fn default_size(self) -> (u32, u32) {
        match self {
            PlotKind::Polar => (1000, 900),
            PlotKind::Warp => (1600, 430),
            PlotKind::Density => (1200, 1000),
            PlotKind::Ratio => (1200, 620),
        }
    }

    /// The default number of points: 1024 Halton points for `warp`, 10⁶ iid samples for
    /// `density`; `polar` and `ratio` draw no samples (0).
    pub fn default_samples(self) -> usize {
        match self {
            PlotKind::Warp => 1024,
            PlotKind::Density => 1_000_000,
            PlotKind::Polar | PlotKind::Ratio => 0,
        }
    }
}

impl fmt::Display for PlotKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// An unknown `--kind`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownPlotKind(pub String);

impl fmt::Display for UnknownPlotKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "unknown plot kind `{}`; expected one of: polar, warp, density, ratio",
            self.0
        )
    }
}

impl std::error::Error for UnknownPlotKind {}

impl FromStr for PlotKind {
    type Err = UnknownPlotKind;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        gonio::input::find_by_name(PlotKind::ALL, PlotKind::as_str, s)
            .ok_or_else(|| UnknownPlotKind(s.to_string()))
    }
}

/// What a plot is drawn from.
pub struct PlotInput<'a> {
    /// Shown in every picture's title (e.g. the file name).
    pub title: String,
    /// The (expanded) diagram in the gonio frame: θ from +z, φ from +x; values e.g. in candela.
    pub diagram: &'a gonio::Diagram,
    /// The sampler whose pdf, samples and target are drawn.
    pub sampler: &'a dyn gonio::Sampler,
    /// The HDS map behind the sampler, if it is one: `warp` draws the intermediate stages of its
    /// map ([`gonio::MapRef::stages`]); `ratio` marks its guaranteed range of pdf / target
    /// ([`gonio::MapRef::ratio_bound`]).
    pub map: Option<gonio::MapRef<'a>>,
    /// Number of points: Halton points for `warp`, iid samples for `density` (0: the kind's default).
    pub samples: usize,
    /// Seed of the iid samples of `density`.
    pub seed: u64,
    /// Photometric data: angles are labelled γ = 180° − θ (0° = nadir) and values in cd.
    pub photometric: bool,
    /// A type A or B photometric file: `polar` draws its own H = 0° and V = 0° planes from the
    /// measured (H, V) table, as floodlight catalogues do, instead of C-plane cuts of the
    /// resampled diagram.
    pub hv_photometry: Option<&'a gonio::Photometry>,
}

impl PlotInput<'_> {
    fn samples_or_default(&self, kind: PlotKind) -> usize {
        if self.samples == 0 {
            kind.default_samples()
        } else {
            self.samples
        }
    }
}

/// The bundled font (DejaVu Sans, Bitstream Vera licence: `assets/fonts/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Registers the bundled font as plotters' `sans-serif` (once per process).
fn ensure_font() -> Result<()> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| register_font("sans-serif", FontStyle::Normal, FONT).is_ok());
    if !ok {
        bail!("the bundled font could not be loaded");
    }
    Ok(())
}

/// The image format of an output path, from its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Png,
    Svg,
}

fn format_of(path: &Path) -> Result<Format> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("png") => Ok(Format::Png),
        Some("svg") => Ok(Format::Svg),
        _ => bail!(
            "cannot tell the image format of `{}`: the output file must end in .png or .svg",
            path.display()
        ),
    }
}

/// Draws `kind` of `input` into `out` (.png or .svg, by extension) at `width` × `height` pixels.
pub fn render(
    kind: PlotKind,
    input: &PlotInput,
    out: &Path,
    width: u32,
    height: u32,
) -> Result<()> {
    write_picture(&Chart { kind, input }, out, width, height)
}

/// A picture of `gonio plot`, drawn alike on the bitmap backend (PNG) and the vector one (SVG).
pub trait Picture {
    /// Draws the picture on `root`; `svg`: vector output, where every raster cell is an element,
    /// so their number should stay modest.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, svg: bool) -> Result<()>
    where
        DB::ErrorType: 'static;
}

/// Draws `picture` into `out` (.png or .svg, by extension) at `width` × `height` pixels. Like
/// every command's output: written to a temporary file next to `out`, renamed onto it only on
/// success.
pub fn write_picture(picture: &impl Picture, out: &Path, width: u32, height: u32) -> Result<()> {
    let format = format_of(out)?;
    if !(200..=10_000).contains(&width) || !(150..=10_000).contains(&height) {
        bail!("picture size {width}×{height} is out of range (200–10000 × 150–10000 pixels)");
    }
    ensure_font()?;
    let mut file = crate::output::Output::create(Some(out))?;
    let bytes = match format {
        Format::Png => {
            let mut rgb = vec![0u8; width as usize * height as usize * 3];
            {
                let root =
                    BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
                picture.draw(&root, false)?;
                root.present()?;
            }
            encode_png(&rgb, width, height)?
        }
        Format::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
                picture.draw(&root, true)?;
                root.present()?;
            }
            svg.into_bytes()
        }
    };
    file.write_all(&bytes)
        .with_context(|| format!("cannot write `{}`", out.display()))?;
    file.finish()?;
    Ok(())
}

/// Encodes an RGB buffer as PNG: indexed colour when the picture has at most 256 colours (most of
/// ours: flat fills and lines), else RGB; best compression either way (plotters' own encoder writes
/// files several times larger).
fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    let mut enc = png::Encoder::new(&mut bytes, width, height);
    enc.set_compression(png::Compression::Best);
    enc.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    let mut palette: Vec<[u8; 3]> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut indexed = Vec::with_capacity(rgb.len() / 3);
    for px in rgb.chunks_exact(3) {
        let c = [px[0], px[1], px[2]];
        let k = *index.entry(c).or_insert_with(|| {
            palette.push(c);
            palette.len() - 1
        });
        if palette.len() > 256 {
            break;
        }
        indexed.push(k as u8);
    }
    if palette.len() <= 256 {
        enc.set_color(png::ColorType::Indexed);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_palette(palette.concat());
        // Filters rarely help indexed images.
        enc.set_adaptive_filter(png::AdaptiveFilterType::NonAdaptive);
        enc.set_filter(png::FilterType::NoFilter);
        enc.write_header()?.write_image_data(&indexed)?;
    } else {
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.write_header()?.write_image_data(rgb)?;
    }
    Ok(bytes)
}

/// `gonio plot FILE -o OUT --kind K [--samples N] [--seed S] [--method M] [--width W] [--height H]`.
pub fn run(args: &PlotArgs, settings: &crate::settings::Settings) -> Result<()> {
    let loaded = load::load(&args.input, settings)?;
    let kind = PlotKind::from(args.kind);
    let sampler = load::build_sampler(args.method.diagram()?, &loaded)?;
    let title = match loaded.kind {
        load::InputKind::Example => loaded.name.clone(),
        _ => Path::new(&loaded.name)
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| loaded.name.clone()),
    };
    let input = PlotInput {
        title,
        diagram: &loaded.diagram,
        sampler: sampler.as_ref(),
        map: sampler.hds_map(),
        samples: args.samples.unwrap_or(0),
        seed: args.seed,
        photometric: loaded.kind.is_photometric(),
        hv_photometry: loaded
            .photometry
            .as_deref()
            .filter(|p| p.photometric_type != gonio::photometry::PhotometricType::C),
    };
    let (w, h) = kind.default_size();
    render(
        kind,
        &input,
        &args.output,
        args.width.unwrap_or(w),
        args.height.unwrap_or(h),
    )
}

impl From<crate::args::PlotKind> for PlotKind {
    fn from(k: crate::args::PlotKind) -> Self {
        use crate::args::PlotKind as A;
        match k {
            A::Polar => PlotKind::Polar,
            A::Warp => PlotKind::Warp,
            A::Density => PlotKind::Density,
            A::Ratio => PlotKind::Ratio,
        }
    }
}

/// One of the four pictures of a luminaire's (or sky's) map.
struct Chart<'a> {
    kind: PlotKind,
    input: &'a PlotInput<'a>,
}

impl Picture for Chart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, svg: bool) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let (kind, input) = (self.kind, self.input);
        let n = input.samples_or_default(kind);
        if n == 0 && matches!(kind, PlotKind::Warp | PlotKind::Density) {
            bail!("the {kind} plot needs at least one sample");
        }
        root.fill(&WHITE)?;
        match kind {
            PlotKind::Polar => polar::draw(root, input),
            PlotKind::Warp => warp::draw(root, input, n),
            PlotKind::Density => density::draw(root, svg, input, n),
            PlotKind::Ratio => ratio::draw(root, svg, input),
        }
    }
}

/// The largest font size up to `size` (down to 9 px) at which `text` fits in `room` pixels, and the
/// text, shortened with "…" if it does not fit even at 9 px.
fn fit(text: &str, size: f64, room: u32) -> (String, f64) {
    let width = |t: &str, s: f64| ("sans-serif", s).into_font().box_size(t).map_or(0, |b| b.0);
    let mut s = size;
    while s > 9.0 && width(text, s) > room {
        s -= 1.0;
    }
    let mut text = text.to_string();
    while width(&text, s) > room && text.chars().count() > 2 {
        text = text.trim_end_matches('…').to_string();
        text.pop();
        text = format!("{}…", text.trim_end());
    }
    (text, s)
}

/// `area.titled(text)` with the text [`fit`] to the area's width.
fn titled<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
) -> Result<DrawingArea<DB, Shift>>
where
    DB::ErrorType: 'static,
{
    let (w, _) = area.dim_in_pixel();
    let (text, s) = fit(text, size, w.saturating_sub(12));
    Ok(area.titled(&text, ("sans-serif", s).into_font().color(&BLACK))?)
}

/// Font of tick labels.
fn label_font() -> TextStyle<'static> {
    ("sans-serif", 13).into_font().color(&BLACK)
}

/// Font of axis descriptions.
fn desc_font() -> TextStyle<'static> {
    ("sans-serif", 14).into_font().color(&BLACK)
}

/// A short human form of a number: 3 significant digits, no exponent for 1e-3 ≤ |x| < 1e6.
fn fmt_num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if !(1e-3..1e6).contains(&a) {
        return format!("{x:.2e}");
    }
    let digits = (2 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A "nice" step (1, 2, 2.5 or 5 × 10^k) close to `raw`.
fn nice_step(raw: f64) -> f64 {
    if !raw.is_finite() || raw <= 0.0 {
        return 1.0;
    }
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let n = if m < 1.5 {
        1.0
    } else if m < 2.25 {
        2.0
    } else if m < 3.5 {
        2.5
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    };
    n * p
}

/// The unit of the diagram's values as labels spell it.
fn value_unit(input: &PlotInput) -> &'static str {
    if input.photometric {
        "cd"
    } else {
        "diagram units"
    }
}

#[cfg(test)]
mod tests;
