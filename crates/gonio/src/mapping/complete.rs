//! Completion of a user's diagram to the grid the tables need (docs/DERIVATION.md §8.1, A15): a
//! parallel at the pole, one at the end of the domain, and a meridian at φ = 0.
//!
//! **The support of the map is the measured range** (docs/MAPPING.md, "Completion"). Outside
//! [θ_0, θ_{N−1}] the data says nothing, so the map puts no light there:
//! * beyond the last parallel the map simply ends: it covers the spherical zone [0, θ_{N−1}] (the
//!   disk of the tables has radius x_{N−1} = √2 sin(θ_{N−1}/2) instead of 1), exactly zero light
//!   outside, and no distortion added (the cell coordinates s are the same);
//! * above the first parallel (a missing pole cap) a disk cannot be mapped onto a zone with a hole,
//!   so the cap gets **zero** values: a zero pole parallel and a *guard* parallel of zeros at a
//!   distance of [`GUARD_FRACTION`] × (the first cell's width) above θ_0, which confines the step
//!   from the edge values to zero to that thin band. The light in the band is at most about
//!   [`GUARD_FRACTION`] of the first cell's, so at most ~1e-7 of the probability lies outside the
//!   measured range and the map's power equals the data's integral to the same relative amount. A
//!   first parallel whose values are all zero needs no guard (there is no step).
//!
//! The values of the completed diagram are divided by the data's largest value (so the tables are
//! the same for any finite scale of values, 1e-320 … `f64::MAX`); [`Completed::scale`] gives it back.

use crate::diagram::{Diagram, DiagramError, MAX_NODES};
use std::f64::consts::TAU;

/// Width of a zero guard parallel's band, as a fraction of the width of the measured cell next to
/// it (see the module documentation).
pub(crate) const GUARD_FRACTION: f64 = 1e-7;

/// One zone of directions that the data does not cover and that the map completes with **zero**
/// light (reported as a warning by the library, `gonio info` and the CLI). Angles in degrees, in the
/// frame of the diagram the map was built from (θ from +z).
#[derive(Debug, Clone, PartialEq)]
pub struct Completion {
    /// Start of the zone without data (degrees). The map puts no light in the zone, except in the
    /// band between the guard parallel and the measured edge.
    pub theta_from_deg: f64,
    /// End of the zone without data (degrees).
    pub theta_to_deg: f64,
    /// The zero guard parallel that confines the step at the measured edge, if one was needed
    /// (degrees); the light between it and the edge is the only light outside the measured range.
    pub guard_deg: Option<f64>,
}

/// Degrees for a message: rounded to 1e-9° (radians → degrees round-off hidden).
fn show_deg(d: f64) -> f64 {
    (d * 1e9).round() / 1e9
}

impl std::fmt::Display for Completion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "no data for θ in [{}°, {}°]: completed with zero intensity",
            show_deg(self.theta_from_deg),
            show_deg(self.theta_to_deg)
        )?;
        if let Some(g) = self.guard_deg.map(show_deg) {
            write!(
                f,
                " (a zero guard parallel at θ = {g}° holds the step to zero; at most ~{:.0e} of the light lies outside the measured range)",
                GUARD_FRACTION
            )?;
        }
        Ok(())
    }
}

/// A completed diagram: the grid the tables need, values divided by `scale`.
#[derive(Debug, Clone)]
pub(crate) struct Completed {
    pub(crate) diagram: Diagram,
    /// The data's largest value (the completed values are the data's divided by it).
    #[allow(dead_code)]
    pub(crate) scale: f64,
    /// The zones completed with zero light, in the frame of the diagram given to [`complete`].
    pub(crate) completions: Vec<Completion>,
}

/// The largest f64 below `x`, for finite x > 0 (`f64::next_down` needs Rust 1.86; MSRV 1.80).
pub(crate) fn next_down(x: f64) -> f64 {
    debug_assert!(x > 0.0 && x.is_finite());
    f64::from_bits(x.to_bits() - 1)
}

/// The smallest f64 above `x`, for finite x ≥ +0.
fn next_up(x: f64) -> f64 {
    debug_assert!(x >= 0.0 && x.is_finite());
    f64::from_bits(x.abs().to_bits() + 1)
}

