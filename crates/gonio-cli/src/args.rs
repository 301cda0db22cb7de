//! Argument structs shared between `main.rs` and the command modules written by other engineers
//! (`plot`, `bench`). They are plain clap `Args` structs: a module receives the parsed struct and
//! does the rest with [`crate::load::load`] and [`crate::load::build_sampler`].

use clap::{Args, ValueEnum};
use gonio::Method;
use std::path::PathBuf;

/// A usage error found after parsing (an option that does not apply to the input): `main` exits
/// with code 2 for it, as for clap's own.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// `--method`: the sampling methods of diagrams and those of BRDF files, one list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodName {
    /// The HDS map (every input kind).
    Hds,
    /// Piecewise-constant (every input kind).
    PiecewiseConstant,
    /// Bilinear patches (diagrams).
    Bilinear,
    /// Rejection sampling (diagrams).
    Rejection,
    /// Uniform directions (diagrams).
    Uniform,
    /// Cosine-weighted lobe (BRDF files).
    Cosine,
    /// A fitted GGX lobe (BRDF files).
    GgxFit,
}

impl MethodName {
    /// The library's method for a diagram, or a usage error for a BRDF-only method.
    pub fn diagram(self) -> Result<Method, UsageError> {
        Ok(match self {
            MethodName::Hds => Method::Hds,
            MethodName::PiecewiseConstant => Method::PiecewiseConstant,
            MethodName::Bilinear => Method::Bilinear,
            MethodName::Rejection => Method::Rejection,
            MethodName::Uniform => Method::Uniform,
            m @ (MethodName::Cosine | MethodName::GgxFit) => {
                return Err(UsageError(format!(
                    "--method {}: a method of BRDF files only; diagrams take hds, \
                     piecewise-constant, bilinear, rejection or uniform",
                    m.to_possible_value()
                        .map_or_else(String::new, |v| v.get_name().to_owned())
                )))
            }
        })
    }
}

/// The options of a tabulated BRDF input (MERL `.binary`, UTIA `.bin`, gonio BRDF JSON; the
/// format is recognised from the content). A BRDF file is one more input kind of the commands
/// `info`, `sample`, `pdf`, `invert`, `check`, `plot` and `bench`; these options apply to it only.
#[derive(Debug, Clone, Default, Args)]
pub struct BrdfOptions {
    /// BRDF files: the incident direction ω_i, polar angle and azimuth in degrees in the local
    /// shading frame (z the normal, x the tangent), 0 ≤ THETA ≤ 90.
    #[arg(long, value_name = "THETA,PHI", value_parser = parse_incident)]
    pub incident: Option<(f64, f64)>,
    /// BRDF files, MERL: polar nodes of the grid the half-angle table is resampled on (46).
    #[arg(long, value_name = "N")]
    pub merl_theta: Option<usize>,
    /// BRDF files, MERL: azimuth nodes of that grid (90).
    #[arg(long, value_name = "N")]
    pub merl_phi: Option<usize>,
    /// BRDF files: polar nodes of the outgoing grid of the slice maps (46).
    #[arg(long, value_name = "N")]
    pub theta_o: Option<usize>,
    /// BRDF files: azimuth nodes of the outgoing grid of the slice maps (90).
    #[arg(long, value_name = "N")]
    pub phi_o: Option<usize>,
}

impl BrdfOptions {
    /// The first BRDF option given, by name (refused for other inputs: it would be ignored).
    pub fn given(&self) -> Option<&'static str> {
        if self.incident.is_some() {
            Some("--incident")
        } else if self.merl_theta.is_some() {
            Some("--merl-theta")
        } else if self.merl_phi.is_some() {
            Some("--merl-phi")
        } else if self.theta_o.is_some() {
            Some("--theta-o")
        } else if self.phi_o.is_some() {
            Some("--phi-o")
        } else {
            None
        }
    }
}

/// `--incident THETA,PHI`: degrees, 0 ≤ THETA ≤ 90, PHI finite.
pub fn parse_incident(s: &str) -> Result<(f64, f64), String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let bad = || format!("--incident takes THETA,PHI in degrees (0 ≤ THETA ≤ 90), got `{s}`");
    if parts.len() != 2 {
        return Err(bad());
    }
    let t: f64 = parts[0].parse().map_err(|_| bad())?;
    let p: f64 = parts[1].parse().map_err(|_| bad())?;
    if !(0.0..=90.0).contains(&t) || !p.is_finite() {
        return Err(bad());
    }
    Ok((t, p))
}

