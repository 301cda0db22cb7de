//! `gonio info|sample|pdf|invert|check|plot|bench FILE --incident THETA,PHI` on a BRDF file, and
//! its alias `gonio brdf info|sample|…`: tabulated BRDFs (MERL `.binary`, UTIA `.bin`, gonio BRDF
//! JSON; the format is recognised from the content, [`sniff`]). `main` sends a top-level command
//! whose FILE is a BRDF file here ([`route`]).
//!
//! Directions are in the local shading frame (z the normal, x the tangent), both pointing away
//! from the surface; `--incident` gives ω_i's polar angle and azimuth in degrees.

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use gonio::brdf::{
    read_any, BrdfMethod, BrdfSampler, CosineBrdf, GgxFit, IncidentSampler, MerlOptions, MerlRaw,
    PerSliceConstant, SamplerOptions, TabulatedBrdf,
};
use gonio::sampler::direction;
use gonio::sequence::{Sequence, SequenceKind};
use gonio::{Sampler, Vec3};
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

/// `gonio brdf …`.
#[derive(Debug, Args)]
pub struct BrdfArgs {
    #[command(subcommand)]
    command: BrdfCommand,
}

#[derive(Debug, Subcommand)]
enum BrdfCommand {
    /// Format, grids, slices, memory, build time (MERL: the resampling error).
    Info(Common),
    /// Sample outgoing directions: CSV `u,v,x,y,z,pdf,w_r,w_g,w_b`.
    Sample(SampleArgs),
    /// The pdf of each direction of `--directions` (CSV `x,y,z` per line): `x,y,z,pdf`.
    Pdf(DirArgs),
    /// The point of the square of each direction of `--directions`: `x,y,z,u,v`.
    Invert(DirArgs),
    /// The check battery at the incident direction; exit 3 if an item fails.
    Check(CheckArgs),
    /// Draw the slice f·cos θ_o over the outgoing hemisphere and its samples (PNG or SVG).
    Plot(PlotArgs),
    /// Time per sample of every method at the incident direction, against the light map of the
    /// same slice diagram (`HemisphereMap`), and the sampler's memory.
    Bench(BenchArgs),
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum MethodArg {
    Hds,
    Cosine,
    GgxFit,
    PiecewiseConstant,
}

#[derive(Debug, Args)]
struct Common {
    /// The BRDF file.
    file: PathBuf,
    /// Incident direction (required): polar angle and azimuth in degrees, e.g. `30,0`.
    #[arg(long, value_name = "THETA,PHI", value_parser = parse_incident)]
    incident: (f64, f64),
    /// MERL resampling: polar nodes 0°…90° (incident and outgoing).
    #[arg(long, default_value_t = 46)]
    merl_theta: usize,
    /// MERL resampling: relative azimuth nodes.
    #[arg(long, default_value_t = 90)]
    merl_phi: usize,
    /// Slice grid (when the table's own grid cannot be used): polar nodes 0°…90°.
    #[arg(long, default_value_t = 46)]
    theta_o: usize,
    /// Slice grid: azimuth nodes.
    #[arg(long, default_value_t = 90)]
    phi_o: usize,
}

#[derive(Debug, Args)]
struct SampleArgs {
    #[command(flatten)]
    common: Common,
    /// Number of samples.
    #[arg(
        short = 'n',
        long,
        visible_alias = "samples",
        default_value_t = 10,
        conflicts_with = "points"
    )]
    count: usize,
    /// Point sequence on the unit square (as `gonio sample`: Halton from index 1; the default
    /// here is iid points of `--seed`).
    #[arg(long, default_value = "random")]
    sequence: SequenceKind,
    /// Seed (the random stream, Sobol' scrambling; Halton ignores it).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Map these points instead of a sequence: a CSV file with columns `u,v` (by header name;
    /// `-` reads standard input), every point checked before anything is written.
    #[arg(long, value_name = "UV.csv")]
    points: Option<String>,
    /// Output file (`-` or absent: standard output).
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    output: Option<PathBuf>,
    /// Sampling method.
    #[arg(long, value_enum, default_value = "hds")]
    method: MethodArg,
}

