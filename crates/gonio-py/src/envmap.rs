//! `gonio.EnvMap`: an environment map (`.hdr`, `.exr`, `.pfm` lat-long image) sampled by the HDS
//! sphere map, with numpy batches (frame and lookups: docs/ENVMAPS.md).

use crate::sampler::PySampler;
use crate::{arrays, detached, no_panic, GonioError, InputError};
use gonio::envmap::{EnvOptions, EnvironmentMap, Lookup, Weight};
use gonio::image::Image;
use gonio::Sampler;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

/// An environment light: an image's luminance as a density per steradian over the sphere,
/// sampled exactly (``sample``, ``pdf``, ``invert``) and its RGB radiance (``eval``).
///
/// ``EnvMap(path, lookup="nearest", mis_compensation=False, weight="luminance")``. Directions
/// are gonio's frame: the image's top row is +z, its centre column +x (docs/ENVMAPS.md).
/// ``weight`` is what the density is proportional to: ``"luminance"`` (Rec. 709 Y),
/// ``"red"``/``"green"``/``"blue"`` or 0/1/2 (one channel), or an array of shape
/// (height, width), row 0 at the top, finite and ≥ 0 (taken as float32, as the C ABI takes it).
#[pyclass(name = "EnvMap", module = "gonio", frozen)]
pub struct PyEnvMap {
    env: EnvironmentMap,
}

#[pymethods]
impl PyEnvMap {
    #[new]
    #[pyo3(signature = (path, lookup = "nearest", mis_compensation = false, weight = None))]
    fn new(
        path: std::path::PathBuf,
        lookup: &str,
        mis_compensation: bool,
        weight: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let lookup = match lookup {
            "nearest" => Lookup::Nearest,
            "bilinear" => Lookup::Bilinear,
            other => {
                return Err(InputError::new_err(format!(
                    "lookup: {other:?} is not \"nearest\" or \"bilinear\""
                )))
            }
        };
        let (weight, custom_shape) = parse_weight(weight)?;
        let img = no_panic("EnvMap", || {
            Image::read(&path).map_err(|e| format!("{}: {e}", path.display()))
        })?
        .map_err(GonioError::new_err)?;
        if let Some([h, w]) = custom_shape {
            if (h, w) != (img.height(), img.width()) {
                return Err(InputError::new_err(format!(
                    "weight: an array of shape ({h}, {w}) for {}, an image of {} × {} pixels (expected shape ({}, {}))",
                    path.display(),
                    img.width(),
                    img.height(),
                    img.height(),
                    img.width()
                )));
            }
        }
        let options = EnvOptions {
            weight,
            lookup,
            mis_compensation,
        };
        let env = no_panic("EnvMap", || {
            EnvironmentMap::with_options(img, options)
                .map_err(|e| format!("{}: {e}", path.display()))
        })?
        .map_err(GonioError::new_err)?;
        Ok(Self { env })
    }

    /// Image width in pixels.
    #[getter]
    fn width(&self) -> usize {
        self.env.image().width()
    }

    /// Image height in pixels.
    #[getter]
    fn height(&self) -> usize {
        self.env.image().height()
    }

    /// ∫ luminance dω over the sphere (image unit × sr).
    #[getter]
    fn power(&self) -> f64 {
        self.env.power()
    }