/// What `gonio plot` draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PlotKind {
    /// Polar intensity curves of the diagram (C-planes).
    Polar,
    /// The warp of the unit square: grid lines of the square mapped onto the disk/sphere.
    Warp,
    /// Sample density: histogram of sampled directions against the target.
    Density,
    /// The pdf/target ratio over the sphere.
    Ratio,
}

/// `gonio plot FILE -o OUT.png|OUT.svg [--kind K] [--samples N] [--seed S] [--method M]
/// [--width W] [--height H]`.
#[derive(Debug, Clone, Args)]
pub struct PlotArgs {
    /// Input diagram: `.json`, `.ies`, `.ldt`, or `example` for the built-in luminaire.
    #[arg(value_name = "FILE")]
    pub input: String,
    /// Output image; the extension (`.png` or `.svg`) picks the format.
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    pub output: PathBuf,
    /// What to draw.
    #[arg(long, value_enum, default_value_t = PlotKind::Polar)]
    pub kind: PlotKind,
    /// Number of samples for the sample-based kinds (default: 1024 Halton points for warp, 10⁶
    /// iid samples for density).
    #[arg(long)]
    pub samples: Option<usize>,
    /// Seed of the sample sequence.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Sampling method: hds, piecewise-constant, bilinear, rejection, uniform; for a BRDF file
    /// hds, cosine, ggx-fit, piecewise-constant.
    #[arg(long, value_enum, default_value_t = MethodName::Hds)]
    pub method: MethodName,
    #[command(flatten)]
    pub brdf: BrdfOptions,
    /// Image width in pixels (default: per kind, e.g. 1200 for density).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (default: per kind).
    #[arg(long)]
    pub height: Option<u32>,
}

/// `gonio bench FILE [--json] [--method M]... [--samples N] [--threads T]`.
#[derive(Debug, Clone, Args)]
pub struct BenchArgs {
    /// Input diagram: `.json`, `.ies`, `.ldt`, or `example` for the built-in luminaire.
    #[arg(value_name = "FILE")]
    pub input: String,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Methods to measure (repeat the option for several); none given = every method.
    #[arg(long = "method", value_name = "M")]
    pub methods: Vec<Method>,
    /// Samples per measurement.
    #[arg(short = 'n', long, default_value_t = 1_000_000)]
    pub samples: usize,
    /// Rayon worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Also measure the HDS map's SIMD structure-of-arrays batch paths (f64 and f32, one thread
    /// and all threads, best of 5 wall-clock runs).
    #[arg(long)]
    pub soa: bool,
    #[command(flatten)]
    pub brdf: BrdfOptions,
}

impl BenchArgs {
    /// The methods to measure: those given, or all of them when none was.
    pub fn methods(&self) -> Vec<Method> {
        if self.methods.is_empty() {
            Method::ALL.to_vec()
        } else {
            self.methods.clone()
        }
    }
}

/// Output format of `gonio sample`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SampleFormat {
    /// Text with the header `u,v,x,y,z,pdf`, numbers in shortest round-trip form.
    Csv,
    /// Little-endian f32 rows of the six numbers u, v, x, y, z, pdf; no header.
    F32,
    /// Little-endian f64 rows of the six numbers u, v, x, y, z, pdf; no header.
    F64,
}

/// The options `sample`, `pdf` and `invert` share: where the rows go and which sampler (of a
/// luminaire, or of a BRDF at an incident direction) makes them.
#[derive(Debug, Clone, Args)]
pub struct RunOptions {
    /// Output file (`-` or absent: standard output).
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    pub output: Option<PathBuf>,
    /// Sampling method: hds, piecewise-constant, bilinear, rejection, uniform; for a BRDF file
    /// hds, cosine, ggx-fit, piecewise-constant.
    #[arg(long, value_enum, default_value_t = MethodName::Hds)]
    pub method: MethodName,
    #[command(flatten)]
    pub brdf: BrdfOptions,
}