#[derive(Debug, Args)]
struct DirArgs {
    #[command(flatten)]
    common: Common,
    /// CSV file of directions `x,y,z` (`-` for stdin).
    #[arg(long)]
    directions: PathBuf,
    /// Sampling method.
    #[arg(long, value_enum, default_value = "hds")]
    method: MethodArg,
}

#[derive(Debug, Args)]
struct CheckArgs {
    #[command(flatten)]
    common: Common,
    /// The cheaper battery (about ten times faster, same tolerances).
    #[arg(long)]
    quick: bool,
    /// Seed of every random item.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

#[derive(Debug, Args)]
struct PlotArgs {
    #[command(flatten)]
    common: Common,
    /// Output image; the extension (`.png` or `.svg`) picks the format.
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    output: PathBuf,
    /// Number of samples drawn as dots.
    #[arg(long, default_value_t = 2000)]
    samples: usize,
    /// Seed of the iid points of the square.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Sampling method of the dots.
    #[arg(long, value_enum, default_value = "hds")]
    method: MethodArg,
    /// Image width in pixels.
    #[arg(long, default_value_t = 1200)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 700)]
    height: u32,
}

#[derive(Debug, Args)]
struct BenchArgs {
    #[command(flatten)]
    common: Common,
    /// Samples per method.
    #[arg(short = 'n', long, default_value_t = 1_000_000)]
    count: usize,
}

fn parse_incident(s: &str) -> Result<(f64, f64), String> {
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

struct Loaded {
    brdf: TabulatedBrdf,
    format: &'static str,
    merl_error: Option<(f64, usize)>,
}

fn load(c: &Common) -> Result<Loaded> {
    let bytes = read_bytes(&c.file)?;
    let merl = MerlOptions {
        n_theta: c.merl_theta,
        n_phi: c.merl_phi,
    };
    let brdf = read_any(&bytes, &merl).with_context(|| c.file.display().to_string())?;
    let first = gonio::brdf::strip_json_bom(&bytes)
        .iter()
        .find(|b| !b.is_ascii_whitespace());
    let (format, merl_error) = if first == Some(&b'{') {
        ("gonio BRDF JSON", None)
    } else if bytes.len() as u64 == gonio::brdf::UTIA_SIZE {
        ("UTIA raw", None)
    } else {
        let raw = MerlRaw::parse(&bytes)?;
        (
            "MERL binary",
            Some((raw.resampling_error(&brdf), raw.no_data())),
        )
    };
    Ok(Loaded {
        brdf,
        format,
        merl_error,
    })
}

fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    crate::input::read_regular(
        path,
        &path.display().to_string(),
        crate::input::FileKind::Brdf,
    )
}

/// The commands a BRDF file may follow at the top level (`gonio sample FILE --incident …`).
pub const COMMANDS: [&str; 7] = ["info", "sample", "pdf", "invert", "check", "plot", "bench"];

/// The BRDF format of a file, from its content (not its name): `MERL binary` (a 12-byte header
/// of three int32 dimensions matching the length, or 90 × 90 × 180), `UTIA raw` (exactly
/// `UTIA_SIZE` bytes) or `gonio BRDF JSON` (a JSON object whose `format` is `"gonio-brdf"`, which
/// tells it from a diagram JSON; a file that does not parse counts when its first 4 KiB name
/// `"gonio-brdf"`, so that its own reader reports the error). `None` for anything else, and for
/// what is not a readable regular file (the command then reports it as usual).
pub fn sniff(path: &Path) -> Option<&'static str> {
    use std::io::Read;
    let meta = std::fs::metadata(path).ok()?;
    if !meta.is_file()
        || meta.len() > gonio::input::file::read_limit(gonio::input::file::FileKind::Brdf)
    {
        return None;
    }
    let mut head = Vec::with_capacity(4096);
    std::fs::File::open(path)
        .ok()?
        .take(4096)
        .read_to_end(&mut head)
        .ok()?;
    let first = gonio::brdf::strip_json_bom(&head)
        .iter()
        .find(|b| !b.is_ascii_whitespace());
    if first == Some(&b'{') {
        #[derive(serde::Deserialize)]
        struct Probe {
            format: Option<serde_json::Value>,
        }
        let named = |v: &[u8]| v.windows(12).any(|w| w == b"\"gonio-brdf\"");
        let bytes = std::fs::read(path).ok()?;
        return match serde_json::from_slice::<Probe>(gonio::brdf::strip_json_bom(&bytes)) {
            Ok(p) => (p.format.as_ref().and_then(|f| f.as_str()) == Some("gonio-brdf"))
                .then_some("gonio BRDF JSON"),
            Err(_) => named(&head).then_some("gonio BRDF JSON"),
        };
    }
    if meta.len() == gonio::brdf::UTIA_SIZE {
        return Some("UTIA raw");
    }
    if head.len() >= 12 {
        let dim = |k: usize| {
            i32::from_le_bytes([
                head[4 * k],
                head[4 * k + 1],
                head[4 * k + 2],
                head[4 * k + 3],
            ]) as i64
        };
        let (a, b, c) = (dim(0), dim(1), dim(2));
        let length = a
            .checked_mul(b)
            .and_then(|ab| ab.checked_mul(c))
            .and_then(|abc| abc.checked_mul(24))
            .and_then(|n| n.checked_add(12));
        if (a > 0 && b > 0 && c > 0 && length == Some(meta.len() as i64))
            || (a, b, c) == (90, 90, 180)
        {
            return Some("MERL binary");
        }
    }
    None
}

