//! Stanford PLY: ASCII, binary little endian and binary big endian, with the `vertex` element
//! (x, y, z; nx, ny, nz kept as normals; every other scalar property kept by name) and the `face`
//! element (a list property `vertex_indices` or `vertex_index`; polygons fan-triangulated). Other
//! elements are read past and reported with a [`MeshWarning::Skipped`].
//!
//! Every element count is checked against the bytes present before anything is allocated: a
//! binary element needs at least its fixed size, an ASCII value at least two bytes.

use super::{printable, Mesh, MeshError, MeshWarning, VertexProperty, MAX_ELEMENTS};

const FMT: &str = "PLY";

/// A mesh read from PLY, with what the reader completed or skipped.
#[derive(Debug, Clone)]
pub struct PlyRead {
    /// The mesh.
    pub mesh: Mesh,
    /// Warnings.
    pub warnings: Vec<MeshWarning>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
    fn integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Debug, Clone)]
enum Property {
    Scalar(String, Scalar),
    List(String, Scalar, Scalar),
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
    line: usize,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

fn syntax(line: usize, byte: usize, message: impl Into<String>) -> MeshError {
    super::syntax_error(FMT, line, byte, message)
}

/// The data cursor: binary or ASCII tokens.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    enc: Encoding,
    line: usize,
}

impl Cursor<'_> {
    fn truncated(&self, what: &str) -> MeshError {
        MeshError::Truncated {
            format: FMT,
            byte: self.bytes.len(),
            what: what.into(),
        }
    }
    fn here(&self) -> (usize, usize) {
        (
            if self.enc == Encoding::Ascii {
                self.line
            } else {
                0
            },
            self.pos,
        )
    }
    fn read(&mut self, t: Scalar, what: &str) -> Result<f64, MeshError> {
        if self.enc == Encoding::Ascii {
            return self.token(t, what);
        }
        let n = t.size();
        let Some(b) = self.bytes.get(self.pos..self.pos + n) else {
            return Err(self.truncated(what));
        };
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.enc == Encoding::Big {
            a[..n].reverse();
        }
        Ok(match t {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }
    fn token(&mut self, t: Scalar, what: &str) -> Result<f64, MeshError> {
        while let Some(&c) = self.bytes.get(self.pos) {
            if c == b'\n' {
                self.line += 1;
            } else if !c.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|c| !c.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.truncated(what));
        }
        let s = std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("");
        let v: Option<f64> = if t.integer() {
            s.parse::<i64>().ok().map(|i| i as f64)
        } else {
            s.parse::<f64>().ok()
        };
        match v {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(syntax(
                self.line,
                start,
                format!("{what}: `{}` is not a valid {:?} value", printable(s), t),
            )),
        }
    }
}

/// A finite value with no fractional part (an index or a list length; a float PLY property may
/// hold 1.5 or NaN, which are refused rather than truncated).
fn whole(v: f64) -> bool {
    v.is_finite() && v.fract() == 0.0
}

/// Reads a PLY file's bytes.
pub fn read_ply(bytes: &[u8]) -> Result<PlyRead, MeshError> {
    read_ply_located(bytes).map_err(|e| super::with_column(e, bytes))
}

