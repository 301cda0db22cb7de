//! `gonio.EnvMap`: an environment map (`.hdr`, `.exr`, `.pfm` lat-long image) sampled by the HDS
//! sphere map, with numpy batches (frame and lookups: docs/ENVMAPS.md).

use crate::sampler::PySampler;
use crate::{arrays, detached, no_panic, GonioError, InputError};
use gonio::batch::PAR_CHUNK;
use gonio::envmap::{EnvOptions, EnvironmentMap, Float32EnvironmentMap, Lookup, Weight};
use gonio::image::Image;
use gonio::sampler::normalize;
use gonio::Batches;
use gonio::Sampler;
use pyo3::prelude::*;
use rayon::prelude::*;

/// An environment light: an image's luminance as a density per steradian over the sphere,
/// sampled exactly (``sample``, ``pdf``, ``invert``) and its RGB radiance (``eval``).
///
/// ``EnvMap(path, lookup="nearest", mis_compensation=False, weight="luminance",
/// precision="float64")``. Batches run on all threads with the GIL released; each output row
/// depends only on its input row, so results do not depend on the number of threads. Directions are gonio's frame: the image's top row is +z, its centre
/// column +x (docs/ENVMAPS.md). ``precision="float32"`` keeps only the map's float32 map (about
/// 10 bytes per pixel instead of 18; the float32 map's contract, docs/API.md) and returns float32
/// arrays.
/// ``weight`` is what the density is proportional to: ``"luminance"`` (Rec. 709 Y),
/// ``"red"``/``"green"``/``"blue"`` or 0/1/2 (one channel), or an array of shape
/// (height, width), row 0 at the top, finite and ≥ 0 (taken as float32, as the C ABI takes it).
#[pyclass(name = "EnvMap", module = "gonio", frozen)]
pub struct PyEnvMap {
    inner: Inner,
}

/// The float64 map, or the float32 one (`precision="float32"`). (Boxed: the two differ in size,
/// and one is built per object.)
enum Inner {
    F64(Box<EnvironmentMap>),
    F32(Box<Float32EnvironmentMap>),
}

impl PyEnvMap {
    fn image(&self) -> &Image {
        match &self.inner {
            Inner::F64(e) => e.image(),
            Inner::F32(e) => e.image(),
        }
    }
    fn options(&self) -> &EnvOptions {
        match &self.inner {
            Inner::F64(e) => e.options(),
            Inner::F32(e) => e.options(),
        }
    }
    /// The float64 map, or an InputError saying that `what` needs it.
    fn f64_map(&self, what: &str) -> PyResult<&EnvironmentMap> {
        match &self.inner {
            Inner::F64(e) => Ok(e),
            Inner::F32(_) => Err(InputError::new_err(format!(
                "{what}: needs the float64 map (EnvMap(..., precision=\"float64\"), the default)"
            ))),
        }
    }
}

