//! Triangle meshes and the inverse map as a texture parameterisation (`docs/TEXTURE.md`).
//!
//! An object that is star-shaped about a centre is a function of direction, so the inverse of a
//! [`crate::SphereMap`] gives its whole surface one chart of the unit square whose texel density per
//! steradian is the map's pdf: any density the user wants, by building the map from a diagram of
//! that density. The data flow of this room is
//!
//! * [`obj`] and [`ply`] read a [`Mesh`] (polygons fan-triangulated, attributes kept);
//! * [`star`] finds or checks a centre from which the mesh is star-shaped;
//! * [`param`] builds the density diagram, the map, and the UVs ([`UvMesh`]), cutting faces along
//!   the layout's seams so that every output triangle lies in one chart;
//! * [`metrics`] measures a parameterisation (texel area per surface area, Sander stretch, seams)
//!   and [`param`] offers the compared layouts (latitude–longitude, cube map, equal-area
//!   octahedral);
//! * [`generate`] makes the test shapes; [`bake`] resamples a spherical texture into the map's
//!   square and renders a preview.
//!
//! Frames: positions are in the file's units and frame; directions from the centre use the
//! library's convention (θ from +z, φ from +x toward +y). UV (0, 0) is the square's corner that the
//! map's `sample([0, 0])` uses; the OBJ writer writes `vt u v` unchanged (OBJ's v axis points up, as
//! the map's second coordinate).

// Small fixed-size coordinate loops read better with indices.
#![allow(clippy::needless_range_loop)]

pub mod bake;
pub mod generate;
pub mod metrics;
pub mod obj;
pub mod param;
pub mod ply;
pub mod star;

pub use param::{parameterise, Density, Layout, UvMesh, UvOptions, UvResult};
pub use star::{find_center, StarCheck};

/// A triangle mesh as read from a file, with the attributes the readers keep.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Triangles, counter-clockwise as in the file (polygons fan-triangulated), indexing
    /// `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Normal vectors (OBJ `vn`, or PLY `nx ny nz` one per vertex).
    pub normals: Vec<[f64; 3]>,
    /// Per-corner normal indices into `normals`, one triple per triangle; empty when the file gives
    /// none. A corner without a normal holds [`NO_INDEX`].
    pub triangle_normals: Vec<[u32; 3]>,
    /// Texture coordinates of the input (OBJ `vt`); the parameterisation replaces them.
    pub texcoords: Vec<[f64; 2]>,
    /// Other per-vertex scalar properties (PLY properties beyond x, y, z, nx, ny, nz; OBJ vertex
    /// colours as `red`, `green`, `blue` in [0, 1]).
    pub vertex_properties: Vec<VertexProperty>,
    /// For each triangle, the index of the polygon of the file it came from.
    pub source_face: Vec<u32>,
}

/// Index value meaning "none" in [`Mesh::triangle_normals`] and [`Corner`].
pub const NO_INDEX: u32 = u32::MAX;

/// A named per-vertex scalar property.
#[derive(Debug, Clone, PartialEq)]
pub struct VertexProperty {
    /// Its name in the file.
    pub name: String,
    /// One value per vertex.
    pub values: Vec<f64>,
}

impl Mesh {
    /// The values of a per-vertex property by name.
    pub fn property(&self, name: &str) -> Option<&[f64]> {
        self.vertex_properties
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.values.as_slice())
    }

    /// Checks that every index is in range and every position finite (the readers guarantee it;
    /// meshes built in code are checked by [`parameterise`]).
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        if self.positions.len() >= NO_INDEX as usize {
            return Err(MeshError::TooLarge {
                what: "vertices",
                count: self.positions.len() as u64,
                limit: MAX_ELEMENTS,
            });
        }
        for (i, p) in self.positions.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(MeshError::NonFinitePosition { vertex: i });
            }
        }
        let n = self.positions.len() as u32;
        for (f, t) in self.triangles.iter().enumerate() {
            for &v in t {
                if v >= n {
                    return Err(MeshError::BadTriangle {
                        triangle: f,
                        index: v,
                        vertices: self.positions.len(),
                    });
                }
            }
        }
        if !self.triangle_normals.is_empty() && self.triangle_normals.len() != self.triangles.len()
        {
            return Err(MeshError::AttributeShape {
                what: "triangle_normals",
                expected: self.triangles.len(),
                found: self.triangle_normals.len(),
            });
        }
        for p in &self.vertex_properties {
            if p.values.len() != self.positions.len() {
                return Err(MeshError::AttributeShape {
                    what: "vertex property",
                    expected: self.positions.len(),
                    found: p.values.len(),
                });
            }
        }
        Ok(())
    }
}

