//! A piecewise-constant image over an equal-area map, sampled marginal–conditionally (the method of
//! pbrt-v4's `GoniometricLight`).

use super::equal_area::{
    equal_area_hemisphere_to_square, equal_area_sphere_to_square, equal_area_square_to_hemisphere,
    equal_area_square_to_sphere,
};
use super::{clamp_unit, invert_cdf, BuildError, ImageCdfs, Target};
use crate::diagram::Diagram;
use crate::sampler::{normalize, spherical, Domain, InvertError, Point2, Sample, Sampler, Vec3};
use rayon::prelude::*;

/// Default image resolution R (pixels per side): 256 × 256 pixels, 64 Ki pixels, about 1 MiB of
/// tables. On the sphere a pixel covers 4π/R² ≈ 1.9·10⁻⁴ sr (about 0.8° × 0.8°), on the hemisphere
/// half that; the same resolution as pbrt-v4 scenes commonly give goniometric images.
pub const DEFAULT_RESOLUTION: usize = 256;

/// Largest accepted image resolution (pixels per side): 4096² pixels, about 256 MiB of tables.
pub const MAX_RESOLUTION: usize = 4096;

/// Sub-pixel points per axis averaged into each pixel: S = 4, i.e. the midpoint rule on a 4 × 4 grid
/// of the pixel in the square, mapped through the equal-area map (so each point stands for the same
/// solid angle and the mean is the pixel's mean target up to the quadrature error).
pub const SUPERSAMPLING: usize = 4;

/// Piecewise-constant 2D sampling over an equal-area map of the unit square.
///
/// * **Map** `m`: on [`Domain::Sphere`], Clarberg's octahedral equal-area map
///   ([`super::equal_area::equal_area_square_to_sphere`], area A = 4π); on [`Domain::Hemisphere`],
///   the concentric map followed by the Lambert lift
///   ([`super::equal_area::equal_area_square_to_hemisphere`], A = 2π), so that no pixel straddles
///   the equator and every sample lies in z ≥ 0 (Clarberg's sphere map folds the lower hemisphere
///   into the square's corners and its equator crosses pixels diagonally).
/// * **Image**: R × R pixels over the square, pixel (row r, column c) = [c/R, (c+1)/R] × [r/R, (r+1)/R]
///   in (u, v); its value f_rc is the target averaged over S × S = 4 × 4 sub-pixel midpoints mapped
///   through `m`.
/// * **Sampling**: u₁ picks the row by inverting the marginal CDF of the row sums (binary search),
///   u₀ the column by inverting that row's conditional CDF; the continuous offsets inside the pixel
///   make the map continuous within rows; the point is mapped through `m`.
/// * **Density**, exactly: pdf(ω) = f_rc / (Σ f / R²) / A per steradian, where (r, c) is the pixel
///   holding m⁻¹(ω). (Σ f / R² is the mean pixel value, so f_rc / mean is the density on the square.)
/// * **Inverse**: m⁻¹, then the two piecewise-linear CDFs evaluated at the point, in closed form.
///
/// Weaknesses inherent to the method: the density is constant per pixel, so pdf ≠ target inside
/// pixels where the target varies; a pixel whose average is positive but that contains directions of
/// zero target (at the edge of a beam or of the diagram's θ range) gives those directions pdf > 0;
/// a pixel whose sub-pixel points all miss a narrow positive feature gives it pdf = 0 (biased).
/// Pixels of value 0 are never sampled. A sample drawn on an edge of its pixel (u at a CDF
/// breakpoint, u = 1, the fold lines of Clarberg's map) is moved into the pixel by a few ulps where
/// the rounding of m⁻¹(m(p)) would otherwise give the neighbouring pixel, so [`Sampler::pdf`] and
/// `invert` always see the sampled pixel: `pdf(sample(u).direction) == sample(u).pdf` exactly and
/// `invert(sample(u)) = u` to ~1e-13. `invert` is discontinuous across row boundaries in u₀.
///
/// ```
/// use gonio::baselines::PiecewiseConstant;
/// use gonio::{Diagram, Domain, Sampler};
/// let d = Diagram::from_degrees(&[0.0, 90.0, 180.0], &[0.0], &[vec![1.0, 0.5, 0.2]]).unwrap();
/// let pc = PiecewiseConstant::with_resolution(&d, Domain::Sphere, 64).unwrap();
/// assert_eq!(pc.resolution(), 64);
/// let s = pc.sample([0.2, 0.9]);
/// assert!((pc.pdf(s.direction) - s.pdf).abs() <= 1e-12 * s.pdf); // constant on its pixel
/// let u = pc.invert(s.direction).unwrap();
/// assert!((u[0] - 0.2).abs() < 1e-9 && (u[1] - 0.9).abs() < 1e-9);
/// ```
#[derive(Debug, Clone)]
pub struct PiecewiseConstant {
    target: Target,
    resolution: usize,
    /// Density per steradian of each pixel, row-major (`pdf[r * R + c]`).
    pdf: Vec<f64>,
    /// Normalised CDF of the row sums, R + 1 entries.
    /// The marginal and conditional CDFs of the pixels.
    cdfs: ImageCdfs,
}

