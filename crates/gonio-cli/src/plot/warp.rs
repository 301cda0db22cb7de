//! `warp`: the same Halton points of the unit square after every stage of the map, coloured by
//! their stratum of the square, so one sees that strata stay compact (strata stay strata).
//!
//! With a [`gonio::HemisphereMap`]: square → M_B (disk) → M_C (star domain) → M_D (disk, which is
//! the Lambert equal-area projection of the hemisphere) → directions on the equal-area (φ, cos θ)
//! rectangle. With a [`gonio::SphereMap`]: the same stages of the map of its more probable
//! hemisphere (split layout; the other hemisphere's points are left out of the stage panels) or
//! of its single map (Lambert layout, whose M_D disk has radius √2), then all directions on the
//! (φ, cos θ) rectangle of the sphere. Without either (a baseline): the square → the directions in
//! Lambert equal-area disk(s) (one per hemisphere) and on the rectangle.

use super::colour::stratum;
use super::grid::{rect_chart, z_range};
use super::{desc_font, label_font, titled, PlotInput};
use anyhow::Result;
use gonio::sequence::{Sequence, SequenceKind};
use gonio::{Domain, MapRef, Point2, Vec3};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::f64::consts::TAU;

/// Most points drawn: more show nothing new and make huge SVG files.
pub const MAX_POINTS: usize = 16_384;

/// Strata per side of the square used for the colours.
const STRATA: usize = 8;

/// Where the points of one panel lie.
enum Panel {
    /// The unit square (u, v).
    Square(Vec<(f64, f64)>),
    /// A disk of radius `extent` (or more), points in Cartesian (x, y).
    Disk {
        caption: String,
        points: Vec<(f64, f64)>,
        extent: f64,
    },
    /// The equal-area rectangle (φ in degrees, cos θ).
    Rect {
        caption: String,
        points: Vec<(f64, f64)>,
        domain: Domain,
    },
}

fn cart((r, phi): (f64, f64)) -> (f64, f64) {
    (r * phi.cos(), r * phi.sin())
}

/// Lambert azimuthal equal-area position of a direction in the unit disk of its hemisphere.
fn lambert(d: Vec3) -> (f64, f64) {
    let (_, phi) = gonio::sampler::spherical(d);
    cart(((1.0 - d[2].abs()).max(0.0).sqrt(), phi))
}

fn rect_point(d: Vec3) -> (f64, f64) {
    let (_, phi) = gonio::sampler::spherical(d);
    (phi.to_degrees(), d[2])
}

