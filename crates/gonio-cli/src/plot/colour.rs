//! Colour maps and colour bars.

use super::axis::Ticked;
use super::{desc_font, label_font};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Cells where the quantity is undefined (e.g. the target is 0).
pub const UNDEFINED: RGBColor = RGBColor(190, 190, 190);
/// Cells that should be impossible (e.g. samples where the target is 0).
pub const IMPOSSIBLE: RGBColor = RGBColor(0, 0, 0);

/// Viridis (perceptually uniform, colour-blind safe), sampled at 9 points (0xRRGGBB).
const VIRIDIS: [u32; 9] = [
    0x440154, 0x482878, 0x3e4a89, 0x31688e, 0x26828e, 0x1f9e89, 0x35b779, 0x6dcd59, 0xfde725,
];

/// Blue – white – red, for signed quantities centred at the middle (0xRRGGBB).
const DIVERGING: [u32; 7] = [
    0x2166ac, 0x67a9cf, 0xd1e5f0, 0xf7f7f7, 0xfddbc7, 0xef8a62, 0xb2182b,
];

fn lerp_table(table: &[u32], t: f64) -> RGBColor {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (table.len() - 1) as f64;
    let i = (x.floor() as usize).min(table.len() - 2);
    let f = x - i as f64;
    let (a, b) = (table[i], table[i + 1]);
    let mix = |shift: u32| {
        let (p, q) = ((a >> shift) & 0xff, (b >> shift) & 0xff);
        (p as f64 + f * (q as f64 - p as f64)).round() as u8
    };
    RGBColor(mix(16), mix(8), mix(0))
}

/// Sequential map for t ∈ [0, 1].
pub fn viridis(t: f64) -> RGBColor {
    lerp_table(&VIRIDIS, t)
}

/// Diverging map for t ∈ [−1, 1] (white at 0).
pub fn diverging(t: f64) -> RGBColor {
    lerp_table(&DIVERGING, 0.5 * (t + 1.0))
}

/// Colour of stratum (i, j) of a k × k grid of the square: hue follows i, lightness follows j.
pub fn stratum(i: usize, j: usize, k: usize) -> RGBColor {
    let k = k.max(2) as f64;
    let hue = 0.8 * i as f64 / (k - 1.0);
    let light = 0.28 + 0.45 * j as f64 / (k - 1.0);
    let c = HSLColor(hue, 0.85, light).to_rgba();
    RGBColor(c.0, c.1, c.2)
}

/// A vertical colour bar.
pub struct Bar<'a> {
    /// Value range drawn, bottom to top (in the bar's own coordinate, e.g. ln ratio).
    pub lo: f64,
    pub hi: f64,
    /// Colour of a bar coordinate.
    pub colour: &'a dyn Fn(f64) -> RGBColor,
    /// What the colour encodes, with unit (drawn along the bar).
    pub desc: String,
    /// Tick positions in bar coordinates; `None`: plotters' own.
    pub ticks: Option<Vec<f64>>,
    /// Tick label of a bar coordinate.
    pub label: &'a dyn Fn(f64) -> String,
    /// Horizontal marks across the bar (position, text), e.g. a guaranteed bound.
    pub marks: Vec<(f64, String)>,
}

/// Layout shared by a panel and its bar so that both plotting regions line up.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    pub margin: u32,
    pub x_label: u32,
}

impl Bar<'_> {
    /// Draws the bar into `area`; its plotting region lines up with a chart built with the same
    /// `frame`.
    pub fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        frame: Frame,
    ) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let bar = self;
        let (lo, hi) = if bar.hi > bar.lo {
            (bar.lo, bar.hi)
        } else {
            (bar.lo - 0.5, bar.lo + 0.5)
        };
        // Plotting region: the bar (22 px) and, when there are marks, room for their text on its left.
        let (w, _) = area.dim_in_pixel();
        let plot_w: i32 = if bar.marks.is_empty() { 22 } else { 58 };
        let x_lo = if bar.marks.is_empty() {
            0.0
        } else {
            -(plot_w as f64 / 22.0 - 1.0)
        };
        let right = (w as i32 - plot_w - 4 - frame.margin as i32).max(10);
        let mut b = ChartBuilder::on(area);
        b.margin(frame.margin)
            .margin_left(4)
            .x_label_area_size(frame.x_label)
            .right_y_label_area_size(right);
        let steps = 256;
        let cells = (0..steps).map(|k| {
            let a = lo + (hi - lo) * k as f64 / steps as f64;
            let b = lo + (hi - lo) * (k + 1) as f64 / steps as f64;
            Rectangle::new([(0.0, a), (1.0, b)], (bar.colour)(0.5 * (a + b)).filled())
        });
        let ticks = bar.ticks.clone().unwrap_or_else(|| auto_ticks(lo, hi));
        let mut chart = b.build_cartesian_2d(x_lo..1.0f64, Ticked::new(lo..hi, ticks))?;
        chart.draw_series(cells)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_label_style(label_font())
            .y_label_formatter(&|v| (bar.label)(*v))
            .y_desc(bar.desc.as_str())
            .axis_desc_style(desc_font())
            .draw()?;
        chart.draw_series(std::iter::once(Rectangle::new(
            [(0.0, lo), (1.0, hi)],
            BLACK.stroke_width(1),
        )))?;
        let mark_font = ("sans-serif", 12)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Right, VPos::Center));
        for (y, text) in &bar.marks {
            let y = y.clamp(lo, hi);
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(-0.25, y), (1.0, y)],
                BLACK.stroke_width(2),
            )))?;
            chart.draw_series(std::iter::once(Text::new(
                text.clone(),
                (-0.35, y),
                mark_font.clone(),
            )))?;
        }
        Ok(())
    }
}

/// About 6 evenly spaced "nice" ticks covering [lo, hi].
pub fn auto_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let step = super::nice_step((hi - lo) / 5.0);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}
