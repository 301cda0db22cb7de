//! The equal-area (φ, cos θ) rectangle that `density`, `ratio` and `warp` draw directions on.
//!
//! x = φ in degrees [0, 360), y = z = cos θ. The map (θ, φ) ↦ (φ, cos θ) is equal-area
//! (dω = dφ d(cos θ)), so equal areas of the picture hold equal solid angles and a uniform
//! density looks uniform. The y axis is labelled with the angles themselves (θ, or γ = 180° − θ
//! for photometric data) at their cos positions.

use super::axis::Ticked;
use super::colour::{Frame, UNDEFINED};
use super::{desc_font, label_font, PlotInput};
use anyhow::Result;
use gonio::{Domain, Vec3};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::f64::consts::TAU;

/// The range of z = cos θ a domain covers.
pub fn z_range(domain: Domain) -> (f64, f64) {
    match domain {
        Domain::Hemisphere => (0.0, 1.0),
        Domain::Sphere => (-1.0, 1.0),
    }
}

/// An nx × ny grid of equal cells on the rectangle [0, 2π) × [z0, z1].
#[derive(Debug, Clone, Copy)]
pub struct Grid {
    pub nx: usize,
    pub ny: usize,
    pub z0: f64,
    pub z1: f64,
}

impl Grid {
    pub fn new(domain: Domain, nx: usize, ny: usize) -> Self {
        let (z0, z1) = z_range(domain);
        Grid {
            nx: nx.max(1),
            ny: ny.max(1),
            z0,
            z1,
        }
    }

    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Solid angle of one cell, sr.
    pub fn cell_solid_angle(&self) -> f64 {
        TAU / self.nx as f64 * (self.z1 - self.z0) / self.ny as f64
    }

    /// The direction at fractional position (fx, fy) ∈ [0, 1]² inside cell (i, j).
    pub fn direction(&self, i: usize, j: usize, fx: f64, fy: f64) -> Vec3 {
        let phi = TAU * (i as f64 + fx) / self.nx as f64;
        let z = self.z0 + (self.z1 - self.z0) * (j as f64 + fy) / self.ny as f64;
        let s = (1.0 - z * z).max(0.0).sqrt();
        [s * phi.cos(), s * phi.sin(), z]
    }

    /// The cell index (j · nx + i) holding direction `d`, or `None` outside the rectangle.
    pub fn index(&self, d: Vec3) -> Option<usize> {
        let (_, phi) = gonio::sampler::spherical(d);
        let z = d[2];
        if !(z >= self.z0 && z <= self.z1) {
            return None;
        }
        let i = ((phi / TAU * self.nx as f64) as usize).min(self.nx - 1);
        let j = (((z - self.z0) / (self.z1 - self.z0) * self.ny as f64) as usize).min(self.ny - 1);
        Some(j * self.nx + i)
    }

    /// Cell corners in chart coordinates (φ in degrees, z).
    pub fn corners(&self, i: usize, j: usize) -> [(f64, f64); 2] {
        let dz = (self.z1 - self.z0) / self.ny as f64;
        let dx = 360.0 / self.nx as f64;
        [
            (i as f64 * dx, self.z0 + j as f64 * dz),
            ((i + 1) as f64 * dx, self.z0 + (j + 1) as f64 * dz),
        ]
    }
}

/// A chart on the rectangle.
pub type RectChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<Ticked, Ticked>>;

/// Frame of every rectangle chart (the colour bars use the same one to line up).
pub const FRAME: Frame = Frame {
    margin: 8,
    x_label: 48,
};

/// Width of the y label area of a rectangle chart.
pub const Y_LABEL: u32 = 66;

