//! Exact importance sampling of f_r·cos θ_o for any incident direction: the HDS map of the slice
//! diagram blended between the tabulated incident directions ([`crate::mapping::BlendedMap`]).
//!
//! **Slices.** At every tabulated incident node (θ_i,a, φ_i,b) the slice diagram is
//! s(θ_o, Δφ) = f̄(ω_i, θ_o, φ_i,b + Δφ)·cos θ_o on an outgoing grid in the frame turned by the
//! incident azimuth (Δφ = φ_o − φ_i, so the specular peak stays near Δφ = 180° in every slice);
//! f̄ is f_r for one channel, its luminance ([`super::LUMINANCE`]) for three. The grid is the
//! table's own outgoing grid when it spans θ_o = 0°…90° and starts at Δφ = 0 (no resampling, e.g.
//! the MERL reader's and the analytic tables), otherwise the uniform grid of [`SamplerOptions`].
//! Every slice gets its HDS map ([`crate::HemisphereMap`]).
//!
//! **Blending.** For ω_i = (θ_i, φ_i) the weights are those of the table's own interpolation:
//! linear in θ_i between the two neighbouring slices (clamped beyond the tabulated range), and for
//! anisotropic tables bilinear in (θ_i, φ_i), periodic in φ_i. The map for ω_i is the HDS map of
//! the blend Σ w_k s_k / ∫s_k of the normalised slices, read from the slices' tables exactly, then
//! turned by φ_i. Its pdf is Σ w_k pdf_k(ω_o) (the exact density of that map), it is bijective
//! with a closed-form inverse, continuous in u, and continuous in ω_i: the weights are
//! continuous and a slice enters or leaves the blend with weight 0 (see
//! [`crate::mapping::blend`]). The exception is the normal direction θ_i = 0, where φ_i is
//! undefined: the density there is continuous, the parametrisation turns with φ_i.
//!
//! **Empty slices.** A slice without reflectance above the horizon gets no map and drops out of
//! the blend (the others' weights are renormalised). Where every neighbouring slice is empty the
//! sampler falls back to cosine sampling and returns **zero weights**: a documented zero-weight
//! sample, never NaN.
//!
//! **Weight.** `weight[c] = f_r,c(ω_i, ω_o)·cos θ_o / pdf`, with f_r the table's own
//! interpolation ([`TabulatedBrdf::eval`]); 0 where the pdf is 0.

use super::{periodic, BrdfError, Symmetry, TabulatedBrdf};
use crate::mapping::blend::MAX_PARTS;
use crate::mapping::blob::{self, BrdfTable, Precision, TablesError};
use crate::mapping::BlendedMap;
use crate::sampler::{spherical, Point2, Sampler, Vec3};
use crate::{Diagram, HemisphereMap};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The outgoing grid of the slice diagrams when the table's own grid cannot be used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SamplerOptions {
    /// Polar nodes 0°…90° of the outgoing grid (≥ 2).
    pub theta_o: usize,
    /// Azimuthal nodes of the outgoing grid (≥ 1).
    pub phi_o: usize,
    /// Resample even when the table's own grid could be used.
    pub force_resample: bool,
}

impl Default for SamplerOptions {
    fn default() -> Self {
        SamplerOptions {
            theta_o: 46,
            phi_o: 90,
            force_resample: false,
        }
    }
}

/// One sample of a BRDF: the outgoing direction, its exact pdf (per sr) and the weight
/// f_r·cos θ_o / pdf per channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrdfSample {
    /// The outgoing direction (local frame).
    pub direction: Vec3,
    /// The exact density of the map that produced it, per steradian.
    pub pdf: f64,
    /// f_r·cos θ_o / pdf per channel (0 where the pdf is 0).
    pub weight: [f64; 3],
}

/// The HDS sampler of a [`TabulatedBrdf`]; see docs/BRDF.md.
#[derive(Debug, Clone)]
pub struct BrdfSampler {
    brdf: TabulatedBrdf,
    /// Slice maps, index a·(number of φ_i) + b; `None` for a slice without reflectance.
    slices: Vec<Option<HemisphereMap>>,
    /// Per slice (same index) its map's total T_k and κ_k, contiguous for the blend (0 for an
    /// empty slice).
    parts: Vec<[f64; 2]>,
    /// The outgoing grid of the slices (radians).
    theta_o: Vec<f64>,
    phi_o: Vec<f64>,
    resampled: bool,
}

