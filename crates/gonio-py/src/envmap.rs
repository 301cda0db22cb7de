//! `gonio.EnvMap`: an environment map (`.hdr`, `.exr`, `.pfm` lat-long image) sampled by the HDS
//! sphere map, with numpy batches (frame and lookups: docs/ENVMAPS.md).

use crate::{arrays, detached, no_panic, GonioError, InputError};
use gonio::envmap::{EnvOptions, EnvironmentMap, Lookup};
use gonio::image::Image;
use gonio::Sampler;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

/// An environment light: an image's luminance as a density per steradian over the sphere,
/// sampled exactly (``sample``, ``pdf``, ``invert``) and its RGB radiance (``eval``).
///
/// ``EnvMap(path, lookup="nearest", mis_compensation=False)``. Directions are gonio's frame:
/// the image's top row is +z, its centre column +x (docs/ENVMAPS.md).
#[pyclass(name = "EnvMap", module = "gonio", frozen)]
pub struct PyEnvMap {
    env: EnvironmentMap,
}

#[pymethods]
impl PyEnvMap {
    #[new]
    #[pyo3(signature = (path, lookup = "nearest", mis_compensation = false))]
    fn new(path: std::path::PathBuf, lookup: &str, mis_compensation: bool) -> PyResult<Self> {
        let lookup = match lookup {
            "nearest" => Lookup::Nearest,
            "bilinear" => Lookup::Bilinear,
            other => {
                return Err(InputError::new_err(format!(
                    "lookup: {other:?} is not \"nearest\" or \"bilinear\""
                )))
            }
        };
        let env = no_panic("EnvMap", || {
            let img = Image::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            EnvironmentMap::with_options(
                img,
                EnvOptions {
                    lookup,
                    mis_compensation,
                    ..EnvOptions::default()
                },
            )
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
