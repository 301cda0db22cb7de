//! What renderers do today, behind the same contract as [`BrdfSampler`] ([`BrdfMethod`]):
//! cosine-weighted sampling (pbrt-v2's MERL material), GGX visible-normal sampling (Heitz 2018)
//! with roughness fitted to the table (dj_brdf's and Mitsuba's measured plugins), and a
//! piecewise-constant tabulation of the nearest incident slice (a per-slice pixel image over the
//! equal-area hemisphere map, [`crate::baselines::PiecewiseConstant`]).
//!
//! Each returns the exact density of its own map and `weight = f_r·cos θ_o / pdf` per channel with
//! f_r the table's interpolation. GGX reflections that land below the horizon are returned as
//! **zero-weight samples** (their direction has z < 0 and `pdf` is the density of the reflected
//! direction); the nearest-slice tabulation is discontinuous in ω_i by construction.

use super::analytic::{ggx_d, ggx_g1};
use super::sampler::{cosine_invert, cosine_sample, scalar_albedo, BrdfSample, BrdfSampler};
use super::{clamped, periodic, scalar_albedo_grid, Symmetry, TabulatedBrdf};
use crate::baselines::PiecewiseConstant;
use crate::sampler::{normalize, spherical, Domain, InvertError, Point2, Sample, Sampler, Vec3};
use crate::vector::dot;
use std::f64::consts::{PI, TAU};

/// A BRDF sampling method: samples ω_o for an incident direction, with exact pdf and inverse.
pub trait BrdfMethod: Send + Sync {
    /// Short name (`hds`, `cosine`, `ggx-fit`, `piecewise-constant`).
    fn name(&self) -> &'static str;
    /// Samples ω_o for incident ω_i at a point of the unit square.
    fn sample(&self, wi: Vec3, u: Point2) -> BrdfSample;
    /// The exact density of `sample` at ω_o, per steradian.
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64;
    /// The point of the square that `sample` maps to ω_o (`None` where there is none).
    fn invert(&self, wi: Vec3, wo: Vec3) -> Option<Point2>;
}

fn weight(brdf: &TabulatedBrdf, wi: Vec3, wo: Vec3, pdf: f64) -> [f64; 3] {
    if !(pdf > 0.0) || !(wo[2] > 0.0) {
        return [0.0; 3];
    }
    let f = brdf.eval(wi, wo);
    let k = wo[2] / pdf;
    [f[0] * k, f[1] * k, f[2] * k]
}

impl BrdfMethod for BrdfSampler {
    fn name(&self) -> &'static str {
        "hds"
    }
    fn sample(&self, wi: Vec3, u: Point2) -> BrdfSample {
        BrdfSampler::sample(self, wi, u)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        BrdfSampler::pdf(self, wi, wo)
    }
    fn invert(&self, wi: Vec3, wo: Vec3) -> Option<Point2> {
        BrdfSampler::invert(self, wi, wo)
    }
}

/// Cosine-weighted sampling (concentric map + lift), pdf = cos θ_o / π.
#[derive(Debug, Clone, Copy)]
pub struct CosineBrdf<'a> {
    brdf: &'a TabulatedBrdf,
}

impl<'a> CosineBrdf<'a> {
    /// Cosine sampling of `brdf`.
    pub fn new(brdf: &'a TabulatedBrdf) -> Self {
        CosineBrdf { brdf }
    }
}

impl BrdfMethod for CosineBrdf<'_> {
    fn name(&self) -> &'static str {
        "cosine"
    }
    fn sample(&self, wi: Vec3, u: Point2) -> BrdfSample {
        let d = cosine_sample(u);
        let pdf = d[2] / PI;
        BrdfSample {
            direction: d,
            pdf,
            weight: weight(self.brdf, wi, d, pdf),
        }
    }
    fn pdf(&self, _wi: Vec3, wo: Vec3) -> f64 {
        wo[2].max(0.0) / PI
    }
    fn invert(&self, _wi: Vec3, wo: Vec3) -> Option<Point2> {
        (wo[2] >= 0.0).then(|| cosine_invert(wo))
    }
}

/// GGX visible-normal sampling (Heitz 2018, "Sampling the GGX Distribution of Visible Normals")
/// with (α_x, α_y) fitted to the table: the pair, from a log-spaced grid 0.02…1.5, that minimises
/// the second moment ∫ (f̄ cos θ_o)² / pdf dω_o summed over θ_i = 0°, 30°, 60° (and φ_i = 0°, 90°
/// for anisotropic tables), by quadrature.
#[derive(Debug, Clone, Copy)]
pub struct GgxFit<'a> {
    brdf: &'a TabulatedBrdf,
    alpha: (f64, f64),
}

