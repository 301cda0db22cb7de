//! Completion of a user's diagram to the grid the tables need (ALGORITHM §10 A15): a parallel at
//! the pole, one at the end of the domain, and a meridian at φ = 0.

use crate::diagram::{Diagram, DiagramError};
use std::f64::consts::TAU;

/// What the parallel added at the far end of the domain holds.
#[derive(Debug, Clone, Copy)]
pub(crate) enum FarEnd {
    /// Zero (a hemisphere's horizon: the diagram carries no power beyond its last parallel).
    Zero,
    /// The mean of the last parallel over the meridians (a pole).
    Mean,
}

/// Returns the diagram with θ_0 = 0, θ_{N−1} = `theta_max` and φ_0 = 0, adding:
/// * a pole parallel at θ = 0 holding the mean of the first parallel over the meridians (one value:
///   every meridian meets at the pole), if θ_0 > 0;
/// * a parallel at `theta_max` per `far`, if θ_{N−1} < `theta_max`;
/// * a meridian at φ = 0 whose values interpolate linearly between the last and the first meridian
///   (exact: the interpolant in φ is unchanged), if φ_0 > 0.
///
/// The diagram must lie within [0, `theta_max`].
pub(crate) fn complete(
    diagram: &Diagram,
    theta_max: f64,
    far: FarEnd,
) -> Result<Diagram, DiagramError> {
    let (n, m) = (diagram.n_parallels(), diagram.n_meridians());
    let theta = diagram.theta();
    if theta[n - 1] > theta_max {
        return Err(DiagramError::BeyondDomain {
            theta_deg: theta[n - 1].to_degrees(),
            limit_deg: theta_max.to_degrees(),
        });
    }
    let mean = |j: usize| (0..m).map(|i| diagram.value(i, j)).sum::<f64>() / m as f64;
    let add_pole = theta[0] > 0.0;
    let add_end = theta[n - 1] < theta_max;
    let mut new_theta = Vec::with_capacity(n + 2);
    if add_pole {
        new_theta.push(0.0);
    }
    new_theta.extend_from_slice(theta);
    if add_end {
        new_theta.push(theta_max);
    }
    let (pole, end) = (mean(0), mean(n - 1));
    let row = |i: usize| -> Vec<f64> {
        let mut r = Vec::with_capacity(n + 2);
        if add_pole {
            r.push(pole);
        }
        r.extend((0..n).map(|j| diagram.value(i, j)));
        if add_end {
            r.push(match far {
                FarEnd::Zero => 0.0,
                FarEnd::Mean => end,
            });
        }
        r
    };
    let phi = diagram.phi();
    let mut new_phi = Vec::with_capacity(m + 1);
    let mut values = Vec::with_capacity((m + 1) * new_theta.len());
    if phi[0] > 0.0 {
        // Linear interpolation across the wrap sector [φ_{M−1}, φ_0 + 2π] at 2π.
        let e = (TAU - phi[m - 1]) / (phi[0] + TAU - phi[m - 1]);
        let (a, b) = (row(m - 1), row(0));
        new_phi.push(0.0);
        values.extend(a.iter().zip(&b).map(|(a, b)| (1.0 - e) * a + e * b));
    }
    for (i, &p) in phi.iter().enumerate() {
        new_phi.push(p);
        values.extend(row(i));
    }
    Diagram::new(new_theta, new_phi, values)
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
    let m = diagram.n_meridians();
    let values: Vec<f64> = (0..m)
        .flat_map(|i| order.iter().map(move |&j| diagram.value(i, j)))
        .collect();
    Diagram::new(new_theta, diagram.phi().to_vec(), values).ok()
}

/// Inserts a parallel at θ = π/2 (values linear in θ between its neighbours, i.e. the target
/// interpolant is unchanged) when the diagram crosses the horizon without a node there.
pub(crate) fn with_horizon_node(diagram: &Diagram) -> Diagram {
    let half = std::f64::consts::FRAC_PI_2;
    let theta = diagram.theta();
    let n = theta.len();
    if !(theta[0] < half && theta[n - 1] > half) || theta.contains(&half) {
        return diagram.clone();
    }
    let j = theta.partition_point(|&t| t < half); // theta[j-1] < half < theta[j]
    let t = (half - theta[j - 1]) / (theta[j] - theta[j - 1]);
    let mut new_theta = theta.to_vec();
    new_theta.insert(j, half);
    let m = diagram.n_meridians();
    let mut values = Vec::with_capacity(m * (n + 1));
    for i in 0..m {
        for k in 0..n {
            if k == j {
                values.push((1.0 - t) * diagram.value(i, j - 1) + t * diagram.value(i, j));
            }
            values.push(diagram.value(i, k));
        }
    }
    Diagram::new(new_theta, diagram.phi().to_vec(), values)
        .expect("inserting an interpolated parallel keeps a valid diagram valid")
}
