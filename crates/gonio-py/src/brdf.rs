//! `gonio.read_brdf`, `gonio.Brdf`, `gonio.BrdfSampler`: tabulated BRDFs (MERL, UTIA, gonio BRDF
//! JSON) and the exact importance sampling of f_r·cos θ_o (frame and grids: docs/BRDF.md).
//!
//! Directions are in the local shading frame (z the normal), both pointing away from the surface;
//! they need not be unit vectors (each row is normalised), but a row that is not finite or is the
//! zero vector raises InputError naming the row. `wi` is one direction (3,) for every row or one
//! per row (n, 3).

use crate::diagram::parse_error;
use crate::{arrays, detached, BuildError, GonioError, InputError};
use gonio::brdf::{
    read_any, scalar_albedo, BrdfError, BrdfMethod, BrdfSampler, CosineBrdf, GgxFit, MerlOptions,
    PerSliceConstant, SamplerOptions, Symmetry, TabulatedBrdf,
};
use gonio::sampler::normalize;
use gonio::{Point2, Vec3};
use numpy::{PyArray1, PyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use rayon::prelude::*;
use std::borrow::Cow;
use std::path::PathBuf;
use std::sync::Arc;

// Rows per rayon task (small batches stay on one thread): the library's batch task size.
use gonio::batch::PAR_CHUNK as CHUNK;

/// A tabulated BRDF f_r(ω_i, ω_o) in 1/sr, 1 or 3 channels, read by [`read_brdf`].
#[pyclass(name = "Brdf", module = "gonio", frozen)]
pub struct PyBrdf {
    brdf: Arc<TabulatedBrdf>,
}

/// The error of a BRDF file: ParseError (with line and column for JSON) or GonioError.
fn brdf_error(path: &std::path::Path, e: BrdfError) -> PyErr {
    let file = path.display().to_string();
    match e {
        BrdfError::Json {
            line,
            column,
            message,
        } => parse_error(&file, line, column, &message),
        other => GonioError::new_err(format!("{file}: {other}")),
    }
}

/// ``read_brdf(path, *, merl_theta=46, merl_phi=90)``: a BRDF file, its format recognised from
/// the content (gonio BRDF JSON, UTIA raw, MERL binary resampled to `merl_theta` polar nodes and
/// `merl_phi` relative azimuths).
#[pyfunction]
#[pyo3(signature = (path, *, merl_theta = 46, merl_phi = 90, progress = None))]
pub(crate) fn read_brdf<'py>(
    py: Python<'py>,
    path: PathBuf,
    merl_theta: usize,
    merl_phi: usize,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<PyBrdf> {
    let progress = crate::progress::Progress::new(py, progress, "read_brdf")?;
    let merl = MerlOptions {
        n_theta: merl_theta,
        n_phi: merl_phi,
    };
    let name = path.display().to_string();
    progress.report("reading the file", 0.0)?;
    let bytes = crate::diagram::read_input(&path, &name, gonio::input::file::FileKind::Brdf)?;
    progress.report("decoding (a MERL file: resampling)", 0.1)?;
    let brdf =
        detached(py, "read_brdf", || read_any(&bytes, &merl))?.map_err(|e| brdf_error(&path, e))?;
    progress.report("done", 1.0)?;
    Ok(PyBrdf {
        brdf: Arc::new(brdf),
    })
}

/// InputError for the first row of `ds` that is not a finite non-zero vector.
fn check_dirs(ds: &[Vec3], what: &str) -> PyResult<()> {
    if let Some(k) = ds.iter().position(|d| normalize(*d).is_none()) {
        let d = ds[k];
        return Err(InputError::new_err(format!(
            "{what}: row {k}: ({}, {}, {}) is not a finite non-zero direction",
            d[0], d[1], d[2]
        )));
    }
    Ok(())
}

/// InputError for the first point of `pts` outside the unit square (or NaN).
fn check_square(pts: &[Point2], what: &str) -> PyResult<()> {
    if let Some(k) = pts
        .iter()
        .position(|p| !(0.0..=1.0).contains(&p[0]) || !(0.0..=1.0).contains(&p[1]))
    {
        return Err(InputError::new_err(format!(
            "{what}: row {k}: point ({}, {}) is outside the unit square [0, 1]²",
            pts[k][0], pts[k][1]
        )));
    }
    Ok(())
}

/// The incident directions: one for every row, or one per row.
enum Incident<'py> {
    One([Vec3; 1]),
    Many(arrays::Rows<'py, 3>),
}

impl Incident<'_> {
    fn slice(&self) -> Cow<'_, [Vec3]> {
        match self {
            Incident::One(d) => Cow::Borrowed(&d[..]),
            Incident::Many(r) => r.as_slice(),
        }
    }
}

