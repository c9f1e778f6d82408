//! The Wavefront OBJ reader: positions (`v`), texture coordinates (`vt`), normals (`vn`), faces
//! (`f`), and the material statements (`mtllib`, `usemtl`) that [`crate::scene::model::obj`]
//! resolves against MTL files.
//!
//! Faces take the `v`, `v/vt`, `v//vn` and `v/vt/vn` forms. Negative indices count back from
//! the last one read. Polygons are fanned into triangles from their first vertex. Every other
//! statement (`o`, `g`, `s`, `l`, ...) is ignored. Every error names its line and column (in
//! characters, as scene-file errors do). A UTF-8 byte order mark at the start of the file
//! (Windows editors write one) is skipped.
//!
//! Scene files' meshes ([`parse_obj`]) take the positions only, and ignore the texture and
//! normal references as they always did; model files ([`parse_obj_model`]) check and keep them.
//!
//! Why not the `tobj` crate: its errors say what went wrong but not where, and every mistake in
//! a user's file must name its line and column.

use std::borrow::Cow;

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use crate::scene::MAX_COORDINATE;

/// The UTF-8 byte order mark, which some editors write at the start of a text file.
const BOM: &[u8] = b"\xEF\xBB\xBF";

/// A mesh's triangles, each with the line and column of the face it came from.
#[derive(Clone, Debug, Default)]
pub struct ObjMesh {
    /// Triangles in file order, polygons fanned.
    pub triangles: Vec<[Vec3; 3]>,
    /// For each triangle, the 1-based (line, column) of its face statement.
    pub origins: Vec<(u32, u32)>,
}

/// A mistake in an OBJ file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ObjError {
    /// 1-based line.
    pub line: usize,
    /// 1-based column in characters (invalid UTF-8 counts as [`line_text`] shows it).
    pub column: usize,
    /// What was wrong and what would be right.
    pub message: String,
}

/// An OBJ file as a model: indexed vertices (one per distinct position/UV/normal corner),
/// triangles, and the materials by name.
#[derive(Clone, Debug, Default)]
pub struct ObjModel {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Texture coordinates, one per position when any corner has one (zero where none).
    pub uvs: Vec<Vec2>,
    /// Normals, one per position when any corner has one (zero where none).
    pub normals: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's index into `material_names`.
    pub triangle_materials: Vec<u32>,
    /// The names given to `usemtl`, in order of first use; "" for faces before any.
    pub material_names: Vec<String>,
    /// The libraries `mtllib` names, each with its 1-based line and column.
    pub libraries: Vec<(String, usize, usize)>,
}

/// Reads `bytes` as OBJ, giving up with an error past `max_triangles` triangles or
/// `max_vertices` vertices.
pub fn parse_obj(
    bytes: &[u8],
    max_triangles: usize,
    max_vertices: usize,
) -> Result<ObjMesh, ObjError> {
    let mut mesh = ObjMesh::default();
    read(
        bytes,
        max_triangles,
        max_vertices,
        false,
        &mut |event| match event {
            Event::Face(face, origin) => {
                for i in 1..face.len() - 1 {
                    mesh.triangles.push([face[0].0, face[i].0, face[i + 1].0]);
                    mesh.origins.push(origin);
                }
            }
            Event::Material(..) | Event::Library(..) => {}
        },
    )?;
    Ok(mesh)
}

/// Reads `bytes` as an OBJ model with its texture coordinates, normals and materials, giving up
/// with an error past `max_triangles` triangles or `max_vertices` vertices.
pub fn parse_obj_model(
    bytes: &[u8],
    max_triangles: usize,
    max_vertices: usize,
) -> Result<ObjModel, ObjError> {
    let mut m = ObjModel::default();
    let mut corners: HashMap<[u32; 3], u32> = HashMap::new();
    let mut material = None;
    let mut corner_ids: Vec<u32> = Vec::new();
    read(
        bytes,
        max_triangles,
        max_vertices,
        true,
        &mut |event| match event {
            Event::Face(face, _) => {
                let mat = *material.get_or_insert_with(|| {
                    m.material_names.push(String::new());
                    m.material_names.len() as u32 - 1
                });
                corner_ids.clear();
                for &(p, uv, n, key) in face {
                    let next = m.positions.len() as u32;
                    let id = *corners.entry(key).or_insert(next);
                    if id == next {
                        m.positions.push(p);
                        if let Some(uv) = uv {
                            m.uvs.resize(m.positions.len() - 1, Vec2::ZERO);
                            m.uvs.push(uv);
                        }
                        if let Some(n) = n {
                            m.normals.resize(m.positions.len() - 1, Vec3::ZERO);
                            m.normals.push(n);
                        }
                    }
                    corner_ids.push(id);
                }
                for i in 1..corner_ids.len() - 1 {
                    m.triangles
                        .push([corner_ids[0], corner_ids[i], corner_ids[i + 1]]);
                    m.triangle_materials.push(mat);
                }
            }
            Event::Material(name) => {
                let at = m.material_names.iter().position(|n| n == name);
                material = Some(at.unwrap_or_else(|| {
                    m.material_names.push(name.to_string());
                    m.material_names.len() - 1
                }) as u32);
            }
            Event::Library(name, line, column) => {
                m.libraries.push((name.to_string(), line, column))
            }
        },
    )?;
    if !m.uvs.is_empty() {
        m.uvs.resize(m.positions.len(), Vec2::ZERO);
    }
    if !m.normals.is_empty() {
        m.normals.resize(m.positions.len(), Vec3::ZERO);
    }
    Ok(m)
}