/// One corner of a [`UvMesh`] triangle: indices of its position, texture coordinate and normal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Corner {
    /// Index into the positions.
    pub position: u32,
    /// Index into the texture coordinates.
    pub uv: u32,
    /// Index into the normals, or [`NO_INDEX`].
    pub normal: u32,
}

/// A mesh file's contents, PLY or OBJ: by the name's extension (`.ply`, `.obj`, any letter case)
/// when `name` has one, else by the content (a PLY file begins with `ply`). The readers'
/// warnings come back beside the mesh, never dropped. The CLI (`gonio uv`, `gonio bake`) and
/// Python (`gonio.read_mesh`) read meshes here, after the one file reader
/// ([`crate::input::file`], [`crate::input::file::FileKind::Mesh`]).
///
/// # Errors
/// The reader's [`MeshError`], located.
pub fn read_any(
    bytes: &[u8],
    name: Option<&std::path::Path>,
) -> Result<(Mesh, Vec<MeshWarning>), MeshError> {
    let ext = name
        .and_then(|p| p.extension())
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let is_ply = match ext.as_deref() {
        Some("ply") => true,
        Some("obj") => false,
        _ => bytes.starts_with(b"ply"),
    };
    if is_ply {
        ply::read_ply(bytes).map(|r| (r.mesh, r.warnings))
    } else {
        obj::read_obj(bytes).map(|r| (r.mesh, r.warnings))
    }
}

/// The largest element count (vertices, faces, list length) a reader accepts.
pub const MAX_ELEMENTS: u64 = 1 << 28;

/// Something a reader completed, repaired or dropped: never silent.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshWarning {
    /// Polygons with more than three corners were fan-triangulated.
    #[error("{count} polygons with more than 3 corners were fan-triangulated (first on line {first_line})")]
    Triangulated {
        /// How many polygons.
        count: usize,
        /// Line (OBJ) or face index (PLY) of the first.
        first_line: usize,
    },
    /// Statements or elements the reader does not use were skipped.
    #[error("{count} `{keyword}` statements/elements were skipped (first on line {first_line})")]
    Skipped {
        /// The keyword or element name.
        keyword: String,
        /// How many.
        count: usize,
        /// Line of the first (0 for PLY binary data).
        first_line: usize,
    },
}

/// Why a mesh was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// A syntax error at a known place of the file.
    #[error("{}: {message}", place(format, *line, *column, *byte))]
    Syntax {
        /// `"OBJ"` or `"PLY"`.
        format: &'static str,
        /// 1-based line (for binary PLY data: 0).
        line: usize,
        /// 1-based column in characters on that line (0 for binary PLY data).
        column: usize,
        /// Byte offset from the start of the file.
        byte: usize,
        /// What is wrong.
        message: String,
    },
    /// A face refers to an element that does not exist.
    #[error("{}: {kind} index {index} is out of range (there are {count})", place(format, *line, *column, *byte))]
    Index {
        /// `"OBJ"` or `"PLY"`.
        format: &'static str,
        /// 1-based line (binary PLY: 0).
        line: usize,
        /// 1-based column in characters on that line (0 for binary PLY data).
        column: usize,
        /// Byte offset.
        byte: usize,
        /// `"vertex"`, `"normal"` or `"texture"`.
        kind: &'static str,
        /// The index as written.
        index: i64,
        /// How many such elements exist at that point.
        count: usize,
    },
    /// A count exceeds a limit or the bytes present.
    #[error("{count} {what} exceed the limit of {limit} (or the bytes present)")]
    TooLarge {
        /// What was counted.
        what: &'static str,
        /// The count.
        count: u64,
        /// The limit.
        limit: u64,
    },
    /// The file ended inside the data.
    #[error("{format}: the file ends at byte {byte} inside {what}")]
    Truncated {
        /// `"OBJ"` or `"PLY"`.
        format: &'static str,
        /// Byte offset of the end.
        byte: usize,
        /// What was being read.
        what: String,
    },
    /// The mesh has no triangles.
    #[error("the mesh has no triangles")]
    Empty,
    /// A working buffer could not be allocated (the mesh is too large for the memory available).
    #[error("out of memory: {what} needs {bytes} bytes, which could not be allocated")]
    OutOfMemory {
        /// What the buffer is for.
        what: &'static str,
        /// Its size.
        bytes: u64,
    },
    /// A position is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFinitePosition {
        /// The vertex index.
        vertex: usize,
    },
    /// A triangle indexes a missing vertex (meshes built in code).
    #[error("triangle {triangle} refers to vertex {index}, but there are {vertices}")]
    BadTriangle {
        /// The triangle.
        triangle: usize,
        /// The index.
        index: u32,
        /// The number of vertices.
        vertices: usize,
    },
    /// An attribute array does not match the element count.
    #[error("{what}: expected {expected} entries, found {found}")]
    AttributeShape {
        /// Which attribute.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Found length.
        found: usize,
    },
    /// The mesh is not closed: some edges belong to one triangle only (holes), or to more than two.
    #[error("the mesh is not closed: {boundary_edges} edges belong to one triangle only and {nonmanifold_edges} to more than two or twice in one direction (first: vertices {first_edge:?}); fill the holes first (no hole policy: a hole would leave a region of the sphere without surface)")]
    NotClosed {
        /// Edges used by one triangle only.
        boundary_edges: usize,
        /// Edges used by more than two triangles, or twice in the same direction.
        nonmanifold_edges: usize,
        /// The first such edge.
        first_edge: [u32; 2],
    },
    /// No centre was found from which the mesh is star-shaped.
    #[error("the mesh is not star-shaped from {center:?} (the best centre found): {failing} of {triangles} triangles face the wrong way or are seen edge-on (first: {first_failing:?}); their projected solid angles sum to {solid_angle_sum:.9} sr (a star-shaped mesh needs no failing triangle and 4π)")]
    NotStarShaped {
        /// The best centre found (fewest failing triangles).
        center: [f64; 3],
        /// How many triangles fail there.
        failing: usize,
        /// The number of triangles.
        triangles: usize,
        /// The first failing triangles (at most 16).
        first_failing: Vec<usize>,
        /// Σ signed solid angles (oriented so that most are positive).
        solid_angle_sum: f64,
    },
    /// A user density is unusable.
    #[error("density: {0}")]
    Density(String),
    /// The map could not be built from the density diagram.
    #[error("the density diagram: {0}")]
    Diagram(#[from] crate::diagram::DiagramError),
}

