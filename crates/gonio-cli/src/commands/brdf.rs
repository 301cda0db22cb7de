//! A tabulated BRDF file (MERL `.binary`, UTIA `.bin`, gonio BRDF JSON; the format is recognised
//! from the content, [`sniff`]) is one more input kind of `gonio info|sample|pdf|invert|check|plot|
//! bench FILE --incident THETA,PHI`: each of those commands asks [`input`] first and comes here for
//! a BRDF file, with its own parsed arguments (the same options as for a luminaire: `--points`,
//! `--sequence`, `--seed`, `-o`, `--format`, `--method`, `--json`). `gonio brdf CMD …` is the same
//! commands with the input required to be a BRDF file ([`run`]). Nothing rewrites argv.
//!
//! Directions are in the local shading frame (z the normal, x the tangent), both pointing away
//! from the surface; `--incident` gives ω_i's polar angle and azimuth in degrees. At a fixed ω_i a
//! BRDF method is a [`Sampler`] of ω_o ([`IncidentSampler`]), so `pdf`, `invert` and `check` run the
//! same code as for every other input.

use crate::args::{
    BenchArgs, BrdfOptions, CheckArgs, DirectionsArgs, InfoArgs, MethodName, PlotArgs, PlotKind,
    SampleArgs, UsageError,
};
use crate::settings::Settings;
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use gonio::brdf::{
    read_any, BrdfMethod, BrdfSampler, CosineBrdf, GgxFit, IncidentSampler, MerlOptions, MerlRaw,
    PerSliceConstant, SamplerOptions, TabulatedBrdf,
};
use gonio::sampler::direction;
use gonio::sequence::{Sequence, SequenceKind};
use gonio::{Point2, Sampler, Vec3};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// `gonio brdf CMD FILE --incident THETA,PHI …`: the top-level commands on a BRDF file, by name
/// (the same arguments; the input must be a BRDF file).
#[derive(Debug, Args)]
pub struct BrdfArgs {
    #[command(subcommand)]
    command: BrdfCommand,
}

#[derive(Debug, Subcommand)]
enum BrdfCommand {
    /// Format, grids, slices, memory, albedo at the incident direction.
    Info(InfoArgs),
    /// Outgoing directions with their exact pdf and weights f·cos/pdf (`w_r,w_g,w_b`).
    Sample(SampleArgs),
    /// The pdf of each given outgoing direction.
    Pdf(DirectionsArgs),
    /// The point of the square of each given outgoing direction.
    Invert(DirectionsArgs),
    /// The test battery at the incident direction.
    Check(CheckArgs),
    /// The slice f·cos θ_o at the incident direction with samples over it.
    Plot(PlotArgs),
    /// Time and weight variance of every method.
    Bench(BenchArgs),
}

/// Runs `gonio brdf CMD …`; `Ok(false)` when `check` found a failure.
pub fn run(a: &BrdfArgs, s: &Settings) -> Result<bool> {
    let need = |cmd: &str, file: &str, o: &BrdfOptions| -> Result<Input> {
        match input(cmd, file, o)? {
            Some(b) => Ok(b),
            None => Err(UsageError(format!(
                "`gonio brdf {cmd}` needs the incident direction --incident THETA,PHI in degrees, \
                 e.g. --incident 30,0"
            ))
            .into()),
        }
    };
    match &a.command {
        BrdfCommand::Info(x) => info(&need("info", &x.input, &x.brdf)?, x).map(|()| true),
        BrdfCommand::Sample(x) => {
            sample(&need("sample", &x.input, &x.run.brdf)?, x, s).map(|()| true)
        }
        BrdfCommand::Pdf(x) => pdf(&need("pdf", &x.input, &x.run.brdf)?, x).map(|()| true),
        BrdfCommand::Invert(x) => invert(&need("invert", &x.input, &x.run.brdf)?, x).map(|()| true),
        BrdfCommand::Check(x) => check(&need("check", &x.input, &x.brdf)?, x, s),
        BrdfCommand::Plot(x) => plot(&need("plot", &x.input, &x.brdf)?, x).map(|()| true),
        BrdfCommand::Bench(x) => bench(&need("bench", &x.input, &x.brdf)?, x).map(|()| true),
    }
}

/// A BRDF input: the file, the incident direction and the grids.
#[derive(Debug, Clone)]
pub struct Input {
    file: PathBuf,
    /// (θ_i, φ_i) in degrees.
    incident: (f64, f64),
    merl: MerlOptions,
    theta_o: usize,
    phi_o: usize,
}

