//! The battery through the public API on a non-trivial warp written here: cosine-weighted
//! hemisphere sampling through the library's Shirley–Chiu concentric disk (Malley's method), with
//! its inverse.

use gonio::check::{
    chi_square_points, run_battery, BatteryOptions, ChiSquareOptions, RatioOptions, Status,
};
use gonio::mapping::concentric;
use gonio::sequence::{Sequence, SequenceKind};
use gonio::{Domain, InvertError, Point2, Sample, Sampler, Vec3};
use std::f64::consts::{FRAC_1_PI, TAU};

struct ConcentricCosine;

/// Square [0,1]² → unit disk as `[x, y]`: the library's concentric map (M_B of the HDS mapping).
fn square_to_disk(u: Point2) -> [f64; 2] {
    let (r, phi) = concentric::square_to_disk(u);
    [r * phi.cos(), r * phi.sin()]
}

/// Its inverse, through the library's polar inverse.
fn disk_to_square(p: [f64; 2]) -> Point2 {
    let mut phi = p[1].atan2(p[0]);
    if phi < 0.0 {
        phi += TAU;
    }
    concentric::disk_to_square(p[0].hypot(p[1]).min(1.0), phi)
}

impl Sampler for ConcentricCosine {
    fn name(&self) -> &'static str {
        "concentric-cosine"
    }
    fn domain(&self) -> Domain {
        Domain::Hemisphere
    }
    fn sample(&self, u: Point2) -> Sample {
        let [x, y] = square_to_disk(u);
        let z = (1.0 - x * x - y * y).max(0.0).sqrt();
        Sample {
            direction: [x, y, z],
            pdf: z * FRAC_1_PI,
        }
    }
    fn pdf(&self, d: Vec3) -> f64 {
        d[2].max(0.0) * FRAC_1_PI
    }
    fn invert(&self, d: Vec3) -> Result<Point2, InvertError> {
        if d[2].is_nan() || d[2] < 0.0 {
            return Err(InvertError::OutsideDomain);
        }
        Ok(disk_to_square([d[0], d[1]]))
    }
    fn target_pdf(&self, d: Vec3) -> f64 {
        self.pdf(d)
    }
    fn memory_bytes(&self) -> usize {
        0
    }
}

#[test]
fn concentric_cosine_passes_with_a_tight_claimed_bound() {
    let mut opts = BatteryOptions::quick().with_seed(2026);
    opts.round_trip.tolerance = 1e-12;
    opts.ratio = RatioOptions {
        claimed_bound: Some((1.0, 1.0)),
        ..opts.ratio
    };
    opts.flux_total = 1200.0;
    let sampler: Box<dyn Sampler> = Box::new(ConcentricCosine);
    let r = run_battery(sampler.as_ref(), &opts);
    assert!(r.passed, "{r}");
    assert_eq!(r.round_trip.status, Status::Pass);
    assert!(r.round_trip.max_error < 1e-12, "{r}");
    assert!((r.ratio.min_ratio - 1.0).abs() < 1e-12 && (r.ratio.max_ratio - 1.0).abs() < 1e-12);
    assert!((r.flux.estimate - 1200.0).abs() < 1e-6);
    let json = serde_json::to_string_pretty(&r).unwrap();
    assert!(json.contains("\"sampler\": \"concentric-cosine\""));
}

#[test]
fn low_discrepancy_points_beat_iid_points() {
    let opts = ChiSquareOptions::default();
    let n = 1 << 16;
    let per_dof = |kind| {
        let mut pts = vec![[0.0; 2]; n];
        Sequence::new(kind, 1).fill(0, &mut pts);
        chi_square_points(&ConcentricCosine, &pts, &opts).chi2_per_dof
    };
    let (halton, sobol, random) = (
        per_dof(SequenceKind::Halton),
        per_dof(SequenceKind::Sobol),
        per_dof(SequenceKind::Random),
    );
    assert!(halton < 0.1 && sobol < 0.1, "{halton} {sobol}");
    assert!(random > 0.7 && random < 1.3, "{random}");
}
