//! `gonio.Sampler`: any method on any domain, batches with the GIL released on rayon threads.

use crate::arrays;
use crate::batch::{fmt_row, in_slices, map_rows};
use crate::types::{domain_name, parse_domain, PyDiagram};
use crate::{detached, BuildError, InputError};
use gonio::batch::{Soa, CHUNK, PAR_CHUNK};
use gonio::mapping::blob::{self, Frame, Precision, Target};
use gonio::sampler::normalize;
use gonio::Method;
use gonio::{InvertError, Sampler};
use numpy::{Element, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use rayon::prelude::*;

/// A sampler of a diagram: a bijective map from the unit square [0, 1]² to unit directions with
/// the exact density of every sample.
///
/// Frame (README "The frame"): directions are unit vectors (x, y, z) in the diagram's frame, θ
/// from +z, φ from +x toward +y; for photometric files nadir (γ = 0°) is −z and C = 0° is +x.
/// Densities are per steradian.
///
/// Every batch method takes an array of shape (n, 2) (points) or (n, 3) (directions), C- or
/// Fortran-ordered. `sample`, `pdf` and `invert` keep float32: a float32 array in gives float32
/// arrays out, through the sampler's float32 batch calls (its float32 map where it has one, else
/// the float64 map rounded once); any other real dtype is read as float64 and gives float64.
/// Batches run on all threads with the GIL released; each output row depends only on its input
/// row, so results do not depend on the number of threads.
#[pyclass(name = "Sampler", module = "gonio", frozen)]
pub(crate) struct PySampler {
    sampler: gonio::Built<'static>,
    /// The method's name (`Method::as_str`, or an environment map's sampler kind).
    method: &'static str,
    ratio_bound: Option<(f64, f64)>,
    target_power: f64,
    /// The diagram it was built from and its frame: the grid target of `tables()`.
    target: Option<(gonio::Diagram, Frame)>,
    /// The blob a `from_tables` sampler was read from, and its precision.
    blob: Option<(Vec<u8>, Precision)>,
}

/// A built sampler, its guaranteed ratio bound (if the method claims one) and the power its
/// target normalises (diagram units × sr).
pub(crate) type Built = (gonio::Built<'static>, Option<(f64, f64)>, f64);

/// Builds the sampler of `method` for `diagram` on `domain` through the library's factory
/// [`Method::build_with`], with its guaranteed ratio bound and target power.
pub(crate) fn build(
    method: Method,
    diagram: &gonio::Diagram,
    domain: gonio::Domain,
    resolution: Option<usize>,
    seed: Option<u64>,
    tolerance: Option<f64>,
) -> Result<Built, gonio::BuildError> {
    let mut options = gonio::BuildOptions::default().tolerance(tolerance);
    if let Some(r) = resolution {
        options = options.resolution(r);
    }
    if let Some(s) = seed {
        options = options.seed(s);
    }
    let s = method.build_with(diagram, domain, &options)?;
    let (bound, power) = (s.ratio_bound(), s.target_power());
    Ok((s, bound, power))
}

impl PySampler {
    pub(crate) fn build(
        diagram: &Bound<'_, PyDiagram>,
        method: &str,
        domain: Option<&str>,
        resolution: Option<usize>,
        seed: Option<u64>,
        tolerance: Option<f64>,
    ) -> PyResult<Self> {
        let py = diagram.py();
        let d = diagram.get();
        let method: Method = method
            .parse()
            .map_err(|e: gonio::method::ParseMethodError| InputError::new_err(e.to_string()))?;
        let domain = match domain {
            Some(s) => parse_domain(s)?,
            None => d.default_domain(),
        };
        let what = format!("{}: cannot build the {method} sampler", d.name);
        let built = detached(py, &what, || {
            build(method, &d.diagram, domain, resolution, seed, tolerance)
        })?;
        let (sampler, ratio_bound, target_power) =
            built.map_err(|e| BuildError::new_err(format!("{what}: {e}")))?;
        let frame = if d.source.is_photometric() {
            Frame::Photometric
        } else {
            Frame::Generic
        };
        Ok(PySampler {
            sampler,
            method: method.as_str(),
            ratio_bound,
            target_power,
            target: Some((d.diagram.clone(), frame)),
            blob: None,
        })
    }

    /// A sampler built elsewhere (an environment map's own map or one of its peers), named
    /// `method`.
    pub(crate) fn from_sampler(sampler: gonio::Built<'static>, method: &'static str) -> Self {
        let (ratio_bound, target_power) = (sampler.ratio_bound(), sampler.target_power());
        PySampler {
            sampler,
            method,
            ratio_bound,
            target_power,
            target: None,
            blob: None,
        }
    }

    pub(crate) fn inner(&self) -> &dyn Sampler {
        &*self.sampler
    }

    pub(crate) fn ratio_bound_value(&self) -> Option<(f64, f64)> {
        self.ratio_bound
    }

    pub(crate) fn target_power_value(&self) -> f64 {
        self.target_power
    }
}

#[pymethods]
impl PySampler {
    /// The sampler of `method` ("hds", "piecewise-constant", "bilinear", "rejection",
    /// "uniform") for `diagram` on `domain` ("hemisphere", "sphere"; default: the diagram's
    /// `domain`). `resolution`, `seed` and `tolerance` are the build options of the methods that
    /// take them. Raises BuildError when no such sampler can be built.
    #[new]
    #[pyo3(signature = (diagram, method = "hds", domain = None, *, resolution = None, seed = None, tolerance = None))]
    fn py_new(
        diagram: &Bound<'_, PyDiagram>,
        method: &str,
        domain: Option<&str>,
        resolution: Option<usize>,
        seed: Option<u64>,
        tolerance: Option<f64>,
    ) -> PyResult<Self> {
        Self::build(diagram, method, domain, resolution, seed, tolerance)
    }

    /// The method's name as the CLI's `--method` spells it.
    #[getter]
    fn method(&self) -> &'static str {
        self.method
    }

    /// "hemisphere" (z ≥ 0, 2π sr) or "sphere" (4π sr).
    #[getter]
    fn domain(&self) -> &'static str {
        domain_name(self.sampler.domain())
    }

    /// The guaranteed (min, max) of pdf / target_pdf over the domain where the target is
    /// positive, or None when the method claims no bound.
    #[getter]
    fn ratio_bound(&self) -> Option<(f64, f64)> {
        self.ratio_bound
    }

    /// Bytes held by the sampler's precomputed tables.
    #[getter]
    fn memory_bytes(&self) -> usize {
        self.sampler.memory_bytes()
    }

    /// The integral over the domain of the diagram the target density normalises, in the
    /// diagram's unit × sr (lumens for candela): intensity = target_power × target_pdf.
    #[getter]
    fn target_power(&self) -> f64 {
        self.target_power
    }

    /// The HDS map's tables as one blob (docs/TABLES.md, layout version 1): `precision`
    /// "float32" (the float32 map, what `gonio_device.h` and the Dr.Jit plugins sample) or
    /// "float64" (the f64 map's own tables), with the diagram the sampler was built from as its
    /// grid target (photometric frame for IES/EULUMDAT input). Raises InputError for another
    /// method than "hds" or a grid too large for float32 tables.
    #[pyo3(signature = (precision = "float32"))]
    fn tables<'py>(&self, py: Python<'py>, precision: &str) -> PyResult<Bound<'py, PyBytes>> {
        let p = parse_precision(precision)?;
        if let Some((bytes, bp)) = &self.blob {
            if *bp != p {
                return Err(InputError::new_err(format!(
                    "tables: this sampler was read from {} tables and writes only those",
                    bp.name()
                )));
            }
            return Ok(PyBytes::new(py, bytes));
        }
        let map = self.sampler.hds_map().ok_or_else(|| {
            InputError::new_err(format!(
                "tables: the {} sampler has no tables (only \"hds\" has)",
                self.method
            ))
        })?;
        let (target, frame) = match &self.target {
            Some((d, f)) => (Target::Grid(d), *f),
            None => (Target::None, Frame::Generic),
        };
        let bytes = py
            .detach(|| blob::write(map, p, frame, &target))
            .map_err(|e| InputError::new_err(format!("tables: {e}")))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// The sampler of a table blob (`tables()`, `gonio tables`, `gonio_sampler_tables`),
    /// validated first (docs/TABLES.md lists every check): it samples, evaluates and inverts as
    /// the map that wrote it, bit for bit in the blob's precision (float32 arrays for a float32
    /// blob). Its `target_pdf` is the blob's grid target normalised (0 without one); it has no
    /// ratio bound. Raises InputError naming the field or table at fault.
    #[staticmethod]
    fn from_tables(data: &[u8]) -> PyResult<Self> {
        let t = blob::read(data).map_err(|e| InputError::new_err(e.to_string()))?;
        let target = match &t.target {
            blob::TargetTables::Grid(d) => Some((d.clone(), t.frame)),
            _ => None,
        };
        let precision = t.precision;
        let mut s = PySampler::from_sampler(gonio::Built::Other(Box::new(t)), "hds");
        s.target = target;
        s.blob = Some((data.to_vec(), precision));
        Ok(s)
    }

    /// Maps points `u` of the unit square, shape (n, 2), each coordinate in [0, 1], to unit
    /// directions (n, 3) and their exact density (n,) per steradian. Returns (directions, pdf),
    /// float32 for a float32 `u`, else float64. Raises InputError for a point outside [0, 1]² or
    /// NaN (naming its row).
    ///
    /// `out=(directions, pdf)`: C-contiguous arrays of the result's dtype and of shapes (n, 3) and
    /// (n,) to write into (and return) instead of new ones; reusing them across calls saves the
    /// page faults of fresh memory. They must not overlap `u` or each other (InputError).
    #[pyo3(signature = (u, *, out = None))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        if let Some(rows) = arrays::rows32::<2>(u, "u")? {
            let (d, p) = self.sample_t(py, rows.as_slice(), rows.span, out)?;
            return Ok((d.into_any(), p.into_any()));
        }
        let rows = arrays::rows::<2>(u, "u")?;
        let (d, p) = self.sample_t(py, &rows.as_slice(), rows.span, out)?;
        Ok((d.into_any(), p.into_any()))
    }

    /// Density of `sample` per steradian at `directions` (n, 3), normalised first; 0 outside the
    /// domain. float32 for float32 `directions` (normalised in float64 and rounded to float32,
    /// then the float32 batch call), else float64. Raises InputError for a zero or non-finite
    /// direction. `out`: a C-contiguous array of the result's dtype and of shape (n,) to write
    /// into (and return), not overlapping `directions`.
    #[pyo3(signature = (directions, *, out = None))]
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if let Some(rows) = arrays::rows32::<3>(directions, "directions")? {
            return Ok(self.pdf_t(py, rows.as_slice(), rows.span, out)?.into_any());
        }
        let rows = arrays::rows::<3>(directions, "directions")?;
        Ok(self.pdf_t(py, &rows.as_slice(), rows.span, out)?.into_any())
    }

    /// The target density per steradian at `directions` (n, 3): the diagram interpolated
    /// bilinearly in (θ, φ), normalised to integrate to 1 over the domain; 0 outside it.
    fn target_pdf<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let rows = arrays::rows::<3>(directions, "directions")?;
        let s = self.sampler.as_ref();
        map_rows(py, "target_pdf", &rows.as_slice(), |d| {
            normalize(*d).map(|d| s.target_pdf(d))
        })
    }

    /// The points (n, 2) of the unit square that `sample` maps to `directions` (n, 3),
    /// normalised first; float32 for float32 `directions` (as `pdf`), else float64. Raises
    /// InputError for a direction outside the domain or where the density is 0 (no point maps to
    /// it), naming its row, and for a method without inverse ("rejection"). `out`: a
    /// C-contiguous array of the result's dtype and of shape (n, 2) to write into (and return),
    /// not overlapping `directions`.
    #[pyo3(signature = (directions, *, out = None))]
    fn invert<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let s = self.sampler.as_ref();
        if s.invert([0.0, 0.0, 1.0]) == Err(InvertError::Unsupported) {
            return Err(InputError::new_err(format!(
                "method `{}` has no inverse; use hds, piecewise-constant, bilinear or uniform",
                s.name()
            )));
        }
        if let Some(rows) = arrays::rows32::<3>(directions, "directions")? {
            return Ok(self
                .invert_t(py, rows.as_slice(), rows.span, out)?
                .into_any());
        }
        let rows = arrays::rows::<3>(directions, "directions")?;
        Ok(self
            .invert_t(py, &rows.as_slice(), rows.span, out)?
            .into_any())
    }

    fn __repr__(&self) -> String {
        format!(
            "gonio.Sampler(method={:?}, domain={:?}, memory_bytes={})",
            self.method,
            domain_name(self.sampler.domain()),
            self.sampler.memory_bytes()
        )
    }
}