/// The θ of the guard parallel next to the measured edge `edge`, on the side of `toward` (the pole
/// or the far end of the domain), `width` the width of the adjacent measured cell; `None` when the
/// band would reach `toward` itself (the edge is then within a few ulps of it, or the band fills
/// the whole gap: the zero at `toward` alone bounds the step).
fn guard(edge: f64, toward: f64, width: f64) -> Option<f64> {
    let step = GUARD_FRACTION * width;
    let g = if toward < edge {
        let g = edge - step;
        if g < edge {
            g
        } else {
            next_down(edge)
        }
    } else {
        let g = edge + step;
        if g > edge {
            g
        } else {
            next_up(edge)
        }
    };
    let strictly_between = if toward < edge {
        g > toward
    } else {
        g < toward
    };
    strictly_between.then_some(g)
}

/// Returns the diagram with θ_0 = 0 and φ_0 = 0, values divided by `scale` (the data's largest
/// value, shared by both halves of a sphere), adding:
/// * if θ_0 > 0: a zero pole parallel at θ = 0, and a zero guard parallel just above θ_0 unless the
///   first parallel is all zero (a disk cannot be mapped onto a zone without its pole, so the cap
///   gets zero values and the step to them is confined to the guard band);
/// * nothing beyond θ_{N−1}: the map covers the spherical zone [0, θ_{N−1}] (a disk of radius
///   x_{N−1} = √2 sin(θ_{N−1}/2)), so there is exactly no light beyond the last parallel; a zone
///   [θ_{N−1}, `theta_max`] is still reported as a [`Completion`] (without a guard);
/// * a meridian at φ = 0 whose values interpolate linearly between the last and the first meridian
///   (exact: the interpolant in φ is unchanged), if φ_0 > 0.
///
/// `mirrored`: the diagram is the lower half of a sphere diagram read as θ′ = π − θ; the reported
/// [`Completion`]s are then given in the original θ. The diagram must lie within [0, `theta_max`];
/// the completed grid must fit in [`MAX_NODES`] (checked before anything is allocated).
pub(crate) fn complete(
    diagram: &Diagram,
    theta_max: f64,
    mirrored: bool,
    scale: f64,
) -> Result<Completed, DiagramError> {
    let (n, m) = (diagram.n_parallels(), diagram.n_meridians());
    let theta = diagram.theta();
    if theta[n - 1] > theta_max {
        return Err(DiagramError::BeyondDomain {
            theta_deg: theta[n - 1].to_degrees(),
            limit_deg: theta_max.to_degrees(),
        });
    }
    let zero_parallel = |j: usize| (0..m).all(|i| diagram.value(i, j) == 0.0);
    let add_pole = theta[0] > 0.0;
    let add_end = theta[n - 1] < theta_max;
    let pole_guard = if add_pole && !zero_parallel(0) {
        guard(theta[0], 0.0, theta[1] - theta[0])
    } else {
        None
    };
    // The far end needs no parallel: the map covers the zone [0, θ_{N−1}] (its disk has radius
    // x_{N−1} ≤ 1), so beyond the last parallel there is exactly no light and nothing to add.
    let mut head = Vec::new();
    if add_pole {
        head.push(0.0);
        head.extend(pole_guard);
    }
    let new_n = n + head.len();
    let new_m = m + usize::from(diagram.phi()[0] > 0.0);
    if new_n.checked_mul(new_m).is_none_or(|c| c > MAX_NODES) {
        return Err(DiagramError::TooLarge {
            parallels: new_n,
            meridians: new_m,
        });
    }
    let deg = |t: f64| {
        if mirrored {
            180.0 - t.to_degrees()
        } else {
            t.to_degrees()
        }
    };
    let zone = |a: f64, b: f64, g: Option<f64>| {
        let (a, b) = (deg(a), deg(b));
        Completion {
            theta_from_deg: a.min(b),
            theta_to_deg: a.max(b),
            guard_deg: g.map(deg),
        }
    };
    let mut completions = Vec::new();
    if add_pole {
        completions.push(zone(0.0, theta[0], pole_guard));
    }
    if add_end {
        completions.push(zone(theta[n - 1], theta_max, None));
    }
    if mirrored {
        completions.reverse();
    }
    let mut new_theta = Vec::with_capacity(new_n);
    new_theta.extend_from_slice(&head);
    new_theta.extend_from_slice(theta);
    // Meridian i of the completed grid: the head's zeros, then the data divided by `scale`.
    let row = |i: usize| {
        diagram.values()[i * n..(i + 1) * n]
            .iter()
            .map(|v| v / scale)
    };
    let phi = diagram.phi();
    let mut new_phi = Vec::with_capacity(new_m);
    let mut values = Vec::with_capacity(new_m * new_n);
    if phi[0] > 0.0 {
        // Linear interpolation across the wrap sector [φ_{M−1}, φ_0 + 2π] at 2π.
        let e = (TAU - phi[m - 1]) / (phi[0] + TAU - phi[m - 1]);
        new_phi.push(0.0);
        values.extend(head.iter().map(|_| (1.0 - e) * 0.0 + e * 0.0));
        values.extend(row(m - 1).zip(row(0)).map(|(a, b)| (1.0 - e) * a + e * b));
    }
    for (i, &p) in phi.iter().enumerate() {
        new_phi.push(p);
        values.extend(head.iter().map(|_| 0.0));
        values.extend(row(i));
    }
    Ok(Completed {
        diagram: Diagram::new(new_theta, new_phi, values)?,
        scale,
        completions,
    })
}