/// Builds the chart of the rectangle for `domain` with axes labelled for `input` (θ or γ, φ or C).
/// `compact`: fewer ticks and short axis descriptions, for small panels.
pub fn rect_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    domain: Domain,
    input: &PlotInput,
    compact: bool,
) -> Result<RectChart<'a, DB>>
where
    DB::ErrorType: 'static,
{
    let (z0, z1) = z_range(domain);
    let step = if domain == Domain::Hemisphere { 15 } else { 30 };
    let mut zs: Vec<f64> = (0..=180)
        .step_by(step)
        .map(|t| (t as f64).to_radians().cos())
        .filter(|&z| z >= z0 - 1e-9 && z <= z1 + 1e-9)
        .map(|z| z.clamp(z0, z1))
        .collect();
    zs.sort_by(|a, b| b.total_cmp(a));
    // Drop ticks that crowd the previous one (near the poles cos θ changes slowly).
    let min_gap = 0.07 * (z1 - z0);
    let mut kept: Vec<f64> = Vec::with_capacity(zs.len());
    for &z in &zs {
        match kept.last() {
            Some(&k) if k - z < min_gap => {}
            _ => kept.push(z),
        }
    }
    // Keep the bottom end (the nadir, or the horizon) rather than the tick just above it.
    if let (Some(&last), Some(&end)) = (kept.last(), zs.last()) {
        if last != end {
            if kept.len() > 1 && last - end < min_gap {
                kept.pop();
            }
            kept.push(end);
        }
    }
    let zs = kept;
    let x_step = if compact { 90 } else { 45 };
    let xs: Vec<f64> = (0..=360).step_by(x_step).map(f64::from).collect();
    let mut chart = ChartBuilder::on(area)
        .margin(FRAME.margin)
        .x_label_area_size(if compact { 40 } else { FRAME.x_label })
        .y_label_area_size(if compact { 52 } else { Y_LABEL })
        .build_cartesian_2d(Ticked::new(0.0..360.0, xs), Ticked::new(z0..z1, zs))?;
    let photometric = input.photometric;
    let y_fmt = move |z: &f64| {
        let theta = z.clamp(-1.0, 1.0).acos().to_degrees();
        let a = if photometric { 180.0 - theta } else { theta };
        format!("{:.0}°", a)
    };
    let (x_desc, y_desc) = if compact {
        if photometric {
            ("C-plane φ", "γ (0° = nadir)")
        } else {
            ("azimuth φ", "θ from +z")
        }
    } else if photometric {
        (
            "C-plane = azimuth φ (°), equal-area in (φ, cos γ)",
            "γ (0° = nadir), spaced by cos γ",
        )
    } else {
        (
            "azimuth φ (°), equal-area in (φ, cos θ)",
            "θ from +z, spaced by cos θ",
        )
    };
    chart
        .configure_mesh()
        .disable_mesh()
        .x_label_style(label_font())
        .y_label_style(label_font())
        .x_label_formatter(&|x| format!("{:.0}°", x))
        .y_label_formatter(&y_fmt)
        .x_desc(x_desc)
        .y_desc(y_desc)
        .axis_desc_style(desc_font())
        .draw()?;
    Ok(chart)
}

/// Fills every cell of `grid` with `colour(value)`; NaN values get [`UNDEFINED`].
/// `colour` may itself return special colours (e.g. for impossible cells).
pub fn draw_cells<DB: DrawingBackend>(
    chart: &mut RectChart<'_, DB>,
    grid: &Grid,
    values: &[f64],
    colour: &dyn Fn(f64) -> RGBColor,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    chart.draw_series((0..grid.ny).flat_map(|j| {
        (0..grid.nx).map(move |i| {
            let v = values[j * grid.nx + i];
            let c = if v.is_nan() { UNDEFINED } else { colour(v) };
            Rectangle::new(grid.corners(i, j), c.filled())
        })
    }))?;
    Ok(())
}

/// Draws a thin frame around the plotting region (over the cells).
pub fn draw_border<DB: DrawingBackend>(chart: &mut RectChart<'_, DB>, grid: &Grid) -> Result<()>
where
    DB::ErrorType: 'static,
{
    chart.draw_series(std::iter::once(Rectangle::new(
        [(0.0, grid.z0), (360.0, grid.z1)],
        BLACK.stroke_width(1),
    )))?;
    Ok(())
}

/// Grid cells for a picture of `width_px` × `height_px` pixels: about `px` pixels per cell, at most
/// `max_cells` cells (SVG output keeps this small: every cell is one element).
pub fn cells_for(width_px: u32, height_px: u32, px: f64, max_cells: usize) -> (usize, usize) {
    let mut nx = (width_px as f64 / px).round().max(8.0);
    let mut ny = (height_px as f64 / px).round().max(4.0);
    let s = (max_cells as f64 / (nx * ny)).sqrt();
    if s < 1.0 {
        nx = (nx * s).floor().max(8.0);
        ny = (ny * s).floor().max(4.0);
    }
    (nx as usize, ny as usize)
}
