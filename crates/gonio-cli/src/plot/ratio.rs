//! `ratio`: pdf / target over the domain on the equal-area rectangle, diverging colours centred at
//! 1 (log scale), grey where the target is 0, the guaranteed bound marked on the colour bar.

use super::colour::{diverging, Bar, IMPOSSIBLE};
use super::grid::{cells_for, draw_border, draw_cells, rect_chart, Grid, FRAME, Y_LABEL};
use super::{fmt_num, titled, PlotInput};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;

/// Width of the colour bar's area in pixels.
const BAR_AREA: u32 = 150;

/// Ratios at which the colour bar gets a tick, when in range.
const TICKS: [f64; 25] = [
    0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 0.67, 0.8, 0.9, 0.95, 0.98, 0.99, 1.0, 1.01, 1.02, 1.05, 1.1,
    1.25, 1.5, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0,
];

/// pdf / target at the centre of every cell: NaN where both are 0 (or the target is 0 and the pdf
/// is too), +∞ where the target is 0 but the pdf is not.
pub fn ratio_grid(input: &PlotInput, grid: &Grid) -> Vec<f64> {
    let s = input.sampler;
    (0..grid.len())
        .into_par_iter()
        .map(|k| {
            let d = grid.direction(k % grid.nx, k / grid.nx, 0.5, 0.5);
            let (p, t) = (s.pdf(d), s.target_pdf(d));
            if t > 0.0 {
                p / t
            } else if p > 0.0 {
                f64::INFINITY
            } else {
                f64::NAN
            }
        })
        .collect()
}

pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    svg: bool,
    input: &PlotInput,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let domain = input.sampler.domain();
    let (w, h) = root.dim_in_pixel();
    let (nx, ny) = if svg {
        cells_for(w - BAR_AREA - Y_LABEL, h - 150, 7.0, 12_000)
    } else {
        cells_for(w - BAR_AREA - Y_LABEL, h - 150, 2.0, 200_000)
    };
    let grid = Grid::new(domain, nx, ny);
    let ratio = ratio_grid(input, &grid);
    let finite = ratio.iter().copied().filter(|r| r.is_finite());
    let (omin, omax) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
        (a.min(r), b.max(r))
    });
    let impossible = ratio.iter().filter(|r| r.is_infinite()).count();
    let undefined = ratio.iter().filter(|r| r.is_nan()).count();

    // The colour scale covers what the picture shows (the bound may be reached only in directions
    // between the cell centres; a mark beyond the scale is drawn at its end).
    let mut extent = 1.02f64.ln();
    for r in [omin, omax] {
        if r > 0.0 && r.is_finite() {
            extent = extent.max(r.ln().abs());
        }
    }
    // Include the guaranteed bound when it lies not far beyond what the grid shows.
    if let Some((a, b)) = input.map.map(gonio::MapRef::ratio_bound) {
        for r in [a, b] {
            if r > 0.0 && r.is_finite() && r.ln().abs() <= 2.0 * extent {
                extent = extent.max(r.ln().abs());
            }
        }
    }
    let extent = extent.min(100f64.ln()) * 1.05;

    let bound = match input.map.map(gonio::MapRef::ratio_bound) {
        Some((a, b)) => format!("guaranteed [{a:.4}, {b:.4}]"),
        None => "no guaranteed bound".to_string(),
    };
    let observed = if omin.is_finite() {
        format!("on this grid [{omin:.4}, {omax:.4}]")
    } else {
        "target 0 everywhere".to_string()
    };
    let title = format!(
        "{} — pdf / target of `{}`: {}, {}",
        input.title,
        input.sampler.name(),
        bound,
        observed
    );
    let area = titled(root, &title, 22.0)?;
    let mut notes = vec![format!(
        "{} × {} cells, value at each centre; log colour scale centred at 1",
        nx, ny
    )];
    if undefined > 0 {
        notes.push("grey: target = 0".into());
    }
    if impossible > 0 {
        notes.push(format!(
            "black: pdf > 0 where target = 0 ({impossible} cells)"
        ));
    }
    let area = titled(&area, &notes.join("; "), 16.0)?;
    let (left, right) = area.split_horizontally(w - BAR_AREA);

    let mut chart = rect_chart(&left, domain, input, false)?;
    let colour = move |r: f64| {
        if r.is_infinite() {
            IMPOSSIBLE
        } else if r <= 0.0 {
            diverging(-1.0)
        } else {
            diverging(r.ln() / extent)
        }
    };
    draw_cells(&mut chart, &grid, &ratio, &colour)?;
    draw_border(&mut chart, &grid)?;

    let bar_colour = move |y: f64| diverging(y / extent);
    let label = |y: f64| fmt_num(y.exp());
    let ticks: Vec<f64> = TICKS
        .iter()
        .map(|t| t.ln())
        .filter(|y| y.abs() <= extent)
        .collect();
    let ticks = thin_ticks(&ticks, 0.18 * extent);
    let mut marks = Vec::new();
    if let Some((a, b)) = input.map.map(gonio::MapRef::ratio_bound) {
        if a > 0.0 {
            let y = a.ln();
            let text = if y < -extent { "min ↓" } else { "min" };
            marks.push((y.max(-extent), text.to_string()));
        }
        if b > 0.0 {
            let y = b.ln();
            let text = if y > extent { "max ↑" } else { "max" };
            marks.push((y.min(extent), text.to_string()));
        }
    }
    Bar {
        lo: -extent,
        hi: extent,
        colour: &bar_colour,
        desc: if marks.is_empty() {
            "pdf / target (log scale)".into()
        } else {
            "pdf / target (lines: guaranteed bound)".into()
        },
        ticks: Some(ticks),
        label: &label,
        marks,
    }
    .draw(&right, FRAME)?;
    Ok(())
}

/// Keeps the tick at 1 (coordinate 0) and, going outwards from it, every tick at least `gap` away
/// from the last one kept.
fn thin_ticks(ticks: &[f64], gap: f64) -> Vec<f64> {
    let mut up = vec![0.0];
    for &y in ticks.iter().filter(|&&y| y > 0.0) {
        if y - up[up.len() - 1] >= gap {
            up.push(y);
        }
    }
    let mut down = vec![0.0];
    for &y in ticks.iter().rev().filter(|&&y| y < 0.0) {
        if down[down.len() - 1] - y >= gap {
            down.push(y);
        }
    }
    down.reverse();
    down.pop();
    down.extend(up);
    down
}
