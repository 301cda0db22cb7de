//! `gonio pdf` and `gonio invert`: densities and preimages of the caller's directions.

use crate::args::DirectionsArgs;
use crate::csv_in::read_columns;
use crate::load::{build_sampler, load};
use crate::output::{push_csv_row, Output};
use gonio::sampler::{invert_batch_par, normalize, pdf_batch_par};
use gonio::{InvertError, Sampler, Vec3};
use std::io::Write;

/// (1-based line, 1-based data row) of an input row.
type LineRow = (usize, usize);

/// Rows per batch.
const BATCH: usize = 1 << 16;

/// Reads and normalises the directions; refuses zero or non-finite ones, naming the row. Also
/// returns the (line, row) of each direction for later messages.
fn read_directions(path: &str) -> anyhow::Result<(Vec<Vec3>, Vec<LineRow>)> {
    let rows = read_columns(path, ["x", "y", "z"])?;
    let locs = rows.iter().map(|r| (r.line, r.row)).collect();
    let dirs = rows
        .iter()
        .map(|r| {
            normalize(r.values).ok_or_else(|| {
                let [x, y, z] = r.values;
                anyhow::anyhow!(
                    "{}: direction ({x}, {y}, {z}) is zero or not finite",
                    r.locate(path)
                )
            })
        })
        .collect::<anyhow::Result<Vec<Vec3>>>()?;
    Ok((dirs, locs))
}

/// Runs `gonio pdf`: output `x,y,z,pdf` with the normalised direction.
pub fn run_pdf(a: &DirectionsArgs, settings: &crate::settings::Settings) -> anyhow::Result<()> {
    let loaded = load(&a.input, settings)?;
    let sampler = build_sampler(a.run.method.diagram()?, &loaded)?;
    write_pdf(&*sampler, a)
}

/// The pdf of every direction of `--directions` under `sampler`, as CSV `x,y,z,pdf`.
pub fn write_pdf(sampler: &dyn Sampler, a: &DirectionsArgs) -> anyhow::Result<()> {
    let (dirs, _) = read_directions(&a.directions)?;
    let mut out = Output::create(a.run.output.as_deref())?;
    out.write_all(b"x,y,z,pdf\n")?;
    let mut pdf = vec![0.0; BATCH.min(dirs.len())];
    for chunk in dirs.chunks(BATCH) {
        let p = &mut pdf[..chunk.len()];
        pdf_batch_par(sampler, chunk, p);
        let mut buf = Vec::with_capacity(chunk.len() * 80);
        for (d, p) in chunk.iter().zip(p.iter()) {
            push_csv_row(&mut buf, &[d[0], d[1], d[2], *p]);
        }
        out.write_all(&buf)?;
    }
    out.finish()
}

/// Runs `gonio invert`: output `x,y,z,u,v` with the normalised direction, one row per input row.
/// A direction with no preimage — density 0 there, or outside a hemisphere sampler's domain —
/// gets empty `u,v` fields; how many is said on standard error, and the exit status stays 0.
/// Only a malformed input row (not a number, a zero or non-finite direction) stops the run.
pub fn run_invert(a: &DirectionsArgs, settings: &crate::settings::Settings) -> anyhow::Result<()> {
    let loaded = load(&a.input, settings)?;
    let sampler = build_sampler(a.run.method.diagram()?, &loaded)?;
    write_invert(&*sampler, a)
}

/// The point of the square of every direction of `--directions` under `sampler`, as CSV
/// `x,y,z,u,v` (empty `u,v` and one warning where there is none).
pub fn write_invert(sampler: &dyn Sampler, a: &DirectionsArgs) -> anyhow::Result<()> {
    if sampler.invert([0.0, 0.0, 1.0]) == Err(InvertError::Unsupported) {
        anyhow::bail!(
            "method `{}` has no inverse; use hds, piecewise-constant, bilinear or uniform",
            sampler.name()
        );
    }
    let (dirs, locs) = read_directions(&a.directions)?;
    let mut uv: Vec<Result<[f64; 2], InvertError>> = vec![Ok([0.0; 2]); dirs.len()];
    invert_batch_par(sampler, &dirs, &mut uv);
    let mut out = Output::create(a.run.output.as_deref())?;
    out.write_all(b"x,y,z,u,v\n")?;
    let (mut zero, mut outside) = (0usize, 0usize);
    for (dc, uc) in dirs.chunks(BATCH).zip(uv.chunks(BATCH)) {
        let mut buf = Vec::with_capacity(dc.len() * 80);
        for (d, u) in dc.iter().zip(uc) {
            match u {
                Ok(u) => push_csv_row(&mut buf, &[d[0], d[1], d[2], u[0], u[1]]),
                Err(e) => {
                    match e {
                        InvertError::OutsideDomain => outside += 1,
                        _ => zero += 1,
                    }
                    push_csv_row(&mut buf, &[d[0], d[1], d[2]]);
                    // `x,y,z` + two empty fields.
                    buf.pop();
                    buf.extend_from_slice(b",,\n");
                }
            }
        }
        out.write_all(&buf)?;
    }
    out.finish()?;
    if let Some(k) = uv.iter().position(|r| r.is_err()) {
        let (line, row) = locs[k];
        let mut kinds = Vec::new();
        if zero > 0 {
            kinds.push(format!("{zero} where the density is 0"));
        }
        if outside > 0 {
            kinds.push(format!(
                "{outside} outside the sampler's domain ({:?})",
                sampler.domain()
            ));
        }
        eprintln!(
            "gonio: warning: {} of {} directions have no preimage ({}; the first at {}:{line}, \
             row {row}): their u,v fields are empty",
            zero + outside,
            dirs.len(),
            kinds.join(", "),
            a.directions
        );
    }
    Ok(())
}
