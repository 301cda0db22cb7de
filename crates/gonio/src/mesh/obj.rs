//! Wavefront OBJ: a reader of `v`, `vt`, `vn`, `f` (polygons fan-triangulated, negative indices
//! relative to the elements read so far) and a writer of a [`UvMesh`] with `vt` and, when a texture
//! is named, an `mtllib`/`usemtl` pair and the MTL text.
//!
//! Other statements (`o`, `g`, `s`, `usemtl`, `mtllib`, `l`, `p`, …) are skipped with a
//! [`MeshWarning::Skipped`]. Vertex colours (`v x y z r g b`) are kept as the vertex properties
//! `red`, `green`, `blue`. Every error names the line and byte offset.

use super::{Corner, Mesh, MeshError, MeshWarning, UvMesh, VertexProperty, NO_INDEX};
use std::collections::BTreeMap;
use std::fmt::Write as _;

const FMT: &str = "OBJ";

/// A mesh read from OBJ, with what the reader completed or skipped.
#[derive(Debug, Clone)]
pub struct ObjRead {
    /// The mesh.
    pub mesh: Mesh,
    /// Warnings (triangulated polygons, skipped statements).
    pub warnings: Vec<MeshWarning>,
}

fn syntax(line: usize, byte: usize, message: impl Into<String>) -> MeshError {
    super::syntax_error(FMT, line, byte, message)
}

fn number(tok: &str, line: usize, byte: usize, what: &str) -> Result<f64, MeshError> {
    match tok.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(syntax(
            line,
            byte,
            format!("{what}: `{}` is not a finite number", clip(tok)),
        )),
    }
}

fn clip(s: &str) -> String {
    super::printable(s)
}

/// Resolves a 1-based or negative OBJ index against `count` elements read so far.
fn resolve(
    tok: &str,
    count: usize,
    kind: &'static str,
    line: usize,
    byte: usize,
) -> Result<u32, MeshError> {
    let i: i64 = tok
        .parse()
        .map_err(|_| syntax(line, byte, format!("`{}` is not a {kind} index", clip(tok))))?;
    let k = if i > 0 {
        i - 1
    } else if i < 0 {
        count as i64 + i
    } else {
        -1
    };
    if k < 0 || k >= count as i64 {
        return Err(MeshError::Index {
            format: FMT,
            line,
            column: 0,
            byte,
            kind,
            index: i,
            count,
        });
    }
    Ok(k as u32)
}

/// Reads an OBJ file's bytes.
pub fn read_obj(bytes: &[u8]) -> Result<ObjRead, MeshError> {
    read_obj_located(bytes).map_err(|e| super::with_column(e, bytes))
}

