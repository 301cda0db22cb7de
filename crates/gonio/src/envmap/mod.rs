//! Environment maps: a latitude–longitude high-dynamic-range image of radiance, sampled exactly by
//! the HDS sphere map ([`crate::SphereMap`]).
//!
//! # The frame
//!
//! Directions are gonio's (θ from **+z**, φ from **+x toward +y**, `(sin θ cos φ, sin θ sin φ,
//! cos θ)`). An image of W × H pixels (row 0 at the top, see [`crate::image`]) covers the sphere
//! with
//!
//! * **rows**: the top edge of the image is the zenith +z (θ = 0), the bottom edge the nadir −z
//!   (θ = π), θ = π·y/H for the continuous row coordinate y ∈ [0, H] from the top edge; pixel row r
//!   covers θ ∈ [πr/H, π(r+1)/H], its centre at π(r + ½)/H;
//! * **columns**: with the continuous column coordinate x ∈ [0, W) from the left edge and
//!   s = x/W, **φ = π − 2πs** (mod 2π): the **centre of the image (s = ½) looks along +x** (φ = 0),
//!   s = ¼ along +y (φ = π/2), s = ¾ along −y, and the left and right edges (s = 0, 1) along −x,
//!   where the seam φ = π lies. φ decreases to the right, so that the image seen from inside the
//!   sphere with +z up is not mirrored (the convention of Blender's equirectangular images).
//!
//! **Mitsuba 3** (`envmap` emitter, `src/emitters/envmap.cpp`): its local frame is Y-up,
//! `uv = (atan2(x, −z)/2π, acos(y)/π)`. A gonio direction g = (g_x, g_y, g_z) is the Mitsuba local
//! direction **m = (g_y, g_z, g_x)** (a rotation, a cyclic permutation of the axes), and both read
//! the same column: Mitsuba's u equals s above. So `to_world` = the matrix with rows
//! (0, 0, 1), (1, 0, 0), (0, 1, 0) makes a Mitsuba scene's world directions gonio's. Mitsuba
//! places its rows differently: row r at θ = πr/(H − 1) (the first and last rows *at* the poles)
//! rather than at pixel centres; its row-r node direction lies inside gonio's pixel row r, so a
//! direction at a Mitsuba node reads the same pixel in both (tested in the Python suite).
//!
//! **pbrt-v4** (`ImageInfiniteLight`, `src/pbrt/lights.cpp`) takes no lat-long image: it reads a
//! square image in the equal-area octahedral layout and looks up the light-space direction w at
//! pixel ⌊`EqualAreaSphereToSquare`(w)·N⌋, y counted from the top row, with pbrt's light space z
//! up. gonio's [`crate::baselines::equal_area::equal_area_square_to_sphere`] is the same map, so
//! gonio's frame *is* pbrt-v4's light space: `gonio convert IN.hdr OUT.exr --to pbrt-v4` writes, at
//! pixel (x, y), this map's radiance averaged over the directions of that square cell.
//!
//! # The diagram
//!
//! The sampling density is a per-pixel **weight** ([`Weight`]: Rec. 709 luminance
//! Y = 0.2126 R + 0.7152 G + 0.0722 B by default, one channel, or the caller's values) as a
//! density **per steradian**, on a [`Diagram`] of W meridians × (H + 2) parallels: the meridians
//! at the pixel-column centres, the parallels at θ = 0, at the H row centres and at θ = π. The pole
//! parallels hold the **mean of the first (last) row**, so the density is continuous at the poles
//! (one value for every φ); the meridians wrap around (the last one is followed by the first), so
//! it is continuous across the seam. A constant image gives a constant diagram, and the HDS map's
//! density (bilinear in (√(1 − cos θ), φ) between the nodes) is then exactly uniform, 1/(4π).
//! Negative values (possible in EXR and PFM files) are weighted as 0, with a warning.
//!
//! # Radiance
//!
//! [`EnvironmentMap::eval`] returns the image's RGB radiance in a direction, by [`Lookup`]:
//! `Nearest` is the pixel that holds the direction (the image as a piecewise-constant function,
//! what pbrt-v4 and most renderers return); `Bilinear` is the same interpolant as the diagram's
//! nodes (bilinear in (θ, φ) between the pixel centres, wrapping across the seam, towards the
//! poles' mean colour in the half rows next to them), continuous everywhere.

