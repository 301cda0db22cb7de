//! `gonio`: importance sampling of luminaire intensity distributions from the command line.
//!
//! A thin layer over the `gonio` library: argument parsing ([`args`]), input loading and sampler
//! construction ([`load`]), output formatting ([`output`]) and progress display ([`progress`]).
//! See `docs/CLI.md` for every command, format and exit code.
//!
//! Exit codes: 0 success; 1 error; 2 usage error; 3 `check` ran and an item failed.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

pub mod args;
pub mod bench;
pub mod cleanup;
pub mod commands;
pub mod csv_in;
pub mod envmap_in;
pub mod input;
pub mod load;
pub mod output;
pub mod plot;
pub mod progress;
pub mod settings;

use args::{BenchArgs, CheckArgs, ConvertArgs, DirectionsArgs, InfoArgs, PlotArgs, SampleArgs};

/// Importance sampling of goniometric diagrams (Havran–Dmitriev–Seidel mapping).
///
/// FILE is a native diagram (.json), an IES LM-63 file (.ies), a EULUMDAT file (.ldt), an
/// environment map (.hdr, .exr, .pfm), a tabulated BRDF (MERL, UTIA, gonio BRDF JSON; with
/// `--incident THETA,PHI`), or the word `example` for the built-in example luminaire.
#[derive(Debug, Parser)]
#[command(name = "gonio", version, propagate_version = true)]
struct Cli {
    /// Never show progress bars. Warnings are still printed: they say what was completed or
    /// repaired in the data, which a result must not hide.
    #[arg(short, long, global = true)]
    quiet: bool,
    /// Refine the HDS map until pdf / target is guaranteed within [1 − TOL, 1 + TOL] wherever the
    /// target is positive (e.g. 0.01); default: the paper's map on the file's grid. Applies to
    /// every command that builds the HDS map.
    #[arg(long, global = true, value_name = "TOL", value_parser = parse_tolerance)]
    tolerance: Option<f64>,
    /// Environment maps (.hdr, .exr, .pfm): what the sampling density is proportional to
    /// (default luminance, Rec. 709).
    #[arg(long, global = true, value_enum, value_name = "W")]
    weight: Option<envmap_in::WeightArg>,
    /// Environment maps: how the radiance columns r,g,b are read (default nearest: the pixel
    /// holding the direction; bilinear: between pixel centres, the interpolant the density
    /// follows).
    #[arg(long, global = true, value_enum, value_name = "L")]
    lookup: Option<envmap_in::LookupArg>,
    /// Environment maps: MIS compensation (the weight minus its solid-angle mean, clamped at 0;
    /// for use with MIS only, docs/ENVMAPS.md).
    #[arg(long, global = true)]
    mis_compensation: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Sample directions with their exact pdf (CSV `u,v,x,y,z,pdf` or binary rows).
    Sample(SampleArgs),
    /// The pdf of each given direction (CSV `x,y,z,pdf`).
    Pdf(DirectionsArgs),
    /// The point of the unit square each given direction comes from (CSV `x,y,z,u,v`).
    Invert(DirectionsArgs),
    /// Grid, power, memory, build time and pdf/target bound; header fields of photometric files.
    Info(InfoArgs),
    /// Convert between JSON, IES LM-63-2019 and EULUMDAT (by the output's extension).
    Convert(ConvertArgs),
    /// Run the statistical test battery; exit 0 only if every item passes.
    Check(CheckArgs),
    /// Draw a picture (PNG or SVG).
    Plot(PlotArgs),
    /// Measure speed and memory of the sampling methods.
    Bench(BenchArgs),
    /// One-chart UVs for a star-shaped mesh from the inverse map (OBJ with `vt`).
    Uv(commands::uv::UvArgs),
    /// Bake an equirectangular PNG (or a checkerboard) into the map's square texture.
    Bake(commands::uv::BakeArgs),
    /// Tabulated BRDFs (MERL, UTIA, gonio BRDF JSON): the commands info, sample, pdf, invert,
    /// check, plot, bench with `FILE --incident THETA,PHI`, as at the top level (`gonio sample
    /// FILE --incident 30,0`), the input required to be a BRDF file.
    Brdf(commands::brdf::BrdfArgs),
    /// Write the HDS map's tables as one blob (docs/TABLES.md) for GPU and Dr.Jit code.
    Tables(commands::tables::TablesArgs),
}

/// `--tolerance`: a number in (0, 1), the library's one rule
/// (`gonio::mapping::refine::valid_tolerance`).
fn parse_tolerance(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(t) if gonio::mapping::refine::valid_tolerance(t) => Ok(t),
        _ => Err(format!(
            "the tolerance must be a number in (0, 1), got `{s}`"
        )),
    }
}

/// Exit code of a usage error.
const EXIT_USAGE: u8 = 2;
/// Exit code of a check whose battery found a failure.
const EXIT_CHECK_FAILED: u8 = 3;

