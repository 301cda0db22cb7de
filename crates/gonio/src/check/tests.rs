//! Battery tests on small samplers written for the purpose (correct and deliberately wrong ones).
//! They live here, not in the public API: the public baselines are elsewhere.

use super::*;
use crate::sampler::{spherical, InvertError, Point2, Sample, Sampler, Vec3};
use std::f64::consts::{FRAC_1_PI, TAU};
use std::sync::Mutex;

/// Density the test samplers claim or aim at.
#[derive(Clone, Copy, PartialEq)]
enum Lobe {
    Uniform,
    Cosine,
}

impl Lobe {
    fn hemisphere_pdf(self, d: Vec3) -> f64 {
        if d[2] < 0.0 {
            return 0.0;
        }
        match self {
            Lobe::Uniform => 0.5 * FRAC_1_PI,
            Lobe::Cosine => d[2] * FRAC_1_PI,
        }
    }
}

/// A hemisphere sampler: draws `draws`, claims density `claims` from both `sample` and `pdf`
/// (scaled by `scale`; `sample` additionally by `sample_scale`), aims at `target`.
#[derive(Clone, Copy)]
struct Hemi {
    draws: Lobe,
    claims: Lobe,
    target: Lobe,
    scale: f64,
    sample_scale: f64,
    swap_inverse: bool,
    has_inverse: bool,
}

impl Hemi {
    fn correct(lobe: Lobe) -> Self {
        Hemi {
            draws: lobe,
            claims: lobe,
            target: lobe,
            scale: 1.0,
            sample_scale: 1.0,
            swap_inverse: false,
            has_inverse: true,
        }
    }
}

impl Sampler for Hemi {
    fn name(&self) -> &'static str {
        "test-hemisphere"
    }
    fn domain(&self) -> Domain {
        Domain::Hemisphere
    }
    fn sample(&self, u: Point2) -> Sample {
        let phi = TAU * u[1];
        let z = match self.draws {
            Lobe::Uniform => u[0],
            // Malley: uniform disk radius² = 1 − u0, lifted to the hemisphere.
            Lobe::Cosine => u[0].sqrt(),
        };
        let r = (1.0 - z * z).max(0.0).sqrt();
        let direction = [r * phi.cos(), r * phi.sin(), z];
        Sample {
            direction,
            pdf: self.pdf(direction) * self.sample_scale,
        }
    }
    fn pdf(&self, d: Vec3) -> f64 {
        self.scale * self.claims.hemisphere_pdf(d)
    }
    fn invert(&self, d: Vec3) -> Result<Point2, InvertError> {
        if !self.has_inverse {
            return Err(InvertError::Unsupported);
        }
        if d[2] < 0.0 {
            return Err(InvertError::OutsideDomain);
        }
        let (_, phi) = spherical(d);
        let u0 = match self.draws {
            Lobe::Uniform => d[2],
            Lobe::Cosine => d[2] * d[2],
        };
        let u = [u0, phi / TAU];
        Ok(if self.swap_inverse { [u[1], u[0]] } else { u })
    }
    fn target_pdf(&self, d: Vec3) -> f64 {
        self.target.hemisphere_pdf(d)
    }
    fn memory_bytes(&self) -> usize {
        0
    }
}

/// Uniform on the whole sphere, correct.
struct UniformSphere;

impl Sampler for UniformSphere {
    fn name(&self) -> &'static str {
        "test-uniform-sphere"
    }
    fn domain(&self) -> Domain {
        Domain::Sphere
    }
    fn sample(&self, u: Point2) -> Sample {
        let z = 1.0 - 2.0 * u[0];
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = TAU * u[1];
        Sample {
            direction: [r * phi.cos(), r * phi.sin(), z],
            pdf: 0.25 * FRAC_1_PI,
        }
    }
    fn pdf(&self, _: Vec3) -> f64 {
        0.25 * FRAC_1_PI
    }
    fn invert(&self, d: Vec3) -> Result<Point2, InvertError> {
        let (_, phi) = spherical(d);
        Ok([0.5 * (1.0 - d[2]), phi / TAU])
    }
    fn target_pdf(&self, d: Vec3) -> f64 {
        // A lobe toward +z: (1 + z) / 4π integrates to 1.
        (1.0 + d[2]) * 0.25 * FRAC_1_PI
    }
    fn memory_bytes(&self) -> usize {
        0
    }
}