mod float32;
mod peers;

pub use float32::Float32EnvironmentMap;
pub use peers::LatLongPiecewiseConstant;

use crate::diagram::{Diagram, DiagramError};
use crate::image::Image;
use crate::mapping::SphereMap;
use crate::sampler::{normalize, Batches, InvertError, Point2, Sampler, Vec3};
use std::f64::consts::{PI, TAU};

/// What the sampling density is proportional to, per pixel.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Weight {
    /// Rec. 709 / sRGB luminance Y = 0.2126 R + 0.7152 G + 0.0722 B (the default).
    #[default]
    Luminance,
    /// One channel: 0 = R, 1 = G, 2 = B.
    Channel(usize),
    /// The caller's weights, W × H values row-major (row 0 at the top), finite and ≥ 0.
    Custom(Vec<f32>),
}

impl Weight {
    /// The weight's name: `luminance`, `red`, `green`, `blue` or `custom` (a channel index above
    /// 2, which the map refuses, is named `blue`).
    pub fn name(&self) -> &'static str {
        match self {
            Weight::Luminance => "luminance",
            Weight::Channel(0) => "red",
            Weight::Channel(1) => "green",
            Weight::Channel(_) => "blue",
            Weight::Custom(_) => "custom",
        }
    }
}

/// How [`EnvironmentMap::eval`] reads the image (see the [module documentation](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Lookup {
    /// The pixel that holds the direction.
    #[default]
    Nearest,
    /// Bilinear between pixel centres, continuous across the seam and at the poles.
    Bilinear,
}

impl Lookup {
    /// The lookup's name: `nearest` or `bilinear`.
    pub fn name(self) -> &'static str {
        match self {
            Lookup::Nearest => "nearest",
            Lookup::Bilinear => "bilinear",
        }
    }
}

/// Options of [`EnvironmentMap::with_options`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EnvOptions {
    /// What the density is proportional to.
    pub weight: Weight,
    /// How radiance is looked up.
    pub lookup: Lookup,
    /// MIS compensation (Karlík et al. 2019, as pbrt-v4's and Mitsuba 3's option): the weight
    /// minus its solid-angle mean over the sphere, clamped at 0, so that light sampling leaves the
    /// dim, nearly uniform part to BSDF sampling. Use it only with MIS: alone it gives 0 density
    /// where the radiance is below the mean (biased). If no pixel exceeds the mean (a constant
    /// image) the plain weight is used, with a warning.
    pub mis_compensation: bool,
}

/// Why an environment map was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EnvMapError {
    /// Every weight is 0 (an all-black image, or a channel that is 0 everywhere).
    #[error("the environment map is black: every pixel's weight ({weight}) is 0, so there is no light to sample")]
    Black {
        /// The weight, in words.
        weight: String,
    },
    /// A bad option.
    #[error("{0}")]
    BadOption(String),
    /// The diagram or the map refused the image (e.g. too large).
    #[error(transparent)]
    Diagram(#[from] DiagramError),
    /// The map has no float32 map ([`Float32EnvironmentMap`]).
    #[error("no float32 map: {0}")]
    Float32(#[from] crate::mapping::Float32MapError),
}

/// One sample of an environment map: a direction, its exact density and the radiance there.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnvSample {
    /// Unit direction, gonio's frame.
    pub direction: Vec3,
    /// Density of the map at `direction`, per steradian ([`EnvironmentMap::pdf`] there).
    pub pdf: f64,
    /// The image's RGB radiance in `direction` ([`EnvironmentMap::eval`]).
    pub radiance: [f32; 3],
}

/// An environment light: an image and the HDS sphere map of its weight. See the
/// [module documentation](self) for the frame.
///
/// ```
/// use gonio::envmap::EnvironmentMap;
/// use gonio::image::Image;
/// // A constant sky: the density is exactly uniform.
/// let sky = Image::constant(16, 8, [1.0, 1.0, 1.0]).unwrap();
/// let env = EnvironmentMap::new(sky).unwrap();
/// let s = env.sample([0.3, 0.6]);
/// assert!((s.pdf - 1.0 / (4.0 * std::f64::consts::PI)).abs() < 1e-12);
/// assert_eq!(s.radiance, [1.0, 1.0, 1.0]);
/// let u = env.invert(s.direction).unwrap();
/// assert!((u[0] - 0.3).abs() < 1e-9 && (u[1] - 0.6).abs() < 1e-9);
/// ```
#[derive(Debug, Clone)]
pub struct EnvironmentMap {
    radiance: Radiance,
    map: SphereMap,
    options: EnvOptions,
    warnings: Vec<String>,
}

