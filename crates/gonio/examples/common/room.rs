//! The scene of the light-transport experiments (`light_transport.rs`, `refinement.rs`): a point
//! light at the origin over a floor (z = −3) and a wall (y = 3), each cut into 1 m patches; which
//! patch a direction hits, and every patch's mean irradiance by the midpoint rule.

use gonio::Vec3;
use rayon::prelude::*;

pub const FLOOR_Z: f64 = -3.0;
pub const WALL_Y: f64 = 3.0;
pub const X_RANGE: (f64, f64) = (-4.0, 8.0);
pub const FLOOR_Y: (f64, f64) = (-4.0, 3.0);
pub const WALL_Z: (f64, f64) = (-3.0, 1.0);
pub const NX: usize = 12;
pub const NFY: usize = 7;
pub const NWZ: usize = 4;
pub const PATCHES: usize = NX * NFY + NX * NWZ;
/// The patch a direction from the origin lands in (first plane hit), if any.
#[inline]
pub fn patch(d: Vec3) -> Option<usize> {
    let t_floor = if d[2] < 0.0 {
        FLOOR_Z / d[2]
    } else {
        f64::INFINITY
    };
    let t_wall = if d[1] > 0.0 {
        WALL_Y / d[1]
    } else {
        f64::INFINITY
    };
    if t_floor < t_wall {
        let (x, y) = (t_floor * d[0], t_floor * d[1]);
        let ix = (x - X_RANGE.0).floor();
        let iy = (y - FLOOR_Y.0).floor();
        (ix >= 0.0 && ix < NX as f64 && iy >= 0.0 && iy < NFY as f64)
            .then(|| iy as usize * NX + ix as usize)
    } else if t_wall.is_finite() {
        let (x, z) = (t_wall * d[0], t_wall * d[2]);
        let ix = (x - X_RANGE.0).floor();
        let iz = (z - WALL_Z.0).floor();
        (ix >= 0.0 && ix < NX as f64 && iz >= 0.0 && iz < NWZ as f64)
            .then(|| NX * NFY + iz as usize * NX + ix as usize)
    } else {
        None
    }
}

/// Mean irradiance of every patch by the midpoint rule with k × k points, for intensity `i`.
pub fn reference(i: &(dyn Fn(Vec3) -> f64 + Sync), k: usize) -> Vec<f64> {
    (0..PATCHES)
        .into_par_iter()
        .map(|pi| {
            let mut sum = 0.0;
            for a in 0..k {
                for b in 0..k {
                    let (fa, fb) = ((a as f64 + 0.5) / k as f64, (b as f64 + 0.5) / k as f64);
                    let (p, nc) = if pi < NX * NFY {
                        let (ix, iy) = (pi % NX, pi / NX);
                        (
                            [
                                X_RANGE.0 + ix as f64 + fa,
                                FLOOR_Y.0 + iy as f64 + fb,
                                FLOOR_Z,
                            ],
                            -FLOOR_Z,
                        )
                    } else {
                        let q = pi - NX * NFY;
                        let (ix, iz) = (q % NX, q / NX);
                        (
                            [
                                X_RANGE.0 + ix as f64 + fa,
                                WALL_Y,
                                WALL_Z.0 + iz as f64 + fb,
                            ],
                            WALL_Y,
                        )
                    };
                    let d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
                    let dist = d2.sqrt();
                    sum += i([p[0] / dist, p[1] / dist, p[2] / dist]) * (nc / dist) / d2;
                }
            }
            sum / (k * k) as f64
        })
        .collect()
}

/// The relative RMSE of the estimates `sums`/`n` against the reference `r` (over its mean).
pub fn rel_rmse(sums: &[f64], n: f64, r: &[f64]) -> f64 {
    let mean = r.iter().sum::<f64>() / r.len() as f64;
    let mse = sums
        .iter()
        .zip(r)
        .map(|(s, r)| (s / n - r).powi(2))
        .sum::<f64>()
        / r.len() as f64;
    mse.sqrt() / mean
}
