//! `gonio tables FILE -o OUT.bin [--precision f32|f64]`: the HDS map's tables as one blob
//! (docs/TABLES.md), for the device header, the Dr.Jit plugins or a renderer's own loader.

use crate::load::{build_sampler, load};
use crate::output::Output;
use clap::{Args, ValueEnum};
use gonio::mapping::blob::{self, Frame, Precision, Target};
use gonio::Method;
use std::io::Write;
use std::path::PathBuf;

/// The blob's float precision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PrecisionArg {
    /// The float32 map (what GPU and Dr.Jit code samples).
    F32,
    /// The f64 map's own tables.
    F64,
}

/// `gonio tables`.
#[derive(Debug, Clone, Args)]
pub struct TablesArgs {
    /// Input: `.json`, `.ies`, `.ldt`, an environment map (`.hdr`, `.exr`, `.pfm`), a BRDF file
    /// (MERL, UTIA, gonio BRDF JSON: the family of every incident slice), or `example`.
    #[arg(value_name = "FILE")]
    pub input: String,
    /// Output file of the blob.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Float precision of the tables (default f32).
    #[arg(long, value_enum, default_value = "f32")]
    pub precision: PrecisionArg,
}

/// Writes the blob of FILE's HDS map (with its diagram, or its environment map's image, as the
/// target) and prints one line: the layout, grid and size.
pub fn run(a: &TablesArgs, settings: &crate::settings::Settings) -> anyhow::Result<()> {
    let precision = match a.precision {
        PrecisionArg::F32 => Precision::F32,
        PrecisionArg::F64 => Precision::F64,
    };
    let path = std::path::Path::new(&a.input);
    if let Some(format) = crate::commands::brdf::sniff(path) {
        // A BRDF file: the whole family of incident slices (no --incident needed).
        let bytes = crate::commands::brdf::family_tables(path, precision)?;
        let fam = blob::read_family(&bytes).map_err(|e| anyhow::anyhow!("{}: {e}", a.input))?;
        let mut out = Output::create(Some(&a.output))?;
        out.write_all(&bytes)?;
        out.finish()?;
        eprintln!(
            "{}: {} bytes, {} tables, BRDF family ({format}) of {} slices ({} without reflectance), grid {} × {}",
            a.output.display(),
            bytes.len(),
            precision.name(),
            fam.slices.len(),
            fam.slices.iter().filter(|s| s.is_none()).count(),
            fam.grid.0,
            fam.grid.1
        );
        return Ok(());
    }
    let loaded = load(&a.input, settings)?;
    let bytes = if let Some(env) = &loaded.envmap {
        blob::write_envmap(env, precision)
    } else {
        let sampler = build_sampler(Method::Hds, &loaded)?;
        let map = sampler.hds_map().expect("the HDS method builds an HDS map");
        let frame = if loaded.kind.is_photometric() {
            Frame::Photometric
        } else {
            Frame::Generic
        };
        blob::write(map, precision, frame, &Target::Grid(&loaded.diagram))
    }
    .map_err(|e| anyhow::anyhow!("{}: {e}", loaded.name))?;
    let info = blob::read(&bytes).map_err(|e| anyhow::anyhow!("{}: {e}", loaded.name))?;
    let mut out = Output::create(Some(&a.output))?;
    out.write_all(&bytes)?;
    out.finish()?;
    let grids: Vec<String> = info
        .grids
        .iter()
        .flatten()
        .map(|(m, n)| format!("{m} × {n}"))
        .collect();
    eprintln!(
        "{}: {} bytes, {} tables, {:?} layout, {} frame, maps {}",
        a.output.display(),
        bytes.len(),
        precision.name(),
        info.layout,
        info.frame.name(),
        grids.join(" + ")
    );
    Ok(())
}