/// Rec. 709 luminance of a linear RGB triple.
#[inline]
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// φ of the centre of pixel column `c` of `w` (radians, in [0, 2π)).
#[inline]
pub fn column_phi(c: usize, w: usize) -> f64 {
    let p = PI - TAU * (c as f64 + 0.5) / w as f64;
    let p = p.rem_euclid(TAU);
    if p >= TAU {
        0.0
    } else {
        p
    }
}

/// The continuous column coordinate s ∈ [0, 1) of azimuth φ: s = ½ − φ/2π (mod 1).
#[inline(always)]
pub fn phi_to_s(phi: f64) -> f64 {
    let r = 0.5 - phi / TAU;
    // For φ ∈ [0, 2π) (every azimuth the lookups pass), |r| < 1, where `rem_euclid(1.0)` is r,
    // or r + 1 for r < 0, exactly: the same bits without the library call.
    let s = if r.abs() < 1.0 {
        if r < 0.0 {
            r + 1.0
        } else {
            r
        }
    } else {
        r.rem_euclid(1.0)
    };
    if s >= 1.0 {
        0.0
    } else {
        s
    }
}

/// The direction of the continuous image coordinates (s, t) ∈ [0, 1]²: s across from the left
/// edge, t down from the top edge (θ = πt, φ = π − 2πs).
pub fn image_direction(s: f64, t: f64) -> Vec3 {
    crate::sampler::direction(PI * t, PI - TAU * s)
}

impl EnvironmentMap {
    /// The environment light of `image` with the default options (luminance, nearest lookup, no
    /// MIS compensation).
    ///
    /// # Errors
    /// As [`EnvironmentMap::with_options`].
    pub fn new(image: Image) -> Result<Self, EnvMapError> {
        Self::with_options(image, EnvOptions::default())
    }

    /// The environment light of `image`.
    ///
    /// # Errors
    /// [`EnvMapError::Black`] if every weight is 0; [`EnvMapError::BadOption`] for a channel
    /// outside 0..3 or custom weights of the wrong length or with negative or non-finite values;
    /// [`EnvMapError::Diagram`] if the map cannot be built.
    pub fn with_options(image: Image, options: EnvOptions) -> Result<Self, EnvMapError> {
        let mut warnings = image.warnings().to_vec();
        let diagram = weight_diagram(&image, &options, &mut warnings)?;
        // The diagram is given away and not kept: the map drops it once its hemisphere parts are
        // made (before the tables are built); the tables hold its values (divided by their
        // largest), and `diagram()` rebuilds it from the image.
        let map = SphereMap::from_diagram(diagram)?;
        Ok(Self {
            radiance: Radiance::new(image),
            map,
            options,
            warnings,
        })
    }

    /// The image.
    pub fn image(&self) -> &Image {
        &self.radiance.image
    }

    /// The diagram the map samples (W meridians × (H + 2) parallels; see the module
    /// documentation), **rebuilt** from the image and the options on each call (the map does not
    /// keep it, to save 8 bytes per pixel; the values are the same as at build time).
    pub fn diagram(&self) -> Diagram {
        weight_diagram(&self.radiance.image, &self.options, &mut Vec::new())
            .expect("the diagram was built from the same image and options before")
    }

    /// The HDS sphere map.
    pub fn map(&self) -> &SphereMap {
        &self.map
    }

    /// The options it was built with.
    pub fn options(&self) -> &EnvOptions {
        &self.options
    }

    /// What was repaired or ignored while reading and building, one sentence each.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Bytes held beyond the image: the map's tables ([`Sampler::memory_bytes`] of
    /// [`EnvironmentMap::map`]), the grid angles its hemisphere maps keep beside them, the
    /// caller's weights when [`Weight::Custom`] and the struct itself (the warnings' text
    /// excluded).
    pub fn memory_bytes_beyond_image(&self) -> usize {
        let custom = match &self.options.weight {
            Weight::Custom(v) => 4 * v.len(),
            _ => 0,
        };
        self.map.memory_bytes() + self.map.grid_bytes() + custom + std::mem::size_of::<Self>()
    }