/// An empty vector with room for `n` elements, allocated fallibly: [`MeshError::OutOfMemory`]
/// instead of an abort when the memory is not there (a `texture_uv` call with 10⁸ faces under a
/// memory limit once aborted in [`star::check_closed`]).
/// A syntax error of `format` at 1-based `line` and byte offset `byte` (its column filled in
/// later by [`with_column`]).
pub(crate) fn syntax_error(
    format: &'static str,
    line: usize,
    byte: usize,
    message: impl Into<String>,
) -> MeshError {
    MeshError::Syntax {
        format,
        line,
        column: 0,
        byte,
        message: message.into(),
    }
}

pub(crate) fn try_vec<T>(n: usize, what: &'static str) -> Result<Vec<T>, MeshError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| MeshError::OutOfMemory {
        what,
        bytes: (n as u64).saturating_mul(std::mem::size_of::<T>() as u64),
    })?;
    Ok(v)
}

/// Where an error is: `OBJ line 3, column 7 (byte 22)` in text, `PLY byte 310` in binary data.
fn place(format: &str, line: usize, column: usize, byte: usize) -> String {
    match (line, column) {
        (0, _) => format!("{format} byte {byte}"),
        (l, 0) => format!("{format} line {l} (byte {byte})"),
        (l, c) => format!("{format} line {l}, column {c} (byte {byte})"),
    }
}

/// `e` with the column of its line and byte filled in from the file's `bytes` (the readers
/// locate by byte offset; the column is counted once, here, for the error only).
pub(crate) fn with_column(e: MeshError, bytes: &[u8]) -> MeshError {
    let column_of = |line: usize, byte: usize| -> usize {
        if line == 0 || byte > bytes.len() {
            return 0;
        }
        let start = bytes[..byte]
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |p| p + 1);
        String::from_utf8_lossy(&bytes[start..byte]).chars().count() + 1
    };
    match e {
        MeshError::Syntax {
            format,
            line,
            byte,
            message,
            ..
        } => MeshError::Syntax {
            format,
            line,
            column: column_of(line, byte),
            byte,
            message,
        },
        MeshError::Index {
            format,
            line,
            byte,
            kind,
            index,
            count,
            ..
        } => MeshError::Index {
            format,
            line,
            column: column_of(line, byte),
            byte,
            kind,
            index,
            count,
        },
        e => e,
    }
}

/// At most 40 characters of `s` for a message, control characters (ESC, NUL, …) escaped as
/// `\u{1b}`, so that a message never echoes raw control bytes from a file to a terminal.
pub(crate) fn printable(s: &str) -> String {
    let mut out = String::new();
    for c in s.chars().take(40) {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}