fn vndf_basis(wi: Vec3, ax: f64, ay: f64) -> (Vec3, Vec3, Vec3) {
    let vh = normalize([ax * wi[0], ay * wi[1], wi[2]]).unwrap_or([0.0, 0.0, 1.0]);
    let l2 = vh[0] * vh[0] + vh[1] * vh[1];
    let t1 = if l2 > 0.0 {
        let s = 1.0 / l2.sqrt();
        [-vh[1] * s, vh[0] * s, 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let t2 = [
        vh[1] * t1[2] - vh[2] * t1[1],
        vh[2] * t1[0] - vh[0] * t1[2],
        vh[0] * t1[1] - vh[1] * t1[0],
    ];
    (vh, t1, t2)
}

impl<'a> GgxFit<'a> {
    /// GGX VNDF sampling with given roughness.
    pub fn with_alpha(brdf: &'a TabulatedBrdf, alpha_x: f64, alpha_y: f64) -> Self {
        GgxFit {
            brdf,
            alpha: (alpha_x, alpha_y),
        }
    }

    /// GGX VNDF sampling with roughness fitted to `brdf` (see the type's documentation).
    pub fn fit(brdf: &'a TabulatedBrdf) -> Self {
        let cands: Vec<f64> = (0..24)
            .map(|k| 0.02 * (1.5f64 / 0.02).powf(k as f64 / 23.0))
            .collect();
        let mut incident = vec![];
        let phis: &[f64] = match brdf.symmetry() {
            Symmetry::Isotropic => &[0.0],
            Symmetry::Anisotropic => &[0.0, 90.0],
        };
        for &t in &[0.0f64, 30.0, 60.0] {
            for &p in phis {
                incident.push(crate::sampler::direction(t.to_radians(), p.to_radians()));
            }
        }
        let n = 48;
        // The quadrature points, values and cell solid angles of every incident direction.
        let pts: Vec<Vec<(Vec3, f64)>> = incident
            .iter()
            .map(|&wi| scalar_albedo_grid(brdf, wi, n))
            .collect();
        let cost = |ax: f64, ay: f64| -> f64 {
            let g = GgxFit::with_alpha(brdf, ax, ay);
            incident
                .iter()
                .zip(&pts)
                .map(|(&wi, p)| {
                    let m: f64 = p
                        .iter()
                        .map(|&(wo, v)| {
                            let pdf = g.pdf(wi, wo);
                            if v > 0.0 {
                                if pdf > 0.0 {
                                    v * v / pdf
                                } else {
                                    1e30
                                }
                            } else {
                                0.0
                            }
                        })
                        .sum::<f64>();
                    let a: f64 = p.iter().map(|q| q.1).sum();
                    if a > 0.0 {
                        m * (TAU / (2 * n * n) as f64) / (a * TAU / (2 * n * n) as f64).powi(2)
                    } else {
                        0.0
                    }
                })
                .sum()
        };
        let mut best = (f64::INFINITY, 0.3, 0.3);
        for &ax in &cands {
            let ays: Vec<f64> = match brdf.symmetry() {
                Symmetry::Isotropic => vec![ax],
                Symmetry::Anisotropic => cands.clone(),
            };
            for ay in ays {
                let c = cost(ax, ay);
                if c < best.0 {
                    best = (c, ax, ay);
                }
            }
        }
        GgxFit::with_alpha(brdf, best.1, best.2)
    }

    /// The roughness (α_x, α_y) used.
    pub fn alpha(&self) -> (f64, f64) {
        self.alpha
    }

    fn sample_normal(&self, wi: Vec3, u: Point2) -> Vec3 {
        let (ax, ay) = self.alpha;
        let (vh, t1v, t2v) = vndf_basis(wi, ax, ay);
        let r = u[0].clamp(0.0, 1.0).sqrt();
        let phi = TAU * u[1];
        let t1 = r * phi.cos();
        let s = 0.5 * (1.0 + vh[2]);
        let t2 = (1.0 - s) * (1.0 - t1 * t1).max(0.0).sqrt() + s * r * phi.sin();
        let k = (1.0 - t1 * t1 - t2 * t2).max(0.0).sqrt();
        let nh = [
            t1 * t1v[0] + t2 * t2v[0] + k * vh[0],
            t1 * t1v[1] + t2 * t2v[1] + k * vh[1],
            t1 * t1v[2] + t2 * t2v[2] + k * vh[2],
        ];
        normalize([ax * nh[0], ay * nh[1], nh[2].max(0.0)]).unwrap_or([0.0, 0.0, 1.0])
    }
}

impl BrdfMethod for GgxFit<'_> {
    fn name(&self) -> &'static str {
        "ggx-fit"
    }
    fn sample(&self, wi: Vec3, u: Point2) -> BrdfSample {
        let wi = if wi[2] > 0.0 { wi } else { [0.0, 0.0, 1.0] };
        let h = self.sample_normal(wi, u);
        let c = dot(wi, h);
        let wo = [
            2.0 * c * h[0] - wi[0],
            2.0 * c * h[1] - wi[1],
            2.0 * c * h[2] - wi[2],
        ];
        // A normal whose mirror direction falls below the horizon gives no sample: pdf 0 and
        // weight 0, as `pdf` says there (the mass VNDF sampling loses below the surface).
        let pdf = if wo[2] >= 0.0 {
            self.reflected_pdf(wi, wo)
        } else {
            0.0
        };
        BrdfSample {
            direction: wo,
            pdf,
            weight: weight(self.brdf, wi, wo, pdf),
        }
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        if !(wo[2] >= 0.0) {
            return 0.0;
        }
        self.reflected_pdf(wi, wo)
    }
    fn invert(&self, wi: Vec3, wo: Vec3) -> Option<Point2> {
        let (ax, ay) = self.alpha;
        let wi = if wi[2] > 0.0 { wi } else { [0.0, 0.0, 1.0] };
        let h = normalize([wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]])?;
        if !(h[2] > 0.0) || !(dot(wi, h) > 0.0) {
            return None;
        }
        let (vh, t1v, t2v) = vndf_basis(wi, ax, ay);
        let nh = normalize([h[0] / ax, h[1] / ay, h[2]])?;
        let t1 = dot(nh, t1v);
        let t2w = dot(nh, t2v);
        let s = 0.5 * (1.0 + vh[2]);
        let t2 = (t2w - (1.0 - s) * (1.0 - t1 * t1).max(0.0).sqrt()) / s;
        let r2 = t1 * t1 + t2 * t2;
        let mut phi = t2.atan2(t1);
        if phi < 0.0 {
            phi += TAU;
        }
        Some([r2.min(1.0), (phi / TAU).min(1.0)])
    }
}