    /// Maps a point of the unit square to a direction, its exact density and the radiance there.
    pub fn sample(&self, u: Point2) -> EnvSample {
        let s = self.map.sample(u);
        EnvSample {
            direction: s.direction,
            pdf: s.pdf,
            radiance: self.eval(s.direction),
        }
    }

    /// [`EnvironmentMap::sample`] of every point of `u` through the sphere map's SIMD batch path
    /// ([`Batches::sample_batch_split`]) and the batch radiance lookup
    /// ([`EnvironmentMap::eval_batch`]): sample k's direction goes to `dirs[k]`, its density to
    /// `pdf[k]` and the radiance in that direction to `rgb[k]`. Allocates nothing.
    ///
    /// The directions and densities equal the scalar `sample`'s up to the batch path's round-off
    /// (directions within a few 1e-16, densities within 1e-12 relative; `crates/gonio/tests/batch.rs`);
    /// `rgb[k]` is exactly `eval(dirs[k])` (bit for bit), so a direction within round-off of a
    /// pixel edge may read the neighbouring pixel where the scalar `sample` reads the other.
    ///
    /// # Panics
    /// If the slices differ in length (a programming error, not an input error).
    pub fn sample_batch_rgb(
        &self,
        u: &[Point2],
        dirs: &mut [Vec3],
        pdf: &mut [f64],
        rgb: &mut [[f32; 3]],
    ) {
        assert!(
            u.len() == dirs.len() && u.len() == pdf.len() && u.len() == rgb.len(),
            "sample_batch_rgb: slices differ in length"
        );
        self.map.sample_batch_split(u, dirs, pdf);
        self.eval_batch(dirs, rgb);
    }

    /// [`EnvironmentMap::eval`] of every direction of `dirs` into `rgb`, **bit for bit**, with
    /// the angles of the directions computed on the SIMD lanes of the batch kernels (the scalar
    /// `eval` computes the same operations one direction at a time). Allocates nothing.
    ///
    /// # Panics
    /// If the slices differ in length (a programming error, not an input error).
    pub fn eval_batch(&self, dirs: &[Vec3], rgb: &mut [[f32; 3]]) {
        self.eval_batch_with(dirs, self.options.lookup, rgb)
    }

    /// [`EnvironmentMap::eval_batch`] by the given lookup ([`EnvironmentMap::eval_with`] of each
    /// direction, bit for bit).
    ///
    /// # Panics
    /// If the slices differ in length (a programming error, not an input error).
    pub fn eval_batch_with(&self, dirs: &[Vec3], lookup: Lookup, rgb: &mut [[f32; 3]]) {
        self.radiance.eval_batch_with(dirs, lookup, rgb)
    }

    /// Density of [`EnvironmentMap::sample`] at a direction, per steradian.
    pub fn pdf(&self, direction: Vec3) -> f64 {
        self.map.pdf(direction)
    }

    /// The point of the unit square that [`EnvironmentMap::sample`] maps to `direction`.
    ///
    /// # Errors
    /// As [`Sampler::invert`].
    pub fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        self.map.invert(direction)
    }

    /// The image's RGB radiance in `direction` (normalised first; black for a zero or non-finite
    /// vector), by the map's [`Lookup`].
    pub fn eval(&self, direction: Vec3) -> [f32; 3] {
        self.eval_with(direction, self.options.lookup)
    }

    /// The image's RGB radiance in `direction` by the given lookup. The direction's angles are
    /// [`crate::mapping::simd::math::angles`] (branch-free `atan2`, within a few ulps of
    /// [`crate::sampler::spherical`]), the functions the batch lookup computes on its lanes.
    pub fn eval_with(&self, direction: Vec3, lookup: Lookup) -> [f32; 3] {
        self.radiance.eval_with(direction, lookup)
    }

    /// The total power of the weight over the sphere, ∫ weight dω (the bilinear diagram's
    /// integral), e.g. the luminance integrated over solid angle.
    pub fn power(&self) -> f64 {
        self.map.target_power()
    }
}

