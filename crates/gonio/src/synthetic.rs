//! Synthetic diagrams the project makes itself: the built-in example luminaire and the random
//! families used by the tests and the experiments (issue "paper's experiments").
//!
//! All generators are deterministic for a given seed.

use crate::diagram::Diagram;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::PI;

/// A family of random diagrams.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Family {
    /// Independent uniform values in [0, 1).
    UniformRandom,
    /// Mostly small values with a few nodes 100× larger.
    Spiky,
    /// A sum of 1–4 cosine-power lobes (exponents 1–64) with random axes: smooth, realistic.
    Lobes,
    /// Rotationally symmetric random profile (all meridians equal).
    Rotational,
    /// Uniform values with 60 % of the nodes set to zero.
    ZeroHeavy,
}

impl Family {
    /// Every family, in a fixed order.
    pub const ALL: [Family; 5] = [
        Family::UniformRandom,
        Family::Spiky,
        Family::Lobes,
        Family::Rotational,
        Family::ZeroHeavy,
    ];

    /// Short lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Family::UniformRandom => "uniform-random",
            Family::Spiky => "spiky",
            Family::Lobes => "lobes",
            Family::Rotational => "rotational",
            Family::ZeroHeavy => "zero-heavy",
        }
    }
}

/// Angles of a grid: `count` angles from `start` to `end` (degrees, both included when
/// `include_end`), uniform, or jittered (irregular but strictly increasing) when `irregular`.
fn axis(
    rng: &mut impl Rng,
    count: usize,
    end: f64,
    include_end: bool,
    irregular: bool,
) -> Vec<f64> {
    let steps = if include_end { count.max(2) - 1 } else { count };
    let h = end / steps as f64;
    (0..count)
        .map(|k| {
            let base = k as f64 * h;
            let interior = k > 0 && (!include_end || k + 1 < count);
            if irregular && interior {
                base + rng.gen_range(-0.35..0.35) * h
            } else {
                base
            }
        })
        .collect()
}

/// A random hemisphere diagram (θ ∈ [0°, 90°]) of `n` ≥ 2 parallels and `m` ≥ 1 meridians.
pub fn random_hemisphere(
    family: Family,
    n: usize,
    m: usize,
    irregular: bool,
    seed: u64,
) -> Diagram {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let theta = axis(&mut rng, n.max(2), 90.0, true, irregular);
    let m = if family == Family::Rotational {
        1
    } else {
        m.max(1)
    };
    let phi = axis(&mut rng, m, 360.0, false, irregular);
    let lobes: Vec<([f64; 3], f64, f64)> = (0..rng.gen_range(1..=4))
        .map(|_| {
            let t: f64 = rng.gen_range(0.0..1.3);
            let p: f64 = rng.gen_range(0.0..2.0 * PI);
            let axis = [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()];
            (
                axis,
                2f64.powf(rng.gen_range(0.0..6.0)),
                rng.gen_range(0.2..1.0),
            )
        })
        .collect();
    let profile: Vec<f64> = (0..theta.len()).map(|_| rng.gen()).collect();
    let mut values = grid_values(phi.len(), theta.len(), |i, j| {
        let (pd, td) = (phi[i], theta[j]);
        let r: f64 = rng.gen();
        match family {
            Family::UniformRandom => r,
            Family::Spiky => {
                if r < 0.1 {
                    100.0 * rng.gen::<f64>()
                } else {
                    rng.gen()
                }
            }
            Family::Lobes => {
                let d = crate::sampler::direction(td.to_radians(), pd.to_radians());
                lobes
                    .iter()
                    .map(|(a, e, w)| {
                        w * (d[0] * a[0] + d[1] * a[1] + d[2] * a[2]).max(0.0).powf(*e)
                    })
                    .sum()
            }
            Family::Rotational => profile[j],
            Family::ZeroHeavy => {
                if r < 0.6 {
                    0.0
                } else {
                    rng.gen()
                }
            }
        }
    });
    if values.iter().flatten().all(|&v| v == 0.0) {
        values[0][0] = 1.0;
    }
    Diagram::from_degrees(&theta, &phi, &values).expect("generated diagrams are valid")
}

/// Values on an `m` × `n` grid (`m` meridians of `n` parallels, the layout of
/// [`Diagram::from_degrees`]), `cell(i, j)` called meridian by meridian, parallel by parallel: the
/// table of every generated diagram (so a seeded generator draws its numbers in that order).
pub fn grid_values(m: usize, n: usize, mut cell: impl FnMut(usize, usize) -> f64) -> Vec<Vec<f64>> {
    (0..m)
        .map(|i| (0..n).map(|j| cell(i, j)).collect())
        .collect()
}

/// The built-in example: an asymmetric street-light-like luminaire on the whole sphere, in candela,
/// on a 5° × 15° grid (θ from +z; most light goes down and sideways toward +x, a little goes up).
pub fn example_luminaire() -> Diagram {
    let theta: Vec<f64> = (0..=36).map(|k| 5.0 * k as f64).collect();
    let phi: Vec<f64> = (0..24).map(|k| 15.0 * k as f64).collect();
    // main beam 60° off nadir toward +x, a wide down-light and a weak up-light
    let a = [60f64.to_radians().sin(), 0.0, -60f64.to_radians().cos()];
    tabulate(&theta, &phi, |d| {
        let beam = (d[0] * a[0] + d[2] * a[2]).max(0.0).powi(12);
        let down = (-d[2]).max(0.0).powi(2);
        let up = 0.05 * d[2].max(0.0);
        (1200.0 * beam + 400.0 * down + 300.0 * up).round()
    })
    .expect("the example diagram is valid")
}

/// The diagram of `f`, a function of direction (gonio's frame), on the grid of parallels
/// `theta_deg` and meridians `phi_deg` (degrees): value (i, j) = f(direction(θ_j, φ_i)).
///
/// ```
/// let d = gonio::synthetic::tabulate(&[0.0, 45.0, 90.0], &[0.0, 180.0], |w| w[2].max(0.0))
///     .unwrap();
/// assert_eq!(d.value(1, 0), 1.0);
/// ```
pub fn tabulate(
    theta_deg: &[f64],
    phi_deg: &[f64],
    f: impl Fn(crate::Vec3) -> f64,
) -> Result<Diagram, crate::diagram::DiagramError> {
    let values = grid_values(phi_deg.len(), theta_deg.len(), |i, j| {
        f(crate::sampler::direction(
            theta_deg[j].to_radians(),
            phi_deg[i].to_radians(),
        ))
    });
    Diagram::from_degrees(theta_deg, phi_deg, &values)
}
