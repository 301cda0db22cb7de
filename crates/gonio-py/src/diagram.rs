//! `gonio.Diagram` and the readers `gonio.read`, `gonio.read_bytes`, `gonio.example`.

use crate::arrays;
use crate::batch::map_rows;
use crate::types::{domain_name, PyDiagram, Source};
use crate::{DiagramError, InputError, ParseError};
use gonio::decimal::degrees;
use gonio::input::file::FileKind;
use gonio::photometry::{
    self, write_ies, write_ldt, DirTiltResolver, FileFormat, NoTiltFiles, Photometry, TiltResolver,
    WriteMeta,
};
use gonio::sampler::{normalize, spherical};
use gonio::Diagram;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyString};
use std::path::{Path, PathBuf};

fn diagram_error(e: gonio::DiagramError) -> PyErr {
    DiagramError::new_err(e.to_string())
}

/// A `ParseError` with its location as attributes; the message reads `FILE:LINE:COLUMN: message`
/// as the CLI prints it (line 0: `FILE: message`; column 0: `FILE:LINE: message`).
pub(crate) fn parse_error(file: &str, line: usize, column: usize, message: &str) -> PyErr {
    let text = match (line, column) {
        (0, _) => format!("{file}: {message}"),
        (l, 0) => format!("{file}:{l}: {message}"),
        (l, c) => format!("{file}:{l}:{c}: {message}"),
    };
    let err = ParseError::new_err(text);
    Python::attach(|py| {
        let v = err.value(py);
        let _ = v.setattr("file", file);
        let _ = v.setattr("line", line);
        let _ = v.setattr("column", column);
        let _ = v.setattr("message", message);
    });
    err
}

fn parse_format(format: &str) -> PyResult<Source> {
    match format.trim().to_ascii_lowercase().as_str() {
        "ies" => Ok(Source::Ies),
        "ldt" | "eulumdat" => Ok(Source::Eulumdat),
        "json" => Ok(Source::Json),
        _ => Err(InputError::new_err(format!(
            "unknown format `{format}`; expected \"ies\", \"ldt\" or \"json\""
        ))),
    }
}

/// Reads `bytes` of `source` format; `name` is what messages call the input.
fn load(bytes: &[u8], source: Source, name: &str, tilt: &dyn TiltResolver) -> PyResult<PyDiagram> {
    use gonio::input::LoadError as E;
    let loaded = gonio::input::load(bytes, source, tilt).map_err(|e| match e {
        E::NotUtf8(e) => parse_error(name, 0, 0, &format!("the file is not UTF-8 text ({e})")),
        E::Json {
            line,
            column,
            message,
        } => parse_error(name, line, column, &message),
        E::Parse(e) => parse_error(name, e.line, e.column, &e.message),
        E::Diagram(d) => DiagramError::new_err(format!("{name}: {d}")),
        E::Expand { error, .. } => {
            DiagramError::new_err(format!("{name}: cannot expand the distribution: {error}"))
        }
        E::NotAFileFormat(k) => {
            InputError::new_err(format!("{name}: {} is not a file format", k.label()))
        }
    })?;
    Ok(PyDiagram {
        diagram: loaded.diagram,
        source,
        name: name.to_string(),
        photometry: loaded.photometry,
    })
}

/// Reads a diagram from a file: `.ies` (IES LM-63), `.ldt` (EULUMDAT) or `.json` (gonio's native
/// form), chosen by the extension (any letter case) unless `format` names one of "ies", "ldt",
/// "json". TILT files named by an IES file are read from the file's directory.
///
/// Raises ParseError (with file, line, column) for a file that cannot be read, DiagramError for a
/// distribution that cannot be used.
#[pyfunction]
#[pyo3(signature = (path, format = None))]
pub(crate) fn read(py: Python<'_>, path: PathBuf, format: Option<&str>) -> PyResult<Py<PyDiagram>> {
    let name = path.display().to_string();
    let source = match format {
        Some(f) => parse_format(f)?,
        None => {
            let ext = path
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            match (Source::from_extension(&name), ext.as_deref()) {
                (Some(kind), _) => kind,
                (None, Some(e)) => {
                    return Err(InputError::new_err(format!(
                    "{name}: unknown input format `.{e}`; expected .json, .ies or .ldt (or pass format=)"
                )))
                }
                (None, None) => {
                    return Err(InputError::new_err(format!(
                    "{name}: the file name has no extension; expected .json, .ies or .ldt (or pass format=)"
                )))
                }
            }
        }
    };
    let fk = if source == Source::Json {
        FileKind::Diagram
    } else {
        FileKind::Photometry
    };
    let bytes = read_input(Path::new(&path), &name, fk)?;
    let dir: PathBuf = match Path::new(&path).parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let resolver = DirTiltResolver::new(dir);
    let d = crate::no_panic(&name, || load(&bytes, source, &name, &resolver))??;
    Py::new(py, d)
}