/// (directions (n, 3), pdf (n,)) as numpy arrays of `T`.
type SampleArrays<'py, T> = (Bound<'py, PyArray2<T>>, Bound<'py, PyArray1<T>>);

impl PySampler {
    /// [`PySampler::sample`] in the element type `T` of the rows.
    fn sample_t<'py, T: Float>(
        &self,
        py: Python<'py>,
        pts: &[[T; 2]],
        span: arrays::Span,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<SampleArrays<'py, T>> {
        let n = pts.len();
        let outs: Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)> =
            out.map(|o| o.extract()).transpose().map_err(|_| {
                InputError::new_err("out: expected a tuple (directions, pdf) of numpy arrays")
            })?;
        let (d, p) = (outs.as_ref().map(|o| &o.0), outs.as_ref().map(|o| &o.1));
        let dirs_a = arrays::output(py, d, "out[0] (directions)", &[n, 3])?;
        let pdf_a = arrays::output(py, p, "out[1] (pdf)", &[n])?;
        arrays::check_disjoint(&[
            ("u", span),
            ("out[0] (directions)", arrays::span(&dirs_a)),
            ("out[1] (pdf)", arrays::span(&pdf_a)),
        ])?;
        let s = self.sampler.as_ref();
        let bad = arrays::fill(&dirs_a, "out[0] (directions)", |dirs| {
            arrays::fill(&pdf_a, "out[1] (pdf)", |pdf| {
                in_slices(py, "sample", n, |r| {
                    sample_into(
                        s,
                        &pts[r.clone()],
                        &mut dirs[3 * r.start..3 * r.end],
                        &mut pdf[r],
                    )
                })
            })
        })?;
        if let Some(k) = bad {
            return Err(InputError::new_err(format!(
                "u: row {k}: point {} is outside the unit square [0, 1]²",
                fmt_row(&pts[k].map(Into::into))
            )));
        }
        Ok((dirs_a, pdf_a))
    }

    /// [`PySampler::pdf`] in the element type `T` of the rows.
    fn pdf_t<'py, T: Float>(
        &self,
        py: Python<'py>,
        dirs: &[[T; 3]],
        span: arrays::Span,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<T>>> {
        let s = self.sampler.as_ref();
        let out_a = arrays::output(py, out, "out", &[dirs.len()])?;
        arrays::check_disjoint(&[("directions", span), ("out", arrays::span(&out_a))])?;
        let bad = arrays::fill(&out_a, "out", |out| {
            in_slices(py, "pdf", dirs.len(), |r| {
                pdf_into(s, &dirs[r.clone()], &mut out[r])
            })
        })?;
        if let Some(k) = bad {
            return Err(InputError::new_err(format!(
                "pdf: row {k}: direction {} is zero or not finite",
                fmt_row(&dirs[k].map(Into::into))
            )));
        }
        Ok(out_a)
    }

    /// [`PySampler::invert`] in the element type `T` of the rows.
    fn invert_t<'py, T: Float>(
        &self,
        py: Python<'py>,
        dirs: &[[T; 3]],
        span: arrays::Span,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<T>>> {
        let s = self.sampler.as_ref();
        let out_a = arrays::output(py, out, "out", &[dirs.len(), 2])?;
        arrays::check_disjoint(&[("directions", span), ("out", arrays::span(&out_a))])?;
        let bad = arrays::fill(&out_a, "out", |out| {
            in_slices(py, "invert", dirs.len(), |r| {
                invert_into(s, &dirs[r.clone()], &mut out[2 * r.start..2 * r.end])
            })
        })?;
        if let Some(k) = bad {
            let d = dirs[k].map(Into::into);
            let why = match normalize(d).map(|u| s.invert(u)) {
                None => "is zero or not finite".to_string(),
                Some(Err(InvertError::ZeroDensity)) => {
                    "has density 0: no point of the square maps to it".to_string()
                }
                Some(_) => format!(
                    "lies outside the sampler's domain ({})",
                    domain_name(s.domain())
                ),
            };
            return Err(InputError::new_err(format!(
                "invert: row {k}: direction {} {why}",
                fmt_row(&d)
            )));
        }
        Ok(out_a)
    }
}