/// The incident polar angle and azimuth of a direction; θ_i clamped to [0, π/2].
fn incident_angles(wi: Vec3) -> (f64, f64) {
    let (t, p) = spherical(wi);
    (t.min(FRAC_PI_2), p)
}

fn rotate(d: Vec3, phi: f64) -> Vec3 {
    let (s, c) = phi.sin_cos();
    [c * d[0] - s * d[1], s * d[0] + c * d[1], d[2]]
}

/// Cosine-weighted hemisphere sampling through the concentric map (the fallback of empty slices).
pub(crate) fn cosine_sample(u: Point2) -> Vec3 {
    let (r, phi) = crate::mapping::concentric::square_to_disk(u);
    let z = (1.0 - r * r).max(0.0).sqrt();
    [r * phi.cos(), r * phi.sin(), z]
}

/// Inverse of [`cosine_sample`].
pub(crate) fn cosine_invert(d: Vec3) -> Point2 {
    let r = (d[0] * d[0] + d[1] * d[1]).sqrt().min(1.0);
    let phi = crate::mapping::lift::sphere_to_disk_azimuth(d);
    crate::mapping::concentric::disk_to_square(r, phi)
}

impl BrdfSampler {
    /// Builds the slice maps of `brdf` (see the module documentation for the grid).
    pub fn new(brdf: TabulatedBrdf, options: &SamplerOptions) -> Result<Self, BrdfError> {
        let to = brdf.theta_o();
        let native = !options.force_resample
            && to.len() >= 2
            && to[0] == 0.0
            && (to[to.len() - 1] - FRAC_PI_2).abs() < 1e-12
            && brdf.phi_o()[0] == 0.0;
        let (theta_o, phi_o) = if native {
            let mut t = to.to_vec();
            *t.last_mut().unwrap() = FRAC_PI_2;
            (t, brdf.phi_o().to_vec())
        } else {
            if options.theta_o < 2 || options.phi_o < 1 {
                return Err(BrdfError::Shape {
                    expected: 2,
                    found: options.theta_o.min(options.phi_o),
                    what: "sampler grid: at least 2 θ_o and 1 φ_o nodes".into(),
                });
            }
            (
                super::uniform_theta(options.theta_o, 90.0),
                super::uniform_phi(options.phi_o),
            )
        };
        let theta_deg: Vec<f64> = theta_o.iter().map(|t| t.to_degrees()).collect();
        let phi_deg: Vec<f64> = phi_o.iter().map(|p| p.to_degrees()).collect();
        let mut slices = Vec::with_capacity(brdf.theta_i().len() * brdf.phi_i().len());
        for &ti in brdf.theta_i() {
            for &pi in brdf.phi_i() {
                let values: Vec<Vec<f64>> = phi_o
                    .iter()
                    .map(|&dp| {
                        theta_o
                            .iter()
                            .map(|&t| {
                                let f = brdf.eval_angles(ti, pi, t, pi + dp);
                                (brdf.scalar(f) * t.cos()).max(0.0)
                            })
                            .collect()
                    })
                    .collect();
                let map = if values.iter().flatten().any(|&v| v > 0.0) {
                    let d = Diagram::from_degrees(&theta_deg, &phi_deg, &values).map_err(|e| {
                        BrdfError::Shape {
                            expected: 0,
                            found: 0,
                            what: format!("slice diagram: {e}"),
                        }
                    })?;
                    HemisphereMap::new(&d).ok()
                } else {
                    None
                };
                slices.push(map);
            }
        }
        let parts = slices
            .iter()
            .map(|m| match m {
                Some(m) => [m.core().total(), m.core().view().angular.kappa],
                None => [0.0; 2],
            })
            .collect();
        Ok(BrdfSampler {
            brdf,
            slices,
            parts,
            theta_o,
            phi_o,
            resampled: !native,
        })
    }

    /// The table sampled.
    pub fn brdf(&self) -> &TabulatedBrdf {
        &self.brdf
    }
    /// Whether the slices were resampled to the options' grid (else the table's own grid).
    pub fn resampled(&self) -> bool {
        self.resampled
    }
    /// The slices' outgoing grid (radians): θ_o and Δφ.
    pub fn grid(&self) -> (&[f64], &[f64]) {
        (&self.theta_o, &self.phi_o)
    }
    /// Number of tabulated incident slices, and how many hold no reflectance.
    pub fn slice_counts(&self) -> (usize, usize) {
        (
            self.slices.len(),
            self.slices.iter().filter(|s| s.is_none()).count(),
        )
    }
    /// The map of slice `index` (θ_i index × number of φ_i + φ_i index), `None` for an empty one.
    pub fn slice(&self, index: usize) -> Option<&HemisphereMap> {
        self.slices.get(index).and_then(|s| s.as_ref())
    }