/// `wi` as one direction (3,) or `n` rows (n, 3), checked.
fn incident<'py>(obj: &Bound<'py, PyAny>, n: usize) -> PyResult<Incident<'py>> {
    let arr = arrays::real_array(obj, "wi")?;
    let inc = if arr.ndim() == 1 {
        let v = arrays::vector(obj, "wi")?;
        if v.len() != 3 {
            return Err(InputError::new_err(format!(
                "wi: expected shape (3,) or (n, 3), got ({},)",
                v.len()
            )));
        }
        Incident::One([[v[0], v[1], v[2]]])
    } else {
        let r = arrays::rows::<3>(obj, "wi")?;
        let m = r.as_slice().len();
        if m != n {
            return Err(InputError::new_err(format!(
                "wi: {m} rows where one direction (3,) or {n} rows are needed"
            )));
        }
        Incident::Many(r)
    };
    check_dirs(&inc.slice(), "wi")?;
    Ok(inc)
}

/// A unit vector of a checked row.
fn unit(d: Vec3) -> Vec3 {
    normalize(d).unwrap_or(d)
}

/// `width` values for each outgoing direction of `wo`, `f(ω_i, ω_o, row)` with ω_i the incident
/// direction of `wi` (one for all, or one per row), both made unit; computed off the GIL in
/// parallel. `call` = (the call's name for the GIL release, the buffer's name for its allocation
/// error, `width`).
fn per_direction<'py>(
    py: Python<'py>,
    (wi, wo): (&Bound<'py, PyAny>, &Bound<'py, PyAny>),
    (call, buf, width): (&'static str, &'static str, usize),
    f: impl Fn(Vec3, Vec3, &mut [f64]) + Sync,
) -> PyResult<Vec<f64>> {
    let rows = arrays::rows::<3>(wo, "wo")?;
    let wos = rows.as_slice();
    check_dirs(&wos, "wo")?;
    let inc = incident(wi, wos.len())?;
    let wis = inc.slice();
    detached(py, call, || {
        let mut out = buffer(width * wos.len(), buf)?;
        par_fill(&mut out, width, |k, row| {
            let w = unit(wis[if wis.len() == 1 { 0 } else { k }]);
            f(w, unit(wos[k]), row)
        });
        PyResult::Ok(out)
    })?
}

/// Fills `out` (rows of `k` values, one per row k of the batch) in parallel.
fn par_fill(out: &mut [f64], k: usize, f: impl Fn(usize, &mut [f64]) + Sync) {
    out.par_chunks_mut(k * CHUNK)
        .enumerate()
        .for_each(|(c, block)| {
            for (j, row) in block.chunks_mut(k).enumerate() {
                f(c * CHUNK + j, row);
            }
        });
}

/// A zero-filled buffer of `n` values allocated fallibly.
fn buffer(n: usize, what: &str) -> PyResult<Vec<f64>> {
    let mut v = arrays::try_vec(n, what)?;
    v.resize(n, 0.0);
    Ok(v)
}

#[pymethods]
impl PyBrdf {
    /// 1 or 3 (R, G, B).
    #[getter]
    fn channels(&self) -> usize {
        self.brdf.channels()
    }