impl PiecewiseConstant {
    /// A piecewise-constant sampler at the [`DEFAULT_RESOLUTION`] (256 × 256 pixels).
    ///
    /// # Errors
    /// As [`PiecewiseConstant::with_resolution`].
    pub fn new(diagram: &Diagram, domain: Domain) -> Result<Self, BuildError> {
        Self::with_resolution(diagram, domain, DEFAULT_RESOLUTION)
    }

    /// A piecewise-constant sampler with `resolution` × `resolution` pixels. Building costs
    /// R² · S² target evaluations (run on the rayon threads).
    ///
    /// # Errors
    /// [`BuildError::NotHemisphere`], [`BuildError::NoPower`] as for every baseline;
    /// [`BuildError::Resolution`] unless 1 ≤ `resolution` ≤ [`MAX_RESOLUTION`];
    /// [`BuildError::EmptyImage`] if every pixel averages to 0.
    pub fn with_resolution(
        diagram: &Diagram,
        domain: Domain,
        resolution: usize,
    ) -> Result<Self, BuildError> {
        let target = Target::new(diagram, domain)?;
        if !(1..=MAX_RESOLUTION).contains(&resolution) {
            return Err(BuildError::Resolution {
                resolution,
                max: MAX_RESOLUTION,
            });
        }
        let n = resolution;
        let map = square_map(domain);
        let mut image = vec![0.0; n * n];
        let s = SUPERSAMPLING;
        image.par_chunks_mut(n).enumerate().for_each(|(r, row)| {
            for (c, px) in row.iter_mut().enumerate() {
                let mut sum = 0.0;
                for a in 0..s {
                    for b in 0..s {
                        let p = [
                            (c as f64 + (a as f64 + 0.5) / s as f64) / n as f64,
                            (r as f64 + (b as f64 + 0.5) / s as f64) / n as f64,
                        ];
                        let (t, ph) = spherical(map(p));
                        sum += target.at(t, ph);
                    }
                }
                *px = sum / (s * s) as f64;
            }
        });

        let (cdfs, total) = ImageCdfs::build(&image, n, n);
        if total <= 0.0 {
            return Err(BuildError::EmptyImage { resolution });
        }
        // f / (Σf / R²) is the density on the unit square; the map divides it by its area A.
        let scale = (n * n) as f64 / (total * domain.solid_angle());
        for v in image.iter_mut() {
            *v *= scale;
        }
        Ok(Self {
            target,
            resolution,
            pdf: image,
            cdfs,
        })
    }

    /// Pixels per side of the image.
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// The pixel (row, column) holding the point `p` of the square.
    #[inline]
    fn pixel(&self, p: Point2) -> (usize, usize) {
        let n = self.resolution;
        let idx = |x: f64| ((x * n as f64) as usize).min(n - 1);
        (idx(p[1]), idx(p[0]))
    }

    /// m⁻¹ of a direction, normalised first; `None` outside the domain (or for a zero or
    /// non-finite vector). `pdf`, `invert` and the edge test of `sample` all go through here, so
    /// they agree on the pixel of every direction.
    #[inline]
    fn square_point(&self, direction: Vec3) -> Option<Point2> {
        let d = normalize(direction)?;
        if !self.target.domain.contains(d) {
            return None;
        }
        Some(match self.target.domain {
            Domain::Hemisphere => equal_area_hemisphere_to_square(d),
            Domain::Sphere => equal_area_sphere_to_square(d),
        })
    }

