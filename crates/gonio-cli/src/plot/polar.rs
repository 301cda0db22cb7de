//! `polar`: the intensity curves of the planes C0–C180 and C90–C270 as lighting catalogues draw
//! them: a polar diagram with the nadir at the bottom, C0 (resp. C90) on the right and C180 (resp.
//! C270) on the left, the radius the intensity.
//!
//! A type A or B file is drawn in its own planes instead, from its measured (H, V) table: the
//! plane H = 0° (V from −90° to 90°, V > 0 on the right) and the plane V = 0° (H from −90° to 90°,
//! H > 0 on the right), the angle labelled from the beam axis (H = V = 0°, the nadir). In the
//! gonio frame those are the planes C0–C180 and C90–C270 (type B: (H, V) = sin H·ŷ +
//! cos H (sin V·x̂ − cos V·ẑ); type A likewise with H and V exchanged off the planes).
//!
//! A point at polar angle θ (from +z) is drawn at screen angle θ from straight up, whichever way the
//! angles are labelled: for photometric data γ = 180° − θ, so γ = 0° (nadir) is at the bottom; for a
//! plain diagram θ = 0° (the pole, +z) is at the top. Only the half of the circle the diagram
//! covers is drawn when it lies within one hemisphere.

use super::{fit, fmt_num, label_font, nice_step, titled, value_unit, PlotInput};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::f64::consts::{FRAC_PI_2, PI};

const PLANE_COLOURS: [RGBColor; 2] = [RGBColor(200, 30, 30), RGBColor(30, 80, 200)];
const GRID: RGBColor = RGBColor(200, 200, 200);
const GRID_DARK: RGBColor = RGBColor(120, 120, 120);

/// Values of plane φ = `phi` (right side) and φ + 180° (left side) at the polar angles `thetas`.
fn plane(input: &PlotInput, phi: f64, thetas: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let d = input.diagram;
    let right = thetas.iter().map(|&t| d.interpolate(t, phi)).collect();
    let left = thetas.iter().map(|&t| d.interpolate(t, phi + PI)).collect();
    (right, left)
}

/// The two curves drawn, as (right side, left side) values at the polar angles `thetas`: the C0–C180
/// and C90–C270 planes of the diagram, or for a type A/B file its measured planes H = 0° (V = ±a)
/// and V = 0° (H = ±a), a = 180° − θ the angle from the beam axis.
pub(super) fn curves(input: &PlotInput, thetas: &[f64]) -> [(Vec<f64>, Vec<f64>); 2] {
    match input.hv_photometry {
        Some(p) => {
            let a = |t: f64| 180.0 - t.to_degrees();
            let side = |f: &dyn Fn(f64) -> f64| -> (Vec<f64>, Vec<f64>) {
                (
                    thetas.iter().map(|&t| f(a(t))).collect(),
                    thetas.iter().map(|&t| f(-a(t))).collect(),
                )
            };
            [
                side(&|v| p.intensity_hv(0.0, v)),
                side(&|h| p.intensity_hv(h, 0.0)),
            ]
        }
        None => [0.0, FRAC_PI_2].map(|phi| plane(input, phi, thetas)),
    }
}

