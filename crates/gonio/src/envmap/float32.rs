//! The float32 environment map: an environment light sampled by the float32 map of its HDS
//! sphere map, for renderers that work in float32 (as Mitsuba 3's and pbrt-v4's lights do).
//!
//! [`Float32EnvironmentMap`] holds the image and the [`Float32Map`] of the
//! [`EnvironmentMap`]'s sphere map, and nothing of the float64 map: its tables are the float64
//! tables rounded to f32 (the nodal densities and cumulative masses take 4 bytes per pixel each
//! instead of 8), so it holds about 10 bytes per pixel beyond the image against about 18 for the
//! float64 map (`docs/ENVMAPS.md`).
//!
//! **Contract**: the float32 map's, stated and tested in [`crate::mapping::float32`] (and in
//! `tests/float32_map.rs`): the pdf returned with a sample is the float32 map's exact density at
//! the returned direction to 8 f32 ulps plus a conditioning term where the density is steep;
//! `pdf_soa` at a sample's direction agrees with the sample's pdf to the same bound; the inverse
//! round-trips to 1e-5; the bits do not depend on the backend, the slice length or the threads.
//! This type's samples, densities and inverses are those of
//! [`EnvironmentMap::map`]`().float32_map()` bit for bit (tested), so the float32 map's contract
//! is this type's. The radiance is [`EnvironmentMap::eval_with`] of the f32 direction widened to
//! f64, bit for bit: the same pixel as the float64 map reads for that direction.
//!
//! The frame, the weights, the lookups and the MIS compensation are the [`EnvironmentMap`]'s (see
//! [the module documentation](super)).

use super::{EnvMapError, EnvOptions, EnvironmentMap, Lookup, Radiance, Weight};
use crate::image::Image;
use crate::mapping::{Float32Map, Float32MapError};

/// An environment light sampled by a float32 map (see docs/ENVMAPS.md).
///
/// ```
/// use gonio::envmap::Float32EnvironmentMap;
/// use gonio::image::Image;
/// // A constant sky: the density is uniform, 1/(4π), to float32 round-off.
/// let sky = Image::constant(16, 8, [1.0, 1.0, 1.0]).unwrap();
/// let env = Float32EnvironmentMap::new(sky, Default::default()).unwrap();
/// let (u, v) = ([0.3f32, 0.9], [0.6f32, 0.2]);
/// let (mut x, mut y, mut z, mut pdf) = ([0f32; 2], [0f32; 2], [0f32; 2], [0f32; 2]);
/// let mut rgb = [[0f32; 3]; 2];
/// env.sample_soa(&u, &v, [&mut x, &mut y, &mut z], &mut pdf, &mut rgb);
/// let uniform = 1.0 / (4.0 * std::f32::consts::PI);
/// assert!((pdf[0] - uniform).abs() <= 1e-6 * uniform);
/// assert_eq!(rgb[1], [1.0, 1.0, 1.0]);
/// ```
#[derive(Debug, Clone)]
pub struct Float32EnvironmentMap {
    radiance: Radiance,
    map: Float32Map,
    options: EnvOptions,
    warnings: Vec<String>,
    power: f64,
}

impl EnvironmentMap {
    /// This environment light with its float64 tables replaced by their float32 map
    /// ([`Float32EnvironmentMap`]); the float64 map is dropped.
    ///
    /// # Errors
    /// [`Float32MapError::TooLarge`] for a grid beyond the float32 kernels' index limits (not
    /// reached by images within [`crate::image::MAX_SIDE`]).
    pub fn into_float32(self) -> Result<Float32EnvironmentMap, Float32MapError> {
        let power = self.map.target_power();
        // Each hemisphere's float64 tables are dropped as soon as its float32 tables are made.
        let map = self.map.into_float32_map()?;
        Ok(Float32EnvironmentMap {
            radiance: self.radiance,
            map,
            options: self.options,
            warnings: self.warnings,
            power,
        })
    }
}

impl EnvironmentMap {
    /// The bytes [`EnvironmentMap::into_float32`] would hold beyond the image
    /// ([`Float32EnvironmentMap::memory_bytes_beyond_image`]), without consuming this map and
    /// without making the float32 map (counted from the float64 tables).
    ///
    /// # Errors
    /// As [`EnvironmentMap::into_float32`].
    pub fn float32_memory_bytes_beyond_image(&self) -> Result<usize, Float32MapError> {
        let custom = match &self.options.weight {
            Weight::Custom(v) => 4 * v.len(),
            _ => 0,
        };
        Ok(self.map.float32_map_bytes()? + custom + std::mem::size_of::<Float32EnvironmentMap>())
    }
}