    /// "isotropic" (f depends on θ_i, θ_o, φ_o − φ_i) or "anisotropic".
    #[getter]
    fn symmetry(&self) -> &'static str {
        match self.brdf.symmetry() {
            Symmetry::Isotropic => "isotropic",
            Symmetry::Anisotropic => "anisotropic",
        }
    }

    /// The grids in radians: (theta_i, phi_i, theta_o, phi_o), φ_o relative for isotropic tables.
    #[allow(clippy::type_complexity)]
    #[getter]
    fn grid<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let b = &self.brdf;
        Ok((
            arrays::new_1d(py, b.theta_i())?,
            arrays::new_1d(py, b.phi_i())?,
            arrays::new_1d(py, b.theta_o())?,
            arrays::new_1d(py, b.phi_o())?,
        ))
    }

    /// ``eval(wi, wo)``: f_r (n, channels) in 1/sr; 0 where a direction is below the horizon.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (b, ch) = (&self.brdf, self.brdf.channels());
        let f = per_direction(py, (wi, wo), ("Brdf.eval", "f", ch), |i, o, row| {
            row.copy_from_slice(&b.eval(i, o)[..ch])
        })?;
        arrays::new_2d(py, &f, ch)
    }

    /// ``albedo(wi)`` for wi (n, 3): ∫ f̄(ω_i, ω_o) cos θ_o dω_o (n,), f̄ the luminance of the
    /// channels (or the one channel), exact up to round-off for the table's interpolant.
    fn albedo<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let rows = arrays::rows::<3>(wi, "wi")?;
        let wis = rows.as_slice();
        check_dirs(&wis, "wi")?;
        let b = &self.brdf;
        let a = detached(py, "Brdf.albedo", || {
            let mut a = buffer(wis.len(), "albedo")?;
            par_fill(&mut a, 1, |k, row| row[0] = scalar_albedo(b, unit(wis[k])));
            PyResult::Ok(a)
        })??;
        arrays::new_1d(py, &a)
    }

    /// ``write(path, format="json")``: writes this table to ``path``: ``"json"`` (gonio BRDF
    /// JSON, the table exactly), ``"merl"`` (the MERL binary: the table's interpolant at the
    /// cells' centres; isotropic tables only) or ``"utia"`` (the UTIA raw layout: the interpolant
    /// at its 6 × 48 × 6 × 48 nodes). Returns ``path``.
    #[pyo3(signature = (path, format = "json"))]
    fn write(&self, py: Python<'_>, path: PathBuf, format: &str) -> PyResult<PathBuf> {
        let b = &self.brdf;
        write_brdf(
            py,
            "Brdf.write",
            &path,
            format,
            b.symmetry(),
            |wi, wo| b.eval(wi, wo),
            || Ok(gonio::brdf::write_json(b).into_bytes()),
        )?;
        Ok(path)
    }

    /// ``tables(precision="float32", *, theta_o=46, phi_o=90, force_resample=False) -> bytes``:
    /// the family blob (docs/TABLES.md, "Families") of this table's "hds" sampler with those
    /// options: every incident slice's map, the incident grid and the table, what
    /// ``gonio.drjit.BrdfTables`` and the Mitsuba plugin ``gonio_brdf`` read.
    #[pyo3(signature = (precision = "float32", *, theta_o = 46, phi_o = 90, force_resample = false))]
    fn tables<'py>(
        &self,
        py: Python<'py>,
        precision: &str,
        theta_o: usize,
        phi_o: usize,
        force_resample: bool,
    ) -> PyResult<Bound<'py, PyBytes>> {
        let p = crate::sampler::parse_precision(precision)?;
        let opts = SamplerOptions {
            theta_o,
            phi_o,
            force_resample,
        };
        let brdf = &self.brdf;
        let bytes = detached(py, "Brdf.tables", || {
            let s = BrdfSampler::new(TabulatedBrdf::clone(brdf), &opts)?;
            s.tables(p).map_err(|e| BrdfError::Tables(e.to_string()))
        })?
        .map_err(|e| BuildError::new_err(format!("Brdf.tables: {e}")))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// ``sampler(method="hds", *, theta_o=46, phi_o=90, force_resample=False, resolution=128)``:
    /// a sampler of f_r·cos θ_o. Methods (the C ABI's): "hds" (the HDS map of the blended slice
    /// diagrams), "cosine", "ggx-fit" (a GGX lobe fitted to the table), "piecewise-constant" (the
    /// nearest slice tabulated as a `resolution`² image, discontinuous in ω_i). `theta_o`,
    /// `phi_o`: the slices' outgoing grid when the table's own cannot be used (or
    /// `force_resample`).
    #[pyo3(signature = (method = "hds", *, theta_o = 46, phi_o = 90, force_resample = false,
                        resolution = 128))]
    fn sampler(
        &self,
        py: Python<'_>,
        method: &str,
        theta_o: usize,
        phi_o: usize,
        force_resample: bool,
        resolution: usize,
    ) -> PyResult<PyBrdfSampler> {
        if !matches!(method, "hds" | "cosine" | "ggx-fit" | "piecewise-constant") {
            return Err(InputError::new_err(format!(
                "method: {method:?} is not \"hds\", \"cosine\", \"ggx-fit\" or \"piecewise-constant\""
            )));
        }
        if method == "piecewise-constant" && !(1..=4096).contains(&resolution) {
            return Err(InputError::new_err(format!(
                "resolution: {resolution} is not in 1…4096"
            )));
        }
        let opts = SamplerOptions {
            theta_o,
            phi_o,
            force_resample,
        };
        let brdf = &self.brdf;
        let (sampler, alpha) = detached(py, "Brdf.sampler", || {
            let s = BrdfSampler::new(TabulatedBrdf::clone(brdf), &opts)?;
            let alpha = (method == "ggx-fit").then(|| GgxFit::fit(s.brdf()).alpha());
            Ok::<_, BrdfError>((s, alpha))
        })?
        .map_err(|e| BuildError::new_err(format!("Brdf.sampler: {e}")))?;
        let sampler = Arc::new(sampler);
        let method = match alpha {
            Some((ax, ay)) => Method::Ggx(ax, ay),
            None if method == "cosine" => Method::Cosine,
            None if method == "piecewise-constant" => {
                let s = Arc::clone(&sampler);
                Method::Pc(Arc::new(detached(py, "Brdf.sampler", || {
                    PerSliceConstant::new(s, resolution)
                })?))
            }
            None => Method::Hds,
        };
        Ok(PyBrdfSampler { sampler, method })
    }
}

