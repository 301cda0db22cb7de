//! The `mapping` fuzz target on stable Rust: its recorded findings (docs/FUZZING.md) replayed as
//! regression cases, and a seeded sweep of random inputs through the same decoder and checks
//! (`fuzz/common/mapping_case.rs`). Deterministic: the sweep's inputs come from a fixed seed.

use gonio::sampler::{InvertError, Point2, Sample, Vec3};
use gonio::{Diagram, Domain, HemisphereMap, Sampler, SphereLayout, SphereMap};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

#[path = "../../../fuzz/common/mapping_case.rs"]
mod mapping_case;

fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex digits"))
        .collect()
}

fn to_hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

thread_local! {
    static IN_CASE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `f`, returning the message of its panic, if it panics.
fn panic_of(f: impl FnOnce()) -> Option<String> {
    // The cases' panics are collected; keep them (and only them) off stderr.
    static QUIET: std::sync::Once = std::sync::Once::new();
    QUIET.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !IN_CASE.get() {
                default(info)
            }
        }))
    });
    IN_CASE.set(true);
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    IN_CASE.set(false);
    result.err().map(|e| {
        e.downcast_ref::<String>()
            .cloned()
            .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

/// Runs every input, collecting the ones whose checks fail (with the failure's message).
fn failures<'a>(inputs: impl IntoIterator<Item = &'a [u8]>) -> Vec<String> {
    inputs
        .into_iter()
        .filter_map(|data| {
            panic_of(|| mapping_case::run(data)).map(|msg| format!("{}: {msg}", to_hex(data)))
        })
        .collect()
}

/// The inputs the fuzzer found (docs/FUZZING.md): one-meridian sphere diagrams whose meridian is
/// off φ = 0 (seam round trip), a one-meridian diagram with zeros at the north pole (invert at +z),
/// subnormal-only light (pdf overflow), and the two early findings at u = (0, 0).
const FINDINGS: &[&str] = &[
    "800004ffff00ff0080050d2a2ad8",
    "0300960000009600960000009600",
    "d901954d00ffffff00ffff1023d8",
    "a3010053010300006c96a35304",
];

/// Found by the seeded sweep at `GONIO_FUZZ_CASES=60000` (the first three) and `=100000` (the
/// fourth), docs/FUZZING.md "Ill-conditioned round trips": inverses of a direction on a meridian
/// that carries 1e-8 … 1e-7 of its neighbour's light. The square round trip misses by
/// 1e-9 … 1e-8 there: about an ulp of the azimuth times the inverse's Jacobian ∂u/∂φ, which is
/// ~1e7 where the interpolated radial CDF switches from one meridian's to the other's. Each with
/// the map (`None`: `HemisphereMap`) and that direction.
const ILL_CONDITIONED: &[(&str, &str, Option<SphereLayout>, Vec3)] = &[
    (
        "on meridian 183.27° (4.5e-8 of meridian 198.98°'s light), θ = 8.54°",
        "4ca4339747a4d18fc20b379883c013435ae41eb65635986eed21622515b00b721ee1766fc063f2d6517287fb51",
        None,
        [-0.14820599425210823, -0.008471142935617135, 0.9889202308604614],
    ),
    (
        "on meridian 224.30° (the nearly empty one of two), θ = 76.47°",
        "bbd0c7075464b5cdea11cee6ffcaea9606c005f5850796491aa036ab0d3609db9608808ef05f93c731233570533fc7",
        None,
        [-0.6958656419645036, -0.6789927441437588, 0.23396551398327337],
    ),
    (
        "on meridian 259.99° (4.5e-8 at θ = 64.87°, between two empty ones), θ = 64.87°",
        "fe204f43da647176869009f45e3811213ea12536002d13e09029f9d2418b07947c6a96152f228134cdfe8996",
        None,
        [-0.1573511029988067, -0.8915461097102519, 0.42471892428472535],
    ),
    (
        "Lambert sphere, on meridian 199.82° (4.5e-8 of the peak at θ = 45.50°), θ = 45.50°",
        "65f650dda1d76967d107b7829580d08d32970986c63015bd2d8a390ea1a564553fc67496dceb9d9c2ebd5b8e",
        Some(SphereLayout::Lambert),
        [-0.671009792814004, -0.24189049888022582, 0.700881476784187],
    ),
];

/// The map an [`ILL_CONDITIONED`] case names.
fn build(layout: Option<SphereLayout>, d: &Diagram) -> Box<dyn Sampler> {
    match layout {
        None => Box::new(HemisphereMap::new(d).expect("the map builds")),
        Some(l) => Box::new(SphereMap::with_layout(d, l).expect("the map builds")),
    }
}

#[test]
fn recorded_fuzz_findings_hold() {
    let cases: Vec<Vec<u8>> = FINDINGS
        .iter()
        .copied()
        .chain(ILL_CONDITIONED.iter().map(|c| c.1))
        .map(hex)
        .collect();
    let bad = failures(cases.iter().map(Vec::as_slice));
    assert!(
        bad.is_empty(),
        "{} finding(s) fail:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn seeded_sweep_of_random_inputs_holds() {
    // 4,000 inputs of 0–48 random bytes (GONIO_FUZZ_CASES to run more); each builds up to three
    // maps of at most 9 x 9 nodes.
    let count = std::env::var("GONIO_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4000);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(0x6f6e_696f_6766_757a);
    let cases: Vec<Vec<u8>> = (0..count)
        .map(|_| {
            let n = rng.gen_range(0..=48);
            (0..n).map(|_| rng.gen::<u8>()).collect()
        })
        .collect();
    let bad = failures(cases.iter().map(Vec::as_slice));
    assert!(
        bad.is_empty(),
        "{} of {} inputs fail; first ones:\n{}",
        bad.len(),
        cases.len(),
        bad.iter().take(10).cloned().collect::<Vec<_>>().join("\n")
    );
}

/// The ill-conditioned round trips: the square round trip holds within the inverse's
/// round-off reach (its Jacobian times the round-off of a direction), and that reach is
/// dominated by the azimuth and small enough that an inverse off by 1e-6 would fail.
#[test]
fn ill_conditioned_round_trips_hold_within_the_inverse_jacobian() {
    for &(name, input, layout, d) in ILL_CONDITIONED {
        let case = mapping_case::decode(&hex(input)).expect("the input decodes");
        let map = build(layout, &case.diagram);
        let map = map.as_ref();
        let u = map.invert(d).expect("inside the domain");
        let back = map.sample(u).direction;
        let w = map.invert(back).expect("a sample inverts");
        let miss = (w[0] - u[0]).hypot(w[1] - u[1]);
        let reach = mapping_case::roundoff_reach(map, back, w);
        // The ill-conditioning: the miss exceeds the round-off of a well-conditioned inverse by
        // far, and the direction does not come back (the map stretches the inverse's reach).
        assert!(miss > 1e-10, "{name}: miss {miss:e}");
        assert!(
            miss <= reach + 1e-12 && reach < 2.5e-7,
            "{name}: miss {miss:e}, reach {reach:e}"
        );
        let h = mapping_case::roundoff_reach(map, d, u) + f64::EPSILON;
        assert!(
            mapping_case::forward_spread(map, u, back, h) > 1e-6,
            "{name}"
        );
        assert!(panic_of(|| mapping_case::check_map(map, &[], &[d], &[d])).is_none());
    }
}

/// How [`Wrong`] breaks the inverse.
#[derive(Clone, Copy)]
enum Fault {
    /// Every point moved by this much along both axes, towards the centre of the square.
    Shift(f64),
    /// The same point for every direction.
    Constant(Point2),
}

/// A map whose inverse is deliberately wrong: the checks must catch it.
struct Wrong<'a>(&'a dyn Sampler, Fault);

impl Sampler for Wrong<'_> {
    fn name(&self) -> &'static str {
        "wrong inverse"
    }
    fn domain(&self) -> Domain {
        self.0.domain()
    }
    fn sample(&self, u: Point2) -> Sample {
        self.0.sample(u)
    }
    fn pdf(&self, direction: Vec3) -> f64 {
        self.0.pdf(direction)
    }
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        let u = self.0.invert(direction)?;
        Ok(match self.1 {
            Fault::Shift(c) => u.map(|x| x + c * (0.5 - x).signum()),
            Fault::Constant(p) => p,
        })
    }
    fn target_pdf(&self, direction: Vec3) -> f64 {
        self.0.target_pdf(direction)
    }
    fn memory_bytes(&self) -> usize {
        self.0.memory_bytes()
    }
}