fn read_obj_located(bytes: &[u8]) -> Result<ObjRead, MeshError> {
    let mut mesh = Mesh::default();
    let mut colors: Vec<[f64; 3]> = Vec::new();
    let mut any_color = false;
    let mut corner_normals: Vec<[u32; 3]> = Vec::new();
    let mut any_normal = false;
    let mut skipped: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    let mut triangulated = (0usize, 0usize);
    let mut polygons = 0u32;
    let mut offset = 0usize;
    let mut poly: Vec<(u32, u32)> = Vec::new();
    for (ln, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = ln + 1;
        let start = offset;
        offset += raw.len() + 1;
        let text = std::str::from_utf8(raw)
            .map_err(|e| syntax(line, start + e.valid_up_to(), "not UTF-8 text"))?;
        let text = text.split('#').next().unwrap_or("").trim();
        if text.is_empty() {
            continue;
        }
        // Byte offset of each token, for the messages.
        let base = start + (text.as_ptr() as usize - raw.as_ptr() as usize);
        let mut toks = text.split_ascii_whitespace();
        let kw = toks.next().unwrap_or("");
        let at = |t: &str| base + (t.as_ptr() as usize - text.as_ptr() as usize);
        match kw {
            "v" => {
                let vals: Vec<&str> = toks.collect();
                if vals.len() != 3 && vals.len() != 4 && vals.len() != 6 {
                    return Err(syntax(
                        line,
                        base,
                        format!("`v` needs 3, 4 or 6 numbers, found {}", vals.len()),
                    ));
                }
                let mut p = [0.0; 3];
                for k in 0..3 {
                    p[k] = number(vals[k], line, at(vals[k]), "vertex coordinate")?;
                }
                if vals.len() == 4 {
                    let w = number(vals[3], line, at(vals[3]), "vertex weight")?;
                    if w == 0.0 {
                        return Err(syntax(line, at(vals[3]), "vertex weight w = 0"));
                    }
                    p = [p[0] / w, p[1] / w, p[2] / w];
                    if !p.iter().all(|c| c.is_finite()) {
                        return Err(syntax(
                            line,
                            at(vals[3]),
                            format!("vertex weight {w}: the position divided by it is not finite"),
                        ));
                    }
                }
                let mut c = [0.0; 3];
                if vals.len() == 6 {
                    any_color = true;
                    for k in 0..3 {
                        c[k] = number(vals[3 + k], line, at(vals[3 + k]), "vertex colour")?;
                    }
                }
                mesh.positions.push(p);
                colors.push(c);
            }
            "vt" => {
                let vals: Vec<&str> = toks.collect();
                if vals.is_empty() || vals.len() > 3 {
                    return Err(syntax(line, base, "`vt` needs 1 to 3 numbers"));
                }
                let u = number(vals[0], line, at(vals[0]), "texture coordinate")?;
                let v = match vals.get(1) {
                    Some(t) => number(t, line, at(t), "texture coordinate")?,
                    None => 0.0,
                };
                mesh.texcoords.push([u, v]);
            }
            "vn" => {
                let vals: Vec<&str> = toks.collect();
                if vals.len() != 3 {
                    return Err(syntax(line, base, "`vn` needs 3 numbers"));
                }
                let mut n = [0.0; 3];
                for k in 0..3 {
                    n[k] = number(vals[k], line, at(vals[k]), "normal")?;
                }
                mesh.normals.push(n);
            }
            "f" => {
                poly.clear();
                for t in toks {
                    let b = at(t);
                    let mut parts = t.split('/');
                    let v = resolve(
                        parts.next().unwrap_or(""),
                        mesh.positions.len(),
                        "vertex",
                        line,
                        b,
                    )?;
                    if let Some(vt) = parts.next() {
                        if !vt.is_empty() {
                            resolve(vt, mesh.texcoords.len(), "texture", line, b)?;
                        }
                    }
                    let n = match parts.next() {
                        Some(vn) if !vn.is_empty() => {
                            any_normal = true;
                            resolve(vn, mesh.normals.len(), "normal", line, b)?
                        }
                        _ => NO_INDEX,
                    };
                    if parts.next().is_some() {
                        return Err(syntax(
                            line,
                            b,
                            format!("`{}` has more than v/vt/vn", clip(t)),
                        ));
                    }
                    poly.push((v, n));
                }
                if poly.len() < 3 {
                    return Err(syntax(
                        line,
                        base,
                        format!("a face needs at least 3 corners, found {}", poly.len()),
                    ));
                }
                if poly.len() > 3 {
                    if triangulated.0 == 0 {
                        triangulated.1 = line;
                    }
                    triangulated.0 += 1;
                }
                if mesh.triangles.len() as u64 + poly.len() as u64 > super::MAX_ELEMENTS {
                    return Err(MeshError::TooLarge {
                        what: "triangles",
                        count: mesh.triangles.len() as u64 + poly.len() as u64,
                        limit: super::MAX_ELEMENTS,
                    });
                }
                for k in 1..poly.len() - 1 {
                    mesh.triangles.push([poly[0].0, poly[k].0, poly[k + 1].0]);
                    corner_normals.push([poly[0].1, poly[k].1, poly[k + 1].1]);
                    mesh.source_face.push(polygons);
                }
                polygons = polygons.saturating_add(1);
            }
            _ => {
                let e = skipped.entry(clip(kw)).or_insert((0, line));
                e.0 += 1;
            }
        }
    }
    if any_normal {
        mesh.triangle_normals = corner_normals;
    }
    if any_color {
        for (k, name) in ["red", "green", "blue"].iter().enumerate() {
            mesh.vertex_properties.push(VertexProperty {
                name: (*name).into(),
                values: colors.iter().map(|c| c[k]).collect(),
            });
        }
    }
    if mesh.triangles.is_empty() {
        return Err(MeshError::Empty);
    }
    let mut warnings = Vec::new();
    if triangulated.0 > 0 {
        warnings.push(MeshWarning::Triangulated {
            count: triangulated.0,
            first_line: triangulated.1,
        });
    }
    for (keyword, (count, first_line)) in skipped {
        warnings.push(MeshWarning::Skipped {
            keyword,
            count,
            first_line,
        });
    }
    Ok(ObjRead { mesh, warnings })
}