/// The sampling method of a [`PyBrdfSampler`].
#[derive(Clone)]
enum Method {
    Hds,
    Cosine,
    Ggx(f64, f64),
    /// Shares the HDS sampler whose slices it tabulates.
    Pc(Arc<PerSliceConstant<Arc<BrdfSampler>>>),
}

/// Importance sampling of a tabulated BRDF's f_r·cos θ_o, with exact pdf and inverse.
#[pyclass(name = "BrdfSampler", module = "gonio", frozen)]
pub struct PyBrdfSampler {
    sampler: Arc<BrdfSampler>,
    method: Method,
}

impl PyBrdfSampler {
    fn with<T>(&self, f: impl FnOnce(&dyn BrdfMethod) -> T) -> T {
        let s = &*self.sampler;
        match &self.method {
            Method::Hds => f(s),
            Method::Cosine => f(&CosineBrdf::new(s.brdf())),
            Method::Ggx(ax, ay) => f(&GgxFit::with_alpha(s.brdf(), *ax, *ay)),
            Method::Pc(p) => f(&**p),
        }
    }
}

#[pymethods]
impl PyBrdfSampler {
    /// "hds", "cosine" or "ggx-fit".
    #[getter]
    fn method(&self) -> &'static str {
        self.with(|m| m.name())
    }

    /// Channels of the weights (those of the BRDF).
    #[getter]
    fn channels(&self) -> usize {
        self.sampler.brdf().channels()
    }

    /// Whether the slices were resampled to the requested grid (else the table's own grid).
    #[getter]
    fn resampled(&self) -> bool {
        self.sampler.resampled()
    }

    /// ``tables(precision="float32") -> bytes``: the family blob of this "hds" sampler
    /// (docs/TABLES.md, "Families"); InputError for the other methods.
    #[pyo3(signature = (precision = "float32"))]
    fn tables<'py>(&self, py: Python<'py>, precision: &str) -> PyResult<Bound<'py, PyBytes>> {
        let p = crate::sampler::parse_precision(precision)?;
        if !matches!(self.method, Method::Hds) {
            return Err(InputError::new_err(
                "tables: only the \"hds\" BRDF sampler has tables",
            ));
        }
        let s = &self.sampler;
        let bytes = py
            .detach(|| s.tables(p))
            .map_err(|e| InputError::new_err(format!("tables: {e}")))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Bytes held by the sampler (slice maps and the table).
    #[getter]
    fn memory_bytes(&self) -> usize {
        self.sampler.memory_bytes()
    }

    /// ``sample(wi, u)`` for u (n, 2) in [0, 1]²: (wo (n, 3), pdf (n,) per sr, weight
    /// (n, channels) = f_r·cos θ_o / pdf, 0 where the pdf is 0).
    #[allow(clippy::type_complexity)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        let rows = arrays::rows::<2>(u, "u")?;
        let pts = rows.as_slice();
        check_square(&pts, "u")?;
        let inc = incident(wi, pts.len())?;
        let wis = inc.slice();
        let ch = self.channels();
        let n = pts.len();
        let (d, p, w) = detached(py, "BrdfSampler.sample", || {
            // One row of 3 + 1 + channels values per sample, split afterwards.
            let k = 4 + ch;
            let mut all = buffer(k * n, "samples")?;
            self.with(|m| {
                par_fill(&mut all, k, |j, row| {
                    let s = m.sample(unit(wis[if wis.len() == 1 { 0 } else { j }]), pts[j]);
                    row[..3].copy_from_slice(&s.direction);
                    row[3] = s.pdf;
                    row[4..].copy_from_slice(&s.weight[..ch]);
                })
            });
            let mut d = arrays::try_vec(3 * n, "wo")?;
            let mut p = arrays::try_vec(n, "pdf")?;
            let mut w = arrays::try_vec(ch * n, "weight")?;
            for row in all.chunks(k) {
                d.extend_from_slice(&row[..3]);
                p.push(row[3]);
                w.extend_from_slice(&row[4..]);
            }
            PyResult::Ok((d, p, w))
        })??;
        Ok((
            arrays::new_2d(py, &d, 3)?,
            arrays::new_1d(py, &p)?,
            arrays::new_2d(py, &w, ch)?,
        ))
    }

    /// ``pdf(wi, wo)``: the exact density of ``sample`` at each wo (n,), per steradian.
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let call = ("BrdfSampler.pdf", "pdf", 1);
        let p =
            self.with(|m| per_direction(py, (wi, wo), call, |i, o, row| row[0] = m.pdf(i, o)))?;
        arrays::new_1d(py, &p)
    }

    /// ``invert(wi, wo)``: the points (n, 2) of the square that ``sample`` maps to each wo
    /// (NaN where there is none, e.g. below the horizon).
    fn invert<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let call = ("BrdfSampler.invert", "u", 2);
        let u = self.with(|m| {
            per_direction(py, (wi, wo), call, |i, o, row| {
                row.copy_from_slice(&m.invert(i, o).unwrap_or([f64::NAN; 2]))
            })
        })?;
        arrays::new_2d(py, &u, 2)
    }
}