    /// The pixel (row, column) of a direction, as `pdf` and `invert` see it.
    #[inline]
    fn locate(&self, direction: Vec3) -> Option<(usize, usize)> {
        self.square_point(direction).map(|p| self.pixel(p))
    }

    /// m: the square point `p` as a direction.
    #[inline]
    fn to_direction(&self, p: Point2) -> Vec3 {
        match self.target.domain {
            Domain::Hemisphere => equal_area_square_to_hemisphere(p),
            Domain::Sphere => equal_area_square_to_sphere(p),
        }
    }
}

/// Offsets within a pixel (in pixel units) closer than this to 0 or 1 are checked in `sample`:
/// far above the round-trip error of the equal-area maps (~1e-15 pixel at R = 4096), far below
/// any offset a random u gives except with probability ~4e-6.
const EDGE: f64 = 1e-6;

#[inline]
fn near_edge(t: f64) -> bool {
    !(EDGE..=1.0 - EDGE).contains(&t)
}

/// The equal-area map of the domain (area = the domain's solid angle).
fn square_map(domain: Domain) -> fn(Point2) -> Vec3 {
    match domain {
        Domain::Hemisphere => equal_area_square_to_hemisphere,
        Domain::Sphere => equal_area_square_to_sphere,
    }
}

impl Sampler for PiecewiseConstant {
    target_methods!("piecewise-constant");
    fn sample(&self, u: Point2) -> Sample {
        let n = self.resolution;
        let (r, dv) = invert_cdf(
            &self.cdfs.marginal,
            self.cdfs.marginal_last,
            clamp_unit(u[1]),
        );
        let row = &self.cdfs.conditional[r * (n + 1)..(r + 1) * (n + 1)];
        let (c, du) = invert_cdf(
            row,
            self.cdfs.conditional_last[r] as usize,
            clamp_unit(u[0]),
        );
        let nf = n as f64;
        let mut p = [(c as f64 + du) / nf, (r as f64 + dv) / nf];
        let mut direction = self.to_direction(p);
        // On (or within rounding of) an edge of pixel (r, c), m⁻¹(m(p)) may fall in the
        // neighbouring pixel (e.g. dv = 0 gives p₁ = r/R exactly, and m⁻¹ may return r/R − 1 ulp;
        // u = 1 gives the far edge of the last positive pixel), whose density and CDFs differ — it
        // may even have probability 0. `pdf` and `invert` must see the pixel that was sampled, so
        // move p into the pixel by the smallest step (from 1 ulp, doubling) that makes them agree.
        // Away from the edges the round trip of the map (error ~1e-16) cannot leave the pixel.
        if near_edge(du) || near_edge(dv) {
            let (c0, r0) = (c as f64 / nf, r as f64 / nf);
            let (c1, r1) = ((c + 1) as f64 / nf, (r + 1) as f64 / nf);
            let mut delta = f64::EPSILON;
            while self.locate(direction) != Some((r, c)) {
                if delta > 0.25 / nf {
                    // Unreachable for maps whose round trip is accurate to 1/(4R); the centre of
                    // the pixel is then the safe choice.
                    p = [(c as f64 + 0.5) / nf, (r as f64 + 0.5) / nf];
                    direction = self.to_direction(p);
                    break;
                }
                p = [
                    p[0].clamp(c0 + delta, c1 - delta),
                    p[1].clamp(r0 + delta, r1 - delta),
                ];
                direction = self.to_direction(p);
                delta *= 2.0;
            }
        }
        Sample {
            direction,
            pdf: self.pdf[r * n + c],
        }
    }
    fn pdf(&self, direction: Vec3) -> f64 {
        match self.locate(direction) {
            Some((r, c)) => self.pdf[r * self.resolution + c],
            None => 0.0,
        }
    }
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        let p = self
            .square_point(direction)
            .ok_or(InvertError::OutsideDomain)?;
        let n = self.resolution;
        let (r, c) = self.pixel(p);
        // The rule of every sampler: no point maps where the density is 0 (the pixel's
        // preimage is empty; a point returned here would map elsewhere). The pixel is the one
        // `pdf` finds (`locate` of the same point), found once.
        if self.pdf[r * n + c] == 0.0 {
            return Err(InvertError::ZeroDensity);
        }
        let du = (p[0] * n as f64 - c as f64).clamp(0.0, 1.0);
        let dv = (p[1] * n as f64 - r as f64).clamp(0.0, 1.0);
        let row = &self.cdfs.conditional[r * (n + 1)..(r + 1) * (n + 1)];
        let u0 = row[c] + du * (row[c + 1] - row[c]);
        let u1 = self.cdfs.marginal[r] + dv * (self.cdfs.marginal[r + 1] - self.cdfs.marginal[r]);
        Ok([u0.clamp(0.0, 1.0), u1.clamp(0.0, 1.0)])
    }
    fn memory_bytes(&self) -> usize {
        8 * self.pdf.len() + self.cdfs.bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A beam of a few pixels and an empty upper hemisphere: most rows and columns have zero
    /// probability. Every CDF breakpoint u = (conditional[r][c], marginal[r]) of a positive pixel,
    /// and the far edges u = 1, sample a direction that `pdf` and `invert` place in the sampled
    /// pixel (they used to see the empty neighbour: rounding in m⁻¹(m(p)) moved p = r/R below the
    /// edge, and u = 1 gave the far edge of the last positive pixel).
    fn diagram(theta: &[f64], phi: &[f64], f: impl Fn(f64, f64) -> f64) -> Diagram {
        let values: Vec<Vec<f64>> = phi
            .iter()
            .map(|&p| theta.iter().map(|&t| f(t, p)).collect())
            .collect();
        Diagram::from_degrees(theta, phi, &values).unwrap()
    }

    #[test]
    fn breakpoints_stay_in_their_pixel() {
        let cases = [
            // A narrow beam at the north pole (a few pixels at the square's centre).
            (
                diagram(&[0.0, 2.0, 3.0, 180.0], &[0.0], |t, _| f64::from(t <= 2.0)),
                Domain::Sphere,
            ),
            // Lower hemisphere only, in one quadrant (the square's corner triangles).
            (
                diagram(
                    &[0.0, 100.0, 160.0, 180.0],
                    &[0.0, 90.0, 180.0, 270.0],
                    |t, p| f64::from(t >= 160.0 && p < 100.0),
                ),
                Domain::Sphere,
            ),
            // An off-axis beam in one quadrant of the hemisphere.
            (
                diagram(
                    &[0.0, 40.0, 45.0, 50.0, 90.0],
                    &[0.0, 30.0, 60.0, 90.0],
                    |t, p| f64::from((45.0..=50.0).contains(&t) && p <= 30.0),
                ),
                Domain::Hemisphere,
            ),
        ];
        for (diagram, domain) in &cases {
            for res in [16, 64, 256] {
                let s = PiecewiseConstant::with_resolution(diagram, *domain, res).unwrap();
                check_breakpoints(&s);
            }
        }
    }

    fn check_breakpoints(s: &PiecewiseConstant) {
        let (n, res) = (s.resolution, s.resolution);
        let mut points = vec![[1.0, 1.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]];
        for r in 0..n {
            for c in 0..n {
                if s.pdf[r * n + c] > 0.0 {
                    let row = &s.cdfs.conditional[r * (n + 1)..(r + 1) * (n + 1)];
                    for u0 in [row[c], row[c + 1]] {
                        for u1 in [s.cdfs.marginal[r], s.cdfs.marginal[r + 1]] {
                            points.push([u0, u1]);
                        }
                    }
                }
            }
        }
        for u in points {
            let smp = s.sample(u);
            assert!(smp.pdf > 0.0, "R = {res}: zero density at {u:?}");
            assert_eq!(s.pdf(smp.direction), smp.pdf, "R = {res}: pdf at {u:?}");
            let v = s.invert(smp.direction).unwrap();
            let e = (v[0] - u[0]).abs().max((v[1] - u[1]).abs());
            assert!(e < 1e-12, "R = {res}: invert(sample({u:?})) = {v:?}");
        }
    }
}