impl GgxFit<'_> {
    /// The density of the reflected direction: G₁(ω_i) D(h) / (4 cos θ_i).
    fn reflected_pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        let (ax, ay) = self.alpha;
        let wi = if wi[2] > 0.0 { wi } else { [0.0, 0.0, 1.0] };
        let Some(h) = normalize([wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]]) else {
            return 0.0;
        };
        if !(h[2] > 0.0) || !(dot(wi, h) > 0.0) {
            return 0.0;
        }
        ggx_g1(wi, ax, ay) * ggx_d(h, ax, ay) / (4.0 * wi[2])
    }
}

/// Piecewise-constant sampling of the **nearest** tabulated incident slice: each slice diagram of
/// the HDS sampler tabulated as a pixel image over the equal-area hemisphere map
/// ([`PiecewiseConstant`], `resolution` pixels per side), turned by φ_i. Discontinuous in ω_i.
///
/// `S` is how it holds the HDS sampler whose slices it tabulates: a reference
/// (`PerSliceConstant::new(&sampler, 128)`) or a shared owner (`Arc<BrdfSampler>`, the default,
/// for a method that must own its sampler: the C ABI's and Python's handles).
pub struct PerSliceConstant<S = std::sync::Arc<BrdfSampler>>
where
    S: std::ops::Deref<Target = BrdfSampler>,
{
    sampler: S,
    images: Vec<Option<PiecewiseConstant>>,
}

impl<S: std::ops::Deref<Target = BrdfSampler>> PerSliceConstant<S> {
    /// The HDS sampler whose slices are tabulated.
    pub fn sampler(&self) -> &BrdfSampler {
        &self.sampler
    }

    /// The per-slice images of `sampler`'s slices at `resolution` pixels per side.
    pub fn new(sampler: S, resolution: usize) -> Self {
        let (n, _) = sampler.slice_counts();
        let images = (0..n)
            .map(|k| {
                sampler.slice(k).and_then(|m| {
                    PiecewiseConstant::with_resolution(m.diagram(), Domain::Hemisphere, resolution)
                        .ok()
                })
            })
            .collect();
        PerSliceConstant { sampler, images }
    }

    fn nearest(&self, wi: Vec3) -> (Option<&PiecewiseConstant>, f64) {
        let b = self.sampler.brdf();
        let (t, p) = spherical(wi);
        let (a0, a1, ta) = clamped(b.theta_i(), t.min(std::f64::consts::FRAC_PI_2));
        let a = if ta < 0.5 { a0 } else { a1 };
        let q = match b.symmetry() {
            Symmetry::Isotropic => 0,
            Symmetry::Anisotropic => {
                let (q0, q1, tq) = periodic(b.phi_i(), p);
                if tq < 0.5 {
                    q0
                } else {
                    q1
                }
            }
        };
        let k = a * b.phi_i().len() + q;
        (self.images[k].as_ref(), p)
    }
}

fn rotate(d: Vec3, phi: f64) -> Vec3 {
    let (s, c) = phi.sin_cos();
    [c * d[0] - s * d[1], s * d[0] + c * d[1], d[2]]
}