/// The two element types of the batches; a batch call in either is
/// `sampler.batch(T::call(job))` ([`gonio::batch::Element`]).
pub(crate) trait Float:
    Element + gonio::batch::Element + Copy + Default + Send + Sync + Into<f64> + 'static
{
    /// `x` rounded to this type.
    fn from_f64(x: f64) -> Self;
}

impl Float for f64 {
    fn from_f64(x: f64) -> Self {
        x
    }
}

impl Float for f32 {
    fn from_f64(x: f64) -> Self {
        x as f32
    }
}

/// Runs `f(chunk index, first row, rows, outputs)` on every [`PAR_CHUNK`] rows on all rayon
/// threads; each task returns its first bad row (absolute index), and the lowest is returned.
fn par_rows<T: Sync, const K: usize, O: Send>(
    rows: &[[T; K]],
    out: &mut [O],
    per_row: usize,
    f: impl Fn(usize, &[[T; K]], &mut [O]) -> Option<usize> + Sync,
) -> Option<usize> {
    out.par_chunks_mut(per_row * PAR_CHUNK)
        .zip(rows.par_chunks(PAR_CHUNK))
        .enumerate()
        .filter_map(|(c, (o, r))| f(c * PAR_CHUNK, r, o))
        .min()
}

/// Samples every point into `dirs` (row-major n × 3) and `pdf` through the sampler's
/// structure-of-arrays call ([`Float::sample`]), [`CHUNK`] rows at a time through stack columns;
/// returns the first row outside the unit square (nothing is sampled in its chunk).
pub(crate) fn sample_into<T: Float>(
    s: &dyn Sampler,
    pts: &[[T; 2]],
    dirs: &mut [T],
    pdf: &mut [T],
) -> Option<usize> {
    dirs.par_chunks_mut(3 * PAR_CHUNK)
        .zip(pdf.par_chunks_mut(PAR_CHUNK))
        .zip(pts.par_chunks(PAR_CHUNK))
        .enumerate()
        .filter_map(|(c, ((d, p), u))| {
            let first = c * PAR_CHUNK;
            if let Some(k) = u.iter().position(|u| {
                let (a, b) = (u[0].into(), u[1].into());
                !((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b))
            }) {
                return Some(first + k);
            }
            let mut cols = [[T::default(); CHUNK]; 5];
            for ((u, d), p) in u
                .chunks(CHUNK)
                .zip(d.chunks_mut(3 * CHUNK))
                .zip(p.chunks_mut(CHUNK))
            {
                let m = u.len();
                let [cu, cv, x, y, z] = &mut cols;
                for (k, q) in u.iter().enumerate() {
                    cu[k] = q[0];
                    cv[k] = q[1];
                }
                s.batch(T::call(Soa::Sample {
                    u: &cu[..m],
                    v: &cv[..m],
                    dir: [&mut x[..m], &mut y[..m], &mut z[..m]],
                    pdf: p,
                }));
                for (k, row) in d.chunks_exact_mut(3).enumerate() {
                    row.copy_from_slice(&[x[k], y[k], z[k]]);
                }
            }
            None
        })
        .min()
}