/// The BRDF input of `gonio CMD FILE`: `Some` when `--incident` is given (the BRDF reader then
/// reports on FILE, whatever it is, so a broken BRDF file gets its reader's message); a usage
/// error when FILE is a BRDF file by its content and `--incident` is missing, or when a BRDF
/// option is given for another input (it would be ignored); `None` otherwise.
pub fn input(cmd: &str, file: &str, o: &BrdfOptions) -> Result<Option<Input>> {
    // Inputs that are not BRDFs by their name (the built-in example, a photometric file, an
    // image): a BRDF option is refused for them as for any other input.
    let not_brdf = matches!(
        crate::load::input_kind(file),
        Ok(gonio::input::InputKind::Example
            | gonio::input::InputKind::Ies
            | gonio::input::InputKind::Eulumdat
            | gonio::input::InputKind::EnvMap)
    );
    if let (Some(opt), true) = (o.given(), not_brdf) {
        return Err(UsageError(format!(
            "{opt} applies to BRDF files (MERL, UTIA, gonio BRDF JSON) only; {file} is not one"
        ))
        .into());
    }
    if let Some(incident) = o.incident {
        let merl = MerlOptions::default();
        let opts = SamplerOptions::default();
        return Ok(Some(Input {
            file: PathBuf::from(file),
            incident,
            merl: MerlOptions {
                n_theta: o.merl_theta.unwrap_or(merl.n_theta),
                n_phi: o.merl_phi.unwrap_or(merl.n_phi),
            },
            theta_o: o.theta_o.unwrap_or(opts.theta_o),
            phi_o: o.phi_o.unwrap_or(opts.phi_o),
        }));
    }
    if let Some(format) = sniff(Path::new(file)) {
        return Err(UsageError(format!(
            "{file} is a BRDF file ({format}): `gonio {cmd}` needs the incident direction \
             --incident THETA,PHI in degrees, e.g. --incident 30,0"
        ))
        .into());
    }
    if let Some(opt) = o.given() {
        return Err(UsageError(format!(
            "{opt} applies to BRDF files (MERL, UTIA, gonio BRDF JSON) only"
        ))
        .into());
    }
    Ok(None)
}

struct Loaded {
    brdf: TabulatedBrdf,
    format: &'static str,
    merl_error: Option<(f64, usize)>,
}