/// Writes `mesh` as OBJ text: `v` (with `r g b` when the mesh carries `red`, `green`, `blue`),
/// `vt`, `vn`, and `f p/t[/n]` faces. With `material` = `Some((mtl_file, texture_file))` the text
/// starts with `mtllib` and `usemtl gonio_texture`; [`write_mtl`] makes the MTL.
pub fn write_obj(mesh: &UvMesh, material: Option<(&str, &str)>) -> String {
    let mut s = String::with_capacity(mesh.positions.len() * 40 + mesh.triangles.len() * 30);
    s.push_str("# gonio uv: one chart from the inverse HDS map\n");
    if let Some((mtl, _)) = material {
        let _ = writeln!(s, "mtllib {mtl}");
    }
    let rgb = ["red", "green", "blue"].map(|n| {
        mesh.vertex_properties
            .iter()
            .find(|p| p.name == n)
            .map(|p| &p.values)
    });
    for (i, p) in mesh.positions.iter().enumerate() {
        let _ = write!(s, "v {} {} {}", p[0], p[1], p[2]);
        if let [Some(r), Some(g), Some(b)] = rgb {
            let _ = write!(s, " {} {} {}", r[i], g[i], b[i]);
        }
        s.push('\n');
    }
    for t in &mesh.uvs {
        let _ = writeln!(s, "vt {} {}", t[0], t[1]);
    }
    for n in &mesh.normals {
        let _ = writeln!(s, "vn {} {} {}", n[0], n[1], n[2]);
    }
    if material.is_some() {
        s.push_str("usemtl gonio_texture\n");
    }
    for tri in &mesh.triangles {
        s.push('f');
        for c in tri {
            write_corner(&mut s, c);
        }
        s.push('\n');
    }
    s
}

fn write_corner(s: &mut String, c: &Corner) {
    if c.normal == NO_INDEX {
        let _ = write!(s, " {}/{}", c.position + 1, c.uv + 1);
    } else {
        let _ = write!(s, " {}/{}/{}", c.position + 1, c.uv + 1, c.normal + 1);
    }
}

/// The MTL text of the material `gonio_texture` whose diffuse map is `texture_file`.
pub fn write_mtl(texture_file: &str) -> String {
    format!(
        "# gonio bake\nnewmtl gonio_texture\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1\nmap_Kd {texture_file}\n"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_polygons_negative_indices_and_normals() {
        let text = b"# cube corner\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\ng x\nf -4//1 -3//1 -2//1 -1//1\nf 1/1 2/1 3/1\n";
        let r = read_obj(text).unwrap();
        assert_eq!(r.mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
        assert_eq!(r.mesh.source_face, vec![0, 0, 1]);
        assert_eq!(r.mesh.triangle_normals[0], [0, 0, 0]);
        assert_eq!(r.mesh.triangle_normals[2], [NO_INDEX; 3]);
        assert_eq!(r.warnings.len(), 2);
        assert!(matches!(
            r.warnings[0],
            MeshWarning::Triangulated {
                count: 1,
                first_line: 9
            }
        ));
    }

    #[test]
    fn errors_are_located() {
        let e = read_obj(b"v 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap_err();
        assert_eq!(
            e,
            MeshError::Index {
                format: FMT,
                line: 3,
                column: 7,
                byte: 22,
                kind: "vertex",
                index: 3,
                count: 2
            }
        );
        let e = read_obj(b"v 0 0 0\nv 1 x 0\n").unwrap_err();
        assert!(
            matches!(
                e,
                MeshError::Syntax {
                    line: 2,
                    byte: 12,
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(matches!(
            read_obj(b"v 0 0 nan\n"),
            Err(MeshError::Syntax { .. })
        ));
        assert_eq!(read_obj(b"v 0 0 0\n").unwrap_err(), MeshError::Empty);
        assert!(matches!(
            read_obj(b"v 0 0 0\nf 1 1\n"),
            Err(MeshError::Syntax { line: 2, .. })
        ));
    }

    #[test]
    fn vertex_colours_are_kept() {
        let r = read_obj(b"v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n").unwrap();
        assert_eq!(r.mesh.property("green").unwrap(), &[0.0, 1.0, 0.0]);
    }

    /// Issue 40: OBJ messages echoed raw ESC and NUL bytes from the file.
    #[test]
    fn messages_escape_control_bytes() {
        for text in [
            &b"v 0 0 \x1b[2J\n"[..],
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \x003\n",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/\x07/\x1b/x\n",
        ] {
            let m = read_obj(text).unwrap_err().to_string();
            assert!(!m.chars().any(|c| c.is_control()), "{m:?}");
            assert!(m.contains("\\u{"), "{m:?}");
        }
        let r = read_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n\x1bx 1\nf 1 2 3\n").unwrap();
        let w = r.warnings[0].to_string();
        assert!(!w.chars().any(|c| c.is_control()), "{w:?}");
        // Located by line and column (characters, not bytes).
        let e = read_obj("v 0 0 0\n# é\nv 1 é 0\n".as_bytes()).unwrap_err();
        assert!(
            e.to_string().starts_with("OBJ line 3, column 5 (byte 17)"),
            "{e}"
        );
        // A weight that makes the position overflow is refused (no inf from finite numbers).
        assert!(matches!(
            read_obj(b"v 1e300 0 0 1e-300\n"),
            Err(MeshError::Syntax { line: 1, .. })
        ));
    }
}
