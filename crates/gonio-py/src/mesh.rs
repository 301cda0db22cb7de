//! `gonio.texture_uv`: the inverse map as a texture parameterisation (docs/TEXTURE.md).

use crate::arrays;
use crate::{detached, InputError};
use gonio::mesh::{parameterise, Density, Layout, Mesh, UvOptions};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// One-chart UVs of a closed star-shaped triangle mesh: `vertices` (n, 3) floats, `faces` (m, 3)
/// vertex indices (counter-clockwise seen from outside or consistently clockwise); `density`
/// "surface" (uniform texels over the surface) or "solid-angle"; `weights` (n,) positive
/// per-vertex weights × surface (overrides `density`); `center` (3,) or None (found); `layout`
/// "hds" (the inverse map) or the compared "latlong", "cube", "octahedral".
///
/// Returns a dict: `positions` (k, 3) (the input's vertices, then the vertices the seam cut
/// made), `uvs` (t, 2), `faces` (f, 3) position indices and `face_uvs` (f, 3) uv indices of the
/// output triangles (as OBJ's `f p/t`), `source_face` (f,) the input face of each, `center` (3,),
/// `cut_faces` (the input faces cut along a seam) and `seam` (u of the split layout's seam; None
/// for the other layouts). Errors: `gonio.InputError` (shapes, indices, an open or not
/// star-shaped mesh, with the message of docs/TEXTURE.md).
#[pyfunction]
#[pyo3(signature = (vertices, faces, density = "surface", weights = None, center = None, layout = "hds", *, progress = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn texture_uv<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    density: &str,
    weights: Option<&Bound<'py, PyAny>>,
    center: Option<[f64; 3]>,
    layout: &str,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let progress = crate::progress::Progress::new(py, progress, "texture_uv")?;
    progress.report("reading the arrays", 0.0)?;
    let v = arrays::rows::<3>(vertices, "vertices")?;
    let f = arrays::rows::<3>(faces, "faces")?;
    let mut positions: Vec<[f64; 3]> = arrays::try_vec(v.as_slice().len(), "vertices")?;
    positions.extend_from_slice(&v.as_slice());
    let n = positions.len();
    let mut triangles = arrays::try_vec(f.as_slice().len(), "faces")?;
    for (i, r) in f.as_slice().iter().enumerate() {
        let mut t = [0u32; 3];
        for k in 0..3 {
            let x = r[k];
            if !(x >= 0.0 && x.fract() == 0.0 && (x as usize) < n) {
                return Err(InputError::new_err(format!(
                    "faces[{i}][{k}] = {x} is not a vertex index in 0..{n}"
                )));
            }
            t[k] = x as u32;
        }
        triangles.push(t);
    }
    let density = match (weights, density) {
        (Some(w), _) => Density::VertexWeight(arrays::vector(w, "weights")?),
        (None, "surface") => Density::Surface,
        (None, "solid-angle") => Density::SolidAngle,
        (None, d) => {
            return Err(InputError::new_err(format!(
                "density: `{d}` is not \"surface\" or \"solid-angle\""
            )))
        }
    };
    let layout = match layout {
        "hds" => Layout::Hds,
        "latlong" => Layout::LatLong,
        "cube" => Layout::Cube,
        "octahedral" => Layout::Octahedral,
        l => {
            return Err(InputError::new_err(format!(
                "layout: `{l}` is not one of hds, latlong, cube, octahedral"
            )))
        }
    };
    let mut source_face = arrays::try_vec(triangles.len(), "faces")?;
    source_face.extend(0..triangles.len() as u32);
    let mesh = Mesh {
        positions,
        triangles,
        source_face,
        ..Mesh::default()
    };
    let opts = UvOptions {
        density,
        center,
        layout,
        ..UvOptions::default()
    };
    progress.report("parameterising (star-shape check, map, seam cut)", 0.1)?;
    let r = detached(py, "texture_uv", || parameterise(&mesh, &opts))?.map_err(|e| match e {
        // Memory exhaustion is Python's MemoryError, not a fault of the input.
        gonio::mesh::MeshError::OutOfMemory { .. } => {
            pyo3::exceptions::PyMemoryError::new_err(e.to_string())
        }
        e => InputError::new_err(e.to_string()),
    })?;
    progress.report("writing the arrays", 0.9)?;
    let m = &r.mesh;
    let out = PyDict::new(py);
    out.set_item(
        "positions",
        arrays::new_2d(py, m.positions.as_flattened(), 3)?,
    )?;
    out.set_item("uvs", arrays::new_2d(py, m.uvs.as_flattened(), 2)?)?;
    let idx = |pick: fn(&gonio::mesh::Corner) -> u32| -> Vec<Vec<u32>> {
        m.triangles
            .iter()
            .map(|t| t.iter().map(pick).collect())
            .collect()
    };
    let np = py.import("numpy")?;
    let u32t = np.getattr("uint32")?;
    out.set_item(
        "faces",
        np.call_method1("asarray", (idx(|c| c.position), &u32t))?,
    )?;
    out.set_item(
        "face_uvs",
        np.call_method1("asarray", (idx(|c| c.uv), &u32t))?,
    )?;
    out.set_item(
        "source_face",
        np.call_method1("asarray", (m.source_triangle.clone(), &u32t))?,
    )?;
    out.set_item("center", r.star.center.to_vec())?;
    out.set_item("cut_faces", r.cut_triangles)?;
    out.set_item("seam", r.texture.as_ref().map(|t| t.seam()))?;
    progress.report("done", 1.0)?;
    Ok(out)
}

/// ``read_mesh(path) -> dict``: a PLY (ASCII or binary) or OBJ mesh file, by its extension or
/// content, through the one file reader (regular files only, the mesh size limit of
/// ``read_limit("mesh")``): ``vertices`` (n, 3) float64, ``faces`` (m, 3) uint32 (polygons
/// fan-triangulated), ``normals`` (k, 3) float64 (empty when the file has none) and
/// ``warnings`` (what the reader triangulated or skipped). The arrays go to ``texture_uv``.
/// Errors: FileNotFoundError, GonioError for a refused file, InputError for a malformed one
/// (located: line and column, or element and byte).
#[pyfunction]
pub(crate) fn read_mesh<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
) -> PyResult<Bound<'py, PyDict>> {
    let name = path.display().to_string();
    let bytes = crate::diagram::read_input(&path, &name, gonio::input::file::FileKind::Mesh)?;
    let (mesh, warnings) = detached(py, "read_mesh", || {
        gonio::mesh::read_any(&bytes, Some(&path))
    })?
    .map_err(|e| InputError::new_err(format!("{name}: {e}")))?;
    drop(bytes);
    let out = PyDict::new(py);
    out.set_item(
        "vertices",
        arrays::new_2d(py, mesh.positions.as_flattened(), 3)?,
    )?;
    out.set_item(
        "faces",
        arrays::new_2d(py, mesh.triangles.as_flattened(), 3)?,
    )?;
    out.set_item(
        "normals",
        arrays::new_2d(py, mesh.normals.as_flattened(), 3)?,
    )?;
    out.set_item(
        "warnings",
        warnings.iter().map(|w| w.to_string()).collect::<Vec<_>>(),
    )?;
    Ok(out)
}
