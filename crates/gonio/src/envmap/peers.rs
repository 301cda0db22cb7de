//! The environment-map samplers a renderer would use instead of the HDS map, behind the same
//! [`Sampler`] contract:
//!
//! * [`LatLongPiecewiseConstant`]: the lat-long piecewise-constant map most small renderers use
//!   (pbrt-v3's `InfiniteAreaLight`, `src/lights/infinite.cpp`; Mitsuba 3's `envmap` is its
//!   bilinear relative): marginal–conditional inversion over the image's pixels weighted by
//!   sin θ of the pixel centre, pdf = p(s, t)/(2π² sin θ);
//! * the **pbrt-v4 style** sampler ([`super::EnvironmentMap::pbrt_v4_peer`]): the map resampled
//!   to a square equal-area octahedral image (`imgtool makeequiarea`), sampled piecewise-constant
//!   in 2D, pdf = p(u, v)/(4π) (pbrt-v4's `ImageInfiniteLight`, `src/pbrt/lights.cpp`, and
//!   `PiecewiseConstant2D`, `src/pbrt/util/sampling.h`): the crate's
//!   [`crate::baselines::PiecewiseConstant`] on the map's diagram.

use super::{image_direction, phi_to_s, EnvironmentMap};
use crate::baselines::{clamp_unit, invert_cdf, ImageCdfs, PiecewiseConstant, Target};
use crate::method::BuildError;
use crate::sampler::{normalize, spherical, Domain, InvertError, Point2, Sample, Sampler, Vec3};
use std::f64::consts::PI;

/// Lat-long piecewise-constant sampling of an environment map (see docs/ENVMAPS.md).
///
/// * Weights: pixel (c, r) has f_rc = weight_rc · sin θ_r, θ_r = π(r + ½)/H the row centre.
/// * Sampling: u₁ inverts the marginal CDF of the row sums, u₀ that row's conditional CDF; the
///   continuous offsets give image coordinates (s, t) ∈ [0, 1]², the direction of
///   [`super::image_direction`]`(s, t)`.
/// * Density, exactly: the density on the image square is q_rc = f_rc / mean(f), and per
///   steradian pdf(ω) = q_rc / (2π² sin θ) with θ the direction's own polar angle (dω =
///   2π² sin θ ds dt): it varies inside a pixel and grows like 1/sin θ towards the poles.
/// * Inverse: the two CDFs evaluated at the point, in closed form. The map is discontinuous
///   across row boundaries in u₀ (the conditional CDFs differ between rows).
#[derive(Debug, Clone)]
pub struct LatLongPiecewiseConstant {
    target: Target,
    width: usize,
    height: usize,
    /// Density on the image square of each pixel, row-major.
    q: Vec<f64>,
    /// The marginal and conditional CDFs of the pixels.
    cdfs: ImageCdfs,
}

impl LatLongPiecewiseConstant {
    /// The lat-long sampler of `env`'s weights (the diagram's nodes at the pixel centres, so MIS
    /// compensation, if `env` has it, is included).
    ///
    /// # Errors
    /// [`BuildError::NoPower`] if no pixel off the poles carries weight.
    pub fn new(env: &EnvironmentMap) -> Result<Self, BuildError> {
        let (w, h) = (env.image().width(), env.image().height());
        let d = env.diagram();
        let n = d.n_parallels();
        // Meridian i of the diagram is column c(i); rebuild the pixel weights row-major.
        let mut f = vec![0.0; w * h];
        for (i, &phi) in d.phi().iter().enumerate() {
            let c = ((phi_to_s(phi) * w as f64) as usize).min(w - 1);
            for r in 0..h {
                let st = (PI * (r as f64 + 0.5) / h as f64).sin();
                f[r * w + c] = d.values()[i * n + r + 1] * st;
            }
        }
        let target = Target::new(&d, Domain::Sphere)?;
        let (cdfs, total) = ImageCdfs::build(&f, w, h);
        if !(total > 0.0 && total.is_finite()) {
            return Err(BuildError::NoPower { integral: total });
        }
        let mean = total / (w * h) as f64;
        let q = f.iter().map(|&x| x / mean).collect();
        Ok(Self {
            target,
            width: w,
            height: h,
            q,
            cdfs,
        })
    }

    fn cond(&self, r: usize) -> &[f64] {
        &self.cdfs.conditional[r * (self.width + 1)..(r + 1) * (self.width + 1)]
    }