/// Reads the file `path` of `kind` through the library's one file reader (regular files only,
/// never blocking, the kind's size limit: the same checks and messages as the CLI and the C ABI),
/// and words its error as one exception family: FileNotFoundError for a missing file,
/// PermissionError, OSError for a file that is not regular or cannot be read, ParseError (with
/// `file`) for a file over the limit, MemoryError when its bytes cannot be allocated. The message
/// names the file once.
pub(crate) fn read_input(path: &Path, name: &str, kind: FileKind) -> PyResult<Vec<u8>> {
    gonio::input::file::read_file_with_meta(path, name, kind)
        .map(|(b, _)| b)
        .map_err(|e| file_error(name, e))
}

/// The exception of a file the one reader refused (see [`read_input`]).
fn file_error(name: &str, e: gonio::input::file::ReadFileError) -> PyErr {
    use gonio::input::file::ReadFileError as E;
    let msg = e.to_string();
    match &e {
        E::NotFound { .. } => pyo3::exceptions::PyFileNotFoundError::new_err(msg),
        E::Io { message, .. } if message.contains("ermission") => {
            pyo3::exceptions::PyPermissionError::new_err(msg)
        }
        E::Io { .. } | E::NotRegular { .. } => pyo3::exceptions::PyOSError::new_err(msg),
        E::TooLarge { .. } | E::Grew { .. } => {
            let m = msg.strip_prefix(&format!("{name}: ")).unwrap_or(&msg);
            parse_error(name, 0, 0, m)
        }
        E::NoMemory { .. } => pyo3::exceptions::PyMemoryError::new_err(msg),
    }
}

/// Reads a diagram from the contents of a file, given as bytes or str, in the explicit `format`
/// "ies", "ldt" or "json". `name` is what error messages call the input. A `TILT=<file>` line
/// cannot be resolved here (there is no directory): use `read` for such files.
#[pyfunction]
#[pyo3(signature = (data, format, name = "<bytes>"))]
pub(crate) fn read_bytes(
    py: Python<'_>,
    data: &Bound<'_, PyAny>,
    format: &str,
    name: &str,
) -> PyResult<Py<PyDiagram>> {
    let source = parse_format(format)?;
    let bytes: Vec<u8> = if let Ok(b) = data.cast::<PyBytes>() {
        b.as_bytes().to_vec()
    } else if data.cast::<PyString>().is_ok() {
        data.extract::<String>()?.into_bytes()
    } else if let Ok(b) = data.extract::<Vec<u8>>() {
        b
    } else {
        return Err(InputError::new_err(format!(
            "data: expected bytes or str, got {}",
            data.get_type().name()?
        )));
    };
    let kind = if source == Source::Json {
        FileKind::Diagram
    } else {
        FileKind::Photometry
    };
    gonio::input::file::check_size(name, bytes.len() as u64, kind)
        .map_err(|e| file_error(name, e))?;
    let d = crate::no_panic(name, || load(&bytes, source, name, &NoTiltFiles))??;
    Py::new(py, d)
}

/// The built-in example luminaire (a diagram the project makes itself), in candela, on the sphere.
#[pyfunction]
pub(crate) fn example(py: Python<'_>) -> PyResult<Py<PyDiagram>> {
    Py::new(
        py,
        PyDiagram {
            diagram: gonio::synthetic::example_luminaire(),
            source: Source::Example,
            name: "example".into(),
            photometry: None,
        },
    )
}