/// The diagram's part on one side of the horizon: `upper` keeps θ ≤ π/2; otherwise θ ≥ π/2, mirrored
/// to θ′ = π − θ (so the lower hemisphere reads as an upper one). `None` when the diagram has no
/// parallel strictly inside that hemisphere, or no power there. A node at π/2 must exist if the
/// diagram crosses the horizon (see [`with_horizon_node`]).
pub(crate) fn hemisphere_part(diagram: &Diagram, upper: bool) -> Option<Diagram> {
    let half = std::f64::consts::FRAC_PI_2;
    let theta = diagram.theta();
    let keep: Vec<usize> = (0..theta.len())
        .filter(|&j| {
            if upper {
                theta[j] <= half
            } else {
                theta[j] >= half
            }
        })
        .collect();
    let inside = keep.iter().any(|&j| {
        if upper {
            theta[j] < half
        } else {
            theta[j] > half
        }
    });
    if !inside {
        return None;
    }
    let order: Vec<usize> = if upper {
        keep
    } else {
        keep.into_iter().rev().collect()
    };
    let new_theta: Vec<f64> = order
        .iter()
        .map(|&j| {
            if upper {
                theta[j]
            } else {
                (std::f64::consts::PI - theta[j]).max(0.0)
            }
        })
        .collect();
    // θ is increasing, so the kept parallels are one run of each meridian's row (read backwards
    // for the lower part).
    let n = theta.len();
    let (first, count) = (order[0].min(order[order.len() - 1]), order.len());
    debug_assert!(order.iter().all(|&j| (first..first + count).contains(&j)));
    let mut values = Vec::with_capacity(diagram.n_meridians() * count);
    for row in diagram.values().chunks_exact(n) {
        let run = &row[first..first + count];
        if upper {
            values.extend_from_slice(run);
        } else {
            values.extend(run.iter().rev());
        }
    }
    Diagram::new(new_theta, diagram.phi().to_vec(), values).ok()
}

/// Where a node at the horizon θ = π/2 goes when the diagram crosses it without one: the index
/// j of the first parallel above π/2 and the fraction t of π/2 between θ_{j−1} and θ_j; `None`
/// when no node is needed. The size cap counts the added parallel (checked before allocating).
fn horizon_node(diagram: &Diagram) -> Result<Option<(usize, f64)>, DiagramError> {
    let half = std::f64::consts::FRAC_PI_2;
    let theta = diagram.theta();
    let n = theta.len();
    if !(theta[0] < half && theta[n - 1] > half) || theta.contains(&half) {
        return Ok(None);
    }
    let m = diagram.n_meridians();
    if (n + 1).checked_mul(m).is_none_or(|c| c > MAX_NODES) {
        return Err(DiagramError::TooLarge {
            parallels: n + 1,
            meridians: m,
        });
    }
    let j = theta.partition_point(|&t| t < half); // theta[j-1] < half < theta[j]
    Ok(Some((j, (half - theta[j - 1]) / (theta[j] - theta[j - 1]))))
}