fn read_ply_located(bytes: &[u8]) -> Result<PlyRead, MeshError> {
    // The header: ASCII lines up to `end_header`.
    let mut pos = 0usize;
    let mut line = 0usize;
    let mut elements: Vec<Element> = Vec::new();
    let mut encoding = None;
    loop {
        let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err(MeshError::Truncated {
                format: FMT,
                byte: bytes.len(),
                what: "the header (no `end_header`)".into(),
            });
        };
        line += 1;
        let raw = &bytes[pos..pos + len];
        let start = pos;
        pos += len + 1;
        let text = std::str::from_utf8(raw)
            .map_err(|_| syntax(line, start, "the header is not text"))?
            .trim_end_matches('\r');
        let toks: Vec<&str> = text.split_ascii_whitespace().collect();
        if line == 1 {
            if text.trim() != "ply" {
                return Err(syntax(
                    1,
                    0,
                    "not a PLY file (the first line must be `ply`)",
                ));
            }
            continue;
        }
        match toks.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                encoding = Some(match toks.get(1).copied() {
                    Some("ascii") => Encoding::Ascii,
                    Some("binary_little_endian") => Encoding::Little,
                    Some("binary_big_endian") => Encoding::Big,
                    _ => return Err(syntax(line, start, "unknown PLY format")),
                });
            }
            Some("element") => {
                let (Some(name), Some(count), None) = (toks.get(1), toks.get(2), toks.get(3))
                else {
                    return Err(syntax(line, start, "`element` needs a name and a count"));
                };
                let count: u64 = count.parse().map_err(|_| {
                    syntax(
                        line,
                        start,
                        format!("bad element count `{}`", printable(count)),
                    )
                })?;
                if count > MAX_ELEMENTS {
                    return Err(MeshError::TooLarge {
                        what: "elements",
                        count,
                        limit: MAX_ELEMENTS,
                    });
                }
                elements.push(Element {
                    name: (*name).into(),
                    count,
                    props: Vec::new(),
                    line,
                });
            }
            Some("property") => {
                let Some(el) = elements.last_mut() else {
                    return Err(syntax(line, start, "`property` before any `element`"));
                };
                let p = if toks.get(1) == Some(&"list") {
                    match (
                        toks.get(2).and_then(|s| Scalar::parse(s)),
                        toks.get(3).and_then(|s| Scalar::parse(s)),
                        toks.get(4),
                    ) {
                        (Some(c), Some(i), Some(n)) if c.integer() && toks.len() == 5 => {
                            Property::List((*n).into(), c, i)
                        }
                        _ => return Err(syntax(line, start, "bad list property")),
                    }
                } else {
                    match (toks.get(1).and_then(|s| Scalar::parse(s)), toks.get(2)) {
                        (Some(t), Some(n)) if toks.len() == 3 => Property::Scalar((*n).into(), t),
                        _ => return Err(syntax(line, start, "bad property")),
                    }
                };
                el.props.push(p);
            }
            Some("end_header") => break,
            Some(other) => {
                return Err(syntax(
                    line,
                    start,
                    format!("unknown header keyword `{}`", printable(other)),
                ))
            }
        }
    }
    let Some(enc) = encoding else {
        return Err(syntax(line, pos, "the header has no `format` line"));
    };
    // Caps against the bytes present: each element needs at least its fixed size in binary, or
    // two bytes per value in ASCII.
    let mut need: u128 = 0;
    for el in &elements {
        let per: u64 = el
            .props
            .iter()
            .map(|p| match (p, enc) {
                (_, Encoding::Ascii) => 2,
                (Property::Scalar(_, t), _) => t.size() as u64,
                (Property::List(_, c, _), _) => c.size() as u64,
            })
            .sum();
        need += el.count as u128 * per as u128;
    }
    let available = (bytes.len() - pos) as u128;
    if need > available {
        return Err(MeshError::TooLarge {
            what: "bytes of element data announced by the header",
            count: need.min(u64::MAX as u128) as u64,
            limit: available as u64,
        });
    }
    let mut cur = Cursor {
        bytes,
        pos,
        enc,
        line: line + 1,
    };
    let mut mesh = Mesh::default();
    let mut warnings = Vec::new();
    let mut have_vertices = false;
    let mut triangulated = (0usize, 0usize);
    let mut poly: Vec<u32> = Vec::new();
    for el in &elements {
        let n = el.count as usize;
        if el.name == "vertex" && !have_vertices {
            have_vertices = true;
            let idx = |name: &str| {
                el.props
                    .iter()
                    .position(|p| matches!(p, Property::Scalar(n, _) if n == name))
            };
            let (Some(ix), Some(iy), Some(iz)) = (idx("x"), idx("y"), idx("z")) else {
                return Err(syntax(el.line, 0, "the vertex element lacks x, y or z"));
            };
            let normal = match (idx("nx"), idx("ny"), idx("nz")) {
                (Some(a), Some(b), Some(c)) => Some([a, b, c]),
                _ => None,
            };
            let mut extra: Vec<(usize, VertexProperty)> = Vec::new();
            for (k, p) in el.props.iter().enumerate() {
                if let Property::Scalar(name, _) = p {
                    let used =
                        k == ix || k == iy || k == iz || normal.is_some_and(|nn| nn.contains(&k));
                    if !used {
                        extra.push((
                            k,
                            VertexProperty {
                                name: name.clone(),
                                values: Vec::with_capacity(n),
                            },
                        ));
                    }
                }
            }
            mesh.positions.reserve(n);
            let mut vals = vec![0.0; el.props.len()];
            for v in 0..n {
                for (k, p) in el.props.iter().enumerate() {
                    match p {
                        Property::Scalar(name, t) => {
                            // Every vertex attribute (position, normal, colour, …) must be finite:
                            // a binary NaN normal was once written out as `vn NaN NaN NaN`.
                            let (l, b) = cur.here();
                            let x = cur.read(*t, "vertex data")?;
                            if !x.is_finite() {
                                return Err(syntax(
                                    l,
                                    b,
                                    format!(
                                        "vertex {v}: property `{}` is {x}, not a finite number",
                                        printable(name)
                                    ),
                                ));
                            }
                            vals[k] = x;
                        }
                        Property::List(_, c, t) => {
                            let (l, b) = cur.here();
                            let len = cur.read(*c, "vertex list length")?;
                            if !whole(len) || len < 0.0 {
                                return Err(syntax(
                                    l,
                                    b,
                                    format!("vertex {v}: bad list length {len}"),
                                ));
                            }
                            for _ in 0..len as u64 {
                                cur.read(*t, "vertex list")?;
                            }
                        }
                    }
                }
                let p = [vals[ix], vals[iy], vals[iz]];
                if !p.iter().all(|c| c.is_finite()) {
                    let (l, b) = cur.here();
                    return Err(syntax(
                        l,
                        b,
                        format!("vertex {v} has a non-finite coordinate"),
                    ));
                }
                mesh.positions.push(p);
                if let Some([a, b, c]) = normal {
                    mesh.normals.push([vals[a], vals[b], vals[c]]);
                }
                for (k, prop) in &mut extra {
                    prop.values.push(vals[*k]);
                }
            }
            mesh.vertex_properties = extra.into_iter().map(|(_, p)| p).collect();
        } else if el.name == "face" && mesh.triangles.is_empty() {
            let list = el.props.iter().position(|p| {
                matches!(p, Property::List(n, _, _) if n == "vertex_indices" || n == "vertex_index")
            });
            let Some(list) = list else {
                return Err(syntax(
                    el.line,
                    0,
                    "the face element lacks a `vertex_indices` list",
                ));
            };
            for f in 0..n {
                for (k, p) in el.props.iter().enumerate() {
                    match p {
                        Property::Scalar(_, t) => {
                            cur.read(*t, "face data")?;
                        }
                        Property::List(_, c, t) => {
                            let len = cur.read(*c, "face list length")?;
                            let (l, b) = cur.here();
                            if !whole(len)
                                || len < 0.0
                                || len as u64 > (bytes.len() - cur.pos) as u64
                            {
                                return Err(syntax(
                                    l,
                                    b,
                                    format!("face {f}: bad list length {len}"),
                                ));
                            }
                            if k != list {
                                for _ in 0..len as u64 {
                                    cur.read(*t, "face list")?;
                                }
                                continue;
                            }
                            if len < 3.0 {
                                return Err(syntax(
                                    l,
                                    b,
                                    format!("face {f} has {len} corners; a face needs 3"),
                                ));
                            }
                            poly.clear();
                            for _ in 0..len as u64 {
                                let (l, b) = cur.here();
                                let i = cur.read(*t, "face indices")?;
                                if !whole(i) {
                                    return Err(syntax(
                                        l,
                                        b,
                                        format!(
                                            "face {f}: the vertex index {i} is not a whole number"
                                        ),
                                    ));
                                }
                                if !(i >= 0.0 && (i as usize) < mesh.positions.len()) {
                                    return Err(MeshError::Index {
                                        format: FMT,
                                        line: l,
                                        column: 0,
                                        byte: b,
                                        kind: "vertex",
                                        index: i as i64,
                                        count: mesh.positions.len(),
                                    });
                                }
                                poly.push(i as u32);
                            }
                            if poly.len() > 3 {
                                if triangulated.0 == 0 {
                                    triangulated.1 = f;
                                }
                                triangulated.0 += 1;
                            }
                            for k in 1..poly.len() - 1 {
                                mesh.triangles.push([poly[0], poly[k], poly[k + 1]]);
                                mesh.source_face.push(f as u32);
                            }
                        }
                    }
                }
            }
        } else {
            for _ in 0..n {
                for p in &el.props {
                    match p {
                        Property::Scalar(_, t) => {
                            cur.read(*t, "element data")?;
                        }
                        Property::List(_, c, t) => {
                            let len = cur.read(*c, "list length")?;
                            if !whole(len)
                                || len < 0.0
                                || len as u64 > (bytes.len() - cur.pos) as u64
                            {
                                let (l, b) = cur.here();
                                return Err(syntax(l, b, format!("bad list length {len}")));
                            }
                            for _ in 0..len as u64 {
                                cur.read(*t, "list")?;
                            }
                        }
                    }
                }
            }
            warnings.push(MeshWarning::Skipped {
                keyword: printable(&el.name),
                count: n,
                first_line: el.line,
            });
        }
    }
    if mesh.triangles.is_empty() {
        return Err(MeshError::Empty);
    }
    if triangulated.0 > 0 {
        warnings.push(MeshWarning::Triangulated {
            count: triangulated.0,
            first_line: triangulated.1,
        });
    }
    Ok(PlyRead { mesh, warnings })
}