fn load(b: &Input) -> Result<Loaded> {
    let bytes = read_bytes(&b.file)?;
    let brdf = read_any(&bytes, &b.merl).with_context(|| b.file.display().to_string())?;
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

fn sampler_of(b: &Input, brdf: TabulatedBrdf) -> Result<BrdfSampler> {
    let opts = SamplerOptions {
        theta_o: b.theta_o,
        phi_o: b.phi_o,
        force_resample: false,
    };
    Ok(BrdfSampler::new(brdf, &opts)?)
}

fn incident(b: &Input) -> Vec3 {
    direction(b.incident.0.to_radians(), b.incident.1.to_radians())
}

/// The BRDF method of `--method`, or a usage error for a method of diagrams only.
fn brdf_method(m: MethodName) -> Result<MethodName> {
    match m {
        MethodName::Hds
        | MethodName::Cosine
        | MethodName::GgxFit
        | MethodName::PiecewiseConstant => Ok(m),
        _ => Err(UsageError(format!(
            "--method {}: a method of diagrams only; BRDF files take hds, cosine, ggx-fit or \
             piecewise-constant",
            clap::ValueEnum::to_possible_value(&m)
                .map_or_else(String::new, |v| v.get_name().to_owned())
        ))
        .into()),
    }
}

fn with_method<T>(m: MethodName, s: &BrdfSampler, f: impl FnOnce(&dyn BrdfMethod) -> T) -> T {
    match m {
        MethodName::Cosine => f(&CosineBrdf::new(s.brdf())),
        MethodName::GgxFit => f(&GgxFit::fit(s.brdf())),
        MethodName::PiecewiseConstant => f(&PerSliceConstant::new(s, 128)),
        _ => f(s),
    }
}

/// `gonio info BRDF --incident …` (text, or one JSON object with `--json`).
pub fn info(b: &Input, a: &InfoArgs) -> Result<()> {
    let l = load(b)?;
    let t = &l.brdf;
    let t0 = std::time::Instant::now();
    let s = sampler_of(b, t.clone())?;
    let build = t0.elapsed().as_secs_f64();
    let (n, empty) = s.slice_counts();
    let (gt, gp) = s.grid();
    let wi = incident(b);
    let albedo = gonio::brdf::scalar_albedo(t, wi);
    let nodes = |v: &[f64]| (v.len(), v[0].to_degrees(), v[v.len() - 1].to_degrees());
    let text = if a.json {
        let grid = |v: &[f64]| {
            let (n, lo, hi) = nodes(v);
            serde_json::json!({ "nodes": n, "min_deg": lo, "max_deg": hi })
        };
        let v = serde_json::json!({
            "file": b.file.display().to_string(),
            "format": l.format,
            "symmetry": format!("{:?}", t.symmetry()),
            "channels": t.channels(),
            "theta_i": grid(t.theta_i()),
            "phi_i": grid(t.phi_i()),
            "theta_o": grid(t.theta_o()),
            "phi_o": grid(t.phi_o()),
            "slices": n,
            "empty_slices": empty,
            "slice_grid": [gt.len(), gp.len()],
            "resampled": s.resampled(),
            "memory_bytes": s.memory_bytes(),
            "table_bytes": t.memory_bytes(),
            "build_time_ms": build * 1e3,
            "merl_no_data": l.merl_error.map(|(_, nd)| nd),
            "merl_resampling_error": l.merl_error.map(|(e, _)| e),
            "incident_deg": [b.incident.0, b.incident.1],
            "albedo": albedo,
        });
        serde_json::to_string_pretty(&v)? + "\n"
    } else {
        let deg = |v: &[f64]| {
            let (n, lo, hi) = nodes(v);
            format!("{n} nodes {lo:.4}°…{hi:.4}°")
        };
        let mut w = String::new();
        use std::fmt::Write as _;
        writeln!(w, "file: {}", b.file.display())?;
        writeln!(w, "format: {}", l.format)?;
        writeln!(
            w,
            "symmetry: {:?}, channels: {}",
            t.symmetry(),
            t.channels()
        )?;
        writeln!(w, "theta_i: {}", deg(t.theta_i()))?;
        writeln!(w, "phi_i: {}", deg(t.phi_i()))?;
        writeln!(w, "theta_o: {}", deg(t.theta_o()))?;
        writeln!(w, "phi_o: {}", deg(t.phi_o()))?;
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
            t.memory_bytes() as f64 / 1e6,
            build
        )?;
        if let Some((e, nd)) = l.merl_error {
            writeln!(
                w,
                "merl: {nd} values without data; resampling error (mean L1 of the normalised f·cos at θ_i = 0,30,60,75,85°): {e:.4}"
            )?;
        }
        writeln!(
            w,
            "albedo at incident {:?}: {albedo:.6} (luminance)",
            b.incident
        )?;
        w
    };
    crate::output::print(&text)
}

/// `gonio sample BRDF --incident …`: rows `u,v,x,y,z,pdf,w_r,w_g,w_b` (the weight f·cos/pdf of
/// each channel; 0 where the method has no density) through the same points and writer as every
/// input ([`super::sample::emit`]).
pub fn sample(b: &Input, a: &SampleArgs, settings: &Settings) -> Result<()> {
    let method = brdf_method(a.run.method)?;
    let l = load(b)?;
    let s = sampler_of(b, l.brdf)?;
    let wi = incident(b);
    with_method(method, &s, |m| {
        super::sample::emit(
            a,
            settings,
            "u,v,x,y,z,pdf,w_r,w_g,w_b",
            9,
            &|pts: &[Point2], rows: &mut [f64]| {
                rows.par_chunks_mut(9).zip(pts).for_each(|(row, u)| {
                    let r = m.sample(wi, *u);
                    let (d, w) = (r.direction, r.weight);
                    row.copy_from_slice(&[u[0], u[1], d[0], d[1], d[2], r.pdf, w[0], w[1], w[2]]);
                });
            },
        )
    })
}

/// `gonio pdf BRDF --incident …`: the pdf of each outgoing direction, as for every input.
pub fn pdf(b: &Input, a: &DirectionsArgs) -> Result<()> {
    at_incident(b, a.run.method, |s| super::directions::write_pdf(s, a))
}

/// `gonio invert BRDF --incident …`: the point of the square of each outgoing direction, as for
/// every input (empty fields and a warning where there is none).
pub fn invert(b: &Input, a: &DirectionsArgs) -> Result<()> {
    at_incident(b, a.run.method, |s| super::directions::write_invert(s, a))
}