/// An image's radiance lookups, the part of an environment light that the float64 and the float32
/// environment maps share: the image and the mean colours of its first and last rows.
#[derive(Debug, Clone)]
pub(crate) struct Radiance {
    pub(crate) image: Image,
    /// Mean RGB of the first and last rows (the poles' colour for bilinear lookups).
    pole_rgb: [[f32; 3]; 2],
}

impl Radiance {
    pub(crate) fn new(image: Image) -> Self {
        let h = image.height();
        let pole_rgb = [row_mean_rgb(&image, 0), row_mean_rgb(&image, h - 1)];
        Radiance { image, pole_rgb }
    }

    /// [`EnvironmentMap::eval_batch_with`].
    pub(crate) fn eval_batch_with(&self, dirs: &[Vec3], lookup: Lookup, rgb: &mut [[f32; 3]]) {
        assert_eq!(dirs.len(), rgb.len(), "eval_batch: slices differ in length");
        self.eval_from(|k| dirs[k], lookup, rgb)
    }

    /// [`Radiance::eval_batch_with`] of the float32 directions `dir[·][k]` widened to f64 (the
    /// same operations on the same f64 values, without a copy of the widened directions).
    pub(crate) fn eval_soa_f32(&self, dir: [&[f32]; 3], lookup: Lookup, rgb: &mut [[f32; 3]]) {
        let n = rgb.len();
        assert!(
            dir.iter().all(|c| c.len() == n),
            "eval_soa: slices differ in length"
        );
        let [x, y, z] = dir;
        self.eval_from(
            |k| [f64::from(x[k]), f64::from(y[k]), f64::from(z[k])],
            lookup,
            rgb,
        )
    }

    /// The radiance of direction `dir_at(k)` into `rgb[k]` for every k < `rgb.len()`, in chunks
    /// through the SIMD angles kernel.
    #[inline(always)]
    fn eval_from(&self, dir_at: impl Fn(usize) -> Vec3, lookup: Lookup, rgb: &mut [[f32; 3]]) {
        const CHUNK: usize = 256;
        let backend = crate::mapping::simd::Backend::detect();
        for (j, rgb) in rgb.chunks_mut(CHUNK).enumerate() {
            let n = rgb.len();
            let mut b = [[0.0f64; CHUNK]; 3];
            let mut ok = [false; CHUNK];
            for k in 0..n {
                let u = normalize(dir_at(j * CHUNK + k));
                ok[k] = u.is_some();
                let u = u.unwrap_or([0.0, 0.0, 1.0]);
                b[0][k] = u[0];
                b[1][k] = u[1];
                b[2][k] = u[2];
            }
            let (mut theta, mut phi) = ([0.0f64; CHUNK], [0.0f64; CHUNK]);
            crate::mapping::simd::dispatch::angles(
                backend,
                [&b[0][..n], &b[1][..n], &b[2][..n]],
                [&mut theta[..n], &mut phi[..n]],
            );
            if lookup == Lookup::Nearest {
                // `lookup_angles`' nearest pixel, inlined (the same operations).
                let (w, h) = (self.image.width(), self.image.height());
                let px = self.image.rgb();
                for k in 0..n {
                    let s = phi_to_s(phi[k]);
                    let t = theta[k] / PI;
                    let x = ((s * w as f64) as usize).min(w - 1);
                    let y = ((t * h as f64) as usize).min(h - 1);
                    let i = 3 * (y * w + x);
                    rgb[k] = if ok[k] {
                        [px[i], px[i + 1], px[i + 2]]
                    } else {
                        [0.0; 3]
                    };
                }
            } else {
                for k in 0..n {
                    rgb[k] = if ok[k] {
                        self.lookup_angles(theta[k], phi[k], lookup)
                    } else {
                        [0.0; 3]
                    };
                }
            }
        }
    }

    /// [`EnvironmentMap::eval_with`].
    pub(crate) fn eval_with(&self, direction: Vec3, lookup: Lookup) -> [f32; 3] {
        let Some(d) = normalize(direction) else {
            return [0.0; 3];
        };
        let (theta, phi) = crate::mapping::simd::math::angles(d);
        self.lookup_angles(theta, phi, lookup)
    }

