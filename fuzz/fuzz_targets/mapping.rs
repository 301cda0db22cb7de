//! Fuzz target: the HDS maps on arbitrary small diagrams (angles and values from the input,
//! including zeros, subnormals and values near the largest f64), at the edges and corners of the
//! square and at special directions (poles, horizon, seam φ = 0/2π, axes, tiny offsets from them).
//!
//! Checked for every map that builds: `sample` gives a finite unit direction inside the domain
//! with a finite pdf ≥ 0; where that pdf is positive, `pdf(direction)` agrees with it to 1e-6
//! (relative, with an absolute floor of 1e-12 /sr); `pdf` of any unit direction is finite and ≥ 0; `invert` of a direction with positive
//! pdf gives a point of the closed square that maps back to the direction (to 1e-6).
#![no_main]

use gonio::{Diagram, Domain, HemisphereMap, Sampler, SphereLayout, SphereMap};
use libfuzzer_sys::fuzz_target;

/// Reads bytes from the fuzzer's input; zeros once it runs out.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((b, rest)) => {
                self.0 = rest;
                *b
            }
            None => 0,
        }
    }
    fn u16(&mut self) -> u16 {
        u16::from(self.u8()) << 8 | u16::from(self.u8())
    }
    /// A value: mostly ordinary, sometimes an extreme.
    fn value(&mut self) -> f64 {
        match self.u8() % 16 {
            0..=2 => 0.0,
            3 => f64::MIN_POSITIVE / 4.0, // subnormal
            4 => 1e-300,
            5 => 1e300,
            6 => f64::MAX / 8.0,
            7 => 1.0,
            _ => f64::from(self.u16()) / 64.0,
        }
    }
    /// A point coordinate in [0, 1]: edges, values next to them, or an ordinary fraction.
    fn coord(&mut self) -> f64 {
        match self.u8() % 12 {
            0 => 0.0,
            1 => 1.0,
            2 => f64::EPSILON / 2.0,
            3 => 1.0 - f64::EPSILON / 2.0,
            4 => 0.5,
            5 => 5e-324,
            _ => f64::from(self.u16()) / 65535.0,
        }
    }
}

/// Strictly increasing angles in `[0, max]` (degrees): the first at 0 or a little above, the
/// last exactly at `max` (when `closed` and the input says so) or a little below, uneven steps.
fn angles(b: &mut Bytes, n: usize, max: f64, closed: bool) -> Vec<f64> {
    let w: Vec<f64> = (0..n).map(|_| 1.0 + f64::from(b.u8())).collect();
    let first = match b.u8() % 3 {
        0 => 0.0,
        _ => max * f64::from(b.u8()) / 1024.0,
    };
    let end = if closed && b.u8() % 2 == 0 {
        max
    } else {
        max * (1.0 - (1.0 + f64::from(b.u8())) / 512.0)
    };
    let mut out = vec![first];
    let total: f64 = w[1..].iter().sum();
    let mut acc = 0.0;
    for (k, wk) in w.iter().enumerate().skip(1) {
        acc += wk;
        out.push(if k == n - 1 {
            end
        } else {
            first + (end - first) * acc / total
        });
    }
    out
}

fn norm(d: [f64; 3]) -> f64 {
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

fn check(s: &dyn Sampler, points: &[[f64; 2]], dirs: &[[f64; 3]]) {
    let domain = s.domain();
    for &u in points {
        let x = s.sample(u);
        let d = x.direction;
        assert!(d.iter().all(|c| c.is_finite()), "{u:?} → {d:?}");
        assert!((norm(d) - 1.0).abs() < 1e-12, "{u:?} → {d:?} not unit");
        assert!(x.pdf.is_finite() && x.pdf >= 0.0, "{u:?} → pdf {}", x.pdf);
        if domain == Domain::Hemisphere {
            assert!(d[2] >= 0.0, "{u:?} → {d:?} below the horizon");
        }
        // At a pole the density has one value only if the diagram has one value there; the
        // fuzzer makes diagrams whose meridians differ at θ = 0 or 180° (the limit then depends
        // on the azimuth of approach), so the agreement is checked off the poles.
        let at_pole = 1.0 - d[2].abs() < 1e-12;
        if x.pdf > 0.0 && !at_pole {
            let p = s.pdf(d);
            // Relative 1e-6, with an absolute floor of 1e-12 (per steradian) for densities that
            // are round-off next to zero values.
            assert!(
                (p - x.pdf).abs() <= 1e-6 * x.pdf + 1e-12,
                "{u:?} → {d:?}: sampled pdf {} but pdf() {}",
                x.pdf,
                p
            );
        }
    }
    for &d in dirs {
        let p = s.pdf(d);
        assert!(p.is_finite() && p >= 0.0, "pdf({d:?}) = {p}");
        if p <= 0.0 || !domain.contains(d) {
            continue;
        }
        if let Ok(u) = s.invert(d) {
            assert!(
                u.iter().all(|c| (0.0..=1.0).contains(c)),
                "invert({d:?}) = {u:?} outside the square"
            );
            let back = s.sample(u).direction;
            let gap = norm([back[0] - d[0], back[1] - d[1], back[2] - d[2]]);
            assert!(gap < 1e-6, "invert({d:?}) = {u:?} maps back to {back:?}");
        }
    }
}

fn unit(d: [f64; 3]) -> [f64; 3] {
    let l = norm(d);
    [d[0] / l, d[1] / l, d[2] / l]
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let n = 1 + (b.u8() % 9) as usize; // parallels
    let m = 1 + (b.u8() % 9) as usize; // meridians
    let sphere = b.u8() % 2 == 0;
    let theta = angles(&mut b, n, if sphere { 180.0 } else { 90.0 }, true);
    let phi = angles(&mut b, m, 360.0, false);
    let values: Vec<Vec<f64>> = (0..m).map(|_| (0..n).map(|_| b.value()).collect()).collect();
    let Ok(d) = Diagram::from_degrees(&theta, &phi, &values) else {
        return;
    };
    let mut points: Vec<[f64; 2]> = vec![
        [0.0, 0.0],
        [0.0, 1.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.5, 0.5],
        [0.5, 0.0],
        [0.0, 0.5],
        [1.0, 0.5],
        [0.5, 1.0],
    ];
    for _ in 0..16 {
        points.push([b.coord(), b.coord()]);
    }
    let t = 1e-9;
    let mut dirs: Vec<[f64; 3]> = vec![
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        unit([t, 0.0, 1.0]),
        unit([t, -t * 1e-3, 1.0]),
        unit([1.0, -1e-17, 0.0]),
        unit([1.0, -1e-17, 1e-17]),
        unit([1.0, 1.0, 1.0]),
        unit([1.0, 1.0, -1.0]),
    ];
    for _ in 0..8 {
        let th = std::f64::consts::PI * b.coord();
        let ph = std::f64::consts::TAU * b.coord();
        dirs.push(gonio::sampler::direction(th, ph));
    }
    for &a in d.theta() {
        dirs.push(gonio::sampler::direction(a, 0.0));
        dirs.push(gonio::sampler::direction(a, d.phi()[d.phi().len() / 2]));
    }
    if *d.theta().last().expect("a diagram has parallels") <= std::f64::consts::FRAC_PI_2 {
        if let Ok(map) = HemisphereMap::new(&d) {
            check(&map, &points, &dirs);
        }
    }
    for layout in [SphereLayout::Split, SphereLayout::Lambert] {
        if let Ok(map) = SphereMap::with_layout(&d, layout) {
            check(&map, &points, &dirs);
        }
    }
});