#[pymethods]
impl PyDiagram {
    /// A diagram from arrays: `theta_deg` (N,) strictly increasing in [0°, 180°], `phi_deg` (M,)
    /// strictly increasing in [0°, 360°), `values` (M, N) finite and ≥ 0, not all 0, with
    /// `values[i, j]` at (phi_deg[i], theta_deg[j]) in any unit (candela for a luminaire).
    #[new]
    fn py_new(
        theta_deg: &Bound<'_, PyAny>,
        phi_deg: &Bound<'_, PyAny>,
        values: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let t = arrays::vector(theta_deg, "theta_deg")?;
        let p = arrays::vector(phi_deg, "phi_deg")?;
        let (v, shape) = arrays::table(values, "values")?;
        if shape != [p.len(), t.len()] {
            return Err(DiagramError::new_err(format!(
                "values: expected shape ({}, {}) = (len(phi_deg), len(theta_deg)), got ({}, {})",
                p.len(),
                t.len(),
                shape[0],
                shape[1]
            )));
        }
        let rows: Vec<Vec<f64>> = if t.is_empty() {
            vec![Vec::new(); p.len()]
        } else {
            v.chunks(t.len()).map(<[f64]>::to_vec).collect()
        };
        let diagram = Diagram::from_degrees(&t, &p, &rows).map_err(diagram_error)?;
        Ok(PyDiagram {
            diagram,
            source: Source::Arrays,
            name: "<arrays>".into(),
            photometry: None,
        })
    }

    /// Parallels θ in degrees from +z, strictly increasing, shape (N,): the shortest decimals that
    /// convert back to the stored radians (15.0, not 14.999999999999998), as `to_json` writes them.
    #[getter]
    fn theta_deg<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t: Vec<f64> = self.diagram.theta().iter().map(|&t| degrees(t)).collect();
        arrays::new_1d(py, &t)
    }

    /// Meridians φ in degrees from +x toward +y, strictly increasing in [0°, 360°), shape (M,);
    /// the shortest decimals, as `theta_deg`.
    #[getter]
    fn phi_deg<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p: Vec<f64> = self.diagram.phi().iter().map(|&p| degrees(p)).collect();
        arrays::new_1d(py, &p)
    }

    /// The values, shape (M, N): `values[i, j]` at (phi_deg[i], theta_deg[j]); candela for
    /// photometric files (after every multiplier of the file).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        arrays::new_2d(py, self.diagram.values(), self.diagram.n_parallels())
    }

    /// ∫ over the sphere of the diagram interpolated bilinearly in (θ, φ), in closed form:
    /// value unit × sr, i.e. the luminous flux in lumens for a diagram in candela.
    #[getter]
    fn flux(&self) -> f64 {
        self.diagram.integral()
    }

    /// Where the diagram came from: "ies", "ldt", "json", "example" or "arrays".
    #[getter]
    fn source(&self) -> &'static str {
        self.source.name()
    }

    /// The name the input was given by (a path, "example", "<bytes>", "<arrays>").
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// The domain samplers get by default: "sphere" for photometric input, else "hemisphere" when
    /// every parallel lies at θ ≤ 90°.
    #[getter]
    fn domain(&self) -> &'static str {
        domain_name(self.default_domain())
    }

    /// Everything unusual the reader tolerated, one line each: "FILE:LINE:COLUMN: warning: ...".
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.photometry
            .as_ref()
            .map(|p| {
                p.warnings
                    .iter()
                    .map(|w| format!("{}:{w}", self.name))
                    .collect()
            })
            .unwrap_or_default()
    }

    /// For IES and EULUMDAT input, every field the file declared, as a dict (None otherwise):
    /// format, version, photometric_type, symmetry, header_lines, keywords, lamp_sets, tilt,
    /// vertical_angles_deg, horizontal_angles_deg, raw_values, intensity_scale, candela,
    /// max_intensity_cd, and "ies" or "ldt" with the format's own fields.
    #[getter]
    fn header<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        match &self.photometry {
            Some(p) => Ok(Some(header_dict(py, p)?)),
            None => Ok(None),
        }
    }

    /// The diagram's value interpolated bilinearly in (θ, φ) at unit `directions` (n, 3) (the
    /// same interpolant every sampler's target follows): candela for photometric input. Directions
    /// are normalised first; zero or non-finite ones raise InputError.
    fn intensity<'py>(
        &self,
        py: Python<'py>,
        directions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let rows = arrays::rows::<3>(directions, "directions")?;
        let dirs = rows.as_slice();
        let d = &self.diagram;
        map_rows(py, "intensity", &dirs, |v| {
            let v = normalize(*v)?;
            let (t, p) = spherical(v);
            Some(d.interpolate(t, p))
        })
    }

    /// A sampler of this diagram: see `gonio.Sampler`.
    #[pyo3(signature = (method = "hds", domain = None, *, resolution = None, seed = None, tolerance = None))]
    fn sampler(
        slf: &Bound<'_, Self>,
        method: &str,
        domain: Option<&str>,
        resolution: Option<usize>,
        seed: Option<u64>,
        tolerance: Option<f64>,
    ) -> PyResult<crate::sampler::PySampler> {
        crate::sampler::PySampler::build(slf, method, domain, resolution, seed, tolerance)
    }

    /// The diagram in gonio's native JSON form (angles in degrees), as text.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.diagram.to_json())
            .map(|s| s + "\n")
            .map_err(|e| InputError::new_err(e.to_string()))
    }

    /// The diagram as text of `format` "json", "ies" (IES LM-63-2019) or "ldt" (EULUMDAT); the
    /// values must be candela for the photometric formats. `luminaire` names it in the header.
    #[pyo3(signature = (format, luminaire = None))]
    fn dumps(&self, format: &str, luminaire: Option<String>) -> PyResult<String> {
        dumps(
            &self.diagram,
            format,
            luminaire.unwrap_or_else(|| self.stem()),
        )
    }

    /// Writes the diagram to `path` in the format of its extension (.json, .ies, .ldt) or of
    /// `format`; see `dumps`.
    #[pyo3(signature = (path, format = None))]
    fn write(&self, path: PathBuf, format: Option<&str>) -> PyResult<()> {
        let fmt = out_format(&path, format)?;
        let text = dumps(&self.diagram, &fmt, self.stem())?;
        std::fs::write(&path, text).map_err(|e| {
            pyo3::exceptions::PyOSError::new_err(format!("cannot write {}: {e}", path.display()))
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "gonio.Diagram(source={:?}, name={:?}, parallels={}, meridians={}, flux={})",
            self.source.name(),
            self.name,
            self.diagram.n_parallels(),
            self.diagram.n_meridians(),
            self.diagram.integral()
        )
    }
}