/// Uniform over the cap z ≥ ½ (solid angle π), pdf 1/π there, but aims at the uniform hemisphere:
/// zero pdf where the target is positive.
struct Cap;

impl Sampler for Cap {
    fn name(&self) -> &'static str {
        "test-cap"
    }
    fn domain(&self) -> Domain {
        Domain::Hemisphere
    }
    fn sample(&self, u: Point2) -> Sample {
        let z = 0.5 + 0.5 * u[0];
        let r = (1.0 - z * z).sqrt();
        let phi = TAU * u[1];
        let d = [r * phi.cos(), r * phi.sin(), z];
        Sample {
            direction: d,
            pdf: self.pdf(d),
        }
    }
    fn pdf(&self, d: Vec3) -> f64 {
        if d[2] >= 0.5 {
            FRAC_1_PI
        } else {
            0.0
        }
    }
    fn invert(&self, d: Vec3) -> Result<Point2, InvertError> {
        let (_, phi) = spherical(d);
        Ok([2.0 * d[2] - 1.0, phi / TAU])
    }
    fn target_pdf(&self, _: Vec3) -> f64 {
        0.5 * FRAC_1_PI
    }
    fn memory_bytes(&self) -> usize {
        0
    }
}

/// Everything NaN.
struct NanSampler;

impl Sampler for NanSampler {
    fn name(&self) -> &'static str {
        "test-nan"
    }
    fn domain(&self) -> Domain {
        Domain::Sphere
    }
    fn sample(&self, _: Point2) -> Sample {
        Sample {
            direction: [f64::NAN; 3],
            pdf: f64::NAN,
        }
    }
    fn pdf(&self, _: Vec3) -> f64 {
        f64::NAN
    }
    fn invert(&self, _: Vec3) -> Result<Point2, InvertError> {
        Ok([f64::NAN; 2])
    }
    fn target_pdf(&self, _: Vec3) -> f64 {
        f64::NAN
    }
    fn memory_bytes(&self) -> usize {
        0
    }
}

fn quick() -> BatteryOptions {
    BatteryOptions::quick()
}

#[test]
fn sidak() {
    assert!((sidak_threshold(0.01, 1) - 0.01).abs() < 1e-17);
    let k = 10;
    let t = sidak_threshold(0.01, k);
    assert!((1.0 - (1.0 - t).powi(k as i32) - 0.01).abs() < 1e-15);
    assert!(t > 0.01 / 10.0 && t < 0.0011);
    assert_eq!(sidak_threshold(0.05, 0), sidak_threshold(0.05, 1));
}

#[test]
fn correct_samplers_pass_everything() {
    let samplers: Vec<(Box<dyn Sampler>, bool)> = vec![
        (Box::new(Hemi::correct(Lobe::Uniform)), true),
        (Box::new(Hemi::correct(Lobe::Cosine)), true),
        (
            Box::new(Hemi {
                target: Lobe::Cosine,
                ..Hemi::correct(Lobe::Uniform)
            }),
            true,
        ),
        (Box::new(UniformSphere), true),
    ];
    for (s, _) in &samplers {
        let r = run_battery(s.as_ref(), &quick());
        assert!(r.passed, "{r}");
        let q = r.qmc_chi_square.as_ref().unwrap();
        assert_eq!(q.status, Status::Info);
        assert!(q.chi2_per_dof < 0.2, "{r}");
        assert!(r.chi_square.chi2_per_dof > 0.7 && r.chi_square.chi2_per_dof < 1.3);
        assert!(r.round_trip.max_error < 1e-12, "{r}");
        assert!((r.normalisation.pdf_integral - 1.0).abs() < 1e-9);
    }
}