    /// The image coordinates (s, t) of a unit direction.
    fn coords(d: Vec3) -> (f64, f64) {
        let (theta, phi) = spherical(d);
        (phi_to_s(phi), theta / PI)
    }

    /// The image position of a unit direction: (x, y) in pixels, and the pixel (row, column)
    /// that holds it.
    fn place(&self, d: Vec3) -> (f64, f64, usize, usize) {
        let (s, t) = Self::coords(d);
        let (xs, ys) = (s * self.width as f64, t * self.height as f64);
        let c = (xs as usize).min(self.width - 1);
        let r = (ys as usize).min(self.height - 1);
        (xs, ys, r, c)
    }

    /// The density at unit direction `d`, which lies in pixel (`r`, `c`).
    fn density_in(&self, d: Vec3, r: usize, c: usize) -> f64 {
        let sin_theta = d[0].hypot(d[1]);
        if !(sin_theta > 0.0) {
            return 0.0;
        }
        self.q[r * self.width + c] / (2.0 * PI * PI * sin_theta)
    }

    fn density(&self, d: Vec3) -> f64 {
        let (_, _, r, c) = self.place(d);
        self.density_in(d, r, c)
    }
}

impl Sampler for LatLongPiecewiseConstant {
    fn name(&self) -> &'static str {
        "latlong-pc"
    }
    fn domain(&self) -> Domain {
        Domain::Sphere
    }
    fn sample(&self, u: Point2) -> Sample {
        let (r, a) = invert_cdf(
            &self.cdfs.marginal,
            self.cdfs.marginal_last,
            clamp_unit(u[1]),
        );
        let (c, b) = invert_cdf(
            self.cond(r),
            self.cdfs.conditional_last[r] as usize,
            clamp_unit(u[0]),
        );
        let s = (c as f64 + b) / self.width as f64;
        let t = (r as f64 + a) / self.height as f64;
        let direction = image_direction(s, t);
        Sample {
            direction,
            pdf: self.density(direction),
        }
    }
    fn pdf(&self, direction: Vec3) -> f64 {
        match normalize(direction) {
            Some(d) => self.density(d),
            None => 0.0,
        }
    }
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        let d = normalize(direction).ok_or(InvertError::OutsideDomain)?;
        let (xs, ys, r, c) = self.place(d);
        if self.density_in(d, r, c) == 0.0 {
            return Err(InvertError::ZeroDensity);
        }
        let (a, b) = (ys - r as f64, xs - c as f64);
        let m = &self.cdfs.marginal;
        let k = self.cond(r);
        Ok([
            (k[c] + b * (k[c + 1] - k[c])).clamp(0.0, 1.0),
            (m[r] + a * (m[r + 1] - m[r])).clamp(0.0, 1.0),
        ])
    }
    fn target_pdf(&self, direction: Vec3) -> f64 {
        self.target.pdf(direction)
    }
    fn memory_bytes(&self) -> usize {
        8 * self.q.len() + self.cdfs.bytes()
    }
    fn target_power(&self) -> f64 {
        self.target.integral
    }
}

impl EnvironmentMap {
    /// The pbrt-v4-style peer: the map's weight resampled onto a `resolution` × `resolution`
    /// equal-area octahedral image (each pixel the mean of 4 × 4 bilinear lookups, as
    /// [`PiecewiseConstant`] builds) and sampled piecewise-constant in 2D, pdf = p(u, v)/(4π).
    /// `None` picks the square with as many pixels as the image (R = round(√(W·H))).
    ///
    /// # Errors
    /// As [`PiecewiseConstant::with_resolution`].
    pub fn pbrt_v4_peer(&self, resolution: Option<usize>) -> Result<PiecewiseConstant, BuildError> {
        let r = resolution.unwrap_or_else(|| {
            ((self.image().width() * self.image().height()) as f64)
                .sqrt()
                .round() as usize
        });
        PiecewiseConstant::with_resolution(&self.diagram(), Domain::Sphere, r.max(1))
    }

    /// The lat-long piecewise-constant peer ([`LatLongPiecewiseConstant::new`]).
    ///
    /// # Errors
    /// As [`LatLongPiecewiseConstant::new`].
    pub fn latlong_peer(&self) -> Result<LatLongPiecewiseConstant, BuildError> {
        LatLongPiecewiseConstant::new(self)
    }
}