    /// The family blob of this sampler (`docs/TABLES.md`, "Families"): every slice's map in
    /// `precision` on the shared grid, the incident grid and the BRDF table, for a device or a
    /// Dr.Jit kernel that blends the slices as [`BrdfSampler::sample`] does. Read it back with
    /// [`crate::mapping::blob::read_family`] (or [`super::from_tables`]).
    ///
    /// # Errors
    /// [`TablesError::Float32`] for a grid beyond the float32 kernels' limits;
    /// [`TablesError::Target`] when every slice is empty.
    pub fn tables(&self, precision: Precision) -> Result<Vec<u8>, TablesError> {
        let slices: Vec<Option<&HemisphereMap>> = self.slices.iter().map(|s| s.as_ref()).collect();
        let b = &self.brdf;
        blob::write_family(
            &slices,
            precision,
            &BrdfTable {
                anisotropic: b.symmetry() == Symmetry::Anisotropic,
                channels: b.channels(),
                theta_i: b.theta_i(),
                phi_i: b.phi_i(),
                theta_o: b.theta_o(),
                phi_o: b.phi_o(),
                values: b.values(),
            },
        )
    }

    /// Bytes held: the slices' tables (with the diagrams they keep) and the BRDF table.
    pub fn memory_bytes(&self) -> usize {
        self.slices
            .iter()
            .flatten()
            .map(|m| m.memory_bytes() + 8 * m.diagram().values().len())
            .sum::<usize>()
            + self.brdf.memory_bytes()
    }

    /// The neighbouring slices of ω_i and their weights (positive, summing to 1), without empty
    /// slices; `len` 0 when every neighbour is empty.
    fn weights(&self, ti: f64, pi: f64) -> ([usize; MAX_PARTS], [f64; MAX_PARTS], usize) {
        let (a0, a1, ta) = super::clamped(self.brdf.theta_i(), ti);
        let np = self.brdf.phi_i().len();
        let (q0, q1, tq) = match self.brdf.symmetry() {
            Symmetry::Isotropic => (0, 0, 0.0),
            Symmetry::Anisotropic => periodic(self.brdf.phi_i(), pi),
        };
        let mut idx = [0; MAX_PARTS];
        let mut w = [0.0; MAX_PARTS];
        let mut len = 0;
        for (a, wa) in [(a0, 1.0 - ta), (a1, ta)] {
            for (q, wq) in [(q0, 1.0 - tq), (q1, tq)] {
                let wk = wa * wq;
                let k = a * np + q;
                if wk > 0.0 && self.slices[k].is_some() {
                    if let Some(pos) = idx[..len].iter().position(|&x| x == k) {
                        w[pos] += wk;
                    } else {
                        idx[len] = k;
                        w[len] = wk;
                        len += 1;
                    }
                }
            }
        }
        let s: f64 = w[..len].iter().sum();
        for x in w[..len].iter_mut() {
            *x /= s;
        }
        (idx, w, len)
    }