#[test]
fn ratio_and_flux_figures() {
    // Uniform sampling of a cosine target: pdf/target = (1/2π)/(cos θ/π) = 1/(2 cos θ), and
    // target > 1 % of max ⇔ cos θ > 0.01, so the ratio spans [0.5, 50) on the grid.
    let s = Hemi {
        target: Lobe::Cosine,
        ..Hemi::correct(Lobe::Uniform)
    };
    let r = pdf_target_ratio(&s, &RatioOptions::default());
    assert_eq!(r.status, Status::Pass);
    assert!((r.min_ratio - 0.5).abs() < 1e-12);
    assert_eq!(r.argmin_deg.unwrap()[0], 0.0);
    assert!(r.max_ratio > 30.0 && r.max_ratio < 50.0);
    let claimed = RatioOptions {
        claimed_bound: Some((0.5, 50.0)),
        ..RatioOptions::default()
    };
    assert_eq!(pdf_target_ratio(&s, &claimed).status, Status::Pass);
    let too_tight = RatioOptions {
        claimed_bound: Some((0.5, 20.0)),
        ..RatioOptions::default()
    };
    assert_eq!(pdf_target_ratio(&s, &too_tight).status, Status::Fail);
    // Flux in lumens of a 1000-lm cosine lobe: estimate within 5 standard errors.
    let f = flux_estimate(&s, 1000.0, &FluxOptions::default());
    assert_eq!(f.status, Status::Pass, "{}", f.message);
    assert!(f.standard_error > 0.0 && f.deviation_sigmas.abs() < 5.0);
    // Perfect importance sampling: zero variance, exact estimate.
    let f = flux_estimate(&Hemi::correct(Lobe::Cosine), 3.0, &FluxOptions::default());
    assert_eq!(f.status, Status::Pass);
    assert!(f.standard_error < 1e-12);
}

#[test]
fn sampling_cosine_but_claiming_uniform_fails_chi_square() {
    let s = Hemi {
        draws: Lobe::Cosine,
        ..Hemi::correct(Lobe::Uniform)
    };
    let r = run_battery(&s, &quick());
    assert!(!r.passed);
    assert_eq!(r.chi_square.status, Status::Fail);
    assert!(r.chi_square.p_value < 1e-10);
    assert!(r.qmc_chi_square.as_ref().unwrap().chi2_per_dof > 10.0);
    // Its pdf is self-consistent and normalised, so those items pass.
    assert_eq!(r.pdf_consistency.status, Status::Pass);
    assert_eq!(r.normalisation.status, Status::Pass);
    // Its inverse is that of the map it does draw with, so the round trip passes.
    assert_eq!(r.round_trip.status, Status::Pass);
    assert!(r.failures().contains(&"chi-square"));
}

#[test]
fn wrong_inverse_fails_round_trip_only() {
    let s = Hemi {
        swap_inverse: true,
        ..Hemi::correct(Lobe::Cosine)
    };
    let r = run_battery(&s, &quick());
    assert_eq!(r.round_trip.status, Status::Fail);
    assert!(r.round_trip.max_error > 0.1);
    assert_eq!(r.failures(), vec!["round trip"]);
}

#[test]
fn unsupported_inverse_is_not_applicable() {
    let s = Hemi {
        has_inverse: false,
        ..Hemi::correct(Lobe::Cosine)
    };
    let r = run_battery(&s, &quick());
    assert_eq!(r.round_trip.status, Status::NotApplicable);
    assert!(r.passed, "{r}");
}

#[test]
fn unnormalised_and_inconsistent_pdfs_fail() {
    let s = Hemi {
        scale: 2.0,
        ..Hemi::correct(Lobe::Cosine)
    };
    let r = run_battery(&s, &quick());
    assert_eq!(r.normalisation.status, Status::Fail);
    assert!((r.normalisation.pdf_integral - 2.0).abs() < 1e-9);
    assert_eq!(r.chi_square.status, Status::Fail);
    assert_eq!(r.pdf_consistency.status, Status::Pass);

    let s = Hemi {
        sample_scale: 1.01,
        ..Hemi::correct(Lobe::Cosine)
    };
    let r = pdf_consistency(&s, &PdfConsistencyOptions::default());
    assert_eq!(r.status, Status::Fail);
    assert!((r.max_rel_error - 0.01 / 1.01).abs() < 1e-12);
    // The flux estimate uses the pdf the sample carries: 1 % off.
    let f = flux_estimate(&s, 1.0, &FluxOptions::default());
    assert_eq!(f.status, Status::Fail);
}

#[test]
fn zero_pdf_where_target_is_positive_fails_ratio_and_flux() {
    let r = run_battery(&Cap, &quick());
    assert_eq!(r.ratio.status, Status::Fail);
    assert_eq!(r.ratio.min_ratio, 0.0);
    assert_eq!(r.flux.status, Status::Fail);
    assert!((r.flux.estimate - 0.5).abs() < 1e-12);
    // The histogram does follow its own pdf.
    assert_eq!(r.chi_square.status, Status::Pass, "{r}");
    assert_eq!(r.round_trip.status, Status::Pass, "{r}");
}

