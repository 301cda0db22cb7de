//! The `mapping` fuzz target's case: bytes → a small diagram (angles and values from the input,
//! including zeros, subnormals and values near the largest f64) → every HDS map that builds →
//! the properties below at the edges and corners of the square and at special directions (poles,
//! horizon, seam φ = 0/2π, axes, tiny offsets from them).
//!
//! Shared by the fuzz target (`fuzz/fuzz_targets/mapping.rs`) and the regression test
//! (`crates/gonio/tests/mapping_fuzz_cases.rs`, which replays the recorded findings and a seeded
//! sweep of random inputs on stable Rust).
//!
//! Checked for every map that builds: `sample` gives a finite unit direction inside the domain
//! with a finite pdf ≥ 0; where that pdf is positive, `pdf(direction)` agrees with it to 1e-6
//! (relative, with absolute floors of 1e-12 /sr and 1e-9 of the largest density seen); `pdf` of any unit direction is finite and ≥ 0;
//! `invert` of a direction with positive pdf gives a point of the closed square that maps back to
//! the direction (to 1e-6), or, where the map stretches an ulp of the square over more than that
//! (densities far below the mean), to a direction that inverts to the same point (to 1e-9).

use gonio::{Diagram, Domain, HemisphereMap, Sampler, SphereLayout, SphereMap};

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

fn check(label: &str, s: &dyn Sampler, points: &[[f64; 2]], dirs: &[[f64; 3]], nodes: &[[f64; 3]]) {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        check_map(s, points, dirs, nodes)
    }));
    if let Err(e) = r {
        let msg = e.downcast_ref::<String>().cloned().unwrap_or_default();
        panic!("{label}: {msg}");
    }
}

fn check_map(s: &dyn Sampler, points: &[[f64; 2]], dirs: &[[f64; 3]], nodes: &[[f64; 3]]) {
    let domain = s.domain();
    // The largest density at the diagram's nodes (where the bilinear target has its maxima): the
    // scale of the absolute floor below.
    let peak = nodes.iter().map(|&d| s.pdf(d)).fold(0.0, f64::max);
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
            // Relative 1e-6, with absolute floors of 1e-12 /sr (round-off next to zero values)
            // and 1e-9 of the peak density (at the foot of a steep segment, such as a zero guard
            // band 1e-7 of its cell wide, the direction's round-off moves the density that much).
            assert!(
                (p - x.pdf).abs() <= 1e-6 * x.pdf + 1e-12 + 1e-9 * peak,
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
        let Ok(u) = s.invert(d) else { continue };
        {
            assert!(
                u.iter().all(|c| (0.0..=1.0).contains(c)),
                "invert({d:?}) = {u:?} outside the square"
            );
            let back = s.sample(u).direction;
            let gap = norm([back[0] - d[0], back[1] - d[1], back[2] - d[2]]);
            // Below a billionth of the peak (or of the uniform) density the preimage of a
            // direction's neighbourhood can be thinner than an ulp of the square: nothing to
            // round-trip.
            if gap < 1e-6 || p < 1e-9 * peak.max(0.25 * std::f64::consts::FRAC_1_PI) {
                continue;
            }
            // Where the density is far below its mean the map stretches an ulp of the square
            // over a visible angle (dω/du² = 1/pdf, and more along one axis), so the direction
            // cannot come back to 1e-6; the round trip is then well conditioned in the square:
            // the direction it gave must invert to the same point.
            let again = s
                .invert(back)
                .map(|w| norm([w[0] - u[0], w[1] - u[1], 0.0]));
            assert!(
                again.is_ok_and(|g| g < 1e-9),
                "invert({d:?}) = {u:?} maps back to {back:?} (pdf {p}), which inverts to {again:?} off"
            );
        }
    }
}

fn unit(d: [f64; 3]) -> [f64; 3] {
    let l = norm(d);
    [d[0] / l, d[1] / l, d[2] / l]
}

/// Decodes one input into a diagram, builds every map that accepts it and checks the
/// properties above; panics (with the failing case) when one does not hold.
pub fn run(data: &[u8]) {
    let mut b = Bytes(data);
    let n = 1 + (b.u8() % 9) as usize; // parallels
    let m = 1 + (b.u8() % 9) as usize; // meridians
    let sphere = b.u8() % 2 == 0;
    let theta = angles(&mut b, n, if sphere { 180.0 } else { 90.0 }, true);
    let phi = angles(&mut b, m, 360.0, false);
    let values: Vec<Vec<f64>> = (0..m)
        .map(|_| (0..n).map(|_| b.value()).collect())
        .collect();
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
    // Every node of the diagram, just off the poles so that each meridian's own value is read.
    let nodes: Vec<[f64; 3]> = d
        .theta()
        .iter()
        .flat_map(|&t| {
            let t = t.clamp(1e-9, std::f64::consts::PI - 1e-9);
            d.phi()
                .iter()
                .map(move |&p| gonio::sampler::direction(t, p))
        })
        .collect();
    if *d.theta().last().expect("a diagram has parallels") <= std::f64::consts::FRAC_PI_2 {
        if let Ok(map) = HemisphereMap::new(&d) {
            check("HemisphereMap", &map, &points, &dirs, &nodes);
        }
    }
    for layout in [SphereLayout::Split, SphereLayout::Lambert] {
        if let Ok(map) = SphereMap::with_layout(&d, layout) {
            check(
                &format!("SphereMap {layout:?}"),
                &map,
                &points,
                &dirs,
                &nodes,
            );
        }
    }
}