    /// The radiance at polar angle `theta` ∈ [0, π] and azimuth `phi` ∈ [0, 2π) by `lookup`.
    #[inline]
    fn lookup_angles(&self, theta: f64, phi: f64, lookup: Lookup) -> [f32; 3] {
        let (w, h) = (self.image.width(), self.image.height());
        let s = phi_to_s(phi);
        let t = theta / PI;
        match lookup {
            Lookup::Nearest => {
                let x = ((s * w as f64) as usize).min(w - 1);
                let y = ((t * h as f64) as usize).min(h - 1);
                self.image.pixel(x, y)
            }
            Lookup::Bilinear => {
                // Columns: centres at s = (c + ½)/W, wrapping.
                let xs = s * w as f64 - 0.5;
                let x0f = xs.floor();
                let b = xs - x0f;
                let x0 = (x0f as isize).rem_euclid(w as isize) as usize;
                let x1 = (x0 + 1) % w;
                let row = |y: usize| -> [f64; 3] {
                    let p = self.image.pixel(x0, y);
                    let q = self.image.pixel(x1, y);
                    [0, 1, 2].map(|c| f64::from(p[c]) * (1.0 - b) + f64::from(q[c]) * b)
                };
                let ys = t * h as f64 - 0.5;
                let mix = |a: [f64; 3], c: [f64; 3], f: f64| -> [f32; 3] {
                    [0, 1, 2].map(|k| (a[k] * (1.0 - f) + c[k] * f) as f32)
                };
                let pole = |k: usize| self.pole_rgb[k].map(f64::from);
                if ys < 0.0 {
                    // Between the zenith (ys = −½) and the first row's centre.
                    mix(pole(0), row(0), ((ys + 0.5) * 2.0).clamp(0.0, 1.0))
                } else if ys >= (h - 1) as f64 {
                    mix(
                        row(h - 1),
                        pole(1),
                        ((ys - (h - 1) as f64) * 2.0).clamp(0.0, 1.0),
                    )
                } else {
                    let y0 = ys as usize;
                    mix(row(y0), row(y0 + 1), ys - y0 as f64)
                }
            }
        }
    }
}

/// The diagram of the image's weights under `options` (see the module documentation), with
/// the warnings of negative weights and of a compensation that left nothing.
fn weight_diagram(
    image: &Image,
    options: &EnvOptions,
    warnings: &mut Vec<String>,
) -> Result<Diagram, EnvMapError> {
    let (w, h) = (image.width(), image.height());
    let rgb = image.rgb();
    let weight_name;
    let mut weights: Vec<f64> = match &options.weight {
        Weight::Luminance => {
            weight_name = "luminance".to_string();
            rgb.chunks_exact(3)
                .map(|p| f64::from(luminance([p[0], p[1], p[2]])))
                .collect()
        }
        Weight::Channel(c) => {
            if *c > 2 {
                return Err(EnvMapError::BadOption(format!(
                    "channel {c} does not exist (0 = R, 1 = G, 2 = B)"
                )));
            }
            weight_name = ["red", "green", "blue"][*c].to_string();
            rgb.chunks_exact(3).map(|p| f64::from(p[*c])).collect()
        }
        Weight::Custom(v) => {
            weight_name = "custom weight".to_string();
            if v.len() != w * h {
                return Err(EnvMapError::BadOption(format!(
                    "{} custom weights for an image of {w} × {h} pixels",
                    v.len()
                )));
            }
            if let Some(k) = v.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
                return Err(EnvMapError::BadOption(format!(
                    "custom weight of pixel (x {}, y {}) is {} (must be finite and ≥ 0)",
                    k % w,
                    k / w,
                    v[k]
                )));
            }
            v.iter().map(|&x| f64::from(x)).collect()
        }
    };
    let negative = weights.iter().filter(|&&x| x < 0.0).count();
    if negative > 0 {
        warnings.push(format!(
            "{negative} pixels have a negative {weight_name}; they are weighted as 0 (their radiance is kept)"
        ));
        for x in &mut weights {
            *x = x.max(0.0);
        }
    }
    if weights.iter().all(|&x| x == 0.0) {
        return Err(EnvMapError::Black {
            weight: weight_name,
        });
    }
    if options.mis_compensation {
        let mean = solid_angle_mean(&weights, w, h);
        let comp: Vec<f64> = weights.iter().map(|&x| (x - mean).max(0.0)).collect();
        if comp.iter().any(|&x| x > 0.0) {
            weights = comp;
        } else {
            warnings.push(
                "MIS compensation left no pixel above the mean (a constant map): the plain weight is used".into(),
            );
        }
    }
    Ok(build_diagram(&weights, w, h)?)
}