/// Rewrites `gonio [GLOBAL…] CMD … FILE …` as `gonio [GLOBAL…] brdf CMD … FILE …` when CMD is one
/// of [`COMMANDS`] and it has `--incident` (an option of BRDF files only: the BRDF reader then
/// reports on FILE, whatever it is). `Err` holds the usage message when one of its plain arguments
/// names a BRDF file ([`sniff`]) and `--incident` is missing.
pub fn route(
    args: Vec<std::ffi::OsString>,
) -> std::result::Result<Vec<std::ffi::OsString>, String> {
    // The subcommand: the first argument that is neither an option nor the value of --tolerance.
    let mut k = 1;
    while k < args.len() {
        let a = args[k].to_string_lossy();
        if a == "--tolerance" {
            k += 2;
        } else if a.starts_with('-') {
            k += 1;
        } else {
            break;
        }
    }
    let Some(cmd) = args.get(k).map(|a| a.to_string_lossy().into_owned()) else {
        return Ok(args);
    };
    if !COMMANDS.contains(&cmd.as_str()) {
        return Ok(args);
    }
    let rest = &args[k + 1..];
    let has_incident = rest.iter().any(|a| {
        let a = a.to_string_lossy();
        a == "--incident" || a.starts_with("--incident=")
    });
    // `--incident` exists for BRDF files only: with it the command goes to the BRDF tree whatever
    // the sniffer says, so that a broken BRDF file gets its reader's message (a missing file, a
    // FIFO, a MERL header that lies), not "unexpected argument '--incident'".
    if !has_incident {
        let found = rest
            .iter()
            .filter(|a| !a.to_string_lossy().starts_with('-'))
            .find_map(|a| sniff(Path::new(a)).map(|f| (a.to_string_lossy().into_owned(), f)));
        if let Some((file, format)) = found {
            return Err(format!(
                "{file} is a BRDF file ({format}): `gonio {cmd}` needs the incident direction \
                 --incident THETA,PHI in degrees, e.g. --incident 30,0 (see `gonio brdf {cmd} --help`)"
            ));
        }
        return Ok(args);
    }
    let mut out = args[..k].to_vec();
    out.push("brdf".into());
    out.extend_from_slice(&args[k..]);
    Ok(out)
}