#[test]
fn nan_sampler_fails_without_panicking() {
    let r = run_battery(&NanSampler, &quick());
    for item in r.items() {
        assert!(
            item.status == Status::Fail || item.status == Status::Info,
            "{}: {:?}",
            item.name,
            item.status
        );
    }
    assert!(!r.passed);
    // The JSON report has nulls where NaNs are.
    let json = serde_json::to_string(&r).unwrap();
    assert!(json.contains("\"passed\":false"));
}

#[test]
fn report_serialises_and_displays() {
    let r = run_battery(&Hemi::correct(Lobe::Cosine), &quick());
    let v: serde_json::Value = serde_json::to_value(&r).unwrap();
    assert_eq!(v["chi_square"]["status"], "pass");
    assert_eq!(v["round_trip"]["status"], "pass");
    assert_eq!(v["options"]["round_trip"]["sequence"], "sobol");
    assert!(v["chi_square"]["dof"].as_u64().unwrap() > 400);
    let text = r.to_string();
    assert!(text.starts_with("sampler 'test-hemisphere' (hemisphere): PASS"));
    assert_eq!(text.lines().count(), 1 + r.items().len());
    // Options round-trip through JSON.
    let o: BatteryOptions = serde_json::from_value(v["options"].clone()).unwrap();
    assert_eq!(o, BatteryOptions::quick());
}

#[test]
fn progress_is_monotone_and_complete() {
    let seen = Mutex::new(Vec::<(String, f64)>::new());
    let cb = |name: &str, f: f64| seen.lock().unwrap().push((name.to_string(), f));
    run_battery_with_progress(&UniformSphere, &quick(), &cb);
    let seen = seen.into_inner().unwrap();
    assert!(seen.len() > 7);
    assert!(seen.windows(2).all(|w| w[0].1 <= w[1].1 + 1e-15));
    assert_eq!(seen.last().unwrap().1, 1.0);
    for name in ["chi-square", "round trip", "flux", "normalisation"] {
        assert!(seen.iter().any(|s| s.0 == name), "{name}");
    }
}

#[test]
fn chi_square_is_calibrated() {
    // 200 independent tests of a correct sampler at α = 0.1: the number of rejections is
    // Binomial(200, 0.1) (mean 20, sd 4.2); accept 5..=40. The mean p-value of a uniform
    // p is 0.5 ± 0.02 (sd 0.289/√200); accept 0.4..0.6.
    let s = Hemi::correct(Lobe::Cosine);
    let mut rejected = 0;
    let mut p_sum = 0.0;
    for seed in 0..200 {
        let o = ChiSquareOptions {
            samples: 20_000,
            seed,
            alpha: 0.1,
            resolution: Some([8, 16]),
            ..ChiSquareOptions::default()
        };
        let r = chi_square_test(&s, &o);
        if r.status == Status::Fail {
            rejected += 1;
        }
        p_sum += r.p_value;
    }
    assert!((5..=40).contains(&rejected), "{rejected}");
    let mean_p = p_sum / 200.0;
    assert!((0.4..0.6).contains(&mean_p), "{mean_p}");
}

#[test]
fn chi_square_pools_sparse_bins() {
    // 2000 samples over 512 bins: expected ≈ 3.9 per bin, so pooling must kick in.
    let o = ChiSquareOptions {
        samples: 2000,
        ..ChiSquareOptions::default()
    };
    let r = chi_square_test(&Hemi::correct(Lobe::Cosine), &o);
    assert!(r.pooled_bins > 0);
    assert_eq!(r.status, Status::Pass, "{}", r.summary());
    assert!((r.expected_total - 1.0).abs() < 1e-9);
}

#[test]
fn qmc_points_give_small_chi_square() {
    let mut pts = vec![[0.0; 2]; 1 << 14];
    crate::sequence::Sequence::new(crate::sequence::SequenceKind::Sobol, 3).fill(0, &mut pts);
    let r = chi_square_points(&UniformSphere, &pts, &ChiSquareOptions::default());
    assert!(r.chi2_per_dof < 0.1, "{}", r.summary());
}
