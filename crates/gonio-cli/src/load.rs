//! Input loading and sampler construction, shared by every command (and by `plot` and `bench`).
//!
//! * [`load`] reads a `.json` (native diagram), `.ies` or `.ldt` file (extension in any letter
//!   case), or the special name [`EXAMPLE`] for the built-in luminaire;
//! * [`build_sampler`] builds the sampler of a [`Method`] for what was loaded, on the domain
//!   [`domain`] chooses;
//! * [`build_hds`] builds the HDS map with its concrete type, for `info` and `check`.

use crate::input::{read_regular, tame, TiltFiles, MAX_INPUT_BYTES};
use anyhow::Context;
use gonio::baselines::Method;
use gonio::mapping::SphereLayout;
use gonio::{Diagram, Domain, HemisphereMap, Sampler, SphereMap};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// The input name that loads [`gonio::synthetic::example_luminaire`] instead of a file.
pub const EXAMPLE: &str = "example";

/// An error located in an input file; printed as `FILE:LINE:COLUMN: message` (without the
/// `gonio: error:` prefix), like a compiler diagnostic. Line and column are 1-based; a column of 0
/// is left out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LocatedError {
    /// The file as the user named it.
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, 0 when unknown.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for LocatedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.line, self.column) {
            (0, _) => write!(f, "{}: {}", self.file, self.message),
            (l, 0) => write!(f, "{}:{l}: {}", self.file, self.message),
            (l, c) => write!(f, "{}:{l}:{c}: {}", self.file, self.message),
        }
    }
}

impl std::error::Error for LocatedError {}

/// The kind of input that was loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// The built-in example luminaire (candela, whole sphere).
    Example,
    /// A native JSON diagram (units as given).
    Json,
    /// An IES LM-63 file (candela).
    Ies,
    /// An EULUMDAT file (candela after scaling).
    Eulumdat,
}

impl InputKind {
    /// Short lowercase name: `example`, `json`, `ies`, `ldt`.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Example => "example",
            InputKind::Json => "json",
            InputKind::Ies => "ies",
            InputKind::Eulumdat => "ldt",
        }
    }

    /// True for IES and EULUMDAT input (and the example, which is in candela too): the diagram's
    /// values are candela and its power is luminous flux in lumens.
    pub fn is_photometric(self) -> bool {
        !matches!(self, InputKind::Json)
    }
}

/// An input, loaded and validated.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The name the input was given by (a path, or [`EXAMPLE`]).
    pub name: String,
    /// What kind of input it was.
    pub kind: InputKind,
    /// The diagram, in the gonio frame (θ from +z, φ from +x toward +y).
    pub diagram: Diagram,
    /// The photometric file as read, for IES and EULUMDAT input.
    pub photometry: Option<Box<gonio::photometry::Photometry>>,
}

impl Loaded {
    /// The domain every sampler for this input covers (see [`domain`]).
    pub fn domain(&self) -> Domain {
        domain(self)
    }
}

/// The format an input name stands for, from its extension (any letter case).
pub fn input_kind(name: &str) -> anyhow::Result<InputKind> {
    if name == EXAMPLE {
        return Ok(InputKind::Example);
    }
    let ext = Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("json") => Ok(InputKind::Json),
        Some("ies") => Ok(InputKind::Ies),
        Some("ldt") => Ok(InputKind::Eulumdat),
        Some(e) => anyhow::bail!(
            "{name}: unknown input format `.{e}`; expected .json, .ies, .ldt or `{EXAMPLE}`"
        ),
        None => anyhow::bail!(
            "{name}: the file name has no extension; expected .json, .ies, .ldt or `{EXAMPLE}`"
        ),
    }
}

/// Loads an input: a `.json`, `.ies` or `.ldt` file, or [`EXAMPLE`].
///
/// Syntax errors come back as a [`LocatedError`] (`FILE:LINE:COLUMN: message`); every other error
/// names the file.
pub fn load(name: &str) -> anyhow::Result<Loaded> {
    let kind = input_kind(name)?;
    let (diagram, photometry) = match kind {
        InputKind::Example => (gonio::synthetic::example_luminaire(), None),
        InputKind::Json => {
            let bytes = read_file(name)?;
            let text = std::str::from_utf8(&bytes)
                .map_err(|e| anyhow::anyhow!("{name}: the file is not UTF-8 text ({e})"))?;
            (diagram_from_json(name, text)?, None)
        }
        InputKind::Ies | InputKind::Eulumdat => {
            let (p, d) = load_photometry(name, kind)?;
            (d, Some(Box::new(p)))
        }
    };
    Ok(Loaded {
        name: name.to_string(),
        kind,
        diagram,
        photometry,
    })
}