fn invert_into<T: Float>(s: &dyn Sampler, dirs: &[[T; 3]], out: &mut [T]) -> Option<usize> {
    par_rows(dirs, out, 2, |first, d, o| {
        let mut cols = [[T::default(); CHUNK]; 3];
        let mut uv = [[T::default(); CHUNK]; 2];
        for (j, (d, o)) in d.chunks(CHUNK).zip(o.chunks_mut(2 * CHUNK)).enumerate() {
            let m = d.len();
            let base = first + j * CHUNK;
            if let Some(k) = first_bad(d, &mut cols) {
                return Some(base + k);
            }
            let [bu, bv] = &mut uv;
            s.batch(T::call(Soa::Invert {
                dir: [&cols[0][..m], &cols[1][..m], &cols[2][..m]],
                uv: [&mut bu[..m], &mut bv[..m]],
            }));
            for (k, row) in o.chunks_exact_mut(2).enumerate() {
                let (a, b) = (bu[k], bv[k]);
                if a.into().is_nan() || b.into().is_nan() {
                    return Some(base + k);
                }
                row.copy_from_slice(&[a, b]);
            }
        }
        None
    })
}

/// Normalises the directions of `d` in f64 into columns of `T` (rounded once to f32 for f32);
/// the index of the first zero or non-finite one.
fn first_bad<T: Float>(d: &[[T; 3]], cols: &mut [[T; CHUNK]; 3]) -> Option<usize> {
    for (k, row) in d.iter().enumerate() {
        match normalize(row.map(Into::into)) {
            Some(e) => {
                for c in 0..3 {
                    cols[c][k] = T::from_f64(e[c]);
                }
            }
            None => return Some(k),
        }
    }
    None
}