fn main() -> ExitCode {
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!(
            "gonio: error: internal error: {}{at}",
            msg.replace('\n', " ")
        );
    }));

    cleanup::install();

    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                    ExitCode::from(EXIT_USAGE)
                } else {
                    ExitCode::SUCCESS
                };
            }
            let text = e.to_string();
            // The message is the part before the first blank line (then come usage and hints).
            let first: Vec<&str> = text
                .lines()
                .map(str::trim)
                .take_while(|l| !l.is_empty())
                .collect();
            let first = first.join(" ");
            let first = first.trim_start_matches("error: ");
            eprintln!("gonio: error: {first} (see `gonio --help`)");
            return ExitCode::from(EXIT_USAGE);
        }
    };
    let settings = settings::Settings {
        quiet: cli.quiet,
        tolerance: cli.tolerance,
        env: envmap_in::EnvCliOptions {
            weight: cli.weight,
            lookup: cli.lookup,
            mis_compensation: cli.mis_compensation,
        },
    };
    let s = &settings;
    // Commands that never read an environment map refuse its options rather than ignore them
    // (the others refuse them in `load` for inputs that are not images).
    if matches!(
        cli.command,
        Command::Brdf(_) | Command::Uv(_) | Command::Bake(_)
    ) {
        if let Some(opt) = settings.env.given() {
            eprintln!(
                "gonio: error: {opt} applies to environment maps (.hdr, .exr, .pfm) only (see `gonio --help`)"
            );
            return ExitCode::from(EXIT_USAGE);
        }
    }

    use commands::brdf;
    let result = match &cli.command {
        Command::Sample(a) => by_kind(
            "sample",
            &a.input,
            &a.run.brdf,
            |b| brdf::sample(b, a, s),
            || commands::sample::run(a, s),
        )
        .map(|()| true),
        Command::Pdf(a) => by_kind(
            "pdf",
            &a.input,
            &a.run.brdf,
            |b| brdf::pdf(b, a),
            || commands::directions::run_pdf(a, s),
        )
        .map(|()| true),
        Command::Invert(a) => by_kind(
            "invert",
            &a.input,
            &a.run.brdf,
            |b| brdf::invert(b, a),
            || commands::directions::run_invert(a, s),
        )
        .map(|()| true),
        Command::Info(a) => by_kind(
            "info",
            &a.input,
            &a.brdf,
            |b| brdf::info(b, a),
            || commands::info::run(a, s),
        )
        .map(|()| true),
        Command::Convert(a) => commands::convert::run(a, s).map(|()| true),
        Command::Check(a) => by_kind(
            "check",
            &a.input,
            &a.brdf,
            |b| brdf::check(b, a, s),
            || commands::check::run(a, s),
        ),
        Command::Plot(a) => by_kind(
            "plot",
            &a.input,
            &a.brdf,
            |b| brdf::plot(b, a),
            || plot::run(a, s),
        )
        .map(|()| true),
        Command::Bench(a) => by_kind(
            "bench",
            &a.input,
            &a.brdf,
            |b| brdf::bench(b, a),
            || bench::run(a, s),
        )
        .map(|()| true),
        Command::Uv(a) => commands::uv::run_uv(a, s).map(|()| true),
        Command::Bake(a) => commands::uv::run_bake(a, s).map(|()| true),
        Command::Brdf(a) => commands::brdf::run(a, s),
        Command::Tables(a) => commands::tables::run(a, s).map(|()| true),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(EXIT_CHECK_FAILED),
        Err(e) => report(&e),
    }
}

/// Runs `cmd` on its input by kind: a BRDF file (`--incident`, or recognised by its content) goes
/// to `brdf`, every other input to `other` ([`commands::brdf::input`] decides, and refuses a BRDF
/// file without `--incident` or a BRDF option on another input).
fn by_kind<T>(
    cmd: &str,
    input: &str,
    options: &args::BrdfOptions,
    brdf: impl FnOnce(&commands::brdf::Input) -> anyhow::Result<T>,
    other: impl FnOnce() -> anyhow::Result<T>,
) -> anyhow::Result<T> {
    match commands::brdf::input(cmd, input, options)? {
        Some(b) => brdf(&b),
        None => other(),
    }
}

/// Prints an error as one line on stderr and picks the exit code. A broken pipe on stdout (the
/// reader went away, e.g. `gonio sample … | head`) exits quietly with 0.
fn report(e: &anyhow::Error) -> ExitCode {
    for cause in e.chain() {
        if let Some(io) = cause.downcast_ref::<std::io::Error>() {
            if io.kind() == std::io::ErrorKind::BrokenPipe {
                return ExitCode::SUCCESS;
            }
        }
    }
    if let Some(usage) = e.downcast_ref::<args::UsageError>() {
        eprintln!("gonio: error: {usage} (see `gonio --help`)");
        return ExitCode::from(EXIT_USAGE);
    }
    if let Some(located) = e.downcast_ref::<load::LocatedError>() {
        eprintln!("gonio: error: {}", one_line(&located.to_string()));
    } else {
        // `{:#}` joins the context chain with ": ".
        eprintln!("gonio: error: {}", one_line(&format!("{e:#}")));
    }
    ExitCode::FAILURE
}

fn one_line(s: &str) -> String {
    s.split('\n')
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}