/// `gonio sample FILE (-n N | --points UV.csv) [--sequence S] [--seed S] [--format F] [-o OUT]
/// [--method M]`.
#[derive(Debug, Clone, Args)]
pub struct SampleArgs {
    /// Input diagram: `.json`, `.ies`, `.ldt`, or `example` for the built-in luminaire.
    #[arg(value_name = "FILE")]
    pub input: String,
    /// Number of samples to draw from the sequence.
    #[arg(
        short = 'n',
        long = "samples",
        value_name = "N",
        required_unless_present = "points",
        conflicts_with = "points"
    )]
    pub n: Option<u64>,
    /// Map these points instead of a sequence: a CSV file with columns `u,v` (by header name).
    #[arg(long, value_name = "UV.csv")]
    pub points: Option<String>,
    /// Point sequence on the unit square (Halton from index 1, skipping the corner (0, 0)).
    #[arg(long, default_value = "halton")]
    pub sequence: gonio::sequence::SequenceKind,
    /// Seed (Sobol' scrambling, random stream; Halton ignores it).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output format.
    #[arg(long, value_enum, default_value_t = SampleFormat::Csv)]
    pub format: SampleFormat,
    #[command(flatten)]
    pub run: RunOptions,
}

/// `gonio pdf|invert FILE --directions DIRS.csv [-o OUT] [--method M]`.
#[derive(Debug, Clone, Args)]
pub struct DirectionsArgs {
    /// Input diagram: `.json`, `.ies`, `.ldt`, or `example` for the built-in luminaire.
    #[arg(value_name = "FILE")]
    pub input: String,
    /// Directions: a CSV file with columns `x,y,z` (by header name; `-` reads standard input).
    #[arg(long, value_name = "DIRS.csv")]
    pub directions: String,
    #[command(flatten)]
    pub run: RunOptions,
}

/// `gonio info FILE [--json]`.
#[derive(Debug, Clone, Args)]
pub struct InfoArgs {
    /// Input diagram: `.json`, `.ies`, `.ldt`, or `example` for the built-in luminaire.
    #[arg(value_name = "FILE")]
    pub input: String,
    /// Print one JSON object (keys documented in docs/CLI.md).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub brdf: BrdfOptions,
}

/// `gonio convert IN OUT`.
#[derive(Debug, Clone, Args)]
pub struct ConvertArgs {
    /// Input: `.json`, `.ies`, `.ldt`, or `example`.
    #[arg(value_name = "IN")]
    pub input: String,
    /// Output; its extension picks the format: `.json`, `.ies` (LM-63-2019) or `.ldt`; with
    /// `--to pbrt-v4`, `.exr` or `.pfm`.
    #[arg(value_name = "OUT")]
    pub output: PathBuf,
    /// Convert for a renderer instead: `pbrt-v4` writes the equal-area image of pbrt-v4's
    /// goniometric light and prints the scene line that uses it.
    #[arg(long, value_enum, value_name = "TARGET")]
    pub to: Option<ConvertTarget>,
    /// Image resolution in pixels per side for `--to pbrt-v4` (default 512).
    #[arg(long, value_name = "N", requires = "to")]
    pub resolution: Option<usize>,
}

/// What `gonio convert --to` converts for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ConvertTarget {
    /// pbrt-v4's `LightSource "goniometric"`: an equal-area octahedral image (`.exr` or `.pfm`).
    #[value(name = "pbrt-v4")]
    PbrtV4,
}

/// `gonio check FILE [--samples N] [--seed S] [--quick] [--json] [--method M]`.
#[derive(Debug, Clone, Args)]
pub struct CheckArgs {
    /// Input diagram: `.json`, `.ies`, `.ldt`, or `example` for the built-in luminaire.
    #[arg(value_name = "FILE")]
    pub input: String,
    /// Samples of the chi-square test and of the flux estimate (default 10⁶, 2·10⁵ with --quick).
    #[arg(long, value_name = "N")]
    pub samples: Option<usize>,
    /// Seed of every random item.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The cheaper battery (about ten times faster, same tolerances).
    #[arg(long)]
    pub quick: bool,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Sampling method: hds, piecewise-constant, bilinear, rejection, uniform; for a BRDF file
    /// hds, cosine, ggx-fit, piecewise-constant.
    #[arg(long, value_enum, default_value_t = MethodName::Hds)]
    pub method: MethodName,
    #[command(flatten)]
    pub brdf: BrdfOptions,
}