/// Adds `read_brdf`, `Brdf` and `BrdfSampler` to the native module.
/// ``analytic_brdf(path, family, *, format="json", albedo=(0.8, 0.8, 0.8), alpha_x=0.3,
/// alpha_y=None, f0=(1, 1, 1), n_theta=46, n_phi=90)``: writes the library's analytic BRDF
/// (``"lambert"``: albedo/π; ``"ggx"``: GGX with height-correlated Smith masking and constant
/// Fresnel ``f0``, α_x along the tangent, α_y = α_x when None) to ``path`` in a file layout:
/// ``"merl"`` (the MERL binary, isotropic only, cells at their centres), ``"utia"`` (the UTIA raw
/// layout, 6 × 48 incident and outgoing nodes to 75°) or ``"json"`` (gonio BRDF JSON on an
/// ``n_theta`` × ``n_phi`` grid). Ground truth for tests and experiments; returns ``path``.
#[pyfunction]
#[pyo3(signature = (path, family, *, format = "json", albedo = [0.8, 0.8, 0.8], alpha_x = 0.3,
                    alpha_y = None, f0 = [1.0, 1.0, 1.0], n_theta = 46, n_phi = 90))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn analytic_brdf(
    py: Python<'_>,
    path: PathBuf,
    family: &str,
    format: &str,
    albedo: [f64; 3],
    alpha_x: f64,
    alpha_y: Option<f64>,
    f0: [f64; 3],
    n_theta: usize,
    n_phi: usize,
) -> PyResult<PathBuf> {
    use gonio::brdf::Analytic;
    let alpha_y = alpha_y.unwrap_or(alpha_x);
    let a = match family {
        "lambert" => Analytic::Lambert { albedo },
        "ggx" => {
            if !(alpha_x > 0.0 && alpha_y > 0.0 && alpha_x.is_finite() && alpha_y.is_finite()) {
                return Err(InputError::new_err(format!(
                    "alpha_x, alpha_y: {alpha_x}, {alpha_y} must be finite and > 0"
                )));
            }
            Analytic::Ggx {
                alpha_x,
                alpha_y,
                f0,
            }
        }
        other => {
            return Err(InputError::new_err(format!(
                "family: {other:?} is not \"lambert\" or \"ggx\""
            )))
        }
    };
    if albedo
        .iter()
        .chain(&f0)
        .any(|v| !(v.is_finite() && *v >= 0.0))
    {
        return Err(InputError::new_err(
            "albedo, f0: every value must be finite and >= 0",
        ));
    }
    write_brdf(
        py,
        "analytic_brdf",
        &path,
        format,
        a.symmetry(),
        |wi, wo| a.eval(wi, wo),
        || {
            let t = detached(py, "analytic_brdf", || a.table(n_theta, n_phi))?
                .map_err(|e| InputError::new_err(format!("analytic_brdf: {e}")))?;
            Ok(gonio::brdf::write_json(&t).into_bytes())
        },
    )?;
    Ok(path)
}

