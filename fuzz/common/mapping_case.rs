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
//! (relative, with absolute floors of 1e-12 /sr and 1e-9 of the largest density seen); `pdf` of
//! any unit direction is finite and ≥ 0; `invert` of a direction with positive pdf gives a point
//! u of the closed square, and the round trip holds **in the square**: the direction `sample(u)`
//! inverts back to u within what the round-off of a direction can move the inverse there
//! ([`roundoff_reach`], the inverse's Jacobian times the direction's round-off, plus 1e-12), and
//! `sample(u)` is the direction itself to 1e-6 unless the map is stretched at u (`sample` moves
//! by more than that within the inverse's round-off reach, [`forward_spread`]). Directions whose
//! density is below 1e-9 of the peak (or of the uniform) density are not round-tripped.

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
    let end = if closed && b.u8().is_multiple_of(2) {
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

/// The properties of the module's documentation on one map, at the square points `points`
/// and the directions `dirs`; `nodes` are the diagram's nodes (the peak density is read there).
/// Panics with the failing point or direction when one does not hold.
pub fn check_map(s: &dyn Sampler, points: &[[f64; 2]], dirs: &[[f64; 3]], nodes: &[[f64; 3]]) {
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
        assert!(
            u.iter().all(|c| (0.0..=1.0).contains(c)),
            "invert({d:?}) = {u:?} outside the square"
        );
        let back = s.sample(u).direction;
        let gap = norm([back[0] - d[0], back[1] - d[1], back[2] - d[2]]);
        // Below a billionth of the peak (or of the uniform) density the preimage of a
        // direction's neighbourhood can be thinner than an ulp of the square: nothing to
        // round-trip.
        if p < 1e-9 * peak.max(0.25 * std::f64::consts::FRAC_1_PI) {
            continue;
        }
        // The round trip in the square: `back` is F(u) up to the round-off of a computed
        // direction, so invert(back) must be u up to what that round-off can move the inverse
        // (the inverse's Jacobian at `back` times the round-off, measured by `roundoff_reach`),
        // plus the square's own round-off (1e-12, about 4,500 ulp of 1). Where the inverse is
        // well conditioned this is far tighter than the direction check below (an inverse off
        // by 1e-10 fails it). At a pole (x = y = 0) a direction has no azimuth: where a whole
        // edge of the square maps onto it (the Lambert sphere's south pole) `invert` returns
        // one of its preimages, and the direction round trip below is the check.
        let at_pole = back[0] == 0.0 && back[1] == 0.0;
        let w = s.invert(back);
        let reach = w.map(|w| roundoff_reach(s, back, w));
        let miss = w.map(|w| norm([w[0] - u[0], w[1] - u[1], 0.0]));
        assert!(
            at_pole || matches!((miss, reach), (Ok(m), Ok(r)) if m <= r + 1e-12),
            "invert({d:?}) = {u:?} maps back to {back:?} (pdf {p}), which inverts to {w:?}: \
             {miss:?} off, round-off reach there {reach:?}"
        );
        // The round trip in direction: `sample(u)` must be `d` to 1e-6, unless the map is
        // stretched at u: u = invert(d) is known only to the inverse's round-off reach at `d`,
        // and where `sample` moves by more than 1e-6 over that reach (dω/du² = 1/pdf, and far
        // more along one axis next to a nearly empty meridian, see `roundoff_reach`), the
        // preimage of d's 1e-6-neighbourhood is thinner than the reach: the computed map can
        // jump over it, and the square round trip above is the statement that `invert` is right.
        // Measured like `roundoff_reach`: `sample` at the step of the reach along both axes.
        if gap >= 1e-6 {
            let h = roundoff_reach(s, d, u) + f64::EPSILON;
            let spread = forward_spread(s, u, back, h);
            assert!(
                spread > 1e-6,
                "invert({d:?}) = {u:?} maps back to {back:?} (pdf {p}), {gap:e} rad away, where \
                 sample moves only {spread:e} rad within the inverse's round-off reach {h:e}"
            );
        }
    }
}

/// The largest distance from `back` = F(u) of F(u ± h e_k) along each axis of the square,
/// summed over the two axes (points outside the square clamped onto it): a bound on how far
/// `sample` moves over the square points within h of u, to first order.
pub fn forward_spread(s: &dyn Sampler, u: [f64; 2], back: [f64; 3], h: f64) -> f64 {
    let moved = |q: [f64; 2]| {
        let x = s
            .sample([q[0].clamp(0.0, 1.0), q[1].clamp(0.0, 1.0)])
            .direction;
        norm([x[0] - back[0], x[1] - back[1], x[2] - back[2]])
    };
    let along_u = moved([u[0] + h, u[1]]).max(moved([u[0] - h, u[1]]));
    let along_v = moved([u[0], u[1] + h]).max(moved([u[0], u[1] - h]));
    along_u + along_v
}

/// η = 2⁻⁴⁸ ≈ 3.6e-15: the round-off budget of a computed direction in [`roundoff_reach`].
const ETA: f64 = 1.0 / (1u64 << 48) as f64;