/// A face corner: its position, texture coordinate and normal if given, and the key of the
/// indices that name them (position, UV, normal; `u32::MAX` where none).
type Corner = (Vec3, Option<Vec2>, Option<Vec3>, [u32; 3]);

/// What [`read`] hands its caller, statement by statement.
enum Event<'a> {
    /// A face (at least 3 corners) with the 1-based line and column of its statement.
    Face(&'a [Corner], (u32, u32)),
    /// `usemtl NAME`.
    Material(&'a str),
    /// `mtllib NAME` with its line and column.
    Library(&'a str, usize, usize),
}

/// Reads the statements of `bytes`, handing faces and material statements to `on`. With
/// `attributes` the faces' texture and normal references are checked and resolved (a model);
/// without, they are skipped, as a scene file's mesh always did.
fn read(
    bytes: &[u8],
    max_triangles: usize,
    max_vertices: usize,
    attributes: bool,
    on: &mut dyn FnMut(Event),
) -> Result<(), ObjError> {
    let mut vertices: Vec<Vec3> = Vec::new();
    let mut uvs: Vec<Vec2> = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    let mut face: Vec<Corner> = Vec::new();
    let mut triangles = 0usize;
    let bytes = bytes.strip_prefix(BOM).unwrap_or(bytes);
    for (n, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = n + 1;
        let content = match raw.iter().position(|&b| b == b'#') {
            Some(i) => &raw[..i],
            None => raw,
        };
        let mut tokens = tokens(content);
        let Some((col, keyword)) = tokens.next() else {
            continue;
        };
        // Token columns are bytes; an error converts its own to characters.
        let err = |byte_column: usize, message: String| ObjError {
            line,
            column: char_column(raw, byte_column),
            message,
        };
        // Reads `N` numbers after the keyword (`needed` of them required, the rest 0).
        let numbers = |tokens: &mut dyn Iterator<Item = (usize, &[u8])>,
                       needed: usize,
                       out: &mut [f32],
                       what: &str|
         -> Result<(), ObjError> {
            for (axis, value) in out.iter_mut().enumerate() {
                let Some((c, tok)) = tokens.next() else {
                    if axis >= needed {
                        return Ok(());
                    }
                    return Err(err(col, format!("{what}, this one has {axis}")));
                };
                *value = number(tok).ok_or_else(|| {
                    err(
                        c,
                        format!("`{}` is not a number", String::from_utf8_lossy(tok)),
                    )
                })?;
                if !value.is_finite() || value.abs() > MAX_COORDINATE {
                    return Err(err(
                        c,
                        format!(
                            "`{}` is out of range: expected a finite number within ±{MAX_COORDINATE:e}",
                            String::from_utf8_lossy(tok)
                        ),
                    ));
                }
            }
            Ok(())
        };
        match keyword {
            b"v" => {
                let mut p = [0.0f32; 3];
                numbers(
                    &mut tokens,
                    3,
                    &mut p,
                    "a vertex needs 3 coordinates (v x y z)",
                )?;
                if vertices.len() >= max_vertices {
                    return Err(err(
                        col,
                        format!("the mesh has more than {max_vertices} vertices, the limit"),
                    ));
                }
                vertices.push(Vec3::from(p));
            }
            b"vt" => {
                let mut t = [0.0f32; 3];
                numbers(
                    &mut tokens,
                    1,
                    &mut t,
                    "a texture coordinate needs a number (vt u v)",
                )?;
                if uvs.len() >= max_vertices {
                    return Err(err(
                        col,
                        format!(
                            "the mesh has more than {max_vertices} texture coordinates, the limit"
                        ),
                    ));
                }
                uvs.push(Vec2::new(t[0], t[1]));
            }
            b"vn" => {
                let mut d = [0.0f32; 3];
                numbers(
                    &mut tokens,
                    3,
                    &mut d,
                    "a normal needs 3 numbers (vn x y z)",
                )?;
                if normals.len() >= max_vertices {
                    return Err(err(
                        col,
                        format!("the mesh has more than {max_vertices} normals, the limit"),
                    ));
                }
                normals.push(Vec3::from(d).normalize_or_zero());
            }
            b"usemtl" | b"mtllib" => {
                let Some((c, _)) = tokens.next() else {
                    return Err(err(
                        col,
                        format!("`{}` needs a name", String::from_utf8_lossy(keyword)),
                    ));
                };
                // The name is the rest of the line (names may hold spaces), trimmed.
                let rest = String::from_utf8_lossy(&content[c - 1..]);
                let name = rest.trim();
                if keyword == b"usemtl" {
                    on(Event::Material(name));
                } else {
                    on(Event::Library(name, line, char_column(raw, c)));
                }
            }
            b"f" => {
                face.clear();
                for (c, tok) in tokens {
                    let mut parts = tok.split(|&b| b == b'/');
                    let index_text = parts.next().unwrap_or(tok);
                    let bad_reference = || {
                        err(
                            c,
                            format!(
                                "`{}` is not a vertex reference: expected i, i/t, i//n or i/t/n with whole numbers",
                                String::from_utf8_lossy(tok)
                            ),
                        )
                    };
                    let whole = |text: &[u8]| {
                        std::str::from_utf8(text)
                            .ok()
                            .and_then(|s| s.parse::<i64>().ok())
                    };
                    let index = whole(index_text).ok_or_else(bad_reference)?;
                    // Resolves a 1-based or negative index among `count` items.
                    let resolve = |index: i64, count: usize, what: &str, plural: &str| {
                        let count = count as i64;
                        let resolved = match index {
                            0 => {
                                return Err(err(
                                    c,
                                    format!(
                                        "{what} index 0: OBJ indices start at 1 (or count back from -1)"
                                    ),
                                ));
                            }
                            i if i > 0 => i - 1,
                            i => count + i,
                        };
                        if !(0..count).contains(&resolved) {
                            return Err(err(
                                c,
                                format!(
                                    "{what} index {index} is out of range: {count} {plural} are defined before this face"
                                ),
                            ));
                        }
                        Ok(resolved as usize)
                    };
                    let v = resolve(index, vertices.len(), "vertex", "vertices")?;
                    let mut key = [v as u32, u32::MAX, u32::MAX];
                    let (mut uv, mut normal) = (None, None);
                    // Models check and keep the texture and normal references; scene files'
                    // meshes never looked at them.
                    if attributes {
                        if let Some(t) = parts.next().filter(|t| !t.is_empty()) {
                            let t = resolve(
                                whole(t).ok_or_else(bad_reference)?,
                                uvs.len(),
                                "texture coordinate",
                                "texture coordinates",
                            )?;
                            key[1] = t as u32;
                            uv = Some(uvs[t]);
                        }
                        if let Some(n) = parts.next() {
                            let n = resolve(
                                whole(n).ok_or_else(bad_reference)?,
                                normals.len(),
                                "normal",
                                "normals",
                            )?;
                            key[2] = n as u32;
                            normal = Some(normals[n]);
                        }
                    }
                    face.push((vertices[v], uv, normal, key));
                }
                if face.len() < 3 {
                    return Err(err(
                        col,
                        format!(
                            "a face needs at least 3 vertices, this one has {}",
                            face.len()
                        ),
                    ));
                }
                if triangles + face.len() - 2 > max_triangles {
                    return Err(err(
                        col,
                        format!("the mesh has more than {max_triangles} triangles, the limit"),
                    ));
                }
                triangles += face.len() - 2;
                // Only ASCII whitespace comes before the keyword: its byte column is its
                // character column.
                let origin = (line.min(u32::MAX as usize) as u32, col as u32);
                on(Event::Face(&face, origin));
            }
            _ => {}
        }
    }
    Ok(())
}

/// Line `line` (1-based) of an OBJ file's `bytes`, as text (invalid UTF-8 replaced by U+FFFD):
/// the line an [`ObjError`] points into. Only that line is converted, however large the file.
pub fn line_text(bytes: &[u8], line: usize) -> Cow<'_, str> {
    let bytes = bytes.strip_prefix(BOM).unwrap_or(bytes);
    let raw = bytes
        .split(|&b| b == b'\n')
        .nth(line.saturating_sub(1))
        .unwrap_or_default();
    String::from_utf8_lossy(raw)
}

/// The 1-based character column of 1-based byte column `byte_column` in `line`, counting as
/// [`line_text`] shows the line.
fn char_column(line: &[u8], byte_column: usize) -> usize {
    let before = &line[..byte_column.saturating_sub(1).min(line.len())];
    String::from_utf8_lossy(before).chars().count() + 1
}

/// The whitespace-separated tokens of a line with their 1-based byte columns.
fn tokens(line: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let mut i = 0;
    std::iter::from_fn(move || {
        while i < line.len() && line[i].is_ascii_whitespace() {
            i += 1;
        }
        if i >= line.len() {
            return None;
        }
        let start = i;
        while i < line.len() && !line[i].is_ascii_whitespace() {
            i += 1;
        }
        Some((start + 1, &line[start..i]))
    })
}

fn number(tok: &[u8]) -> Option<f32> {
    std::str::from_utf8(tok).ok()?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<ObjMesh, ObjError> {
        parse_obj(s.as_bytes(), 100, 100)
    }

    #[test]
    fn faces_of_every_form_and_polygons_fanned() {
        let m = parse(
            "# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\r\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2//1 3/2 4\nf -1 -2 -3\n",
        )
        .unwrap();
        assert_eq!(m.triangles.len(), 3);
        assert_eq!(m.triangles[1][2], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(m.triangles[2][0], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(m.origins, vec![(7, 1), (7, 1), (8, 1)]);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap_err();
        assert_eq!((e.line, e.column), (4, 7));
        assert!(e.message.contains("3 vertices"), "{}", e.message);
        let e = parse("v 0 nan 0\n").unwrap_err();
        assert_eq!((e.line, e.column), (1, 5));
        let e = parse("v 0 0 0\nf 1 0 1\n").unwrap_err();
        assert!(e.message.contains("start at 1"), "{}", e.message);
        let e = parse("v 0 0\n").unwrap_err();
        assert!(e.message.contains("3 coordinates"), "{}", e.message);
        let e = parse("v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap_err();
        assert!(e.message.contains("at least 3"), "{}", e.message);
    }

    #[test]
    fn a_byte_order_mark_is_skipped() {
        let m = parse("\u{FEFF}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert_eq!(m.triangles, vec![[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let e = parse("\u{FEFF}v 0 x 0\n").unwrap_err();
        assert_eq!((e.line, e.column), (1, 5));
        assert_eq!(line_text("\u{FEFF}v 0 x 0\n".as_bytes(), 1), "v 0 x 0");
    }

    #[test]
    fn columns_count_characters() {
        // "é" is two bytes and "→" three: the bad index is the 11th character, the 14th byte.
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let e = parse(&format!("{tri}f 1/é 2/→ 9\n")).unwrap_err();
        assert_eq!((e.line, e.column), (4, 11), "{}", e.message);
        // Invalid UTF-8 counts as the replacement character it is shown as: a cut "→" is one.
        let bad = format!("{tri}f 1/\u{2192} 9\n").replace('\u{2192}', "@");
        let mut bytes = bad.into_bytes();
        let at = bytes.iter().position(|&b| b == b'@').unwrap();
        bytes.splice(at..=at, [0xE2, 0x86]);
        let e = parse_obj(&bytes, 10, 10).unwrap_err();
        assert_eq!((e.line, e.column), (4, 7));
        let shown = line_text(&bytes, 4);
        assert_eq!(shown, "f 1/\u{FFFD} 9");
        assert_eq!(shown.chars().nth(e.column - 1), Some('9'));
    }

    #[test]
    fn limits_are_errors() {
        let many = "v 0 0 0\nv 1 0 0\nv 0 1 0\n".to_string() + &"f 1 2 3\n".repeat(5);
        let e = parse_obj(many.as_bytes(), 4, 10).unwrap_err();
        assert_eq!(e.line, 8);
        let e = parse_obj(b"v 0 0 0\nv 0 0 0\n", 4, 1).unwrap_err();
        assert_eq!(e.line, 2);
    }
}
