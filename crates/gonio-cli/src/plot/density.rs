//! `density`: the sampler's pdf, a histogram of N iid samples, and their standardised difference
//! (observed − expected) / √expected, each on the equal-area rectangle with its colour bar (pdf and
//! histogram on one shared scale).

use super::colour::{diverging, viridis, Bar, IMPOSSIBLE};
use super::grid::{draw_border, draw_cells, rect_chart, Grid, FRAME};
use super::{fmt_num, titled, PlotInput};
use anyhow::Result;
use gonio::sampler::{sample_batch_par, Sample};
use gonio::sequence::{Sequence, SequenceKind};
use gonio::Point2;
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;

/// Width of a colour bar's area in pixels.
const BAR_AREA: u32 = 110;
/// The standardised difference saturates at ± this.
const Z_CLIP: f64 = 4.0;
/// Cells expecting fewer samples than this are not compared (grey): (o − e)/√e is far from
/// normal there.
const MIN_EXPECTED: f64 = 5.0;
/// Sub-points per cell side for the cell average of the pdf.
const SUB: usize = 4;

/// Everything the three panels show.
pub struct Histogram {
    pub grid: Grid,
    /// Cell average of the pdf, per sr.
    pub pdf: Vec<f64>,
    /// Samples per cell.
    pub counts: Vec<u64>,
    /// Samples that fell outside the domain's rectangle (should be 0).
    pub outside: u64,
    pub n: usize,
}

impl Histogram {
    /// Expected samples in cell k.
    pub fn expected(&self, k: usize) -> f64 {
        self.pdf[k] * self.grid.cell_solid_angle() * self.n as f64
    }
}

/// Samples `n` iid points of `input.sampler` and bins them on an `nx` × `ny` grid.
pub fn histogram(input: &PlotInput, n: usize, nx: usize, ny: usize) -> Histogram {
    let s = input.sampler;
    let grid = Grid::new(s.domain(), nx, ny);
    let mut u: Vec<Point2> = vec![[0.0; 2]; n];
    Sequence::new(SequenceKind::Random, input.seed).fill_par(0, &mut u);
    let mut out = vec![Sample::default(); n];
    sample_batch_par(s, &u, &mut out);
    drop(u);
    let (counts, outside) = out
        .par_chunks(1 << 16)
        .map(|chunk| {
            let mut c = vec![0u64; grid.len()];
            let mut o = 0u64;
            for smp in chunk {
                match grid.index(smp.direction) {
                    Some(k) => c[k] += 1,
                    None => o += 1,
                }
            }
            (c, o)
        })
        .reduce(
            || (vec![0u64; grid.len()], 0),
            |(mut a, oa), (b, ob)| {
                a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
                (a, oa + ob)
            },
        );
    let pdf = (0..grid.len())
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % grid.nx, k / grid.nx);
            let mut sum = 0.0;
            for a in 0..SUB {
                for b in 0..SUB {
                    let fx = (a as f64 + 0.5) / SUB as f64;
                    let fy = (b as f64 + 0.5) / SUB as f64;
                    sum += s.pdf(grid.direction(i, j, fx, fy));
                }
            }
            sum / (SUB * SUB) as f64
        })
        .collect();
    Histogram {
        grid,
        pdf,
        counts,
        outside,
        n,
    }
}

/// Histogram cells for `n` samples: about 150 expected samples per cell on average, as many as the
/// picture shows well, three times wider than tall.
pub fn bins_for(n: usize, svg: bool) -> (usize, usize) {
    let max_cells = if svg { 3_000.0 } else { 12_000.0 };
    let cells = (n as f64 / 150.0).clamp(48.0, max_cells);
    let ny = (cells / 3.0).sqrt().round().max(4.0);
    ((3.0 * ny) as usize, ny as usize)
}

pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    svg: bool,
    input: &PlotInput,
    n: usize,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let domain = input.sampler.domain();
    let (nx, ny) = bins_for(n, svg);
    let h = histogram(input, n, nx, ny);
    let grid = h.grid;
    let omega = grid.cell_solid_angle();
    let hist: Vec<f64> = h
        .counts
        .iter()
        .map(|&c| c as f64 / (n as f64 * omega))
        .collect();
    let vmax = h
        .pdf
        .iter()
        .chain(&hist)
        .fold(0.0f64, |a, &b| a.max(b))
        .max(f64::MIN_POSITIVE);

    let mut chi2 = 0.0;
    let mut dof = 0usize;
    let z: Vec<f64> = (0..grid.len())
        .map(|k| {
            let e = h.expected(k);
            let o = h.counts[k] as f64;
            if e >= MIN_EXPECTED {
                let z = (o - e) / e.sqrt();
                chi2 += z * z;
                dof += 1;
                z
            } else if e <= 0.0 && o > 0.0 {
                f64::INFINITY
            } else {
                f64::NAN
            }
        })
        .collect();
    let impossible = z.iter().filter(|v| v.is_infinite()).count();
    let skipped = z.iter().filter(|v| v.is_nan()).count();

    let title = format!(
        "{} — density of `{}`: {} iid samples (seed {}), {} × {} equal-area cells",
        input.title,
        input.sampler.name(),
        n,
        input.seed,
        nx,
        ny
    );
    let area = titled(root, &title, 22.0)?;
    let rows = area.split_evenly((3, 1));
    let (w, _) = root.dim_in_pixel();

    let seq = |v: f64| viridis(v / vmax);
    let seq_bar = |v: f64| viridis(v / vmax);
    let seq_label = |v: f64| fmt_num(v);
    let per_sr = "density (1/sr), shared scale";

    // pdf
    let panel = titled(&rows[0], "pdf of the sampler (cell average)", 16.0)?;
    let (l, r) = panel.split_horizontally(w - BAR_AREA);
    let mut chart = rect_chart(&l, domain, input, false)?;
    draw_cells(&mut chart, &grid, &h.pdf, &seq)?;
    draw_border(&mut chart, &grid)?;
    let bar = Bar {
        lo: 0.0,
        hi: vmax,
        colour: &seq_bar,
        desc: per_sr.into(),
        ticks: None,
        label: &seq_label,
        marks: vec![],
    };
    bar.draw(&r, FRAME)?;

    // histogram
    let mut cap = "histogram of the samples: count / (N · cell solid angle)".to_string();
    if h.outside > 0 {
        cap.push_str(&format!(" — {} samples outside the domain!", h.outside));
    }
    let panel = titled(&rows[1], &cap, 16.0)?;
    let (l, r) = panel.split_horizontally(w - BAR_AREA);
    let mut chart = rect_chart(&l, domain, input, false)?;
    draw_cells(&mut chart, &grid, &hist, &seq)?;
    draw_border(&mut chart, &grid)?;
    bar.draw(&r, FRAME)?;

    // difference
    let mut cap = format!(
        "(observed − expected) / √expected; χ² / cells = {} over {dof} cells (≈ 1 if the pdf is right)",
        if dof > 0 { format!("{:.3}", chi2 / dof as f64) } else { "–".into() }
    );
    if skipped > 0 {
        cap.push_str(&format!("; grey: < {MIN_EXPECTED} expected"));
    }
    if impossible > 0 {
        cap.push_str(&format!(
            "; black: samples where pdf = 0 ({impossible} cells)"
        ));
    }
    let panel = titled(&rows[2], &cap, 16.0)?;
    let (l, r) = panel.split_horizontally(w - BAR_AREA);
    let mut chart = rect_chart(&l, domain, input, false)?;
    let div = |v: f64| {
        if v.is_infinite() {
            IMPOSSIBLE
        } else {
            diverging(v / Z_CLIP)
        }
    };
    draw_cells(&mut chart, &grid, &z, &div)?;
    draw_border(&mut chart, &grid)?;
    let div_bar = |v: f64| diverging(v / Z_CLIP);
    let z_label = |v: f64| format!("{v:+.0}");
    Bar {
        lo: -Z_CLIP,
        hi: Z_CLIP,
        colour: &div_bar,
        desc: "standardised difference (σ)".into(),
        ticks: Some((-4..=4).map(f64::from).collect()),
        label: &z_label,
        marks: vec![],
    }
    .draw(&r, FRAME)?;
    Ok(())
}