/// Writes `mesh` (positions, triangles and vertex properties as `double`) as binary little-endian
/// PLY: the generated test meshes' format, and a round-trip check of [`read_ply`].
pub fn write_ply_binary(mesh: &Mesh) -> Vec<u8> {
    let mut h = format!(
        "ply\nformat binary_little_endian 1.0\ncomment gonio\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n",
        mesh.positions.len()
    );
    for p in &mesh.vertex_properties {
        h.push_str(&format!("property double {}\n", p.name));
    }
    h.push_str(&format!(
        "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.triangles.len()
    ));
    let mut out = h.into_bytes();
    for (i, p) in mesh.positions.iter().enumerate() {
        for c in p {
            out.extend_from_slice(&c.to_le_bytes());
        }
        for q in &mesh.vertex_properties {
            out.extend_from_slice(&q.values[i].to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        for v in t {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment x\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar weight\nelement face 1\nproperty list uchar int vertex_indices\nelement edge 1\nproperty int a\nproperty int b\nend_header\n0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n4 0 1 2 3\n0 1\n";

    #[test]
    fn ascii_with_extra_property_and_quad() {
        let r = read_ply(ASCII.as_bytes()).unwrap();
        assert_eq!(r.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(r.mesh.property("weight").unwrap(), &[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(r.warnings.len(), 2);
    }

    #[test]
    fn binary_round_trip_both_endians() {
        let mut m = read_ply(ASCII.as_bytes()).unwrap().mesh;
        m.source_face = vec![0, 1];
        let bin = write_ply_binary(&m);
        let back = read_ply(&bin).unwrap().mesh;
        assert_eq!(back.positions, m.positions);
        assert_eq!(back.triangles, m.triangles);
        assert_eq!(back.vertex_properties, m.vertex_properties);
        // Big endian by hand: one triangle, float coordinates, ushort indices.
        let mut b = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar ushort vertex_indices\nend_header\n".to_vec();
        for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
            for c in p {
                b.extend_from_slice(&c.to_be_bytes());
            }
        }
        b.push(3);
        for i in [0u16, 1, 2] {
            b.extend_from_slice(&i.to_be_bytes());
        }
        let m = read_ply(&b).unwrap().mesh;
        assert_eq!(m.positions[1], [1.0, 0.0, 0.0]);
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        // Truncated: the last index is missing.
        assert!(matches!(
            read_ply(&b[..b.len() - 1]),
            Err(MeshError::Truncated { .. })
        ));
    }

    #[test]
    fn counts_are_capped_by_the_bytes_present() {
        let b = b"ply\nformat binary_little_endian 1.0\nelement vertex 100000000\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
        assert!(matches!(read_ply(b), Err(MeshError::TooLarge { .. })));
        let e = read_ply(b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").unwrap_err();
        assert!(
            matches!(
                e,
                MeshError::Index {
                    line: 13,
                    index: 7,
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(matches!(
            read_ply(b"plx\n"),
            Err(MeshError::Syntax { line: 1, .. })
        ));
    }

    /// A binary little-endian tetrahedron: float x y z nx ny nz, face indices of type `index`.
    fn tetra(normal_of_vertex_2: f32, index: &str, indices: [f32; 3]) -> Vec<u8> {
        let mut b = format!("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 4\nproperty list uchar {index} vertex_indices\nend_header\n").into_bytes();
        let pts = [
            [1f32, 1., 1.],
            [1., -1., -1.],
            [-1., 1., -1.],
            [-1., -1., 1.],
        ];
        for (k, p) in pts.iter().enumerate() {
            for c in p {
                b.extend(c.to_le_bytes());
            }
            let n = if k == 2 { normal_of_vertex_2 } else { 0.5 };
            for _ in 0..3 {
                b.extend(n.to_le_bytes());
            }
        }
        for (f, t) in [[0f32, 1., 2.], [0., 3., 1.], [0., 2., 3.], [1., 3., 2.]]
            .iter()
            .enumerate()
        {
            b.push(3);
            let t = if f == 3 { indices } else { *t };
            for i in t {
                if index == "float" {
                    b.extend(i.to_le_bytes());
                } else {
                    b.extend((i as i32).to_le_bytes());
                }
            }
        }
        b
    }

    /// Issue 40: a binary PLY with NaN normals was accepted (`uv` wrote `vn NaN NaN NaN`).
    #[test]
    fn non_finite_vertex_attributes_are_refused_with_the_vertex() {
        assert!(read_ply(&tetra(0.5, "int", [1., 3., 2.])).is_ok());
        for bad in [f32::NAN, f32::INFINITY] {
            let e = read_ply(&tetra(bad, "int", [1., 3., 2.])).unwrap_err();
            let header = tetra(0.5, "int", [1., 3., 2.]).len() - 4 * 24 - 4 * 13;
            match &e {
                MeshError::Syntax { byte, message, .. } => {
                    assert_eq!(*byte, header + 2 * 24 + 12, "{e}");
                    // Binary data: located by byte offset, no line.
                    assert!(
                        e.to_string().starts_with(&format!("PLY byte {byte}: ")),
                        "{e}"
                    );
                    assert!(
                        message.contains("vertex 2") && message.contains("`nx`"),
                        "{e}"
                    );
                }
                other => panic!("{other:?}"),
            }
        }
    }

    /// Issue 40: fractional float face indices were truncated and a NaN index was reported as
    /// "vertex index 0 is out of range".
    #[test]
    fn float_face_indices_must_be_whole_numbers() {
        assert!(read_ply(&tetra(0.5, "float", [1., 3., 2.])).is_ok());
        let e = read_ply(&tetra(0.5, "float", [1., 3.5, 2.])).unwrap_err();
        assert!(
            matches!(&e, MeshError::Syntax { message, .. } if message.contains("face 3") && message.contains("3.5") && message.contains("not a whole number")),
            "{e}"
        );
        let e = read_ply(&tetra(0.5, "float", [1., f32::NAN, 2.])).unwrap_err();
        assert!(
            matches!(&e, MeshError::Syntax { message, .. } if message.contains("NaN")),
            "{e}"
        );
    }

    /// Issue 40: messages never echo raw control bytes from the file.
    #[test]
    fn messages_escape_control_bytes() {
        let e = read_ply(b"ply\nformat ascii 1.0\n\x1b[31m\0x\nend_header\n").unwrap_err();
        let m = e.to_string();
        assert!(!m.bytes().any(|b| b.is_ascii_control()), "{m:?}");
        assert!(m.contains("\\u{1b}"), "{m:?}");
        // A skipped element's name, quoted by its warning.
        let text = ASCII.replace("element edge 1", "element \x1b[2J 1");
        let r = read_ply(text.as_bytes()).unwrap();
        for w in &r.warnings {
            let w = w.to_string();
            assert!(!w.chars().any(|c| c.is_control()), "{w:?}");
        }
    }
}