/// [`hemisphere_part`] of [`with_horizon_node`]`(diagram)`, the same values bit for bit, without
/// the copy of the whole diagram with the node (one value a pixel of an environment map: issue 40
/// measured the peak memory of a sphere map's build).
pub(crate) fn hemisphere_part_with_horizon(
    diagram: &Diagram,
    upper: bool,
) -> Result<Option<Diagram>, DiagramError> {
    let Some((j, t)) = horizon_node(diagram)? else {
        return Ok(hemisphere_part(diagram, upper));
    };
    let (half, theta, n, m) = (
        std::f64::consts::FRAC_PI_2,
        diagram.theta(),
        diagram.n_parallels(),
        diagram.n_meridians(),
    );
    let new_theta: Vec<f64> = if upper {
        theta[..j].iter().copied().chain([half]).collect()
    } else {
        theta[j..]
            .iter()
            .rev()
            .chain([&half])
            .map(|&x| (std::f64::consts::PI - x).max(0.0))
            .collect()
    };
    let mut values = Vec::with_capacity(m * new_theta.len());
    for row in diagram.values().chunks_exact(n) {
        let h = (1.0 - t) * row[j - 1] + t * row[j];
        if upper {
            values.extend_from_slice(&row[..j]);
        } else {
            values.extend(row[j..].iter().rev());
        }
        values.push(h);
    }
    Ok(Diagram::new(new_theta, diagram.phi().to_vec(), values).ok())
}

/// Inserts a parallel at θ = π/2 (values linear in θ between its neighbours, i.e. the target
/// interpolant is unchanged) when the diagram crosses the horizon without a node there.
/// (The maps use [`hemisphere_part_with_horizon`]; this is its reference in the tests.)
#[cfg(test)]
pub(crate) fn with_horizon_node(diagram: &Diagram) -> Result<Diagram, DiagramError> {
    let Some((j, t)) = horizon_node(diagram)? else {
        return Ok(diagram.clone());
    };
    let (theta, n, m) = (
        diagram.theta(),
        diagram.n_parallels(),
        diagram.n_meridians(),
    );
    let mut new_theta = theta.to_vec();
    new_theta.insert(j, std::f64::consts::FRAC_PI_2);
    let mut values = Vec::with_capacity(m * (n + 1));
    for row in diagram.values().chunks_exact(n) {
        values.extend_from_slice(&row[..j]);
        values.push((1.0 - t) * row[j - 1] + t * row[j]);
        values.extend_from_slice(&row[j..]);
    }
    Diagram::new(new_theta, diagram.phi().to_vec(), values)
}

#[cfg(test)]
mod horizon_tests {
    use super::*;

    /// The parts made without the copy of the whole diagram (issue 40) are those of the copy with
    /// the horizon node, bit for bit, on grids that cross the horizon, touch it or stay on a side.
    #[test]
    fn parts_with_horizon_are_the_parts_of_the_diagram_with_the_node() {
        let grids: [&[f64]; 5] = [
            &[0.0, 0.3, 1.2, 1.9, 2.5, std::f64::consts::PI],
            &[0.1, 1.5, 1.6],
            &[0.0, std::f64::consts::FRAC_PI_2, 3.0],
            &[0.0, 0.5, 1.0],
            &[1.7, 2.0, 3.1],
        ];
        for theta in grids {
            let phi = vec![0.0, 1.0, 2.5, 4.0];
            let values: Vec<f64> = (0..theta.len() * phi.len())
                .map(|k| 0.1 + ((k * 37) % 11) as f64 / 3.0)
                .collect();
            let d = Diagram::new(theta.to_vec(), phi, values).unwrap();
            let with = with_horizon_node(&d).unwrap();
            for upper in [true, false] {
                let a = hemisphere_part_with_horizon(&d, upper).unwrap();
                let b = hemisphere_part(&with, upper);
                match (a, b) {
                    (Some(a), Some(b)) => {
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(a.theta()), bits(b.theta()), "{theta:?} {upper}");
                        assert_eq!(bits(a.phi()), bits(b.phi()));
                        assert_eq!(bits(a.values()), bits(b.values()), "{theta:?} {upper}");
                    }
                    (None, None) => {}
                    (a, b) => panic!("{theta:?} {upper}: {a:?} vs {b:?}"),
                }
            }
        }
    }
}