impl Float32EnvironmentMap {
    /// The float32 environment light of `image`: [`EnvironmentMap::with_options`], then
    /// [`EnvironmentMap::into_float32`].
    ///
    /// # Errors
    /// As [`EnvironmentMap::with_options`]; [`EnvMapError::Float32`] for a grid beyond the
    /// float32 kernels' limits (not reached by images within [`crate::image::MAX_SIDE`]).
    pub fn new(image: Image, options: EnvOptions) -> Result<Self, EnvMapError> {
        Ok(EnvironmentMap::with_options(image, options)?.into_float32()?)
    }

    /// The image.
    pub fn image(&self) -> &Image {
        &self.radiance.image
    }

    /// The float32 map.
    pub fn map(&self) -> &Float32Map {
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

    /// ∫ weight dω over the sphere (the float64 map's [`EnvironmentMap::power`], kept).
    pub fn power(&self) -> f64 {
        self.power
    }

    /// Bytes held beyond the image: the float32 map ([`Float32Map::memory_bytes`]), the
    /// caller's weights when [`Weight::Custom`] and the struct itself (the warnings' text
    /// excluded).
    pub fn memory_bytes_beyond_image(&self) -> usize {
        let custom = match &self.options.weight {
            Weight::Custom(v) => 4 * v.len(),
            _ => 0,
        };
        self.map.memory_bytes() + custom + std::mem::size_of::<Self>()
    }

    /// Maps the points `(u[k], v[k])` of the unit square to directions `dir[·][k]`, their
    /// densities `pdf[k]` (per steradian) and the radiance there `rgb[k]` (by the map's
    /// [`Lookup`]). Allocates nothing.
    ///
    /// # Panics
    /// If the slices differ in length (a programming error, not an input error).
    pub fn sample_soa(
        &self,
        u: &[f32],
        v: &[f32],
        dir: [&mut [f32]; 3],
        pdf: &mut [f32],
        rgb: &mut [[f32; 3]],
    ) {
        assert_eq!(u.len(), rgb.len(), "sample_soa: slices differ in length");
        let [x, y, z] = dir;
        self.map.sample_soa(u, v, [&mut *x, &mut *y, &mut *z], pdf);
        self.eval_soa_with([&*x, &*y, &*z], self.options.lookup, rgb);
    }

    /// The density (per steradian) at each direction; 0 outside the domain.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn pdf_soa(&self, dir: [&[f32]; 3], pdf: &mut [f32]) {
        self.map.pdf_soa(dir, pdf)
    }

    /// The point of the unit square of each direction; NaN in both coordinates where the
    /// density is 0 or the direction is not finite (the rule of every sampler's inverse).
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn invert_soa(&self, dir: [&[f32]; 3], uv: [&mut [f32]; 2]) {
        self.map.invert_soa_nonzero(dir, uv)
    }

    /// The image's RGB radiance in each direction by the map's [`Lookup`]:
    /// [`EnvironmentMap::eval`] of the direction widened to f64, bit for bit.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn eval_soa(&self, dir: [&[f32]; 3], rgb: &mut [[f32; 3]]) {
        self.eval_soa_with(dir, self.options.lookup, rgb)
    }

    /// [`Float32EnvironmentMap::eval_soa`] by the given lookup.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn eval_soa_with(&self, dir: [&[f32]; 3], lookup: Lookup, rgb: &mut [[f32; 3]]) {
        self.radiance.eval_soa_f32(dir, lookup, rgb)
    }

    /// The radiance of float64 directions ([`EnvironmentMap::eval_batch`], bit for bit; the
    /// float32 directions of [`Float32EnvironmentMap::eval_soa`] widened give the same values).
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn eval_batch(&self, dirs: &[[f64; 3]], rgb: &mut [[f32; 3]]) {
        self.radiance
            .eval_batch_with(dirs, self.options.lookup, rgb)
    }

    /// The radiance in one direction ([`Float32EnvironmentMap::eval_soa`] of one).
    pub fn eval(&self, direction: [f32; 3]) -> [f32; 3] {
        self.radiance
            .eval_with(direction.map(f64::from), self.options.lookup)
    }
}