    /// The map for incident direction `wi` (upper hemisphere), `None` where every neighbouring
    /// slice is empty.
    fn blend(&self, ti: f64, pi: f64) -> Option<BlendedMap<'_>> {
        let (idx, w, len) = self.weights(ti, pi);
        if len == 0 {
            return None;
        }
        let first = self.slices[idx[0]].as_ref()?.core();
        let mut cores = [first; MAX_PARTS];
        let mut totals = [0.0; MAX_PARTS];
        let mut kappas = [0.0; MAX_PARTS];
        for k in 0..len {
            cores[k] = self.slices[idx[k]].as_ref()?.core();
            [totals[k], kappas[k]] = self.parts[idx[k]];
        }
        Some(BlendedMap::from_parts(cores, w, totals, kappas, len))
    }

    /// The slice frame's azimuth for ω_i: the samples of the blend are turned by it.
    fn frame(ti: f64, pi: f64) -> f64 {
        let _ = ti;
        pi
    }

    /// Samples ω_o for incident direction `wi` at a point `u` of the unit square. A `wi` below the
    /// horizon or not finite gives the zero-weight cosine sample (pdf of cosine sampling).
    pub fn sample(&self, wi: Vec3, u: Point2) -> BrdfSample {
        let (ti, pi) = incident_angles(wi);
        match (wi[2] >= 0.0).then(|| self.blend(ti, pi)).flatten() {
            Some(b) => {
                let s = b.sample(u);
                let d = rotate(s.direction, Self::frame(ti, pi));
                let weight = self.weight(ti, pi, d, s.pdf);
                BrdfSample {
                    direction: d,
                    pdf: s.pdf,
                    weight,
                }
            }
            None => {
                let d = cosine_sample(u);
                BrdfSample {
                    direction: d,
                    pdf: d[2] / PI,
                    weight: [0.0; 3],
                }
            }
        }
    }

    /// f_r(ω_i, ω_o)·cos θ_o / pdf for the incident angles `sample` already has (ω_i in the
    /// upper hemisphere, so `ti` is θ_i unclamped): the same value as [`TabulatedBrdf::eval`]
    /// without recomputing ω_i's angles.
    fn weight(&self, ti: f64, pi: f64, wo: Vec3, pdf: f64) -> [f64; 3] {
        if !(pdf > 0.0) || !(wo[2] > 0.0) {
            return [0.0; 3];
        }
        let (to, po) = spherical(wo);
        let f = self.brdf.eval_angles(ti, pi, to, po);
        let k = wo[2] / pdf;
        [f[0] * k, f[1] * k, f[2] * k]
    }

    /// The exact density of [`BrdfSampler::sample`] at ω_o, per steradian (0 below the horizon).
    pub fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        if !(wo[2] >= 0.0) {
            return 0.0;
        }
        let (ti, pi) = incident_angles(wi);
        match (wi[2] >= 0.0).then(|| self.blend(ti, pi)).flatten() {
            Some(b) => b.pdf(rotate(wo, -Self::frame(ti, pi))),
            None => wo[2].max(0.0) / PI,
        }
    }

    /// The point of the unit square that [`BrdfSampler::sample`] maps to ω_o.
    pub fn invert(&self, wi: Vec3, wo: Vec3) -> Option<Point2> {
        if !(wo[2] >= 0.0) || !wo.iter().all(|c| c.is_finite()) {
            return None;
        }
        let (ti, pi) = incident_angles(wi);
        match (wi[2] >= 0.0).then(|| self.blend(ti, pi)).flatten() {
            Some(b) => b.invert(rotate(wo, -Self::frame(ti, pi))),
            None => Some(cosine_invert(wo)),
        }
    }
}

/// ∫ f̄(ω_i, ω_o) cos θ_o dω_o, exact up to round-off: for a fixed ω_i the table's interpolant is
/// piecewise linear in φ_o between the azimuth nodes (so the trapezoidal rule over them is exact)
/// and piecewise linear in θ_o between the polar nodes (so 8-point Gauss–Legendre per segment
/// integrates its product with sin θ_o cos θ_o to ~1e-15).
pub fn scalar_albedo(brdf: &TabulatedBrdf, wi: Vec3) -> f64 {
    const X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let (ti, pi) = incident_angles(wi);
    let offset = match brdf.symmetry() {
        Symmetry::Isotropic => pi,
        Symmetry::Anisotropic => 0.0,
    };
    let phis = brdf.phi_o();
    let m = phis.len();
    let beta: Vec<f64> = (0..m)
        .map(|i| {
            if i + 1 < m {
                phis[i + 1] - phis[i]
            } else {
                phis[0] + TAU - phis[i]
            }
        })
        .collect();
    let ring = |t: f64| -> f64 {
        let v: Vec<f64> = phis
            .iter()
            .map(|&p| brdf.scalar(brdf.eval_angles(ti, pi, t, p + offset)))
            .collect();
        (0..m)
            .map(|i| 0.5 * beta[i] * (v[i] + v[(i + 1) % m]))
            .sum()
    };
    let to = brdf.theta_o();
    let mut total = 0.0;
    for w in to.windows(2) {
        let (mid, half) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
        for k in 0..4 {
            for sgn in [-1.0, 1.0] {
                let t = mid + sgn * half * X[k];
                total += W[k] * half * ring(t) * t.sin() * t.cos();
            }
        }
    }
    total
}