fn panels(input: &PlotInput, u: &[Point2]) -> Vec<Panel> {
    let square = Panel::Square(u.iter().map(|p| (p[0], p[1])).collect());
    let photometric = input.photometric;
    let staged: Option<(Vec<Option<gonio::mapping::Stages>>, String, f64)> = match input.map {
        Some(MapRef::Hemisphere(map)) => Some((
            u.iter().map(|&p| Some(map.stages(p))).collect(),
            String::new(),
            1.0,
        )),
        Some(MapRef::Sphere(map)) => match map.lower_probability() {
            Some(p_lower) => {
                let lower = p_lower >= 0.5;
                let side = if lower { "lower" } else { "upper" };
                Some((
                    u.iter()
                        .map(|&p| Some(map.stages(p)).filter(|s| s.lower == lower))
                        .collect(),
                    format!(" ({side}-hemisphere map)"),
                    1.0,
                ))
            }
            None => Some((
                u.iter().map(|&p| Some(map.stages(p))).collect(),
                " (Lambert sphere)".into(),
                std::f64::consts::SQRT_2,
            )),
        },
        None => None,
    };
    match staged {
        Some((st, which, d_extent)) => {
            let nan = (f64::NAN, f64::NAN);
            let pick = |f: &dyn Fn(&gonio::mapping::Stages) -> (f64, f64)| -> Vec<(f64, f64)> {
                st.iter().map(|s| s.as_ref().map_or(nan, f)).collect()
            };
            let star = pick(&|s| cart(s.star_c));
            let star_extent = st.iter().flatten().fold(1.0f64, |a, s| a.max(s.star_c.0));
            let dirs: Vec<Vec3> = u
                .iter()
                .map(|&p| input.sampler.sample(p).direction)
                .collect();
            vec![
                square,
                Panel::Disk {
                    caption: format!("after M_B (concentric): disk{which}"),
                    points: pick(&|s| cart(s.disk_b)),
                    extent: 1.0,
                },
                Panel::Disk {
                    caption: "after M_C (angular): star domain".into(),
                    points: star,
                    extent: star_extent,
                },
                Panel::Disk {
                    caption: "after M_D (radial): Lambert disk".into(),
                    points: pick(&|s| cart(s.disk_d)),
                    extent: d_extent,
                },
                Panel::Rect {
                    caption: "directions, equal-area (φ, cos θ)".into(),
                    points: dirs.iter().map(|&d| rect_point(d)).collect(),
                    domain: input.sampler.domain(),
                },
            ]
        }
        None => {
            let dirs: Vec<Vec3> = u
                .iter()
                .map(|&p| input.sampler.sample(p).direction)
                .collect();
            let domain = input.sampler.domain();
            let mut v = vec![square];
            let side = |upper: bool| -> Vec<(f64, f64)> {
                dirs.iter()
                    .map(|&d| {
                        if (d[2] >= 0.0) == upper {
                            lambert(d)
                        } else {
                            (f64::NAN, f64::NAN)
                        }
                    })
                    .collect()
            };
            let (up, down) = if photometric {
                ("upper hemisphere (γ > 90°)", "lower hemisphere (γ ≤ 90°)")
            } else {
                ("upper hemisphere z ≥ 0", "lower hemisphere z < 0")
            };
            v.push(Panel::Disk {
                caption: format!("{up}, Lambert equal-area"),
                points: side(true),
                extent: 1.0,
            });
            if domain == Domain::Sphere {
                v.push(Panel::Disk {
                    caption: format!("{down}, Lambert equal-area"),
                    points: side(false),
                    extent: 1.0,
                });
            }
            let axes = if photometric {
                "(C, cos γ)"
            } else {
                "(φ, cos θ)"
            };
            v.push(Panel::Rect {
                caption: format!("directions, equal-area {axes}"),
                points: dirs.iter().map(|&d| rect_point(d)).collect(),
                domain,
            });
            v
        }
    }
}

/// One cell per panel: a single row when the picture is wide (the rectangle panel wider than the
/// square ones), else the square panels in one row above the rectangle.
fn layout<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    ps: &[Panel],
) -> Vec<DrawingArea<DB, Shift>> {
    let (w, h) = area.dim_in_pixel();
    let weight = |p: &Panel| {
        if matches!(p, Panel::Rect { .. }) {
            1.8
        } else {
            1.0
        }
    };
    let total: f64 = ps.iter().map(weight).sum();
    if w as f64 / h as f64 >= 0.6 * total {
        let mut x = 0.0;
        let mut breaks = Vec::new();
        for p in &ps[..ps.len() - 1] {
            x += weight(p) / total * w as f64;
            breaks.push(x.round() as i32);
        }
        area.split_by_breakpoints(breaks, Vec::<i32>::new())
    } else {
        let squares = ps
            .iter()
            .filter(|p| !matches!(p, Panel::Rect { .. }))
            .count();
        let (top, bottom) = area.split_vertically((h as f64 * 0.55) as i32);
        let mut cells = top.split_evenly((1, squares.max(1)));
        cells.truncate(squares);
        cells.push(bottom);
        cells
    }
}

/// The largest centred square inside `area`.
fn square_in<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> DrawingArea<DB, Shift> {
    let (w, h) = area.dim_in_pixel();
    let s = w.min(h);
    let (dx, dy) = ((w - s) / 2, (h - s) / 2);
    area.margin(dy, h - s - dy, dx, w - s - dx)
}

pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    input: &PlotInput,
    n: usize,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let requested = n;
    let n = n.min(MAX_POINTS);
    let mut u: Vec<Point2> = vec![[0.0; 2]; n];
    Sequence::new(SequenceKind::Halton, 0).fill(0, &mut u);
    let colours: Vec<RGBColor> = u
        .iter()
        .map(|p| {
            let s = |x: f64| ((x * STRATA as f64) as usize).min(STRATA - 1);
            stratum(s(p[0]), s(p[1]), STRATA)
        })
        .collect();
    let radius = if n <= 4000 { 2 } else { 1 };
    let stages = if input.map.is_some() {
        "through the stages of the HDS map"
    } else {
        "mapped to directions"
    };
    let count = if requested > n {
        format!("the first {n} (of {requested} requested)")
    } else {
        n.to_string()
    };
    let title = format!(
        "{} — warp of `{}`: {} Halton points {}, coloured by their {}×{} stratum of the square",
        input.title,
        input.sampler.name(),
        count,
        stages,
        STRATA,
        STRATA
    );
    let area = titled(root, &title, 22.0)?;
    let ps = panels(input, &u);
    let cells = layout(&area, &ps);
    let dot = |(x, y): (f64, f64), c: &RGBColor| Circle::new((x, y), radius, c.filled());

    for (panel, cell) in ps.iter().zip(&cells) {
        match panel {
            Panel::Square(pts) => {
                let a = titled(cell, "unit square (u, v)", 16.0)?;
                let a = square_in(&a);
                let mut chart = ChartBuilder::on(&a)
                    .margin(10)
                    .x_label_area_size(42)
                    .y_label_area_size(42)
                    .build_cartesian_2d(0.0..1.0, 0.0..1.0)?;
                chart
                    .configure_mesh()
                    .x_labels(3)
                    .y_labels(3)
                    .light_line_style(WHITE)
                    .bold_line_style(RGBColor(225, 225, 225))
                    .x_label_style(label_font())
                    .y_label_style(label_font())
                    .x_desc("u")
                    .y_desc("v")
                    .axis_desc_style(desc_font())
                    .draw()?;
                chart.draw_series(pts.iter().zip(&colours).map(|(&p, c)| dot(p, c)))?;
            }
            Panel::Disk {
                caption,
                points,
                extent,
            } => {
                let a = titled(cell, caption, 16.0)?;
                let a = square_in(&a);
                let e = extent * 1.04;
                let mut chart = ChartBuilder::on(&a)
                    .margin(10)
                    .x_label_area_size(42)
                    .y_label_area_size(42)
                    .build_cartesian_2d(-e..e, -e..e)?;
                chart
                    .configure_mesh()
                    .disable_mesh()
                    .x_labels(5)
                    .y_labels(5)
                    .x_label_style(label_font())
                    .y_label_style(label_font())
                    .x_label_formatter(&|v| format!("{v:.1}"))
                    .y_label_formatter(&|v| format!("{v:.1}"))
                    .x_desc("x = r cos φ")
                    .y_desc("y = r sin φ")
                    .axis_desc_style(desc_font())
                    .draw()?;
                let circle: Vec<(f64, f64)> = (0..=256)
                    .map(|k| cart((1.0, TAU * k as f64 / 256.0)))
                    .collect();
                chart.draw_series(std::iter::once(PathElement::new(
                    circle,
                    RGBColor(150, 150, 150).stroke_width(1),
                )))?;
                chart.draw_series(
                    points
                        .iter()
                        .zip(&colours)
                        .filter(|(p, _)| p.0.is_finite())
                        .map(|(&p, c)| dot(p, c)),
                )?;
            }
            Panel::Rect {
                caption,
                points,
                domain,
            } => {
                let a = titled(cell, caption, 16.0)?;
                let (cw, ch) = a.dim_in_pixel();
                // Keep the rectangle no taller than wide so it reads as a map, not a strip.
                let a = if ch > cw {
                    let d = ch - cw;
                    a.margin(d / 2, d - d / 2, 0, 0)
                } else {
                    a
                };
                let compact = a.dim_in_pixel().0 < 560;
                let mut chart = rect_chart(&a, *domain, input, compact)?;
                let (z0, z1) = z_range(*domain);
                chart.draw_series(std::iter::once(Rectangle::new(
                    [(0.0, z0), (360.0, z1)],
                    RGBColor(150, 150, 150).stroke_width(1),
                )))?;
                chart.draw_series(points.iter().zip(&colours).map(|(&p, c)| dot(p, c)))?;
            }
        }
    }
    Ok(())
}
