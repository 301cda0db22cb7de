//! `gonio sample`: samples with their exact pdf, from a point sequence or the caller's points.

use crate::args::{SampleArgs, SampleFormat};
use crate::csv_in::read_columns;
use crate::load::{build_sampler, load};
use crate::output::{push_csv_row, Output};
use crate::progress::Progress;
use gonio::sampler::sample_batch_par;
use gonio::sequence::Sequence;
use gonio::{Point2, Sample};
// Rows formatted per rayon task: the library's batch task size.
use gonio::batch::PAR_CHUNK;
use rayon::prelude::*;
use std::io::Write;

/// Points sampled and written per batch: memory stays bounded for any N.
const BATCH: usize = 1 << 16;

/// Runs `gonio sample`.
pub fn run(a: &SampleArgs, settings: &crate::settings::Settings) -> anyhow::Result<()> {
    let loaded = load(&a.input, settings)?;
    let sampler = build_sampler(a.method, &loaded)?;
    // An environment map adds its radiance in each sampled direction (columns r, g, b).
    let env = loaded.envmap.as_deref();
    match &a.points {
        Some(path) => {
            // Validate every point before anything is written.
            let rows = read_columns(path, ["u", "v"])?;
            let mut pts: Vec<Point2> = Vec::with_capacity(rows.len());
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
            drop(rows);
            let mut out = Output::create(a.output.as_deref())?;
            write_header(&mut out, a.format, env)?;
            let progress = Progress::new(pts.len() as u64, "sample", settings.quiet);
            let mut samples = vec![Sample::default(); BATCH.min(pts.len())];
            let mut done = 0u64;
            for chunk in pts.chunks(BATCH) {
                let s = &mut samples[..chunk.len()];
                sample_batch_par(sampler.as_ref(), chunk, s);
                write_rows(&mut out, a.format, chunk, s, env)?;
                done += chunk.len() as u64;
                progress.set(done);
            }
            out.finish()
        }
        None => {
            let n = a.n.unwrap_or(0);
            // Halton starts at index 1: index 0 is the corner u = (0, 0), which maps onto the
            // horizon or a pole, not a representative first sample.
            let seq = match a.sequence {
                gonio::sequence::SequenceKind::Halton => {
                    Sequence::Halton(gonio::sequence::Halton::with_skip(1))
                }
                kind => Sequence::new(kind, a.seed),
            };
            let mut out = Output::create(a.output.as_deref())?;
            write_header(&mut out, a.format, env)?;
            let progress = Progress::new(n, "sample", settings.quiet);
            let cap = (n.min(BATCH as u64)) as usize;
            let mut pts = vec![[0.0; 2]; cap];
            let mut samples = vec![Sample::default(); cap];
            let mut done = 0u64;
            while done < n {
                let len = (n - done).min(BATCH as u64) as usize;
                let (p, s) = (&mut pts[..len], &mut samples[..len]);
                seq.fill_par(done, p);
                sample_batch_par(sampler.as_ref(), p, s);
                write_rows(&mut out, a.format, p, s, env)?;
                done += len as u64;
                progress.set(done);
            }
            out.finish()
        }
    }
}

fn write_header(
    out: &mut Output,
    format: SampleFormat,
    env: Option<&gonio::envmap::EnvironmentMap>,
) -> anyhow::Result<()> {
    if format == SampleFormat::Csv {
        out.write_all(if env.is_some() {
            b"u,v,x,y,z,pdf,r,g,b\n".as_slice()
        } else {
            b"u,v,x,y,z,pdf\n".as_slice()
        })?;
    }
    Ok(())
}

/// Writes one batch of rows `u, v, x, y, z, pdf` in `format`.
fn write_rows(
    out: &mut Output,
    format: SampleFormat,
    pts: &[Point2],
    samples: &[Sample],
    env: Option<&gonio::envmap::EnvironmentMap>,
) -> anyhow::Result<()> {
    let parts: Vec<Vec<u8>> = pts
        .par_chunks(PAR_CHUNK)
        .zip(samples.par_chunks(PAR_CHUNK))
        .map(|(p, s)| {
            let mut buf = Vec::with_capacity(p.len() * 96);
            for (p, s) in p.iter().zip(s) {
                let d = s.direction;
                let rgb = env.map(|e| e.eval(d).map(f64::from));
                let base = [p[0], p[1], d[0], d[1], d[2], s.pdf];
                let full;
                let row: &[f64] = match rgb {
                    Some(c) => {
                        full = [
                            base[0], base[1], base[2], base[3], base[4], base[5], c[0], c[1], c[2],
                        ];
                        &full
                    }
                    None => &base,
                };
                match format {
                    SampleFormat::Csv => push_csv_row(&mut buf, row),
                    SampleFormat::F32 => {
                        for &v in row {
                            buf.extend_from_slice(&(v as f32).to_le_bytes());
                        }
                    }
                    SampleFormat::F64 => {
                        for &v in row {
                            buf.extend_from_slice(&v.to_le_bytes());
                        }
                    }
                }
            }
            buf
        })
        .collect();
    for part in parts {
        out.write_all(&part)?;
    }
    Ok(())
}