fn header_dict<'py>(py: Python<'py>, p: &Photometry) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(
        "format",
        match p.format {
            FileFormat::Ies => "ies",
            FileFormat::Eulumdat => "ldt",
        },
    )?;
    d.set_item("version", p.version.to_string())?;
    d.set_item("photometric_type", p.photometric_type.to_string())?;
    d.set_item("symmetry", format!("{:?}", p.symmetry))?;
    d.set_item("header_lines", PyList::new(py, &p.header)?)?;
    let kw = PyList::empty(py);
    for k in &p.keywords {
        let e = PyDict::new(py);
        e.set_item("key", &k.key)?;
        e.set_item("value", &k.value)?;
        e.set_item("line", k.line)?;
        kw.append(e)?;
    }
    d.set_item("keywords", kw)?;
    let lamps = PyList::empty(py);
    for l in &p.lamp_sets {
        let e = PyDict::new(py);
        e.set_item("count", l.count)?;
        e.set_item("description", &l.description)?;
        e.set_item("flux_lm", l.flux_lm)?;
        e.set_item("color", &l.color)?;
        e.set_item("color_rendering", &l.color_rendering)?;
        e.set_item("watts", l.watts)?;
        lamps.append(e)?;
    }
    d.set_item("lamp_sets", lamps)?;
    let tilt = PyDict::new(py);
    match &p.tilt {
        photometry::Tilt::None => tilt.set_item("kind", "none")?,
        photometry::Tilt::Include(_) => tilt.set_item("kind", "include")?,
        photometry::Tilt::File { name, .. } => {
            tilt.set_item("kind", "file")?;
            tilt.set_item("file", name)?;
        }
    }
    if let Some(t) = p.tilt.table() {
        tilt.set_item("geometry", t.geometry)?;
        tilt.set_item("angles_deg", arrays::new_1d(py, &t.angles_deg)?)?;
        tilt.set_item("factors", arrays::new_1d(py, &t.factors)?)?;
    }
    tilt.set_item("tilt_angle_deg", p.tilt_angle_deg)?;
    d.set_item("tilt", tilt)?;
    d.set_item(
        "vertical_angles_deg",
        arrays::new_1d(py, &p.vertical_angles_deg)?,
    )?;
    d.set_item(
        "horizontal_angles_deg",
        arrays::new_1d(py, &p.horizontal_angles_deg)?,
    )?;
    let nv = p.vertical_angles_deg.len().max(1);
    d.set_item("raw_values", arrays::new_2d(py, &p.raw_values, nv)?)?;
    d.set_item("intensity_scale", p.intensity_scale)?;
    d.set_item("candela", arrays::new_2d(py, &p.candela, nv)?)?;
    d.set_item("max_intensity_cd", p.max_intensity_cd())?;
    if let Some(i) = &p.ies {
        let e = PyDict::new(py);
        e.set_item("version_line", &i.version_line)?;
        e.set_item("lamps", i.lamps)?;
        e.set_item("lumens_per_lamp", i.lumens_per_lamp)?;
        e.set_item("multiplier", i.multiplier)?;
        e.set_item("units_type", i.units_type)?;
        e.set_item("width", i.width)?;
        e.set_item("length", i.length)?;
        e.set_item("height", i.height)?;
        e.set_item("ballast_factor", i.ballast_factor)?;
        e.set_item("second_ballast_field", i.second_ballast_field)?;
        e.set_item("input_watts", i.input_watts)?;
        d.set_item("ies", e)?;
    }
    if let Some(l) = &p.ldt {
        let e = PyDict::new(py);
        e.set_item("company", &l.company)?;
        e.set_item("ityp", l.ityp)?;
        e.set_item("isym", l.isym)?;
        e.set_item("mc", l.mc)?;
        e.set_item("dc", l.dc)?;
        e.set_item("ng", l.ng)?;
        e.set_item("dg", l.dg)?;
        e.set_item("report_number", &l.report_number)?;
        e.set_item("luminaire_name", &l.luminaire_name)?;
        e.set_item("luminaire_number", &l.luminaire_number)?;
        e.set_item("file_name", &l.file_name)?;
        e.set_item("date_user", &l.date_user)?;
        e.set_item(
            "luminaire_dimensions_mm",
            l.luminaire_dimensions_mm.to_vec(),
        )?;
        e.set_item("luminous_area_mm", l.luminous_area_mm.to_vec())?;
        e.set_item(
            "luminous_area_heights_mm",
            l.luminous_area_heights_mm.to_vec(),
        )?;
        e.set_item("downward_flux_fraction_pct", l.downward_flux_fraction_pct)?;
        e.set_item("light_output_ratio_pct", l.light_output_ratio_pct)?;
        e.set_item("conversion_factor", l.conversion_factor)?;
        e.set_item("measurement_tilt_deg", l.measurement_tilt_deg)?;
        e.set_item("direct_ratios", l.direct_ratios.to_vec())?;
        e.set_item("c_angles_deg", l.c_angles_deg.clone())?;
        d.set_item("ldt", e)?;
    }
    Ok(d)
}