/// Writes the BRDF `eval` (of symmetry `symmetry`) to `path` in `format`: "merl" (isotropic
/// only) and "utia" by evaluating it at their nodes, "json" as `json` makes it; `what` names
/// the call in errors.
fn write_brdf(
    py: Python<'_>,
    what: &'static str,
    path: &std::path::Path,
    format: &str,
    symmetry: Symmetry,
    eval: impl Fn(gonio::Vec3, gonio::Vec3) -> [f64; 3] + Sync,
    json: impl FnOnce() -> PyResult<Vec<u8>>,
) -> PyResult<()> {
    let bytes = match format {
        "merl" => {
            if symmetry != Symmetry::Isotropic {
                return Err(InputError::new_err(
                    "format \"merl\": the MERL layout holds isotropic BRDFs only",
                ));
            }
            detached(py, what, || gonio::brdf::write_merl(&eval))?
        }
        "utia" => detached(py, what, || gonio::brdf::write_utia_dirs(&eval))?,
        "json" => json()?,
        other => {
            return Err(InputError::new_err(format!(
                "format: {other:?} is not \"json\", \"merl\" or \"utia\""
            )))
        }
    };
    std::fs::write(path, bytes).map_err(|e| GonioError::new_err(format!("{}: {e}", path.display())))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBrdf>()?;
    m.add_class::<PyBrdfSampler>()?;
    m.add_function(wrap_pyfunction!(read_brdf, m)?)?;
    m.add_function(wrap_pyfunction!(analytic_brdf, m)?)?;
    Ok(())
}
