//! A small Wavefront OBJ reader: vertex positions (`v`) and faces (`f`), nothing else.
//!
//! Faces take the `v`, `v/vt`, `v//vn` and `v/vt/vn` forms; only the position index is used
//! (normals are optional in OBJ and the tracer uses geometric normals). Negative indices count
//! back from the last vertex read. Polygons are fanned into triangles from their first vertex.
//! Every other statement (`vt`, `vn`, `o`, `g`, `s`, `usemtl`, `mtllib`, `l`, ...) is ignored.
//! Every error names its line and column (in characters, as scene-file errors do). A UTF-8 byte
//! order mark at the start of the file (Windows editors write one) is skipped.
//!
//! Why not the `tobj` crate: its errors say what went wrong but not where, and every mistake in
//! a user's file must name its line and column; it also loads materials and texture
//! coordinates that the tracer has no use for. What raytty needs of OBJ fits in this file.

use std::borrow::Cow;

use glam::Vec3;

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

/// Reads `bytes` as OBJ, giving up with an error past `max_triangles` triangles or
/// `max_vertices` vertices.
pub fn parse_obj(
    bytes: &[u8],
    max_triangles: usize,
    max_vertices: usize,
) -> Result<ObjMesh, ObjError> {
    let mut vertices: Vec<Vec3> = Vec::new();
    let mut mesh = ObjMesh::default();
    let mut face: Vec<Vec3> = Vec::new();
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
        match keyword {
            b"v" => {
                let mut p = [0.0f32; 3];
                for (axis, value) in p.iter_mut().enumerate() {
                    let Some((c, tok)) = tokens.next() else {
                        return Err(err(
                            col,
                            format!("a vertex needs 3 coordinates (v x y z), this one has {axis}"),
                        ));
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
                                "vertex coordinate `{}` is out of range: expected a finite number within ±{MAX_COORDINATE:e}",
                                String::from_utf8_lossy(tok)
                            ),
                        ));
                    }
                }
                if vertices.len() >= max_vertices {
                    return Err(err(
                        col,
                        format!("the mesh has more than {max_vertices} vertices, the limit"),
                    ));
                }
                vertices.push(Vec3::from(p));
            }
            b"f" => {
                face.clear();
                for (c, tok) in tokens {
                    let index_text = tok.split(|&b| b == b'/').next().unwrap_or(tok);
                    let index = std::str::from_utf8(index_text)
                        .ok()
                        .and_then(|s| s.parse::<i64>().ok())
                        .ok_or_else(|| {
                            err(
                                c,
                                format!(
                                    "`{}` is not a vertex reference: expected i, i/t, i//n or i/t/n with a whole number i",
                                    String::from_utf8_lossy(tok)
                                ),
                            )
                        })?;
                    let count = vertices.len() as i64;
                    let resolved = match index {
                        0 => {
                            return Err(err(
                                c,
                                "vertex index 0: OBJ indices start at 1 (or count back from -1)"
                                    .to_string(),
                            ));
                        }
                        i if i > 0 => i - 1,
                        i => count + i,
                    };
                    if !(0..count).contains(&resolved) {
                        return Err(err(
                            c,
                            format!(
                                "vertex index {index} is out of range: {count} vertices are defined before this face"
                            ),
                        ));
                    }
                    face.push(vertices[resolved as usize]);
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
                if mesh.triangles.len() + face.len() - 2 > max_triangles {
                    return Err(err(
                        col,
                        format!("the mesh has more than {max_triangles} triangles, the limit"),
                    ));
                }
                // Only ASCII whitespace comes before the keyword: its byte column is its
                // character column.
                let origin = (line.min(u32::MAX as usize) as u32, col as u32);
                for i in 1..face.len() - 1 {
                    mesh.triangles.push([face[0], face[i], face[i + 1]]);
                    mesh.origins.push(origin);
                }
            }
            _ => {}
        }
    }
    Ok(mesh)
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
