//! `gonio.Sampler`: any method on any domain, batches with the GIL released on rayon threads.

use crate::arrays;
use crate::diagram::{domain_name, parse_domain, PyDiagram};
use crate::{detached, BuildError, InputError};
use gonio::sampler::normalize;
use gonio::Method;
use gonio::{InvertError, Point2, Sampler, Vec3};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use rayon::prelude::*;

/// Rows per rayon task. Each output row depends only on its own input row, so the results do not
/// depend on the number of threads.
const CHUNK: usize = 4096;

/// Rows per slice of a batch: between slices the GIL is taken back and pending signals are
/// handled (Ctrl-C raises KeyboardInterrupt within one slice's time, a few ms).
pub(crate) const SLICE: usize = 1 << 18;

/// Runs `f` on consecutive ranges of at most [`SLICE`] of `n` rows with the GIL released,
/// handling signals between them; `f` returns the first bad row of its range (relative to the
/// range's start), which stops the batch. Returns the first bad row of the whole batch.
pub(crate) fn in_slices(
    py: Python<'_>,
    what: &str,
    n: usize,
    mut f: impl FnMut(std::ops::Range<usize>) -> Option<usize> + Send,
) -> PyResult<Option<usize>> {
    let mut start = 0;
    while start < n {
        let end = n.min(start + SLICE);
        if let Some(k) = detached(py, what, || f(start..end))? {
            return Ok(Some(start + k));
        }
        start = end;
        if start < n {
            py.check_signals()?;
        }
    }
    Ok(None)
}

/// Applies `f` to every row on all rayon threads with the GIL released, into a new array; `None`
/// from `f` marks an invalid row, and the first invalid row (lowest index) is reported.
pub(crate) fn map_rows<'py, const K: usize>(
    py: Python<'py>,
    what: &str,
    rows: &[[f64; K]],
    f: impl Fn(&[f64; K]) -> Option<f64> + Sync,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let arr = arrays::output(py, None, what, &[rows.len()])?;
    let bad = arrays::fill(&arr, what, |out| {
        in_slices(py, what, rows.len(), |r| {
            let rows = &rows[r.clone()];
            out[r]
                .par_chunks_mut(CHUNK)
                .zip(rows.par_chunks(CHUNK))
                .enumerate()
                .filter_map(|(c, (o, r))| {
                    let mut first_bad = None;
                    for (k, (o, r)) in o.iter_mut().zip(r).enumerate() {
                        match f(r) {
                            Some(v) => *o = v,
                            None => {
                                first_bad.get_or_insert(c * CHUNK + k);
                            }
                        }
                    }
                    first_bad
                })
                .min()
        })
    })?;
    match bad {
        None => Ok(arr),
        Some(k) => Err(InputError::new_err(format!(
            "{what}: row {k}: direction {} is zero or not finite",
            fmt_row(&rows[k])
        ))),
    }
}

/// A row of numbers for a message, `(x, y, z)`, each in the shortest form that reads back (exponent
/// form for tiny and huge magnitudes: no 300-digit decimals).
pub(crate) fn fmt_row(r: &[f64]) -> String {
    let parts: Vec<String> = r.iter().map(|&x| gonio::decimal::shortest(x)).collect();
    format!("({})", parts.join(", "))
}

/// A sampler of a diagram: a bijective map from the unit square [0, 1]² to unit directions with
/// the exact density of every sample.
///
/// Frame (README "The frame"): directions are unit vectors (x, y, z) in the diagram's frame, θ
/// from +z, φ from +x toward +y; for photometric files nadir (γ = 0°) is −z and C = 0° is +x.
/// Densities are per steradian.
///
/// Every batch method takes an array of shape (n, 2) (points) or (n, 3) (directions), float64 or
/// float32, C- or Fortran-ordered, and returns new float64 arrays. Batches run on all threads with
/// the GIL released; each output row depends only on its input row, so results do not depend on
/// the number of threads.
#[pyclass(name = "Sampler", module = "gonio", frozen)]
pub(crate) struct PySampler {
    sampler: Box<dyn Sampler>,
    method: Method,
    ratio_bound: Option<(f64, f64)>,
    target_power: f64,
}

