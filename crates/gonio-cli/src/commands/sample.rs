//! `gonio sample`: samples with their exact pdf, from a point sequence or the caller's points.
//! One path for every input kind: the points ([`points`]), then rows of a fixed set of columns
//! computed a batch at a time, written by one writer in CSV or binary ([`emit`]). A luminaire or
//! diagram writes `u,v,x,y,z,pdf`, an environment map adds its radiance `r,g,b`, a BRDF file
//! (`--incident`) its weights `w_r,w_g,w_b` ([`super::brdf::sample`]).

use crate::args::{SampleArgs, SampleFormat};
use crate::csv_in::read_columns;
use crate::load::{build_sampler, load};
use crate::output::{push_csv_row, Output};
use crate::progress::Progress;
use crate::settings::Settings;
use gonio::sampler::sample_batch_par;
use gonio::sequence::Sequence;
use gonio::{Point2, Sample};
// Rows formatted per rayon task: the library's batch task size.
use gonio::batch::PAR_CHUNK;
use rayon::prelude::*;
use std::io::Write;

const BATCH: usize = 1 << 16;

pub fn run(a: &SampleArgs, settings: &Settings) -> anyhow::Result<()> {
    let loaded = load(&a.input, settings)?;
    let sampler = build_sampler(a.run.method.diagram()?, &loaded)?;
    // An environment map adds its radiance in each sampled direction (columns r, g, b).
    let env = loaded.envmap.as_deref();
    let (header, cols) = match env {
        Some(_) => ("u,v,x,y,z,pdf,r,g,b", 9),
        None => ("u,v,x,y,z,pdf", 6),
    };
    emit(
        a,
        settings,
        header,
        cols,
        &|pts: &[Point2], rows: &mut [f64]| {
            let mut s = vec![Sample::default(); pts.len()];
            sample_batch_par(&*sampler, pts, &mut s);
            rows.par_chunks_mut(cols)
                .zip(pts.par_iter().zip(&s))
                .for_each(|(row, (p, s))| {
                    let d = s.direction;
                    row[..6].copy_from_slice(&[p[0], p[1], d[0], d[1], d[2], s.pdf]);
                    if let Some(e) = env {
                        let c = e.eval(d);
                        row[6..].copy_from_slice(&c.map(f64::from));
                    }
                });
        },
    )
}

/// Where the points of the square come from: the caller's CSV (every point checked before
/// anything is written) or a sequence.
pub enum Points {
    /// `--points UV.csv`, read and validated.
    Given(Vec<Point2>),
    /// `-n N` points of a sequence.
    Sequence(Sequence, u64),
}

/// The points `a` asks for.
pub fn points(a: &SampleArgs) -> anyhow::Result<Points> {
    match &a.points {
        Some(path) => {
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
            Ok(Points::Given(pts))
        }
        None => {
            // Halton starts at index 1: index 0 is the corner u = (0, 0), which maps onto the
            // horizon or a pole, not a representative first sample.
            let seq = match a.sequence {
                gonio::sequence::SequenceKind::Halton => {
                    Sequence::Halton(gonio::sequence::Halton::with_skip(1))
                }
                kind => Sequence::new(kind, a.seed),
            };
            Ok(Points::Sequence(seq, a.n.unwrap_or(0)))
        }
    }
}

/// The rows of a batch of points: `rows` holds `cols` values a point, row-major.
pub type RowsOf<'a> = dyn Fn(&[Point2], &mut [f64]) + Sync + 'a;

/// Writes `header` (CSV only) and then, [`BATCH`] points at a time, the rows `rows_of` computes
/// for the points of `a`, in `a.format` to `a.output` (or standard output), with a progress bar.
pub fn emit(
    a: &SampleArgs,
    settings: &Settings,
    header: &str,
    cols: usize,
    rows_of: &RowsOf<'_>,
) -> anyhow::Result<()> {
    let points = points(a)?;
    let mut out = Output::create(a.run.output.as_deref())?;
    if a.format == SampleFormat::Csv {
        writeln!(out, "{header}")?;
    }
    let n = match &points {
        Points::Given(p) => p.len() as u64,
        Points::Sequence(_, n) => *n,
    };
    let progress = Progress::new(n, "sample", settings.quiet);
    let cap = n.min(BATCH as u64) as usize;
    let mut pts = vec![[0.0; 2]; cap];
    let mut rows = vec![0.0; cap * cols];
    let mut done = 0u64;
    while done < n {
        let len = (n - done).min(BATCH as u64) as usize;
        let p: &[Point2] = match &points {
            Points::Given(all) => &all[done as usize..done as usize + len],
            Points::Sequence(seq, _) => {
                seq.fill_par(done, &mut pts[..len]);
                &pts[..len]
            }
        };
        let r = &mut rows[..len * cols];
        rows_of(p, r);
        write_rows(&mut out, a.format, r, cols)?;
        done += len as u64;
        progress.set(done);
    }
    out.finish()
}

/// Rows of `cols` values (row-major) in `format`, formatted in parallel, written in order.
fn write_rows(
    out: &mut Output,
    format: SampleFormat,
    rows: &[f64],
    cols: usize,
) -> anyhow::Result<()> {
    let parts: Vec<Vec<u8>> = rows
        .par_chunks(PAR_CHUNK * cols)
        .map(|rows| {
            let mut buf = Vec::with_capacity(rows.len() * 16);
            for row in rows.chunks(cols) {
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