/// The sampler's structure-of-arrays pdf (one `Sampler::batch` call, the SIMD path of the HDS maps) of
/// every normalised direction, written straight into `out`; the first zero or non-finite
/// direction.
fn pdf_into<T: Float>(s: &dyn Sampler, dirs: &[[T; 3]], out: &mut [T]) -> Option<usize> {
    par_rows(dirs, out, 1, |first, d, o| {
        let mut cols = [[T::default(); CHUNK]; 3];
        for (j, (d, o)) in d.chunks(CHUNK).zip(o.chunks_mut(CHUNK)).enumerate() {
            let m = d.len();
            if let Some(k) = first_bad(d, &mut cols) {
                return Some(first + j * CHUNK + k);
            }
            s.batch(T::call(Soa::Pdf {
                dir: [&cols[0][..m], &cols[1][..m], &cols[2][..m]],
                pdf: o,
            }));
        }
        None
    })
}

/// `"float32"` or `"float64"` as the blob's precision.
pub(crate) fn parse_precision(p: &str) -> PyResult<Precision> {
    match p {
        "float32" | "f32" => Ok(Precision::F32),
        "float64" | "f64" => Ok(Precision::F64),
        other => Err(InputError::new_err(format!(
            "precision: {other:?} is not \"float32\" or \"float64\""
        ))),
    }
}