    /// What the density is proportional to: "luminance", "red", "green", "blue" or "custom".
    #[getter]
    fn weight(&self) -> &'static str {
        match self.env.options().weight {
            Weight::Luminance => "luminance",
            Weight::Channel(0) => "red",
            Weight::Channel(1) => "green",
            Weight::Channel(_) => "blue",
            Weight::Custom(_) => "custom",
        }
    }

    /// How ``eval`` (and ``sample``'s rgb) read the image: "nearest" or "bilinear".
    #[getter]
    fn lookup(&self) -> &'static str {
        match self.env.options().lookup {
            Lookup::Nearest => "nearest",
            Lookup::Bilinear => "bilinear",
        }
    }

    /// Bytes held beyond the image (the map's tables; docs/ENVMAPS.md, "Build and memory").
    #[getter]
    fn memory_bytes(&self) -> usize {
        self.env.memory_bytes_beyond_image()
    }

    /// ``sampler(kind="hds", *, resolution=None)``: a ``gonio.Sampler`` over this map's weight
    /// (directions only, no radiance; float32 arrays reach its float32 batch calls):
    ///
    /// * ``"hds"``: this map's own HDS sphere map (the same samples, pdf and inverse as
    ///   ``EnvMap``; a copy of the map);
    /// * ``"latlong"``: the lat-long piecewise-constant peer (pbrt-v3's ``InfiniteAreaLight``);
    /// * ``"pbrt-v4"``: the pbrt-v4-style peer, the weight resampled on a ``resolution``² square
    ///   equal-area image (default round(√(W·H))) sampled piecewise-constant.
    ///
    /// Raises BuildError when the peer cannot be built.
    #[pyo3(signature = (kind = "hds", *, resolution = None))]
    fn sampler(
        &self,
        py: Python<'_>,
        kind: &str,
        resolution: Option<usize>,
    ) -> PyResult<PySampler> {
        if resolution.is_some() && kind != "pbrt-v4" {
            return Err(InputError::new_err(format!(
                "resolution: only the \"pbrt-v4\" sampler takes one, not {kind:?}"
            )));
        }
        if resolution == Some(0) {
            return Err(InputError::new_err("resolution: must be at least 1"));
        }
        let env = &self.env;
        let built: Result<(Box<dyn Sampler>, &'static str), String> =
            detached(py, "EnvMap.sampler", || match kind {
                "hds" => Ok((Box::new(env.clone()) as Box<dyn Sampler>, "hds")),
                "latlong" => env
                    .latlong_peer()
                    .map(|s| (Box::new(s) as Box<dyn Sampler>, "latlong"))
                    .map_err(|e| e.to_string()),
                "pbrt-v4" => env
                    .pbrt_v4_peer(resolution)
                    .map(|s| (Box::new(s) as Box<dyn Sampler>, "pbrt-v4"))
                    .map_err(|e| e.to_string()),
                other => Err(format!(
                    "kind: {other:?} is not \"hds\", \"latlong\" or \"pbrt-v4\""
                )),
            })?;
        match built {
            Ok((s, name)) => Ok(PySampler::from_sampler(s, name)),
            Err(e) if e.starts_with("kind:") => Err(InputError::new_err(e)),
            Err(e) => Err(crate::BuildError::new_err(format!(
                "EnvMap.sampler({kind:?}): {e}"
            ))),
        }
    }

    /// What was repaired or ignored while reading and building.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.env.warnings().to_vec()
    }

    /// ``sample(u)`` for u of shape (n, 2) in [0, 1]²: (directions (n, 3), pdf (n,), rgb (n, 3)).
    #[allow(clippy::type_complexity)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        let rows = arrays::rows::<2>(u, "u")?;
        let pts = rows.as_slice();
        if let Some(k) = pts
            .iter()
            .position(|p| !(0.0..=1.0).contains(&p[0]) || !(0.0..=1.0).contains(&p[1]))
        {
            return Err(InputError::new_err(format!(
                "u: row {k}: point ({}, {}) is outside the unit square [0, 1]²",
                pts[k][0], pts[k][1]
            )));
        }
        let env = &self.env;
        let (d, p, c) = detached(py, "EnvMap.sample", || {
            // The sphere map's SIMD batch path, then the radiance of each direction.
            let n = pts.len();
            let mut d: Vec<[f64; 3]> = arrays::try_vec(n, "directions")?;
            d.resize(n, [0.0; 3]);
            let mut p = arrays::try_vec(n, "pdf")?;
            p.resize(n, 0.0);
            let mut rgb: Vec<[f32; 3]> = arrays::try_vec(n, "rgb")?;
            rgb.resize(n, [0.0; 3]);
            env.sample_batch_rgb(&pts, &mut d, &mut p, &mut rgb);
            let mut c = arrays::try_vec(3 * n, "rgb")?;
            c.extend(rgb.iter().flat_map(|v| v.map(f64::from)));
            PyResult::Ok((d.into_flattened(), p, c))
        })??;
        Ok((
            arrays::new_2d(py, &d, 3)?,
            arrays::new_1d(py, &p)?,
            arrays::new_2d(py, &c, 3)?,
        ))
    }

    /// ``pdf(directions)`` for directions of shape (n, 3): the density per steradian.
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let rows = arrays::rows::<3>(directions, "directions")?;
        let ds = rows.as_slice();
        let env = &self.env;
        let p = detached(py, "EnvMap.pdf", || {
            let mut p = arrays::try_vec(ds.len(), "pdf")?;
            p.resize(ds.len(), 0.0);
            env.pdf_batch(&ds, &mut p);
            PyResult::Ok(p)
        })??;
        arrays::new_1d(py, &p)
    }

    /// ``eval(directions)``: the RGB radiance (n, 3) by the map's lookup.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows = arrays::rows::<3>(directions, "directions")?;
        let ds = rows.as_slice();
        let env = &self.env;
        let c = detached(py, "EnvMap.eval", || {
            // The batch lookup (the angles on SIMD lanes): `EnvironmentMap::eval` bit for bit.
            let mut rgb: Vec<[f32; 3]> = arrays::try_vec(ds.len(), "rgb")?;
            rgb.resize(ds.len(), [0.0; 3]);
            env.eval_batch(&ds, &mut rgb);
            let mut c = arrays::try_vec(3 * ds.len(), "rgb")?;
            c.extend(rgb.iter().flat_map(|v| v.map(f64::from)));
            PyResult::Ok(c)
        })??;
        arrays::new_2d(py, &c, 3)
    }

    /// ``invert(directions)``: the points (n, 2) of the square that ``sample`` maps to them
    /// (NaN where the density is 0 or the direction is not a finite non-zero vector).
    fn invert<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows = arrays::rows::<3>(directions, "directions")?;
        let ds = rows.as_slice();
        let env = &self.env;
        let u = detached(py, "EnvMap.invert", || {
            let mut res = arrays::try_vec(ds.len(), "u")?;
            res.resize(ds.len(), Ok([0.0; 2]));
            env.invert_batch(&ds, &mut res);
            let mut u = arrays::try_vec(2 * ds.len(), "u")?;
            u.extend(res.into_iter().flat_map(|r| r.unwrap_or([f64::NAN; 2])));
            PyResult::Ok(u)
        })??;
        arrays::new_2d(py, &u, 2)
    }
}