/// A built sampler, its guaranteed ratio bound (if the method claims one) and the power its
/// target normalises (diagram units × sr).
pub(crate) type Built = (Box<dyn Sampler>, Option<(f64, f64)>, f64);

/// (directions (n, 3), pdf (n,)) as numpy arrays.
type SampleArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>);

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
        Ok(PySampler {
            sampler,
            method,
            ratio_bound,
            target_power,
        })
    }

    pub(crate) fn inner(&self) -> &dyn Sampler {
        self.sampler.as_ref()
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
        self.method.as_str()
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

    /// Maps points `u` of the unit square, shape (n, 2), each coordinate in [0, 1], to unit
    /// directions (n, 3) and their exact density (n,) per steradian. Returns (directions, pdf).
    /// Raises InputError for a point outside [0, 1]² or NaN (naming its row).
    ///
    /// `out=(directions, pdf)`: C-contiguous float64 arrays of shapes (n, 3) and (n,) to write
    /// into (and return) instead of new ones; reusing them across calls saves the page faults of
    /// fresh memory. They must not overlap `u` or each other (InputError).
    #[pyo3(signature = (u, *, out = None))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<SampleArrays<'py>> {
        let rows = arrays::rows::<2>(u, "u")?;
        let pts = rows.as_slice();
        let n = pts.len();
        let outs: Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)> =
            out.map(|o| o.extract()).transpose().map_err(|_| {
                InputError::new_err("out: expected a tuple (directions, pdf) of numpy arrays")
            })?;
        let (d, p) = (outs.as_ref().map(|o| &o.0), outs.as_ref().map(|o| &o.1));
        let dirs_a = arrays::output(py, d, "out[0] (directions)", &[n, 3])?;
        let pdf_a = arrays::output(py, p, "out[1] (pdf)", &[n])?;
        arrays::check_disjoint(&[
            ("u", rows.span),
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
                fmt_row(&pts[k])
            )));
        }
        Ok((dirs_a, pdf_a))
    }

    /// Density of `sample` per steradian at `directions` (n, 3), normalised first; 0 outside the
    /// domain. Raises InputError for a zero or non-finite direction. `out`: a C-contiguous float64
    /// array of shape (n,) to write into (and return), not overlapping `directions`.
    #[pyo3(signature = (directions, *, out = None))]
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let rows = arrays::rows::<3>(directions, "directions")?;
        let dirs = rows.as_slice();
        let s = self.sampler.as_ref();
        let out_a = arrays::output(py, out, "out", &[dirs.len()])?;
        arrays::check_disjoint(&[("directions", rows.span), ("out", arrays::span(&out_a))])?;
        let bad = arrays::fill(&out_a, "out", |out| {
            in_slices(py, "pdf", dirs.len(), |r| {
                pdf_into(s, &dirs[r.clone()], &mut out[r])
            })
        })?;
        if let Some(k) = bad {
            return Err(InputError::new_err(format!(
                "pdf: row {k}: direction {} is zero or not finite",
                fmt_row(&dirs[k])
            )));
        }
        Ok(out_a)
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
    /// normalised first. Raises InputError for a direction outside the domain or where the density
    /// is 0 (no point maps to it), naming its row, and for a method without inverse ("rejection").
    /// `out`: a C-contiguous float64 array of shape (n, 2) to write into (and return), not
    /// overlapping `directions`.
    #[pyo3(signature = (directions, *, out = None))]
    fn invert<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let s = self.sampler.as_ref();
        if s.invert([0.0, 0.0, 1.0]) == Err(InvertError::Unsupported) {
            return Err(InputError::new_err(format!(
                "method `{}` has no inverse; use hds, piecewise-constant, bilinear or uniform",
                s.name()
            )));
        }
        let rows = arrays::rows::<3>(directions, "directions")?;
        let dirs = rows.as_slice();
        let out_a = arrays::output(py, out, "out", &[dirs.len(), 2])?;
        arrays::check_disjoint(&[("directions", rows.span), ("out", arrays::span(&out_a))])?;
        let bad = arrays::fill(&out_a, "out", |out| {
            in_slices(py, "invert", dirs.len(), |r| {
                invert_into(s, &dirs[r.clone()], &mut out[2 * r.start..2 * r.end])
            })
        })?;
        if let Some(k) = bad {
            let d = dirs[k];
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

    fn __repr__(&self) -> String {
        format!(
            "gonio.Sampler(method={:?}, domain={:?}, memory_bytes={})",
            self.method.as_str(),
            domain_name(self.sampler.domain()),
            self.sampler.memory_bytes()
        )
    }
}