/// Reads an input file: a regular file of at most [`MAX_INPUT_BYTES`] (see [`crate::input`]).
fn read_file(name: &str) -> anyhow::Result<Vec<u8>> {
    read_regular(Path::new(name), name, MAX_INPUT_BYTES)
}

/// Parses the native JSON form, turning library errors into CLI errors that name the file.
pub fn diagram_from_json(name: &str, text: &str) -> anyhow::Result<Diagram> {
    Diagram::from_json_str(text).map_err(|e| match e {
        gonio::Error::Json {
            line,
            column,
            message,
        } => LocatedError {
            file: name.to_string(),
            line,
            column,
            message: tame(strip_serde_location(&message)),
        }
        .into(),
        gonio::Error::Parse(p) => LocatedError {
            file: name.to_string(),
            line: p.line,
            column: p.column,
            message: tame(&p.message),
        }
        .into(),
        other => anyhow::anyhow!("{name}: invalid diagram: {other}"),
    })
}

/// serde_json messages end in " at line L column C", which the CLI prints in front instead.
fn strip_serde_location(message: &str) -> &str {
    match message.rfind(" at line ") {
        Some(k) => &message[..k],
        None => message,
    }
}

fn load_photometry(
    name: &str,
    kind: InputKind,
) -> anyhow::Result<(gonio::photometry::Photometry, Diagram)> {
    use gonio::photometry::{read, FileFormat};
    let bytes = read_file(name)?;
    let format = if kind == InputKind::Ies {
        FileFormat::Ies
    } else {
        FileFormat::Eulumdat
    };
    let dir: PathBuf = match Path::new(name).parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let p = read(&bytes, format, &TiltFiles::new(dir)).map_err(|e| LocatedError {
        file: name.to_string(),
        line: e.line,
        column: e.column,
        message: tame(&e.message),
    })?;
    let d = p
        .to_diagram()
        .map_err(|e| anyhow::anyhow!("{name}: cannot expand the distribution: {e}"))?;
    Ok((p, d))
}

/// The domain of every sampler built for `loaded`: photometric input (IES, EULUMDAT, the example)
/// always gets the whole sphere; a JSON diagram gets the upper hemisphere when its last parallel
/// lies at θ ≤ 90°, the sphere otherwise.
pub fn domain(loaded: &Loaded) -> Domain {
    let theta_max = *loaded
        .diagram
        .theta()
        .last()
        .expect("a diagram has parallels");
    if loaded.kind.is_photometric() || theta_max > std::f64::consts::FRAC_PI_2 {
        Domain::Sphere
    } else {
        Domain::Hemisphere
    }
}

/// The HDS map, with its concrete type (for `info` and `check`, which need more than the
/// [`Sampler`] trait offers).
// One map per run: the size difference of the variants does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum Hds {
    /// The hemisphere map (JSON diagrams within θ ≤ 90°).
    Hemisphere(HemisphereMap),
    /// The sphere map, split layout.
    Sphere(SphereMap),
}