#[cfg(test)]
mod tests {
    //! The package's batch bodies (no Python needed) against the Rust trait's SoA calls, bit for
    //! bit, in f64 and f32, over several rayon tasks.
    use super::*;
    use gonio::synthetic::{example_luminaire, random_hemisphere, Family};
    use gonio::Domain;

    fn bits<T: Float>(v: &[T]) -> Vec<u64> {
        v.iter().map(|&x| x.into().to_bits()).collect()
    }

    fn check<T: Float>(s: &dyn Sampler) {
        let n = 2 * PAR_CHUNK + 300;
        let pts: Vec<[T; 2]> = (0..n)
            .map(|i| {
                let a = (((i * 7919) % 1000) as f64 + 0.5) / 1000.0;
                let b = (((i * 104_729) % 997) as f64 + 0.5) / 997.0;
                [T::from_f64(a), T::from_f64(b)]
            })
            .collect();
        let (mut dirs, mut pdf) = (vec![T::default(); 3 * n], vec![T::default(); n]);
        assert_eq!(sample_into(s, &pts, &mut dirs, &mut pdf), None);
        let u: Vec<T> = pts.iter().map(|p| p[0]).collect();
        let v: Vec<T> = pts.iter().map(|p| p[1]).collect();
        let mut w: [Vec<T>; 4] = std::array::from_fn(|_| vec![T::default(); n]);
        let [x, y, z, p] = &mut w;
        s.batch(T::call(Soa::Sample {
            u: &u,
            v: &v,
            dir: [x, y, z],
            pdf: p,
        }));
        let rows: Vec<T> = (0..3 * n).map(|k| w[k % 3][k / 3]).collect();
        assert_eq!(bits(&dirs), bits(&rows), "{}: sample directions", s.name());
        assert_eq!(bits(&pdf), bits(&w[3]), "{}: sample pdf", s.name());

        // Directions of length 2 over the sphere (normalised by the bodies, in f64, rounded once).
        let d: Vec<[T; 3]> = (0..n)
            .map(|i| {
                let zz = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let phi = 2.399_963 * i as f64;
                let r = (1.0 - zz * zz).sqrt();
                [2.0 * r * phi.cos(), 2.0 * r * phi.sin(), 2.0 * zz].map(T::from_f64)
            })
            .collect();
        let unit: [Vec<T>; 3] = std::array::from_fn(|c| {
            d.iter()
                .map(|r| T::from_f64(normalize(r.map(Into::into)).unwrap()[c]))
                .collect()
        });
        let ur = [&unit[0][..], &unit[1][..], &unit[2][..]];
        let mut got = vec![T::default(); n];
        assert_eq!(pdf_into(s, &d, &mut got), None);
        let mut want = vec![T::default(); n];
        s.batch(T::call(Soa::Pdf {
            dir: ur,
            pdf: &mut want,
        }));
        assert_eq!(bits(&got), bits(&want), "{}: pdf", s.name());
        let (mut iu, mut iv) = (vec![T::default(); n], vec![T::default(); n]);
        s.batch(T::call(Soa::Invert {
            dir: ur,
            uv: [&mut iu, &mut iv],
        }));
        let mut back = vec![T::default(); 2 * n];
        let first_nan = iu.iter().position(|x| (*x).into().is_nan());
        assert_eq!(invert_into(s, &d, &mut back), first_nan, "{}", s.name());
        if first_nan.is_none() {
            let rows: Vec<T> = (0..2 * n)
                .map(|k| if k % 2 == 0 { iu[k / 2] } else { iv[k / 2] })
                .collect();
            assert_eq!(bits(&back), bits(&rows), "{}: invert", s.name());
        }
        // A bad row in the last task is reported by its absolute index.
        let mut bad = d.clone();
        bad[n - 5] = [T::from_f64(0.0); 3];
        assert_eq!(pdf_into(s, &bad, &mut got), Some(n - 5));
        let mut badp = pts.clone();
        badp[n - 7][1] = T::from_f64(1.5);
        assert_eq!(sample_into(s, &badp, &mut dirs, &mut pdf), Some(n - 7));
    }

    #[test]
    fn batch_bodies_give_the_bits_of_the_trait_calls() {
        let lum = example_luminaire();
        let hemi = random_hemisphere(Family::ZeroHeavy, 9, 12, true, 4);
        for s in [
            Method::Hds.build(&lum, Domain::Sphere).unwrap(),
            Method::Bilinear.build(&lum, Domain::Sphere).unwrap(),
            Method::Hds.build(&hemi, Domain::Hemisphere).unwrap(),
        ] {
            check::<f64>(&*s);
            check::<f32>(&*s);
        }
    }
}