/// How far round-off in a direction can move the inverse at `d` (whose inverse is `w`): a bound
/// on |G(d + δ) − G(d)| over the directions d + δ within the round-off of a direction that
/// `sample` computes, G = `invert`.
///
/// **Why it is needed.** The map's inverse is exact in exact arithmetic, but its Jacobian
/// ∂u/∂ω can be huge along the azimuth: r_B² = Ũ(x, ε)/Ũ_{N−1}(ε) interpolates the radial CDFs
/// of two meridians with weight ε = (φ − φ_i)/β_i, and where meridian i carries a fraction
/// q ~ 1e-8 … 1e-7 of its neighbour's light, ∂r_B²/∂ε is of order 1/q on the band ε ≲ q next to meridian i
/// (the conditional CDF switches from meridian i's to its neighbour's there). `sample` computes
/// φ = φ_i + εβ_i and its sine and cosine, `invert` takes atan2 of the result, so the azimuth it
/// reads differs from the forward's by about an ulp of 2π (8.9e-16): with β_i ≈ 0.3 and
/// q ~ 1e-8 the square point moves by 1e-9 … 1e-8. That is the map's conditioning, not a wrong
/// inverse (docs/FUZZING.md, "Ill-conditioned round trips").
///
/// **The bound.** To first order G(d + δ) − G(d) = J δ with J = ∂u/∂ω, so |J δ| ≤ Σ_k |J δ_k|
/// for δ = Σ_k δ_k within the round-off budget of a computed direction, split into the three
/// quantities `invert` reads. Each |J δ_k| is measured as a finite difference at the step of the
/// budget itself, the larger of both signs (so kinks and the curvature of the Jacobian on that
/// scale are included; a step outside the domain is left out), with η = 2⁻⁴⁸ ≈ 3.6e-15:
/// - the azimuth, a rotation about z by η ≈ 4 ulp of 2π (the forward's φ_i + εβ_i and its sine
///   and cosine, the inverse's atan2, the wrap to [0, 2π) and (φ − φ_i)/β_i: about
///   ½ + 1 + 1 + ½ + ½ ulp);
/// - the disk radius as `invert` reads it from x and y (r² = (x² + y²)/(1 + z) for z > 0): x and
///   y scaled by 1 ± η (the radial solve stops at 1e-15 relative, the lift and its inverse add a
///   few ulp);
/// - the disk radius as `invert` reads it from z (r² = 1 − z below the horizon, the Lambert
///   sphere): z ± η, 16 ulp of 1 (z = 1 − r² is rounded to ½ ulp of 1).
///
/// Where the inverse is discontinuous (the seam of the square, v = ½, u > ½, or the split
/// sphere's seam) a step across it measures the jump: the bound then allows either side, which
/// is what the seam's documented behaviour is.
pub fn roundoff_reach(s: &dyn Sampler, d: [f64; 3], w: [f64; 2]) -> f64 {
    let moved = |q: [f64; 3]| {
        s.invert(q)
            .map(|g| norm([g[0] - w[0], g[1] - w[1], 0.0]))
            .unwrap_or(0.0)
    };
    let largest = |step: &dyn Fn(f64) -> [f64; 3]| moved(step(ETA)).max(moved(step(-ETA)));
    // A rotation about z by a (to first order; the length changes by a², far below an ulp).
    let azimuth = largest(&|a| [d[0] - d[1] * a, d[1] + d[0] * a, d[2]]);
    let radius_xy = largest(&|a| [d[0] * (1.0 + a), d[1] * (1.0 + a), d[2]]);
    let radius_z = largest(&|a| [d[0], d[1], d[2] + a]);
    azimuth + radius_xy + radius_z
}

fn unit(d: [f64; 3]) -> [f64; 3] {
    let l = norm(d);
    [d[0] / l, d[1] / l, d[2] / l]
}

/// One decoded input: the diagram, and the square points and directions checked on every map
/// built from it.
pub struct Case {
    /// The diagram (θ ≤ 90° or up to 180°).
    pub diagram: Diagram,
    /// Corners, edge midpoints, centre and 16 points from the input.
    pub points: Vec<[f64; 2]>,
    /// Axes, poles, tiny offsets from them, the seam, 8 directions from the input and every
    /// parallel at φ = 0 and at the middle meridian.
    pub dirs: Vec<[f64; 3]>,
    /// Every node of the diagram, just off the poles (the peak density is read there).
    pub nodes: Vec<[f64; 3]>,
}

/// Decodes one input; `None` when its angles and values make no valid diagram.
pub fn decode(data: &[u8]) -> Option<Case> {
    let mut b = Bytes(data);
    let n = 1 + (b.u8() % 9) as usize; // parallels
    let m = 1 + (b.u8() % 9) as usize; // meridians
    let sphere = b.u8() % 2 == 0;
    let theta = angles(&mut b, n, if sphere { 180.0 } else { 90.0 }, true);
    let phi = angles(&mut b, m, 360.0, false);
    let values: Vec<Vec<f64>> = (0..m)
        .map(|_| (0..n).map(|_| b.value()).collect())
        .collect();
    let d = Diagram::from_degrees(&theta, &phi, &values).ok()?;
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
    Some(Case {
        diagram: d,
        points,
        dirs,
        nodes,
    })
}

/// Decodes one input into a diagram, builds every map that accepts it and checks the
/// properties above; panics (with the failing case) when one does not hold.
pub fn run(data: &[u8]) {
    let Some(Case {
        diagram: d,
        points,
        dirs,
        nodes,
    }) = decode(data)
    else {
        return;
    };
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