/// The `weight` argument of `EnvMap`: the library's [`Weight`] and, for an array, its shape
/// (height, width).
fn parse_weight(weight: Option<&Bound<'_, PyAny>>) -> PyResult<(Weight, Option<[usize; 2]>)> {
    let Some(w) = weight else {
        return Ok((Weight::Luminance, None));
    };
    if let Ok(name) = w.extract::<String>() {
        let weight = match name.as_str() {
            "luminance" => Weight::Luminance,
            "red" => Weight::Channel(0),
            "green" => Weight::Channel(1),
            "blue" => Weight::Channel(2),
            other => {
                return Err(InputError::new_err(format!(
                    "weight: {other:?} is not \"luminance\", \"red\", \"green\", \"blue\", a channel 0-2 or an array"
                )))
            }
        };
        return Ok((weight, None));
    }
    if !w.hasattr("shape")? && !w.is_instance_of::<pyo3::types::PyList>() {
        if let Ok(c) = w.extract::<i64>() {
            return match c {
                0..=2 => Ok((Weight::Channel(c as usize), None)),
                _ => Err(InputError::new_err(format!(
                    "weight: channel {c} does not exist (0 = red, 1 = green, 2 = blue)"
                ))),
            };
        }
    }
    let (v, [h, wd]) = arrays::table(w, "weight")?;
    if let Some(k) = v.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
        return Err(InputError::new_err(format!(
            "weight: row {}, column {}: {} (weights must be finite and ≥ 0)",
            k / wd.max(1),
            k % wd.max(1),
            v[k]
        )));
    }
    if let Some(k) = v.iter().position(|&x| !((x as f32).is_finite())) {
        return Err(InputError::new_err(format!(
            "weight: row {}, column {}: {} does not fit in float32",
            k / wd.max(1),
            k % wd.max(1),
            v[k]
        )));
    }
    Ok((
        Weight::Custom(v.iter().map(|&x| x as f32).collect()),
        Some([h, wd]),
    ))
}