/// The family blob (docs/TABLES.md, "Families") of the BRDF file `path` with the default MERL
/// grid and slice grid: every incident slice, so no incident direction is needed (`gonio tables`).
pub fn family_tables(path: &Path, precision: gonio::mapping::blob::Precision) -> Result<Vec<u8>> {
    let bytes = read_bytes(path)?;
    let brdf =
        read_any(&bytes, &MerlOptions::default()).with_context(|| path.display().to_string())?;
    let sampler = BrdfSampler::new(brdf, &SamplerOptions::default())
        .with_context(|| path.display().to_string())?;
    sampler
        .tables(precision)
        .with_context(|| path.display().to_string())
}

fn sampler_of(c: &Common, brdf: TabulatedBrdf) -> Result<BrdfSampler> {
    let opts = SamplerOptions {
        theta_o: c.theta_o,
        phi_o: c.phi_o,
        force_resample: false,
    };
    Ok(BrdfSampler::new(brdf, &opts)?)
}

fn incident(c: &Common) -> Vec3 {
    direction(c.incident.0.to_radians(), c.incident.1.to_radians())
}

fn read_directions(path: &Path) -> Result<Vec<Vec3>> {
    let reader: Box<dyn BufRead> = if path.as_os_str() == "-" {
        Box::new(std::io::BufReader::new(std::io::stdin()))
    } else {
        Box::new(std::io::BufReader::new(
            std::fs::File::open(path).with_context(|| path.display().to_string())?,
        ))
    };
    let mut out = vec![];
    for (k, line) in reader.lines().enumerate() {
        let line = line?;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') || t.starts_with('x') {
            continue;
        }
        let v: Vec<f64> = t
            .split(',')
            .map(|f| f.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| anyhow::anyhow!("{}:{}: {e}: `{t}`", path.display(), k + 1))?;
        if v.len() != 3 {
            bail!(
                "{}:{}: expected x,y,z, got {} fields",
                path.display(),
                k + 1,
                v.len()
            );
        }
        let d = gonio::sampler::normalize([v[0], v[1], v[2]])
            .ok_or_else(|| anyhow::anyhow!("{}:{}: not a direction", path.display(), k + 1))?;
        out.push(d);
    }
    Ok(out)
}

fn with_method<T>(m: MethodArg, s: &BrdfSampler, f: impl FnOnce(&dyn BrdfMethod) -> T) -> T {
    match m {
        MethodArg::Hds => f(s),
        MethodArg::Cosine => f(&CosineBrdf::new(s.brdf())),
        MethodArg::GgxFit => f(&GgxFit::fit(s.brdf())),
        MethodArg::PiecewiseConstant => f(&PerSliceConstant::new(s, 128)),
    }
}