/// The output format named by `format` or by `path`'s extension.
pub(crate) fn out_format(path: &Path, format: Option<&str>) -> PyResult<String> {
    let name = path.display();
    let f = match format {
        Some(f) => f.to_ascii_lowercase(),
        None => match path.extension().and_then(|e| e.to_str()) {
            Some(e) => e.to_ascii_lowercase(),
            None => {
                return Err(InputError::new_err(format!(
                    "{name}: the output name has no extension; expected .json, .ies or .ldt (or pass format=)"
                )))
            }
        },
    };
    match f.as_str() {
        "json" | "ies" | "ldt" => Ok(f),
        e => Err(InputError::new_err(format!(
            "{name}: unknown output format `{e}`; expected json, ies or ldt"
        ))),
    }
}

/// The text of `d` in `format` ("json", "ies", "ldt"), as `gonio convert` writes it.
pub(crate) fn dumps(d: &Diagram, format: &str, luminaire: String) -> PyResult<String> {
    let meta = WriteMeta {
        luminaire,
        ..WriteMeta::default()
    };
    match format.to_ascii_lowercase().as_str() {
        "json" => serde_json::to_string_pretty(&d.to_json())
            .map(|s| s + "\n")
            .map_err(|e| InputError::new_err(e.to_string())),
        "ies" => Ok(write_ies(d, &meta)),
        "ldt" => Ok(write_ldt(d, &meta)),
        e => Err(InputError::new_err(format!(
            "unknown output format `{e}`; expected json, ies or ldt"
        ))),
    }
}