/// The solid-angle mean of per-pixel weights over the sphere: Σ w·ΔΩ / 4π, ΔΩ of row r
/// = (cos θ_r − cos θ_{r+1})·2π/W.
pub(crate) fn solid_angle_mean(weights: &[f64], w: usize, h: usize) -> f64 {
    let mut sum = 0.0;
    for r in 0..h {
        let (a, b) = (PI * r as f64 / h as f64, PI * (r + 1) as f64 / h as f64);
        let omega = (a.cos() - b.cos()) * TAU / w as f64;
        let row: f64 = weights[r * w..(r + 1) * w].iter().sum();
        sum += row * omega;
    }
    sum / (4.0 * PI)
}

fn row_mean_rgb(image: &Image, y: usize) -> [f32; 3] {
    let mut s = [0f64; 3];
    for x in 0..image.width() {
        let p = image.pixel(x, y);
        for c in 0..3 {
            s[c] += f64::from(p[c]);
        }
    }
    s.map(|v| (v / image.width() as f64) as f32)
}

/// The diagram of per-pixel weights (row-major, row 0 at the top): meridians at the column
/// centres (sorted by φ), parallels at 0, the row centres and π, the poles the rows' means.
pub(crate) fn build_diagram(weights: &[f64], w: usize, h: usize) -> Result<Diagram, DiagramError> {
    let n = h + 2;
    let mut theta = Vec::with_capacity(n);
    theta.push(0.0);
    theta.extend((0..h).map(|r| PI * (r as f64 + 0.5) / h as f64));
    theta.push(PI);
    // φ_c = π − 2π(c + ½)/W decreases with c: meridian order is a reversed rotation of columns.
    let mut cols: Vec<(f64, usize)> = (0..w).map(|c| (column_phi(c, w), c)).collect();
    cols.sort_by(|a, b| a.0.total_cmp(&b.0));
    let phi: Vec<f64> = cols.iter().map(|p| p.0).collect();
    let mean = |r: usize| weights[r * w..(r + 1) * w].iter().sum::<f64>() / w as f64;
    let (north, south) = (mean(0), mean(h - 1));
    // The transpose from the image's rows to the diagram's meridians, in tiles of TILE meridians
    // so that a tile's destinations stay in cache while the rows are read (a plain column walk
    // reads one cache line per value, W × 8 bytes apart).
    const TILE: usize = 64;
    let mut values = vec![0.0; w * n];
    for (tile, tile_cols) in cols.chunks(TILE).enumerate() {
        let k0 = tile * TILE;
        for (dk, _) in tile_cols.iter().enumerate() {
            let k = k0 + dk;
            values[k * n] = north;
            values[k * n + n - 1] = south;
        }
        for r in 0..h {
            let row = &weights[r * w..(r + 1) * w];
            for (dk, &(_, c)) in tile_cols.iter().enumerate() {
                values[(k0 + dk) * n + 1 + r] = row[c];
            }
        }
    }
    Diagram::new(theta, phi, values)
}

/// The environment map behind the one sampler contract (the HDS sphere map of its weight).
impl Sampler for EnvironmentMap {
    fn name(&self) -> &'static str {
        "envmap"
    }
    fn domain(&self) -> crate::Domain {
        crate::Domain::Sphere
    }
    fn sample(&self, u: Point2) -> crate::Sample {
        self.map.sample(u)
    }
    fn pdf(&self, direction: Vec3) -> f64 {
        self.map.pdf(direction)
    }
    fn invert(&self, direction: Vec3) -> Result<Point2, InvertError> {
        self.map.invert(direction)
    }
    fn target_pdf(&self, direction: Vec3) -> f64 {
        self.map.target_pdf(direction)
    }
    fn memory_bytes(&self) -> usize {
        self.memory_bytes_beyond_image()
    }
    fn target_power(&self) -> f64 {
        self.map.target_power()
    }
    fn batch(&self, job: crate::batch::Batch<'_>) {
        self.map.batch(job)
    }
}

#[cfg(test)]
mod tests;