/// Runs `gonio brdf …`; `Ok(false)` when `check` found a failure.
pub fn run(a: &BrdfArgs) -> Result<bool> {
    let out = std::io::stdout();
    let mut w = std::io::BufWriter::new(out.lock());
    match &a.command {
        BrdfCommand::Info(c) => {
            let l = load(c)?;
            let b = &l.brdf;
            let t0 = std::time::Instant::now();
            let s = sampler_of(c, b.clone())?;
            let build = t0.elapsed().as_secs_f64();
            let deg = |v: &[f64]| {
                format!(
                    "{} nodes {:.4}°…{:.4}°",
                    v.len(),
                    v[0].to_degrees(),
                    v[v.len() - 1].to_degrees()
                )
            };
            writeln!(w, "file: {}", c.file.display())?;
            writeln!(w, "format: {}", l.format)?;
            writeln!(
                w,
                "symmetry: {:?}, channels: {}",
                b.symmetry(),
                b.channels()
            )?;
            writeln!(w, "theta_i: {}", deg(b.theta_i()))?;
            writeln!(w, "phi_i: {}", deg(b.phi_i()))?;
            writeln!(w, "theta_o: {}", deg(b.theta_o()))?;
            writeln!(w, "phi_o: {}", deg(b.phi_o()))?;
            let (n, empty) = s.slice_counts();
            let (gt, gp) = s.grid();
            writeln!(
                w,
                "slices: {n} ({empty} without reflectance), grid {} θ_o × {} φ_o ({})",
                gt.len(),
                gp.len(),
                if s.resampled() {
                    "resampled"
                } else {
                    "the table's own"
                }
            )?;
            writeln!(
                w,
                "memory: {:.2} MB (table {:.2} MB), build {:.3} s",
                s.memory_bytes() as f64 / 1e6,
                b.memory_bytes() as f64 / 1e6,
                build
            )?;
            if let Some((e, nd)) = l.merl_error {
                writeln!(
                    w,
                    "merl: {nd} values without data; resampling error (mean L1 of the normalised f·cos at θ_i = 0,30,60,75,85°): {e:.4}"
                )?;
            }
            let wi = incident(c);
            writeln!(
                w,
                "albedo at incident {:?}: {:.6} (luminance)",
                c.incident,
                gonio::brdf::scalar_albedo(b, wi)
            )?;
            Ok(true)
        }
        BrdfCommand::Sample(sa) => {
            let l = load(&sa.common)?;
            let s = sampler_of(&sa.common, l.brdf)?;
            let wi = incident(&sa.common);
            // The points: a CSV file, checked whole before anything is written, or a sequence.
            let points: Vec<[f64; 2]> = match &sa.points {
                Some(path) => {
                    let rows = crate::csv_in::read_columns(path, ["u", "v"])?;
                    let mut pts = Vec::with_capacity(rows.len());
                    for r in &rows {
                        for (k, name) in ["u", "v"].iter().enumerate() {
                            let x = r.values[k];
                            if !(0.0..=1.0).contains(&x) {
                                anyhow::bail!(
                                    "{}: {name} = {x} is outside the unit square [0, 1]",
                                    r.locate(path)
                                );
                            }
                        }
                        pts.push(r.values);
                    }
                    pts
                }
                None => {
                    let seq = match sa.sequence {
                        SequenceKind::Halton => {
                            Sequence::Halton(gonio::sequence::Halton::with_skip(1))
                        }
                        kind => Sequence::new(kind, sa.seed),
                    };
                    (0..sa.count as u64).map(|k| seq.point(k)).collect()
                }
            };
            let mut out = crate::output::Output::create(sa.output.as_deref())?;
            with_method(sa.method, &s, |m| -> Result<()> {
                writeln!(out, "u,v,x,y,z,pdf,w_r,w_g,w_b")?;
                for u in &points {
                    let r = m.sample(wi, *u);
                    let d = r.direction;
                    writeln!(
                        out,
                        "{},{},{},{},{},{},{},{},{}",
                        u[0], u[1], d[0], d[1], d[2], r.pdf, r.weight[0], r.weight[1], r.weight[2]
                    )?;
                }
                Ok(())
            })?;
            out.finish()?;
            Ok(true)
        }
        BrdfCommand::Pdf(da) | BrdfCommand::Invert(da) => {
            let is_pdf = matches!(a.command, BrdfCommand::Pdf(_));
            let l = load(&da.common)?;
            let s = sampler_of(&da.common, l.brdf)?;
            let wi = incident(&da.common);
            let dirs = read_directions(&da.directions)?;
            with_method(da.method, &s, |m| -> Result<()> {
                writeln!(w, "{}", if is_pdf { "x,y,z,pdf" } else { "x,y,z,u,v" })?;
                for d in dirs {
                    if is_pdf {
                        writeln!(w, "{},{},{},{}", d[0], d[1], d[2], m.pdf(wi, d))?;
                    } else {
                        match m.invert(wi, d) {
                            Some(u) => writeln!(w, "{},{},{},{},{}", d[0], d[1], d[2], u[0], u[1])?,
                            None => writeln!(w, "{},{},{},nan,nan", d[0], d[1], d[2])?,
                        }
                    }
                }
                Ok(())
            })?;
            Ok(true)
        }
        BrdfCommand::Plot(pa) => {
            let c = &pa.common;
            let l = load(c)?;
            let s = sampler_of(c, l.brdf)?;
            let wi = incident(c);
            let seq = Sequence::new(SequenceKind::Random, pa.seed);
            let samples: Vec<Vec3> = with_method(pa.method, &s, |m| {
                (0..pa.samples as u64)
                    .map(|k| m.sample(wi, seq.point(k)).direction)
                    .filter(|d| d[2] >= 0.0)
                    .collect()
            });
            let Some(diagram) = (0..s.slice_counts().0).find_map(|k| s.slice(k)) else {
                bail!(
                    "{}: no slice holds reflectance above the horizon",
                    c.file.display()
                );
            };
            let inc = IncidentSampler::new(&s, wi);
            let b = s.brdf();
            let value = |d: Vec3| b.scalar(b.eval(wi, d)) * d[2].max(0.0);
            let name = c
                .file
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| c.file.display().to_string());
            let method = with_method(pa.method, &s, |m| m.name());
            let title = format!(
                "{name} ({}) — slice at θ_i = {}°, φ_i = {}°, samples of `{method}`",
                l.format, c.incident.0, c.incident.1
            );
            crate::plot::brdf::render_slice(
                &crate::plot::brdf::SlicePlot {
                    title,
                    sampler: &inc,
                    method,
                    diagram: diagram.diagram(),
                    value: &value,
                    samples: &samples,
                    mirror: [-wi[0], -wi[1], wi[2]],
                },
                &pa.output,
                pa.width,
                pa.height,
            )?;
            Ok(true)
        }
        BrdfCommand::Check(ca) => {
            let c = &ca.common;
            let l = load(c)?;
            let s = sampler_of(c, l.brdf)?;
            let inc = IncidentSampler::new(&s, incident(c));
            let opts = if ca.quick {
                gonio::BatteryOptions::quick()
            } else {
                gonio::BatteryOptions::default()
            }
            .with_seed(ca.seed);
            let report = gonio::run_battery(&inc, &opts);
            writeln!(w, "incident {:?}: albedo {:.6}", c.incident, inc.albedo())?;
            writeln!(w, "{report}")?;
            Ok(report.passed)
        }
        BrdfCommand::Bench(ba) => {
            let l = load(&ba.common)?;
            let s = sampler_of(&ba.common, l.brdf)?;
            let wi = incident(&ba.common);
            let n = ba.count.max(1);
            let mut us = vec![[0.0; 2]; n];
            Sequence::new(SequenceKind::Random, 1).fill(0, &mut us);
            writeln!(w, "method,ns_per_sample,mean_weight_lum,weight_variance")?;
            // The light map: one slice's HemisphereMap, sampled the same way.
            if let Some(map) = (0..s.slice_counts().0).find_map(|k| s.slice(k)) {
                let t0 = std::time::Instant::now();
                let mut acc = 0.0;
                for u in &us {
                    acc += map.sample(*u).pdf;
                }
                let ns = t0.elapsed().as_secs_f64() * 1e9 / n as f64;
                std::hint::black_box(acc);
                writeln!(w, "light-map,{ns:.1},,")?;
            }
            for m in [
                MethodArg::Hds,
                MethodArg::Cosine,
                MethodArg::GgxFit,
                MethodArg::PiecewiseConstant,
            ] {
                with_method(m, &s, |m| -> Result<()> {
                    let t0 = std::time::Instant::now();
                    let (mut s1, mut s2) = (0.0, 0.0);
                    for u in &us {
                        let r = m.sample(wi, *u);
                        let v = s.brdf().scalar(r.weight);
                        s1 += v;
                        s2 += v * v;
                    }
                    let ns = t0.elapsed().as_secs_f64() * 1e9 / n as f64;
                    let mean = s1 / n as f64;
                    let var = if mean > 0.0 {
                        s2 / n as f64 / (mean * mean) - 1.0
                    } else {
                        f64::NAN
                    };
                    writeln!(w, "{},{ns:.1},{mean:.6},{var:.3e}", m.name())?;
                    Ok(())
                })?;
            }
            writeln!(
                w,
                "# memory of the HDS sampler: {:.2} MB",
                s.memory_bytes() as f64 / 1e6
            )?;
            Ok(true)
        }
    }
}