/// The round-trip checks fail for a wrong inverse: shifted by 1e-10 (far below the 1e-6 of the
/// direction check; the square round trip catches it), shifted by 1e-6 at exactly the
/// ill-conditioned directions (where the square round trip allows 1e-8 … 1e-7), or constant (the
/// square round trip holds trivially; the direction check catches it, except where the map is
/// stretched, so the constant is taken where the density is largest).
#[test]
fn a_wrong_inverse_fails_the_round_trip_checks() {
    for &(name, input, layout, d) in ILL_CONDITIONED {
        let case = mapping_case::decode(&hex(input)).expect("the input decodes");
        let map = build(layout, &case.diagram);
        let map = map.as_ref();
        let run = |s: &dyn Sampler, dirs: &[Vec3]| {
            panic_of(|| mapping_case::check_map(s, &case.points, dirs, &case.nodes))
        };
        assert_eq!(run(map, &case.dirs), None, "{name}: the map itself passes");
        let square = "which inverts to";
        let msg = run(&Wrong(map, Fault::Shift(1e-10)), &case.dirs);
        assert!(
            msg.as_deref().is_some_and(|m| m.contains(square)),
            "{name}: {msg:?}"
        );
        let msg = run(&Wrong(map, Fault::Shift(1e-6)), &[d]);
        assert!(
            msg.as_deref().is_some_and(|m| m.contains(square)),
            "{name}: {msg:?}"
        );
        // A constant at the preimage of the brightest node, where the map is least stretched.
        let brightest = case
            .nodes
            .iter()
            .copied()
            .max_by(|a, b| map.pdf(*a).total_cmp(&map.pdf(*b)))
            .expect("a diagram has nodes");
        let u0 = map.invert(brightest).expect("a node inverts");
        let msg = run(&Wrong(map, Fault::Constant(u0)), &case.dirs);
        assert!(
            msg.as_deref()
                .is_some_and(|m| m.contains("sample moves only")),
            "{name}: {msg:?}"
        );
    }
}

/// `gonio check`'s round-trip item (tolerance 1e-8) on the maps of the ill-conditioned cases: a
/// correct map passes (before the inverse's round-off reach was allowed for, the first one
/// failed at 1.34e-8), and an inverse shifted by 1e-7 fails.
#[test]
fn the_check_round_trip_allows_for_the_inverse_conditioning_only() {
    use gonio::check::{cell_boundary_points, round_trip, RoundTripOptions, Status};
    let mut ill = 0;
    for &(name, input, layout, _) in ILL_CONDITIONED {
        let case = mapping_case::decode(&hex(input)).expect("the input decodes");
        let map = build(layout, &case.diagram);
        let map = map.as_ref();
        let opts = RoundTripOptions {
            extra_points: cell_boundary_points(map, &case.diagram, 64),
            ..RoundTripOptions::default()
        };
        let r = round_trip(map, &opts);
        assert_eq!(r.status, Status::Pass, "{name}: {}", r.summary());
        ill += r.ill_conditioned_points;
        let r = round_trip(&Wrong(map, Fault::Shift(1e-7)), &opts);
        assert_eq!(r.status, Status::Fail, "{name}: {}", r.summary());
    }
    assert!(ill > 0, "no ill-conditioned point was met");
}