/// `gonio check BRDF --incident …`: the battery on the method at ω_i (its flux check integrates
/// the albedo), reported as for every input after a line with the incident direction and albedo.
pub fn check(b: &Input, a: &CheckArgs, settings: &Settings) -> Result<bool> {
    at_incident(b, a.method, |at| {
        let head = format!("incident {:?}: albedo {:.6}\n", b.incident, at.albedo());
        let extra = serde_json::json!({
            "incident_deg": [b.incident.0, b.incident.1],
            "albedo": at.albedo(),
        });
        let opts = super::check::options(a)?;
        super::check::report(at, opts, a, settings, None, &head, extra)
    })
}

/// Runs `f` on the sampler of the BRDF file `b` at its incident direction, by the command's
/// `--method` (a sampler over directions, as any input's).
fn at_incident<T>(
    b: &Input,
    method: MethodName,
    f: impl FnOnce(&IncidentSampler) -> Result<T>,
) -> Result<T> {
    let method = brdf_method(method)?;
    let l = load(b)?;
    let s = sampler_of(b, l.brdf)?;
    with_method(method, &s, |m| {
        f(&IncidentSampler::of(m, s.brdf(), incident(b)))
    })
}

/// `gonio plot BRDF --incident … -o OUT`: the slice at ω_i with the method's samples over it.
pub fn plot(b: &Input, a: &PlotArgs) -> Result<()> {
    if a.kind != PlotKind::Polar {
        return Err(UsageError(
            "--kind: a BRDF file draws one picture, its slice at the incident direction (the default kind)".into(),
        )
        .into());
    }
    let method = brdf_method(a.method)?;
    let l = load(b)?;
    let s = sampler_of(b, l.brdf)?;
    let wi = incident(b);
    let Some(diagram) = (0..s.slice_counts().0).find_map(|k| s.slice(k)) else {
        bail!(
            "{}: no slice holds reflectance above the horizon",
            b.file.display()
        );
    };
    let t = s.brdf();
    let value = |d: Vec3| t.scalar(t.eval(wi, d)) * d[2].max(0.0);
    let name = b
        .file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| b.file.display().to_string());
    let seq = Sequence::new(SequenceKind::Random, a.seed);
    let n = a.samples.unwrap_or(2000);
    // One method object for the samples and the picture (a fitted lobe or per-slice tables are
    // built once).
    with_method(method, &s, |m| {
        let samples: Vec<Vec3> = (0..n as u64)
            .map(|k| m.sample(wi, seq.point(k)).direction)
            .filter(|d| d[2] >= 0.0)
            .collect();
        let at = IncidentSampler::of(m, t, wi);
        let title = format!(
            "{name} ({}) — slice at θ_i = {}°, φ_i = {}°, samples of `{}`",
            l.format,
            b.incident.0,
            b.incident.1,
            m.name()
        );
        crate::plot::brdf::render_slice(
            &crate::plot::brdf::SlicePlot {
                title,
                sampler: &at,
                method: m.name(),
                diagram: diagram.diagram(),
                value: &value,
                samples: &samples,
                mirror: [-wi[0], -wi[1], wi[2]],
            },
            &a.output,
            a.width.unwrap_or(1200),
            a.height.unwrap_or(700),
        )
    })
}

/// `gonio bench BRDF --incident …`: time per sample and weight variance of every method, and of
/// one slice's light map, on `--samples` random points.
pub fn bench(b: &Input, a: &BenchArgs) -> Result<()> {
    if let Some(opt) = [
        (!a.methods.is_empty(), "--method"),
        (a.json, "--json"),
        (a.soa, "--soa"),
        (a.threads.is_some(), "--threads"),
    ]
    .iter()
    .find_map(|&(given, name)| given.then_some(name))
    {
        return Err(UsageError(format!(
            "{opt}: the bench of a BRDF file runs every method, one thread, as CSV"
        ))
        .into());
    }
    let l = load(b)?;
    let s = sampler_of(b, l.brdf)?;
    let wi = incident(b);
    let n = a.samples.max(1);
    let mut us = vec![[0.0; 2]; n];
    Sequence::new(SequenceKind::Random, 1).fill(0, &mut us);
    let mut w = String::new();
    use std::fmt::Write as _;
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
        MethodName::Hds,
        MethodName::Cosine,
        MethodName::GgxFit,
        MethodName::PiecewiseConstant,
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
    crate::output::print(&w)
}