impl<S: std::ops::Deref<Target = BrdfSampler> + Send + Sync> BrdfMethod for PerSliceConstant<S> {
    fn name(&self) -> &'static str {
        "piecewise-constant"
    }
    fn sample(&self, wi: Vec3, u: Point2) -> BrdfSample {
        match self.nearest(wi) {
            (Some(img), p) => {
                let s = img.sample(u);
                let d = rotate(s.direction, p);
                BrdfSample {
                    direction: d,
                    pdf: s.pdf,
                    weight: weight(self.sampler.brdf(), wi, d, s.pdf),
                }
            }
            (None, _) => {
                let d = cosine_sample(u);
                BrdfSample {
                    direction: d,
                    pdf: d[2] / PI,
                    weight: [0.0; 3],
                }
            }
        }
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        if !(wo[2] >= 0.0) {
            return 0.0;
        }
        match self.nearest(wi) {
            (Some(img), p) => img.pdf(rotate(wo, -p)),
            (None, _) => wo[2] / PI,
        }
    }
    fn invert(&self, wi: Vec3, wo: Vec3) -> Option<Point2> {
        if !(wo[2] >= 0.0) {
            return None;
        }
        match self.nearest(wi) {
            (Some(img), p) => img.invert(rotate(wo, -p)).ok(),
            (None, _) => Some(cosine_invert(wo)),
        }
    }
}

/// A BRDF sampling method at one incident direction, behind the crate's [`Sampler`] contract:
/// `sample`, `pdf` and `invert` are the method's at ω_i (an outgoing direction below the horizon
/// or not finite has no preimage, [`InvertError::OutsideDomain`]; one above it where the method
/// has none, [`InvertError::ZeroDensity`]); the target is f̄(ω_i, ω_o)·cos θ_o normalised by
/// [`scalar_albedo`] (used by the check battery and the CLI's `pdf`, `invert` and `check`).
pub struct IncidentSampler<'a> {
    method: &'a dyn BrdfMethod,
    brdf: &'a TabulatedBrdf,
    wi: Vec3,
    /// ∫ f̄ cos θ_o dω_o by quadrature.
    albedo: f64,
    /// Bytes of the method's tables, where known (the HDS sampler's).
    memory: usize,
}

impl BrdfSampler {
    /// The sampler for one incident direction, as a [`Sampler`] (for the check battery): its
    /// target is f̄·cos θ_o normalised by [`scalar_albedo`].
    pub fn at(&self, wi: Vec3) -> IncidentSampler<'_> {
        IncidentSampler::new(self, wi)
    }
}

impl<'a> IncidentSampler<'a> {
    /// The HDS sampler `sampler` at ω_i.
    pub fn new(sampler: &'a BrdfSampler, wi: Vec3) -> Self {
        IncidentSampler {
            memory: sampler.memory_bytes(),
            ..Self::of(sampler, sampler.brdf(), wi)
        }
    }
    /// Any method of `brdf` (the HDS sampler, a baseline) at ω_i.
    pub fn of(method: &'a dyn BrdfMethod, brdf: &'a TabulatedBrdf, wi: Vec3) -> Self {
        IncidentSampler {
            method,
            brdf,
            wi,
            albedo: scalar_albedo(brdf, wi),
            memory: 0,
        }
    }
    /// ∫ f̄(ω_i, ω_o) cos θ_o dω_o (the scalar's directional albedo, [`scalar_albedo`]).
    pub fn albedo(&self) -> f64 {
        self.albedo
    }
}

impl Sampler for IncidentSampler<'_> {
    fn name(&self) -> &'static str {
        match self.method.name() {
            "hds" => "hds-brdf",
            other => other,
        }
    }
    fn domain(&self) -> Domain {
        Domain::Hemisphere
    }
    fn sample(&self, u: Point2) -> Sample {
        let s = self.method.sample(self.wi, u);
        Sample {
            direction: s.direction,
            pdf: s.pdf,
        }
    }
    fn pdf(&self, direction: Vec3) -> f64 {
        self.method.pdf(self.wi, direction)
    }
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        if !(direction[2] >= 0.0) || !direction.iter().all(|c| c.is_finite()) {
            return Err(InvertError::OutsideDomain);
        }
        self.method
            .invert(self.wi, direction)
            .ok_or(InvertError::ZeroDensity)
    }
    fn target_pdf(&self, direction: Vec3) -> f64 {
        if !(direction[2] >= 0.0) || !(self.albedo > 0.0) {
            return 0.0;
        }
        let b = self.brdf;
        b.scalar(b.eval(self.wi, direction)) * direction[2] / self.albedo
    }
    fn target_power(&self) -> f64 {
        self.albedo
    }
    fn memory_bytes(&self) -> usize {
        self.memory
    }
}