impl Hds {
    /// Guaranteed (min, max) of pdf / target_pdf.
    pub fn ratio_bound(&self) -> (f64, f64) {
        match self {
            Hds::Hemisphere(m) => m.ratio_bound(),
            Hds::Sphere(m) => m.ratio_bound(),
        }
    }
    /// What refinement to `--tolerance` asked, reached and cost (`None` without a tolerance).
    pub fn refinement(&self) -> Option<&gonio::mapping::Refinement> {
        match self {
            Hds::Hemisphere(m) => m.refinement(),
            Hds::Sphere(m) => m.refinement(),
        }
    }
    /// The data's integral over the domain (zero outside its measured range), in diagram units ×
    /// sr (lumens for candela): the map's target power.
    pub fn target_power(&self) -> f64 {
        match self {
            Hds::Hemisphere(m) => m.target_power(),
            Hds::Sphere(m) => m.target_power(),
        }
    }
    /// The power of the completed diagram the map samples (data plus zero guard bands).
    pub fn completed_power(&self) -> f64 {
        match self {
            Hds::Hemisphere(m) => m.completed_power(),
            Hds::Sphere(m) => m.completed_power(),
        }
    }
    /// Map power / data power (1 + the zero guard bands' share).
    pub fn power_ratio(&self) -> f64 {
        match self {
            Hds::Hemisphere(m) => m.power_ratio(),
            Hds::Sphere(m) => m.power_ratio(),
        }
    }
    /// The map's target power divided by the data's largest value (always finite).
    pub fn normalised_target_power(&self) -> f64 {
        match self {
            Hds::Hemisphere(m) => m.normalised_target_power(),
            Hds::Sphere(m) => m.normalised_target_power(),
        }
    }
    /// The data's largest value.
    pub fn value_scale(&self) -> f64 {
        match self {
            Hds::Hemisphere(m) => m.value_scale(),
            Hds::Sphere(m) => m.value_scale(),
        }
    }
    /// Probability of a sample outside the data's measured θ range (exact, from the tables).
    pub fn probability_outside_measured(&self) -> f64 {
        match self {
            Hds::Hemisphere(m) => m.probability_outside_measured(),
            Hds::Sphere(m) => m.probability_outside_measured(),
        }
    }
    /// The zones without data that the map completed with zero light, as warning texts.
    pub fn completion_warnings(&self) -> Vec<String> {
        let c = match self {
            Hds::Hemisphere(m) => m.completions(),
            Hds::Sphere(m) => m.completions(),
        };
        c.iter().map(|c| c.to_string()).collect()
    }
    /// Prints [`Hds::completion_warnings`] to stderr as `gonio: warning: NAME: …`.
    pub fn warn_completions(&self, name: &str) {
        for w in self.completion_warnings() {
            eprintln!("gonio: warning: {name}: {w}");
        }
    }
    /// The map as a sampler.
    pub fn as_sampler(&self) -> &dyn Sampler {
        match self {
            Hds::Hemisphere(m) => m,
            Hds::Sphere(m) => m,
        }
    }
    /// The map as a boxed sampler.
    pub fn into_sampler(self) -> Box<dyn Sampler> {
        match self {
            Hds::Hemisphere(m) => Box::new(m),
            Hds::Sphere(m) => Box::new(m),
        }
    }
}

/// The global `--tolerance` (bits of an `f64`; NaN = none): the HDS map is refined to it.
static TOLERANCE: AtomicU64 = AtomicU64::new(NO_TOLERANCE);
const NO_TOLERANCE: u64 = 0x7ff8_0000_0000_0000;

/// Sets the tolerance every HDS map of this run is refined to (the global `--tolerance`).
pub fn set_tolerance(tolerance: Option<f64>) {
    TOLERANCE.store(
        tolerance.map_or(NO_TOLERANCE, f64::to_bits),
        Ordering::Relaxed,
    );
}

/// The tolerance set by [`set_tolerance`], if any.
pub fn tolerance() -> Option<f64> {
    let t = f64::from_bits(TOLERANCE.load(Ordering::Relaxed));
    (!t.is_nan()).then_some(t)
}

/// Builds the HDS map for `loaded` on [`domain`] (refined to [`tolerance`] when one is set, with a
/// warning on stderr when it was not reached), and the time the build took.
pub fn build_hds(loaded: &Loaded) -> anyhow::Result<(Hds, Duration)> {
    let start = Instant::now();
    let d = &loaded.diagram;
    let map = match (domain(loaded), tolerance()) {
        (Domain::Hemisphere, None) => Hds::Hemisphere(HemisphereMap::new(d)?),
        (Domain::Hemisphere, Some(t)) => Hds::Hemisphere(HemisphereMap::with_tolerance(d, t)?),
        (Domain::Sphere, None) => Hds::Sphere(SphereMap::with_layout(d, SphereLayout::Split)?),
        (Domain::Sphere, Some(t)) => Hds::Sphere(SphereMap::with_tolerance(d, t)?),
    };
    if let Some(w) = map.refinement().and_then(|r| r.warning()) {
        eprintln!("gonio: warning: {}: {w}", loaded.name);
    }
    Ok((map, start.elapsed()))
}

/// The sampler of `method` for `loaded`: the HDS map for [`Method::Hds`], the baseline otherwise,
/// on the domain [`domain`] chooses.
pub fn build_sampler(method: Method, loaded: &Loaded) -> anyhow::Result<Box<dyn Sampler>> {
    match method {
        Method::Hds => {
            let (hds, _) = build_hds(loaded)
                .with_context(|| format!("{}: cannot build the HDS map", loaded.name))?;
            hds.warn_completions(&loaded.name);
            Ok(hds.into_sampler())
        }
        m => m
            .build_baseline(&loaded.diagram, domain(loaded))
            .with_context(|| format!("{}: cannot build the {m} sampler", loaded.name)),
    }
}