pub fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, input: &PlotInput) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let d = input.diagram;
    let th = d.theta();
    let (t0, t1) = (th[0], th[th.len() - 1]);
    // Polar angles: a fine even grid plus the nodes, so every measured value is on the curve.
    let mut thetas: Vec<f64> = (0..=360)
        .map(|k| k as f64 * PI / 360.0)
        .filter(|&t| t >= t0 && t <= t1)
        .chain(th.iter().copied())
        .collect();
    thetas.sort_by(f64::total_cmp);
    thetas.dedup_by(|a, b| (*a - *b).abs() < 1e-12);

    let planes = curves(input, &thetas);
    let imax = planes
        .iter()
        .flat_map(|(r, l)| r.iter().chain(l))
        .fold(0.0f64, |a, &b| a.max(b));
    let imax = if imax > 0.0 { imax } else { 1.0 };

    let unit = value_unit(input);
    let title = if input.photometric {
        format!("{} — luminous intensity distribution (cd)", input.title)
    } else {
        format!("{} — diagram values in two vertical planes", input.title)
    };
    let area = titled(root, &title, 22.0)?;
    let (area, foot) = {
        let (_, h) = area.dim_in_pixel();
        area.split_vertically(h.saturating_sub(30))
    };

    // Which halves of the circle hold data (screen up = θ < 90°).
    let upper = t0 < FRAC_PI_2 - 1e-9;
    let lower = t1 > FRAC_PI_2 + 1e-9;
    let (w, h) = area.dim_in_pixel();
    let (w, h) = (w as f64, h as f64);
    let pad = 46.0;
    let (cx, cy, radius) = match (upper, lower) {
        (true, false) => {
            let r = (w / 2.0 - pad).min(h - 2.0 * pad);
            (w / 2.0, (h + r) / 2.0, r)
        }
        (false, true) => {
            let r = (w / 2.0 - pad).min(h - 2.0 * pad);
            (w / 2.0, (h - r) / 2.0, r)
        }
        _ => {
            let r = (w / 2.0).min(h / 2.0) - pad;
            (w / 2.0, h / 2.0, r)
        }
    };
    let radius = radius.max(10.0);
    let (a_lo, a_hi) = match (upper, lower) {
        (true, false) => (0.0, FRAC_PI_2),
        (false, true) => (FRAC_PI_2, PI),
        _ => (0.0, PI),
    };

    let step = nice_step(imax / 4.0);
    let rings = (imax / step - 1e-9).ceil().max(1.0) as usize;
    let rmax = rings as f64 * step;
    let scale = radius / rmax;
    let px = |theta: f64, value: f64, side: f64| -> (i32, i32) {
        let r = value * scale;
        (
            (cx + side * r * theta.sin()).round() as i32,
            (cy - r * theta.cos()).round() as i32,
        )
    };

    // Rings (arcs over the visible span, both sides) and their labels.
    let arc = |r_val: f64| -> Vec<(i32, i32)> {
        let n = 180;
        let left = (0..=n).map(|k| px(a_hi - (a_hi - a_lo) * k as f64 / n as f64, r_val, -1.0));
        let right = (0..=n).map(|k| px(a_lo + (a_hi - a_lo) * k as f64 / n as f64, r_val, 1.0));
        left.chain(right).collect()
    };
    for k in 1..=rings {
        let colour = if k == rings { GRID_DARK } else { GRID };
        area.draw(&PathElement::new(
            arc(k as f64 * step),
            colour.stroke_width(1),
        ))?;
    }
    // Spokes every 15°, labels every 30° just outside the outer ring.
    let spoke_font = label_font().pos(Pos::new(HPos::Center, VPos::Center));
    let mut deg = (a_lo.to_degrees().round()) as i32;
    while deg as f64 <= a_hi.to_degrees() + 1e-9 {
        let t = (deg as f64).to_radians();
        for side in [1.0, -1.0] {
            let colour = if deg % 90 == 0 { GRID_DARK } else { GRID };
            area.draw(&PathElement::new(
                vec![px(t, 0.0, side), px(t, rmax, side)],
                colour.stroke_width(1),
            ))?;
            if deg % 30 == 0 && !(side < 0.0 && (deg == 0 || deg == 180)) {
                let shown = if input.photometric { 180 - deg } else { deg };
                let (x, y) = px(t, rmax + 24.0 / scale, side);
                area.draw(&Text::new(format!("{shown}°"), (x, y), spoke_font.clone()))?;
            }
        }
        deg += 15;
    }
    // Ring values along the spoke (an odd multiple of 15°, where no angle label sits) with the
    // least light near it, so that the curves hide no number.
    let near = |theta: f64, side: f64| -> f64 {
        planes
            .iter()
            .flat_map(|(r, l)| {
                let vals = if side > 0.0 { r } else { l };
                thetas
                    .iter()
                    .zip(vals)
                    .filter(move |(&t, _)| (t - theta).abs() <= 12f64.to_radians())
                    .map(|(_, &v)| v)
            })
            .fold(0.0f64, f64::max)
    };
    let (ring_theta, ring_side) = [15, 45, 75, 105, 135, 165]
        .into_iter()
        .map(|d: i32| (d as f64).to_radians())
        .filter(|&t| t > a_lo && t < a_hi)
        .flat_map(|t| [(t, 1.0), (t, -1.0)])
        .min_by(|a, b| near(a.0, a.1).total_cmp(&near(b.0, b.1)))
        .unwrap_or((FRAC_PI_2, 1.0));
    let ring_font = ("sans-serif", 12)
        .into_font()
        .color(&RGBColor(90, 90, 90))
        .pos(Pos::new(HPos::Center, VPos::Center));
    for k in 1..=rings {
        let v = k as f64 * step;
        let (x, y) = px(ring_theta, v, ring_side);
        let text = if k == rings && input.photometric {
            format!("{} {unit}", fmt_num(v))
        } else {
            fmt_num(v)
        };
        let est = ring_font.font.box_size(&text).unwrap_or((30, 12));
        area.draw(&Rectangle::new(
            [
                (x - est.0 as i32 / 2 - 2, y - est.1 as i32 / 2 - 1),
                (x + est.0 as i32 / 2 + 2, y + est.1 as i32 / 2 + 1),
            ],
            WHITE.filled(),
        ))?;
        area.draw(&Text::new(text, (x, y), ring_font.clone()))?;
    }

    // The curves: left side from the far end to the near pole, then the right side back.
    for (k, (right, left)) in planes.iter().enumerate() {
        let mut path: Vec<(i32, i32)> = thetas
            .iter()
            .zip(left)
            .rev()
            .map(|(&t, &v)| px(t, v, -1.0))
            .collect();
        path.extend(thetas.iter().zip(right).map(|(&t, &v)| px(t, v, 1.0)));
        draw_plane_line(&area, k, path)?;
    }

    // Legend, top left.
    let names = if input.hv_photometry.is_some() {
        ["H = 0° (V −90° … 90°)", "V = 0° (H −90° … 90°)"]
    } else if input.photometric {
        ["C0 – C180", "C90 – C270"]
    } else {
        ["φ = 0° – 180°", "φ = 90° – 270°"]
    };
    let legend_font = ("sans-serif", 15).into_font().color(&BLACK);
    let (lx, ly) = (12, 10);
    let legend_w = if input.hv_photometry.is_some() {
        230
    } else {
        170
    };
    area.draw(&Rectangle::new(
        [(lx - 6, ly - 6), (lx + legend_w, ly + 52)],
        ShapeStyle::from(&WHITE.mix(0.9)).filled(),
    ))?;
    area.draw(&Rectangle::new(
        [(lx - 6, ly - 6), (lx + legend_w, ly + 52)],
        GRID_DARK.stroke_width(1),
    ))?;
    for (k, name) in names.iter().enumerate() {
        let y = ly + 10 + 24 * k as i32;
        let sample = vec![(lx, y), (lx + 36, y)];
        draw_plane_line(&area, k, sample)?;
        area.draw(&Text::new(
            name.to_string(),
            (lx + 46, y),
            legend_font.pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
    }
    // Side labels of the planes.
    let side_font = ("sans-serif", 14).into_font().color(&GRID_DARK);
    let side_text = if input.hv_photometry.is_some() {
        ("V < 0° / H < 0° ←", "→ V > 0° / H > 0°")
    } else if input.photometric {
        ("C180 / C270 ←", "→ C0 / C90")
    } else {
        ("φ = 180° / 270° ←", "→ φ = 0° / 90°")
    };
    let (ww, _) = area.dim_in_pixel();
    area.draw(&Text::new(
        side_text.0,
        (12, (h - 8.0) as i32),
        side_font.pos(Pos::new(HPos::Left, VPos::Bottom)),
    ))?;
    area.draw(&Text::new(
        side_text.1,
        (ww as i32 - 12, (h - 8.0) as i32),
        side_font.pos(Pos::new(HPos::Right, VPos::Bottom)),
    ))?;

    let axes = if input.hv_photometry.is_some() {
        format!(
            "radius: luminous intensity I ({unit}), rings every {} {unit}; angle: from the beam axis H = V = 0° (at the bottom), measured values",
            fmt_num(step)
        )
    } else if input.photometric {
        format!(
            "radius: luminous intensity I ({unit}), rings every {} {unit}; angle: γ from the nadir (0° at the bottom, 180° at the top)",
            fmt_num(step)
        )
    } else {
        format!(
            "radius: diagram value ({unit}), rings every {}; angle: θ from +z (0° = pole at the top, 90° = horizon)",
            fmt_num(step)
        )
    };
    let (axes, size) = fit(&axes, 16.0, ww.saturating_sub(12));
    foot.draw(&Text::new(
        axes,
        (ww as i32 / 2, 12),
        ("sans-serif", size)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Center)),
    ))?;
    Ok(())
}

/// The line of plane `k` through `points`: plane 0 solid, the other dashed, both 3 px wide.
fn draw_plane_line<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    k: usize,
    points: Vec<(i32, i32)>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let style = PLANE_COLOURS[k].stroke_width(3);
    if k == 0 {
        area.draw(&PathElement::new(points, style))?;
    } else {
        area.draw(&DashedPathElement::new(points, 12, 6, style))?;
    }
    Ok(())
}