#[pymethods]
impl PyEnvMap {
    /// The map's tables as one blob (docs/TABLES.md) in the environment map's lat-long frame,
    /// with its RGB image and radiance lookup as the image target: `precision` "float32" (the
    /// float32 map; the only one for an `EnvMap(..., precision="float32")`) or "float64".
    #[pyo3(signature = (precision = "float32"))]
    fn tables<'py>(
        &self,
        py: Python<'py>,
        precision: &str,
    ) -> PyResult<Bound<'py, pyo3::types::PyBytes>> {
        use gonio::mapping::blob::{write_envmap, write_envmap_float32, Precision};
        let p = crate::sampler::parse_precision(precision)?;
        let bytes = py.detach(|| match (&self.inner, p) {
            (Inner::F64(e), _) => write_envmap(e, p).map_err(|e| e.to_string()),
            (Inner::F32(e), Precision::F32) => write_envmap_float32(e).map_err(|e| e.to_string()),
            (Inner::F32(_), Precision::F64) => Err(
                "needs the float64 map (EnvMap(..., precision=\"float64\"), the default)".into(),
            ),
        });
        let bytes = bytes.map_err(|e| InputError::new_err(format!("EnvMap.tables: {e}")))?;
        Ok(pyo3::types::PyBytes::new(py, &bytes))
    }

    #[new]
    #[pyo3(signature = (path, lookup = "nearest", mis_compensation = false, weight = None, precision = "float64", *, progress = None))]
    fn new<'py>(
        py: Python<'py>,
        path: std::path::PathBuf,
        lookup: &str,
        mis_compensation: bool,
        weight: Option<&Bound<'py, PyAny>>,
        precision: &str,
        progress: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let progress = crate::progress::Progress::new(py, progress, "EnvMap")?;
        let float32 = match precision {
            "float64" => false,
            "float32" => true,
            other => {
                return Err(InputError::new_err(format!(
                    "precision: {other:?} is not \"float64\" or \"float32\""
                )))
            }
        };
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
        let name = path.display().to_string();
        progress.report("reading the file", 0.0)?;
        let bytes = crate::diagram::read_input(&path, &name, gonio::input::file::FileKind::Image)?;
        progress.report("decoding the image", 0.1)?;
        let img = no_panic("EnvMap", || {
            let format = gonio::image::ImageFormat::sniff(&bytes)
                .or_else(|| gonio::image::ImageFormat::from_path(&path));
            Image::from_bytes(&bytes, format).map_err(|e| format!("{name}: {e}"))
        })?
        .map_err(GonioError::new_err)?;
        drop(bytes);
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
        progress.report("building the map", 0.35)?;
        let inner = no_panic("EnvMap", || {
            let env = EnvironmentMap::with_options(img, options)
                .map_err(|e| format!("{}: {e}", path.display()))?;
            if float32 {
                env.into_float32()
                    .map(|e| Inner::F32(Box::new(e)))
                    .map_err(|e| format!("{}: {e}", path.display()))
            } else {
                Ok(Inner::F64(Box::new(env)))
            }
        })?
        .map_err(GonioError::new_err)?;
        progress.report("done", 1.0)?;
        Ok(Self { inner })
    }

    /// Image width in pixels.
    #[getter]
    fn width(&self) -> usize {
        self.image().width()
    }

    /// Image height in pixels.
    #[getter]
    fn height(&self) -> usize {
        self.image().height()
    }

    /// ∫ luminance dω over the sphere (image unit × sr).
    #[getter]
    fn power(&self) -> f64 {
        match &self.inner {
            Inner::F64(e) => e.power(),
            Inner::F32(e) => e.power(),
        }
    }

    /// "float64" or "float32": the precision of the map's tables and arithmetic, and of the
    /// arrays its methods return.
    #[getter]
    fn precision(&self) -> &'static str {
        match &self.inner {
            Inner::F64(_) => "float64",
            Inner::F32(_) => "float32",
        }
    }

    /// What the density is proportional to: "luminance", "red", "green", "blue" or "custom".
    #[getter]
    fn weight(&self) -> &'static str {
        self.options().weight.name()
    }

    /// How ``eval`` (and ``sample``'s rgb) read the image: "nearest" or "bilinear".
    #[getter]
    fn lookup(&self) -> &'static str {
        self.options().lookup.name()
    }

    /// Bytes held beyond the image (the map's tables; docs/ENVMAPS.md, "Build and memory").
    #[getter]
    fn memory_bytes(&self) -> usize {
        match &self.inner {
            Inner::F64(e) => e.memory_bytes_beyond_image(),
            Inner::F32(e) => e.memory_bytes_beyond_image(),
        }
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
        let env = self.f64_map("EnvMap.sampler")?;
        let other = |s: Box<dyn Sampler>| gonio::Built::Other(s);
        let built: Result<(gonio::Built<'static>, &'static str), String> =
            detached(py, "EnvMap.sampler", || match kind {
                // The environment map's own sphere map (its sampler is that map).
                "hds" => Ok((env.map().clone().into(), "hds")),
                "latlong" => env
                    .latlong_peer()
                    .map(|s| (other(Box::new(s)), "latlong"))
                    .map_err(|e| e.to_string()),
                "pbrt-v4" => env
                    .pbrt_v4_peer(resolution)
                    .map(|s| (other(Box::new(s)), "pbrt-v4"))
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
        match &self.inner {
            Inner::F64(e) => e.warnings().to_vec(),
            Inner::F32(e) => e.warnings().to_vec(),
        }
    }

    /// ``sample(u)`` for u of shape (n, 2) in [0, 1]²: (directions (n, 3), pdf (n,), rgb (n, 3)),
    /// float64 arrays, or float32 ones for a float32 map (its points are u rounded to float32).
    #[allow(clippy::type_complexity)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
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
        let n = pts.len();
        match &self.inner {
            Inner::F64(env) => {
                let (d, p, c) = detached(py, "EnvMap.sample", || {
                    // The sphere map's SIMD batch path, then the radiance of each direction.
                    let mut d: Vec<[f64; 3]> = arrays::try_vec(n, "directions")?;
                    d.resize(n, [0.0; 3]);
                    let mut p = arrays::try_vec(n, "pdf")?;
                    p.resize(n, 0.0);
                    let mut rgb: Vec<[f32; 3]> = arrays::try_vec(n, "rgb")?;
                    rgb.resize(n, [0.0; 3]);
                    d.par_chunks_mut(PAR_CHUNK)
                        .zip(p.par_chunks_mut(PAR_CHUNK))
                        .zip(rgb.par_chunks_mut(PAR_CHUNK))
                        .zip(pts.par_chunks(PAR_CHUNK))
                        .for_each(|(((d, p), c), u)| env.sample_batch_rgb(u, d, p, c));
                    let mut c = arrays::try_vec(3 * n, "rgb")?;
                    c.extend(rgb.iter().flat_map(|v| v.map(f64::from)));
                    PyResult::Ok((d.into_flattened(), p, c))
                })??;
                Ok((
                    arrays::new_2d(py, &d, 3)?.into_any(),
                    arrays::new_1d(py, &p)?.into_any(),
                    arrays::new_2d(py, &c, 3)?.into_any(),
                ))
            }
            Inner::F32(env) => {
                let (d, p, c) = detached(py, "EnvMap.sample", || {
                    let col = |k: usize| -> PyResult<Vec<f32>> {
                        let mut v = arrays::try_vec(n, "u")?;
                        v.extend(pts.iter().map(|p| p[k] as f32));
                        Ok(v)
                    };
                    let (u, v) = (col(0)?, col(1)?);
                    let [mut x, mut y, mut z, mut p] =
                        [zeros32(n)?, zeros32(n)?, zeros32(n)?, zeros32(n)?];
                    let mut rgb: Vec<[f32; 3]> = arrays::try_vec(n, "rgb")?;
                    rgb.resize(n, [0.0; 3]);
                    x.par_chunks_mut(PAR_CHUNK)
                        .zip(y.par_chunks_mut(PAR_CHUNK))
                        .zip(z.par_chunks_mut(PAR_CHUNK))
                        .zip(p.par_chunks_mut(PAR_CHUNK))
                        .zip(rgb.par_chunks_mut(PAR_CHUNK))
                        .zip(u.par_chunks(PAR_CHUNK).zip(v.par_chunks(PAR_CHUNK)))
                        .for_each(|(((((x, y), z), p), c), (u, v))| {
                            env.sample_soa(u, v, [x, y, z], p, c)
                        });
                    let mut d = arrays::try_vec(3 * n, "directions")?;
                    d.extend((0..n).flat_map(|k| [x[k], y[k], z[k]]));
                    PyResult::Ok((d, p, rgb.into_flattened()))
                })??;
                Ok((
                    arrays::new_2d(py, &d, 3)?.into_any(),
                    arrays::new_1d(py, &p)?.into_any(),
                    arrays::new_2d(py, &c, 3)?.into_any(),
                ))
            }
        }
    }

    /// ``pdf(directions)`` for directions of shape (n, 3): the density per steradian (float32
    /// for a float32 map, of the directions rounded to float32).
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rows = arrays::rows::<3>(directions, "directions")?;
        let ds = rows.as_slice();
        match &self.inner {
            Inner::F64(env) => {
                let p = detached(py, "EnvMap.pdf", || {
                    let mut p = arrays::try_vec(ds.len(), "pdf")?;
                    p.resize(ds.len(), 0.0);
                    p.par_chunks_mut(PAR_CHUNK)
                        .zip(ds.par_chunks(PAR_CHUNK))
                        .for_each(|(p, d)| env.pdf_batch(d, p));
                    PyResult::Ok(p)
                })??;
                Ok(arrays::new_1d(py, &p)?.into_any())
            }
            Inner::F32(env) => {
                let p = detached(py, "EnvMap.pdf", || {
                    let [x, y, z] = soa32(&ds)?;
                    let mut p = zeros32(ds.len())?;
                    p.par_chunks_mut(PAR_CHUNK)
                        .zip(x.par_chunks(PAR_CHUNK))
                        .zip(y.par_chunks(PAR_CHUNK).zip(z.par_chunks(PAR_CHUNK)))
                        .for_each(|((p, x), (y, z))| env.pdf_soa([x, y, z], p));
                    PyResult::Ok(p)
                })??;
                Ok(arrays::new_1d(py, &p)?.into_any())
            }
        }
    }

    /// ``eval(directions)``: the RGB radiance (n, 3) by the map's lookup (a float32 array for a
    /// float32 map; the directions are not rounded to float32 first).
    fn eval<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rows = arrays::rows::<3>(directions, "directions")?;
        let ds = rows.as_slice();
        // The batch lookup of the directions as given (the angles on SIMD lanes, the scalar
        // `eval` bit for bit); for a float32 map not rounded to float32 first, so that a float32
        // sample's direction reads the radiance `sample` returned with it.
        let lookup: &RadianceFn = match &self.inner {
            Inner::F64(env) => &|d, c| env.eval_batch(d, c),
            Inner::F32(env) => &|d, c| env.eval_batch(d, c),
        };
        let rgb = detached(py, "EnvMap.eval", || {
            let mut rgb: Vec<[f32; 3]> = arrays::try_vec(ds.len(), "rgb")?;
            rgb.resize(ds.len(), [0.0; 3]);
            rgb.par_chunks_mut(PAR_CHUNK)
                .zip(ds.par_chunks(PAR_CHUNK))
                .for_each(|(c, d)| lookup(d, c));
            PyResult::Ok(rgb)
        })??;
        match &self.inner {
            Inner::F64(_) => {
                let mut c = arrays::try_vec(3 * rgb.len(), "rgb")?;
                c.extend(rgb.iter().flat_map(|v| v.map(f64::from)));
                Ok(arrays::new_2d(py, &c, 3)?.into_any())
            }
            Inner::F32(_) => Ok(arrays::new_2d(py, rgb.as_flattened(), 3)?.into_any()),
        }
    }

    /// ``invert(directions)``: the points (n, 2) of the square that ``sample`` maps to them
    /// (NaN where the density is 0 or the direction is not a finite non-zero vector; float32 for
    /// a float32 map).
    fn invert<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rows = arrays::rows::<3>(directions, "directions")?;
        let ds = rows.as_slice();
        match &self.inner {
            Inner::F64(env) => {
                let u = detached(py, "EnvMap.invert", || {
                    let mut res = arrays::try_vec(ds.len(), "u")?;
                    res.resize(ds.len(), Ok([0.0; 2]));
                    res.par_chunks_mut(PAR_CHUNK)
                        .zip(ds.par_chunks(PAR_CHUNK))
                        .for_each(|(r, d)| env.invert_batch(d, r));
                    let mut u = arrays::try_vec(2 * ds.len(), "u")?;
                    u.extend(res.into_iter().flat_map(|r| r.unwrap_or([f64::NAN; 2])));
                    PyResult::Ok(u)
                })??;
                Ok(arrays::new_2d(py, &u, 2)?.into_any())
            }
            Inner::F32(env) => {
                let u = detached(py, "EnvMap.invert", || {
                    let [x, y, z] = soa32(&ds)?;
                    let (mut u, mut v) = (zeros32(ds.len())?, zeros32(ds.len())?);
                    u.par_chunks_mut(PAR_CHUNK)
                        .zip(v.par_chunks_mut(PAR_CHUNK))
                        .zip(x.par_chunks(PAR_CHUNK))
                        .zip(y.par_chunks(PAR_CHUNK).zip(z.par_chunks(PAR_CHUNK)))
                        .for_each(|(((u, v), x), (y, z))| env.invert_soa([x, y, z], [u, v]));
                    let mut uv = arrays::try_vec(2 * ds.len(), "u")?;
                    uv.extend(u.iter().zip(&v).flat_map(|(a, b)| [*a, *b]));
                    PyResult::Ok(uv)
                })??;
                Ok(arrays::new_2d(py, &u, 2)?.into_any())
            }
        }
    }
}

/// A batch radiance lookup of float64 directions (either map's `eval_batch`).
type RadianceFn<'a> = dyn Fn(&[[f64; 3]], &mut [[f32; 3]]) + Sync + 'a;

/// `n` zeros, allocated fallibly (MemoryError, never an abort).
fn zeros32(n: usize) -> PyResult<Vec<f32>> {
    let mut v = arrays::try_vec(n, "a float32 buffer")?;
    v.resize(n, 0.0);
    Ok(v)
}

/// Directions as three float32 columns: each normalised in float64 and then rounded to float32
/// (as `gonio.Sampler` passes float32 directions to the float32 map); a zero or non-finite vector
/// becomes NaN, where the float32 map's pdf is 0, its inverse NaN and the radiance black.
fn soa32(ds: &[[f64; 3]]) -> PyResult<[Vec<f32>; 3]> {
    let mut cols = [
        arrays::try_vec(ds.len(), "directions")?,
        arrays::try_vec(ds.len(), "directions")?,
        arrays::try_vec(ds.len(), "directions")?,
    ];
    for d in ds {
        let e = normalize(*d).unwrap_or([f64::NAN; 3]);
        for c in 0..3 {
            cols[c].push(e[c] as f32);
        }
    }
    Ok(cols)
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
