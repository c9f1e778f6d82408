//! STL, ASCII and binary: triangles (the facet normals are not used: the triangles' own
//! orientation gives the geometric normal). Binary is told from ASCII by its size, as a binary
//! file's 80-byte header may itself begin with `solid`: 84 bytes plus 50 a triangle, the count
//! at byte 80.
//!
//! Why not `stl_io`: its errors are I/O errors with no position, and it merges vertices through
//! a map that a model viewer does not need. The format fits in this file; errors give a binary
//! file's byte offset or an ASCII file's line and column.

use glam::Vec3;

use super::{Model, check_triangles};
use crate::scene::MAX_COORDINATE;
use crate::scene::file::SceneFileError;

/// Bytes of a binary STL's header (80) and triangle count (4).
const HEADER: usize = 84;
/// Bytes of a binary STL triangle: normal, three vertices, attribute count.
const RECORD: usize = 50;

/// Reads `bytes` as an STL model named `file`.
pub fn parse(bytes: &[u8], file: &str) -> Result<Model, SceneFileError> {
    let count = bytes
        .get(80..84)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize);
    let binary_size = count.map(|n| HEADER as u64 + RECORD as u64 * n as u64);
    let ascii = bytes.trim_ascii_start().starts_with(b"solid");
    if binary_size == Some(bytes.len() as u64) || (!ascii && count.is_some()) {
        return binary(bytes, count.unwrap_or(0), file);
    }
    if !ascii {
        return Err(SceneFileError::whole_file(
            file,
            format!(
                "{} bytes: too short for a binary STL (84 bytes of header and count) and not ASCII STL (`solid NAME`)",
                bytes.len()
            ),
        ));
    }
    text(bytes, file)
}

fn binary(bytes: &[u8], count: usize, file: &str) -> Result<Model, SceneFileError> {
    let expected = HEADER as u64 + RECORD as u64 * count as u64;
    if expected != bytes.len() as u64 {
        return Err(SceneFileError::whole_file(
            file,
            format!(
                "byte 80: the header says {count} triangles, so a binary STL of {expected} bytes, but the file has {}: it is cut short or not STL",
                bytes.len()
            ),
        ));
    }
    check_triangles(0, count).map_err(|m| SceneFileError::whole_file(file, m))?;
    let mut model = Model::default();
    model.positions.reserve_exact(3 * count);
    model.triangles.reserve_exact(count);
    for (i, rec) in bytes[HEADER..].chunks_exact(RECORD).enumerate() {
        for v in 0..3 {
            let at = 12 + 12 * v;
            let c = |k: usize| {
                let o = at + 4 * k;
                f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]])
            };
            let p = Vec3::new(c(0), c(1), c(2));
            if !p.is_finite() || p.abs().max_element() > MAX_COORDINATE {
                return Err(SceneFileError::whole_file(
                    file,
                    format!(
                        "byte {}: triangle {i}'s vertex {p} is out of range: expected finite coordinates within ±{MAX_COORDINATE:e}",
                        HEADER + i * RECORD + at
                    ),
                ));
            }
            model.positions.push(p);
        }
        let first = 3 * i as u32;
        model.triangles.push([first, first + 1, first + 2]);
    }
    Ok(model)
}

fn text(bytes: &[u8], file: &str) -> Result<Model, SceneFileError> {
    let mut model = Model::default();
    let mut corners = 0usize;
    let mut in_loop = false;
    for (n, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = n + 1;
        let mut words = raw
            .split(|b| b.is_ascii_whitespace())
            .scan(1usize, |at, w| {
                let start = *at;
                *at += w.len() + 1;
                Some((start, w))
            })
            .filter(|(_, w)| !w.is_empty());
        let Some((col, word)) = words.next() else {
            continue;
        };
        let err = |byte_column: usize, message: String| {
            let text = String::from_utf8_lossy(raw);
            let before = &raw[..(byte_column - 1).min(raw.len())];
            let column = String::from_utf8_lossy(before).chars().count() + 1;
            SceneFileError::on_line(file, &text, line, column, message)
        };
        match word {
            b"outer" => {
                if in_loop {
                    return Err(err(
                        col,
                        "`outer loop` inside a loop: expected `endloop`".into(),
                    ));
                }
                in_loop = true;
                corners = 0;
            }
            b"vertex" => {
                if !in_loop {
                    return Err(err(
                        col,
                        "`vertex` outside `outer loop` ... `endloop`".into(),
                    ));
                }
                let mut p = [0.0f32; 3];
                for (k, c) in p.iter_mut().enumerate() {
                    let Some((at, w)) = words.next() else {
                        return Err(err(
                            col,
                            format!("a vertex needs 3 coordinates, this one has {k}"),
                        ));
                    };
                    *c = std::str::from_utf8(w)
                        .ok()
                        .and_then(|s| s.parse::<f32>().ok())
                        .filter(|x| x.is_finite() && x.abs() <= MAX_COORDINATE)
                        .ok_or_else(|| {
                            err(
                                at,
                                format!(
                                    "`{}` is not a coordinate: expected a finite number within ±{MAX_COORDINATE:e}",
                                    String::from_utf8_lossy(w)
                                ),
                            )
                        })?;
                }
                if corners == 3 {
                    return Err(err(
                        col,
                        "a facet has 3 vertices: expected `endloop`".into(),
                    ));
                }
                model.positions.push(Vec3::from(p));
                corners += 1;
            }
            b"endloop" => {
                if !in_loop || corners != 3 {
                    return Err(err(
                        col,
                        format!("`endloop` after {corners} vertices: a facet has exactly 3"),
                    ));
                }
                in_loop = false;
                check_triangles(model.triangles.len(), 1).map_err(|m| err(col, m))?;
                let first = model.positions.len() as u32 - 3;
                model.triangles.push([first, first + 1, first + 2]);
            }
            b"solid" | b"facet" | b"endfacet" | b"endsolid" => {}
            w => {
                return Err(err(
                    col,
                    format!(
                        "unknown keyword `{}`: expected solid, facet, outer loop, vertex, endloop, endfacet or endsolid",
                        String::from_utf8_lossy(w)
                    ),
                ));
            }
        }
    }
    if in_loop {
        return Err(SceneFileError::whole_file(
            file,
            "the file ends inside a facet's loop: it is cut short",
        ));
    }
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRI: &str = "solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\nendsolid t\n";

    #[test]
    fn ascii_and_binary_give_the_same_triangle() {
        let a = parse(TRI.as_bytes(), "t.stl").unwrap();
        let mut b = b"solid but binary".to_vec();
        b.resize(80, 0);
        b.extend(1u32.to_le_bytes());
        for v in [
            0.0f32, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0,
        ] {
            b.extend(v.to_le_bytes());
        }
        b.extend([0, 0]);
        let m = parse(&b, "t.stl").unwrap();
        assert_eq!(m.positions, a.positions);
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn mistakes_are_positioned() {
        let e = parse(
            TRI.replace("vertex 1 0 0", "vertex 1 x 0").as_bytes(),
            "t.stl",
        )
        .unwrap_err();
        assert_eq!((e.line, e.column), (5, 12), "{e}");
        let e = parse(TRI.replace("  vertex 0 1 0\n", "").as_bytes(), "t.stl").unwrap_err();
        assert!(e.message.contains("after 2 vertices"), "{e}");
        let mut b = vec![0u8; 80];
        b.extend(1000u32.to_le_bytes());
        let e = parse(&b, "t.stl").unwrap_err();
        assert!(e.message.starts_with("byte 80"), "{e}");
    }
}