/// Samples every point into `dirs` (row-major n × 3) and `pdf`; returns the first row outside the
/// unit square (nothing is sampled in its chunk).
pub(crate) fn sample_into(
    s: &dyn Sampler,
    pts: &[Point2],
    dirs: &mut [f64],
    pdf: &mut [f64],
) -> Option<usize> {
    dirs.par_chunks_mut(3 * CHUNK)
        .zip(pdf.par_chunks_mut(CHUNK))
        .zip(pts.par_chunks(CHUNK))
        .enumerate()
        .filter_map(|(c, ((d, p), u))| {
            if let Some(k) = u
                .iter()
                .position(|u| !((0.0..=1.0).contains(&u[0]) && (0.0..=1.0).contains(&u[1])))
            {
                return Some(c * CHUNK + k);
            }
            let (rows, _) = d.as_chunks_mut::<3>();
            s.sample_batch_split(u, rows, p);
            None
        })
        .min()
}

fn invert_into(s: &dyn Sampler, dirs: &[Vec3], out: &mut [f64]) -> Option<usize> {
    out.par_chunks_mut(2 * CHUNK)
        .zip(dirs.par_chunks(CHUNK))
        .enumerate()
        .filter_map(|(c, (o, d))| {
            let mut unit = [[0.0; 3]; CHUNK];
            let unit = &mut unit[..d.len()];
            if let Some(k) = normalize_all(d, unit) {
                return Some(c * CHUNK + k);
            }
            let mut res = [Ok([0.0; 2]); CHUNK];
            let res = &mut res[..d.len()];
            s.invert_batch(unit, res);
            for (k, (o, r)) in o.chunks_exact_mut(2).zip(res.iter()).enumerate() {
                match r {
                    Ok(u) => o.copy_from_slice(u),
                    Err(_) => return Some(c * CHUNK + k),
                }
            }
            None
        })
        .min()
}

/// Normalises every direction of `d` into `unit`; the index of the first zero or non-finite one.
fn normalize_all(d: &[Vec3], unit: &mut [Vec3]) -> Option<usize> {
    for (k, (u, d)) in unit.iter_mut().zip(d).enumerate() {
        match normalize(*d) {
            Some(v) => *u = v,
            None => return Some(k),
        }
    }
    None
}

/// The library's batch pdf ([`Sampler::pdf_batch`], the SIMD path of the HDS maps) of every
/// normalised direction; the first zero or non-finite direction.
fn pdf_into(s: &dyn Sampler, dirs: &[Vec3], out: &mut [f64]) -> Option<usize> {
    out.par_chunks_mut(CHUNK)
        .zip(dirs.par_chunks(CHUNK))
        .enumerate()
        .filter_map(|(c, (o, d))| {
            let mut unit = [[0.0; 3]; CHUNK];
            let unit = &mut unit[..d.len()];
            if let Some(k) = normalize_all(d, unit) {
                return Some(c * CHUNK + k);
            }
            s.pdf_batch(unit, o);
            None
        })
        .min()
}
