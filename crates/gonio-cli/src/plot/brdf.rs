//! The slice of a tabulated BRDF (`gonio plot FILE --incident θ,φ -o slice.png`): the slice
//! diagram f̄(ω_i, ω_o)·cos θ_o over the outgoing hemisphere on the equal-area (φ_o, cos θ_o)
//! rectangle of `density` and `ratio` (f̄ the luminance of the table's RGB, or its one channel),
//! viridis colours with a colour bar, the sampled directions drawn over it as dots, and the
//! mirror direction of ω_i marked with a cross.

use super::colour::{viridis, Bar};
use super::grid::{cells_for, draw_border, draw_cells, rect_chart, Grid, FRAME, Y_LABEL};
use super::{fmt_num, titled, write_picture, Picture, PlotInput};
use anyhow::Result;
use gonio::{Diagram, Domain, Sampler, Vec3};
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;
use std::f64::consts::TAU;
use std::path::Path;

/// Width of the colour bar's area in pixels.
const BAR_AREA: u32 = 150;

/// What a slice picture is drawn from.
pub struct SlicePlot<'a> {
    /// The first line of the title (file, incident direction, method).
    pub title: String,
    /// The sampler at the incident direction (for the chart's labels).
    pub sampler: &'a dyn Sampler,
    /// The name of the method that drew `samples`.
    pub method: &'a str,
    /// A diagram for the chart's labels (the axes of a non-photometric hemisphere).
    pub diagram: &'a Diagram,
    /// f̄·cos θ_o at an outgoing direction (1/sr).
    pub value: &'a (dyn Fn(Vec3) -> f64 + Sync),
    /// Sampled outgoing directions, drawn as dots.
    pub samples: &'a [Vec3],
    /// The mirror direction of ω_i, marked with a cross.
    pub mirror: Vec3,
}

/// Draws `plot` into `out` (.png or .svg by extension) at `width` × `height` pixels, through a
/// temporary file renamed onto `out` on success (as every picture of `gonio plot`).
pub fn render_slice(plot: &SlicePlot, out: &Path, width: u32, height: u32) -> Result<()> {
    write_picture(plot, out, width, height)
}

/// Azimuth in degrees [0, 360) and z of a direction: its place on the rectangle.
fn place(d: Vec3) -> (f64, f64) {
    let phi = d[1].atan2(d[0]).rem_euclid(TAU).to_degrees();
    (phi.min(359.999), d[2].clamp(0.0, 1.0))
}

impl Picture for SlicePlot<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, svg: bool) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let plot = self;
        root.fill(&WHITE)?;
        let (w, h) = root.dim_in_pixel();
        let (nx, ny) = if svg {
            cells_for(w - BAR_AREA - Y_LABEL, h - 150, 7.0, 12_000)
        } else {
            cells_for(w - BAR_AREA - Y_LABEL, h - 150, 2.0, 200_000)
        };
        let grid = Grid::new(Domain::Hemisphere, nx, ny);
        let values: Vec<f64> = (0..grid.len())
            .into_par_iter()
            .map(|k| (plot.value)(grid.direction(k % grid.nx, k / grid.nx, 0.5, 0.5)))
            .collect();
        let max = values.iter().copied().fold(0.0f64, f64::max);
        let scale = if max > 0.0 { max } else { 1.0 };
        let area = titled(root, &plot.title, 22.0)?;
        let notes = format!(
            "colour: f·cos θ_o (1/sr, luminance) on {nx} × {ny} cells; dots: {} samples of `{}`; \
             cross: mirror direction",
            plot.samples.len(),
            plot.method
        );
        let area = titled(&area, &notes, 16.0)?;
        let (left, right) = area.split_horizontally(w - BAR_AREA);
        let input = PlotInput {
            title: String::new(),
            diagram: plot.diagram,
            sampler: plot.sampler,
            map: None,
            samples: 0,
            seed: 0,
            photometric: false,
            hv_photometry: None,
        };
        let mut chart = rect_chart(&left, Domain::Hemisphere, &input, false)?;
        let colour = move |v: f64| viridis(v / scale);
        draw_cells(&mut chart, &grid, &values, &colour)?;
        let dot = RGBColor(230, 30, 30);
        chart.draw_series(plot.samples.iter().map(|&d| {
            let (x, y) = place(d);
            Circle::new((x, y), 2, dot.filled())
        }))?;
        if plot.mirror[2] >= 0.0 {
            let (x, y) = place(plot.mirror);
            chart.draw_series(std::iter::once(Cross::new(
                (x, y),
                7,
                WHITE.stroke_width(3),
            )))?;
        }
        draw_border(&mut chart, &grid)?;
        let bar_colour = move |y: f64| viridis(y / scale);
        let label = |y: f64| fmt_num(y);
        Bar {
            lo: 0.0,
            hi: scale,
            colour: &bar_colour,
            desc: "f·cos θ_o (1/sr)".into(),
            ticks: None,
            label: &label,
            marks: vec![],
        }
        .draw(&right, FRAME)?;
        Ok(())
    }
}
