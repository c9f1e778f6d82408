//! PLY (the Stanford polygon format), ASCII and binary of either byte order: the `vertex`
//! element's positions, normals (`nx ny nz`), texture coordinates (`u v`, `s t` or
//! `texture_u texture_v`) and colours (`red green blue`, integer types scaled to [0, 1], taken
//! as sRGB), and the `face` element's index lists, fanned into triangles. Other elements and
//! properties are read past.
//!
//! Why not a crate: `ply-rs-bw` (the maintained fork of `ply-rs`) reads each element into a
//! map from property names to values, a few hundred bytes a vertex and an allocation each,
//! where a 10-million-triangle scan must stay near a hundred bytes a triangle; and its errors
//! give no line or byte offset. The format fits in this file.
//!
//! Errors name the header's line and column, an ASCII body's line and column, or a binary
//! body's byte offset, with the element and property being read. Counts in the header are
//! checked against the file's size before anything is allocated.

use glam::{Vec2, Vec3};

use super::{LoadProgress, LoadStep, Model, check_triangles, srgb_to_linear};
use crate::scene::file::SceneFileError;

/// A property's scalar type.
#[derive(Clone, Copy, Debug, PartialEq)]
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
    fn parse(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
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

    /// The largest value of an integer type (colours are scaled by it), 1 for floats.
    fn unit(self) -> f64 {
        match self {
            Scalar::I8 => 127.0,
            Scalar::U8 => 255.0,
            Scalar::I16 => 32767.0,
            Scalar::U16 => 65535.0,
            Scalar::I32 => 2147483647.0,
            Scalar::U32 => 4294967295.0,
            Scalar::F32 | Scalar::F64 => 1.0,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The value of `raw` (this type's size in bytes) in a binary body of byte order `big`.
    #[inline]
    fn decode(self, raw: &[u8], big: bool) -> f64 {
        let b = self.le_bytes(raw, big);
        match self {
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(b),
            // Every integer type's values are exact in `f64`.
            _ => self.decode_int(raw, big) as f64,
        }
    }

    /// This type's bytes of `raw` in little-endian order, in the first [`Scalar::size`] of eight.
    #[inline]
    fn le_bytes(self, raw: &[u8], big: bool) -> [u8; 8] {
        let size = self.size();
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(&raw[..size]);
        if big {
            b[..size].reverse();
        }
        b
    }

    /// [`Scalar::decode`] for an integer type, exactly.
    #[inline]
    fn decode_int(self, raw: &[u8], big: bool) -> i64 {
        let b = self.le_bytes(raw, big);
        match self {
            Scalar::I8 => b[0] as i8 as i64,
            Scalar::U8 => b[0] as i64,
            Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as i64,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as i64,
            Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64,
            Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64,
            Scalar::F32 | Scalar::F64 => unreachable!("not an integer type"),
        }
    }
}

/// What a vertex property feeds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Position(usize),
    Normal(usize),
    Uv(usize),
    Colour(usize),
    FaceIndices,
    Other,
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list.
    list: Option<Scalar>,
    scalar: Scalar,
    role: Role,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// Reads `bytes` as a PLY model named `file`.
pub fn parse(bytes: &[u8], file: &str) -> Result<Model, SceneFileError> {
    parse_with(bytes, file, &LoadProgress::new())
}

/// [`parse`], counting the records read in `progress`.
pub fn parse_with(
    bytes: &[u8],
    file: &str,
    progress: &LoadProgress,
) -> Result<Model, SceneFileError> {
    let (encoding, elements, body) = header(bytes, file)?;
    let mut model = Model::default();
    let records = elements.iter().map(|e| e.count as u64).sum::<u64>();
    progress.start(LoadStep::Parsing, records);
    let mut reader = Body {
        bytes,
        at: body,
        encoding,
        file,
        line: 0,
        line_start: body,
        progress,
        records: 0,
    };
    if encoding == Encoding::Ascii {
        reader.line = bytes[..body].iter().filter(|&&b| b == b'\n').count() + 1;
    }
    let mut vertices_read = None;
    for e in &elements {
        let min_size = e.properties.iter().map(|p| match p.list {
            Some(c) => c.size(),
            None => p.scalar.size(),
        });
        let min_size = match encoding {
            // At least one character and a separator a value.
            Encoding::Ascii => 2 * e.properties.len(),
            _ => min_size.sum(),
        };
        if e.count.saturating_mul(min_size.max(1)) > bytes.len() - reader.at.min(bytes.len()) {
            return Err(SceneFileError::whole_file(
                file,
                format!(
                    "the header says {} {} elements, more than the file's {} bytes can hold: the file is cut short or its header is wrong",
                    e.count,
                    e.name,
                    bytes.len()
                ),
            ));
        }
        match e.name.as_str() {
            "vertex" => {
                vertex_element(&mut reader, e, &mut model)?;
                vertices_read = Some(e.count);
            }
            "face" => {
                let Some(count) = vertices_read else {
                    return Err(SceneFileError::whole_file(
                        file,
                        "the face element comes before the vertex element: raytty reads vertices first",
                    ));
                };
                face_element(&mut reader, e, count, &mut model)?;
            }
            _ => {
                if e.count > 0 {
                    model.note(format!("PLY element `{}` is not read", e.name));
                }
                for i in 0..e.count {
                    for p in &e.properties {
                        reader.skip(p, &e.name, i)?;
                    }
                    reader.end_record()?;
                    reader.counted();
                }
            }
        }
    }
    Ok(model)
}

fn vertex_element(r: &mut Body, e: &Element, model: &mut Model) -> Result<(), SceneFileError> {
    let has = |role: fn(usize) -> Role| e.properties.iter().any(|p| p.role == role(0));
    for axis in 0..3 {
        if !e.properties.iter().any(|p| p.role == Role::Position(axis)) {
            return Err(SceneFileError::whole_file(
                r.file,
                format!(
                    "the vertex element has no `{}` property: a vertex needs x, y and z",
                    ["x", "y", "z"][axis]
                ),
            ));
        }
    }
    let (normals, uvs, colours) = (has(Role::Normal), has(Role::Uv), has(Role::Colour));
    model.positions.reserve_exact(e.count);
    if normals {
        model.normals.reserve_exact(e.count);
    }
    if uvs {
        model.uvs.reserve_exact(e.count);
    }
    if colours {
        model.colours.reserve_exact(e.count);
    }
    let push = |model: &mut Model, p: [f32; 3], n: [f32; 3], t: [f32; 2], c: [f32; 3]| {
        model.positions.push(Vec3::from(p));
        if normals {
            let n = Vec3::from(n);
            model.normals.push(if n.is_finite() {
                n.normalize_or_zero()
            } else {
                Vec3::ZERO
            });
        }
        if uvs {
            model.uvs.push(Vec2::from(t));
        }
        if colours {
            let c = Vec3::from(c.map(|x| {
                if x.is_finite() {
                    srgb_to_linear(x.clamp(0.0, 1.0))
                } else {
                    0.0
                }
            }));
            model.colours.push(c);
        }
    };
    let in_range = |v: f64| v.is_finite() && v.abs() <= crate::scene::MAX_COORDINATE as f64;
    let start = binary_vertices(r, e, model, in_range, push);
    for i in start..e.count {
        let (mut p, mut n, mut t, mut c) = ([0.0f32; 3], [0.0f32; 3], [0.0f32; 2], [1.0f32; 3]);
        for prop in &e.properties {
            if prop.list.is_some() {
                r.skip(prop, "vertex", i)?;
                continue;
            }
            let at = r.value_start();
            let v = r.scalar(prop.scalar, "vertex", i, &prop.name)?;
            match prop.role {
                Role::Position(k) => {
                    if !in_range(v) {
                        return Err(r.error(
                            at,
                            format!(
                                "vertex {i}: {} = {v} is out of range: expected a finite number within ±{:e}",
                                prop.name,
                                crate::scene::MAX_COORDINATE
                            ),
                        ));
                    }
                    p[k] = v as f32
                }
                Role::Normal(k) => n[k] = v as f32,
                Role::Uv(k) => t[k] = v as f32,
                Role::Colour(k) => c[k] = (v / prop.scalar.unit()) as f32,
                _ => {}
            }
        }
        r.end_record()?;
        r.counted();
        push(model, p, n, t, c);
    }
    Ok(())
}

/// The binary body's fast path for vertices whose properties are all scalars (no lists): fixed
/// records decoded in place, without the general reader's per-value bookkeeping (with
/// [`binary_faces`], a 10M-triangle binary PLY parses in 0.4 s of CPU time, 0.9 s before: perf,
/// one sitting). It stops at the first record with something to report (a
/// position out of range, the file's end) and returns how many it read; the general reader
/// takes over there and says what is wrong, at the same place.
fn binary_vertices(
    r: &mut Body,
    e: &Element,
    model: &mut Model,
    in_range: impl Fn(f64) -> bool + Sync,
    push: impl Fn(&mut Model, [f32; 3], [f32; 3], [f32; 2], [f32; 3]),
) -> usize {
    if r.encoding == Encoding::Ascii || e.properties.iter().any(|p| p.list.is_some()) {
        return 0;
    }
    let big = r.encoding == Encoding::Big;
    let mut props = Vec::new();
    let mut stride = 0;
    for p in &e.properties {
        if p.role != Role::Other {
            props.push((stride, p.scalar, p.role));
        }
        stride += p.scalar.size();
    }
    let records = e
        .count
        .min((r.bytes.len() - r.at.min(r.bytes.len())) / stride.max(1));
    if records == e.count
        && model.positions.is_empty()
        && props.iter().all(|p| matches!(p.2, Role::Position(_)))
    {
        // Positions alone (a scan's usual vertex): decoded in parallel, as faces are in
        // [`all_triangles`]; on a position out of range, read again below to say where.
        use rayon::prelude::*;
        use std::sync::atomic::{AtomicBool, Ordering};
        let bad = AtomicBool::new(false);
        r.bytes[r.at..r.at + records * stride]
            .par_chunks_exact(stride)
            .map(|rec| {
                let mut p = [0.0f32; 3];
                for &(offset, s, role) in &props {
                    let v = s.decode(&rec[offset..], big);
                    if !in_range(v) {
                        bad.store(true, Ordering::Relaxed);
                    }
                    if let Role::Position(k) = role {
                        p[k] = v as f32;
                    }
                }
                Vec3::from(p)
            })
            .collect_into_vec(&mut model.positions);
        if !bad.into_inner() {
            r.at += records * stride;
            r.records += records as u64;
            r.progress.set_done(r.records);
            return records;
        }
        model.positions.clear();
    }
    for i in 0..records {
        let rec = &r.bytes[r.at..r.at + stride];
        let (mut p, mut n, mut t, mut c) = ([0.0f32; 3], [0.0f32; 3], [0.0f32; 2], [1.0f32; 3]);
        for &(offset, s, role) in &props {
            let v = s.decode(&rec[offset..], big);
            match role {
                Role::Position(k) => {
                    if !in_range(v) {
                        return i;
                    }
                    p[k] = v as f32
                }
                Role::Normal(k) => n[k] = v as f32,
                Role::Uv(k) => t[k] = v as f32,
                Role::Colour(k) => c[k] = (v / s.unit()) as f32,
                _ => {}
            }
        }
        push(model, p, n, t, c);
        r.at += stride;
        r.counted();
    }
    records
}

fn face_element(
    r: &mut Body,
    e: &Element,
    vertices: usize,
    model: &mut Model,
) -> Result<(), SceneFileError> {
    if !e.properties.iter().any(|p| p.role == Role::FaceIndices) {
        return Err(SceneFileError::whole_file(
            r.file,
            "the face element has no `vertex_indices` list",
        ));
    }
    model.triangles.reserve(e.count);
    let start = binary_faces(r, e, vertices, model);
    let mut face: Vec<u32> = Vec::new();
    for i in start..e.count {
        for prop in &e.properties {
            let (Role::FaceIndices, Some(count_type)) = (prop.role, prop.list) else {
                r.skip(prop, "face", i)?;
                continue;
            };
            let at = r.value_start();
            let n = r.count(count_type, "face", i)?;
            if n < 3 {
                return Err(r.error(
                    at,
                    format!("face {i} has {n} vertices: a face needs at least 3"),
                ));
            }
            face.clear();
            for _ in 0..n {
                let at = r.value_start();
                let v = r.scalar(prop.scalar, "face", i, &prop.name)?;
                if !(v >= 0.0 && v < vertices as f64 && v.fract() == 0.0) {
                    return Err(r.error(
                        at,
                        format!(
                            "face {i}: vertex index {v} is out of range: the file has {vertices} vertices (indices 0 to {})",
                            vertices.saturating_sub(1)
                        ),
                    ));
                }
                face.push(v as u32);
            }
            check_triangles(model.triangles.len(), face.len() - 2).map_err(|m| r.error(at, m))?;
            for k in 1..face.len() - 1 {
                model.triangles.push([face[0], face[k], face[k + 1]]);
            }
        }
        r.end_record()?;
        r.counted();
    }
    Ok(())
}

/// The binary body's fast path for faces that are one list of vertex indices and nothing else
/// (as scanners write them), as [`binary_vertices`]: it stops at the first face with something
/// to report (fewer than 3 vertices, an index out of range, the file's end, the triangle cap)
/// and returns how many it read, for the general reader to take over.
fn binary_faces(r: &mut Body, e: &Element, vertices: usize, model: &mut Model) -> usize {
    let [prop] = e.properties.as_slice() else {
        return 0;
    };
    let (Role::FaceIndices, Some(count_type), false) =
        (prop.role, prop.list, r.encoding == Encoding::Ascii)
    else {
        return 0;
    };
    let big = r.encoding == Encoding::Big;
    let (cs, is) = (count_type.size(), prop.scalar.size());
    if all_triangles(r, e.count, (count_type, prop.scalar), vertices, model) {
        return e.count;
    }
    let mut face = [0u32; 4];
    for i in 0..e.count {
        let Some(raw) = r.bytes.get(r.at..r.at + cs) else {
            return i;
        };
        let n = count_type.decode_int(raw, big);
        // Triangles and quads; longer faces go the general way.
        if !(3..=4).contains(&n) {
            return i;
        }
        let n = n as usize;
        let Some(list) = r.bytes.get(r.at + cs..r.at + cs + n * is) else {
            return i;
        };
        for (k, raw) in list.chunks_exact(is).enumerate() {
            let v = prop.scalar.decode_int(raw, big);
            if !(0 <= v && v < vertices as i64) {
                return i;
            }
            face[k] = v as u32;
        }
        if check_triangles(model.triangles.len(), n - 2).is_err() {
            return i;
        }
        for k in 1..n - 1 {
            model.triangles.push([face[0], face[k], face[k + 1]]);
        }
        r.at += cs + n * is;
        r.counted();
    }
    e.count
}

/// Reads the header: the encoding, the elements, and where the body starts.
/// [`binary_faces`]'s first try, in parallel: the faces as fixed records of three indices
/// each (a scan's), decoded straight into `model.triangles` (the load of a 10M-triangle PLY
/// waits for half the parse on two cores). False, with nothing read, where a record is not a
/// triangle with its indices in range (the sequential path then reads them and says what is
/// wrong, where), or the file ends first, or the model would pass the triangle cap.
fn all_triangles(
    r: &mut Body,
    count: usize,
    (count_type, index_type): (Scalar, Scalar),
    vertices: usize,
    model: &mut Model,
) -> bool {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicBool, Ordering};
    let big = r.encoding == Encoding::Big;
    let (cs, is) = (count_type.size(), index_type.size());
    let record = cs + 3 * is;
    let Some(body) = count
        .checked_mul(record)
        .and_then(|len| r.bytes.get(r.at..r.at.checked_add(len)?))
    else {
        return false;
    };
    if !model.triangles.is_empty() || check_triangles(0, count).is_err() {
        return false;
    }
    let bad = AtomicBool::new(false);
    let vertices = vertices as i64;
    body.par_chunks_exact(record)
        .map(|raw| {
            let v = [0, 1, 2].map(|k| index_type.decode_int(&raw[cs + k * is..], big));
            if count_type.decode_int(raw, big) != 3
                || v.iter().any(|&v| !(0..vertices).contains(&v))
            {
                bad.store(true, Ordering::Relaxed);
            }
            v.map(|v| v as u32)
        })
        .collect_into_vec(&mut model.triangles);
    if bad.into_inner() {
        model.triangles.clear();
        return false;
    }
    r.at += body.len();
    r.records += count as u64;
    r.progress.set_done(r.records);
    true
}

fn header(bytes: &[u8], file: &str) -> Result<(Encoding, Vec<Element>, usize), SceneFileError> {
    let mut at = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut line = 0;
    loop {
        line += 1;
        let Some(len) = bytes[at..].iter().position(|&b| b == b'\n') else {
            return Err(SceneFileError::whole_file(
                file,
                "the header has no `end_header` line: is this a PLY file?",
            ));
        };
        let raw = &bytes[at..at + len];
        let text = String::from_utf8_lossy(raw);
        at += len + 1;
        let err = |message: String| SceneFileError::on_line(file, &text, line, 1, message);
        let words: Vec<&[u8]> = raw
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty())
            .collect();
        if line == 1 {
            if words != [b"ply"] {
                return Err(err("a PLY file starts with a line `ply`".into()));
            }
            continue;
        }
        match words.first().copied() {
            None | Some(b"comment") | Some(b"obj_info") => {}
            Some(b"format") => {
                encoding = Some(match words.get(1).copied() {
                    Some(b"ascii") => Encoding::Ascii,
                    Some(b"binary_little_endian") => Encoding::Little,
                    Some(b"binary_big_endian") => Encoding::Big,
                    _ => {
                        return Err(err(
                            "expected `format ascii 1.0`, `format binary_little_endian 1.0` or `format binary_big_endian 1.0`".into(),
                        ));
                    }
                });
            }
            Some(b"element") => {
                let (Some(name), Some(count)) = (words.get(1), words.get(2)) else {
                    return Err(err("expected `element NAME COUNT`".into()));
                };
                let count = std::str::from_utf8(count)
                    .ok()
                    .and_then(|c| c.parse::<usize>().ok())
                    .ok_or_else(|| err("the element's count is not a whole number".into()))?;
                elements.push(Element {
                    name: String::from_utf8_lossy(name).into_owned(),
                    count,
                    properties: Vec::new(),
                });
            }
            Some(b"property") => {
                let Some(element) = elements.last_mut() else {
                    return Err(err("a property before any `element` line".into()));
                };
                let bad_type = || {
                    err("unknown property type: expected char, uchar, short, ushort, int, uint, float, double (or int8 ... float64)".into())
                };
                let (list, scalar, name) = if words.get(1) == Some(&&b"list"[..]) {
                    let (Some(c), Some(t), Some(n)) = (words.get(2), words.get(3), words.get(4))
                    else {
                        return Err(err("expected `property list COUNT_TYPE TYPE NAME`".into()));
                    };
                    let c = Scalar::parse(c).ok_or_else(bad_type)?;
                    if !c.is_integer() {
                        return Err(err("a list's count type must be an integer type".into()));
                    }
                    (Some(c), Scalar::parse(t).ok_or_else(bad_type)?, n)
                } else {
                    let (Some(t), Some(n)) = (words.get(1), words.get(2)) else {
                        return Err(err("expected `property TYPE NAME`".into()));
                    };
                    (None, Scalar::parse(t).ok_or_else(bad_type)?, n)
                };
                let name = String::from_utf8_lossy(name).into_owned();
                let role = match (element.name.as_str(), list.is_some(), name.as_str()) {
                    ("vertex", false, "x") => Role::Position(0),
                    ("vertex", false, "y") => Role::Position(1),
                    ("vertex", false, "z") => Role::Position(2),
                    ("vertex", false, "nx") => Role::Normal(0),
                    ("vertex", false, "ny") => Role::Normal(1),
                    ("vertex", false, "nz") => Role::Normal(2),
                    ("vertex", false, "u" | "s" | "texture_u" | "texture_s") => Role::Uv(0),
                    ("vertex", false, "v" | "t" | "texture_v" | "texture_t") => Role::Uv(1),
                    ("vertex", false, "red" | "r" | "diffuse_red") => Role::Colour(0),
                    ("vertex", false, "green" | "g" | "diffuse_green") => Role::Colour(1),
                    ("vertex", false, "blue" | "b" | "diffuse_blue") => Role::Colour(2),
                    ("face", true, "vertex_indices" | "vertex_index") => Role::FaceIndices,
                    _ => Role::Other,
                };
                if role != Role::Other && element.properties.iter().any(|p| p.role == role) {
                    return Err(err(format!("property `{name}` is given twice")));
                }
                if role == Role::FaceIndices && !scalar.is_integer() {
                    return Err(err("face indices must be of an integer type".into()));
                }
                element.properties.push(Property {
                    name,
                    list,
                    scalar,
                    role,
                });
            }
            Some(b"end_header") => break,
            Some(w) => {
                return Err(err(format!(
                    "unknown header line `{}`: expected format, element, property, comment or end_header",
                    String::from_utf8_lossy(w)
                )));
            }
        }
    }
    let Some(encoding) = encoding else {
        return Err(SceneFileError::whole_file(
            file,
            "the header has no `format` line",
        ));
    };
    Ok((encoding, elements, at))
}

/// A cursor over the body: binary values at a byte offset, or ASCII values one record a line.
struct Body<'a> {
    bytes: &'a [u8],
    at: usize,
    encoding: Encoding,
    file: &'a str,
    /// ASCII: the 1-based line of `at` and where that line starts.
    line: usize,
    line_start: usize,
    /// Where the records read are counted, and their count.
    progress: &'a LoadProgress,
    records: u64,
}

impl Body<'_> {
    /// Counts a record read (told to the progress every 64K).
    #[inline]
    fn counted(&mut self) {
        self.records += 1;
        if self.records.is_multiple_of(1 << 16) {
            self.progress.set_done(self.records);
        }
    }

    /// An error at byte `at`: its line and column in an ASCII body, its offset in a binary one.
    fn error(&self, at: usize, message: String) -> SceneFileError {
        if self.encoding == Encoding::Ascii {
            let end = self.bytes[self.line_start..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(self.bytes.len(), |e| self.line_start + e);
            let text = String::from_utf8_lossy(&self.bytes[self.line_start..end]);
            let before = &self.bytes[self.line_start..at.clamp(self.line_start, end)];
            let column = String::from_utf8_lossy(before).chars().count() + 1;
            SceneFileError::on_line(self.file, &text, self.line, column, message)
        } else {
            SceneFileError::whole_file(self.file, format!("byte {at}: {message}"))
        }
    }

    /// Where the next value starts (past the spaces before it in ASCII), for its errors.
    fn value_start(&mut self) -> usize {
        if self.encoding == Encoding::Ascii {
            while self.at < self.bytes.len() && matches!(self.bytes[self.at], b' ' | b'\t' | b'\r')
            {
                self.at += 1;
            }
        }
        self.at
    }

    /// The next ASCII token on the current record's line.
    fn token(&mut self, what: &str) -> Result<std::ops::Range<usize>, SceneFileError> {
        while self.at < self.bytes.len() && matches!(self.bytes[self.at], b' ' | b'\t' | b'\r') {
            self.at += 1;
        }
        let start = self.at;
        while self.at < self.bytes.len() && !self.bytes[self.at].is_ascii_whitespace() {
            self.at += 1;
        }
        if start == self.at {
            return Err(self.error(start, format!("{what}: the line ends early")));
        }
        Ok(start..self.at)
    }

    /// Moves past the end of an ASCII record's line (nothing but spaces may be left on it).
    fn end_record(&mut self) -> Result<(), SceneFileError> {
        if self.encoding != Encoding::Ascii {
            return Ok(());
        }
        while self.at < self.bytes.len() && matches!(self.bytes[self.at], b' ' | b'\t' | b'\r') {
            self.at += 1;
        }
        match self.bytes.get(self.at) {
            Some(b'\n') => {
                self.at += 1;
                self.line += 1;
                self.line_start = self.at;
                Ok(())
            }
            None => Ok(()),
            Some(_) => Err(self.error(
                self.at,
                "more values on the line than the header's properties".into(),
            )),
        }
    }

    fn scalar(
        &mut self,
        s: Scalar,
        element: &str,
        i: usize,
        property: &str,
    ) -> Result<f64, SceneFileError> {
        let what = || format!("{element} {i}, property {property}");
        if self.encoding == Encoding::Ascii {
            let at = self.value_start();
            let range = self.token(&what())?;
            let tok = &self.bytes[range];
            let v = std::str::from_utf8(tok).ok().and_then(|t| {
                if s.is_integer() {
                    t.parse::<i64>().ok().map(|v| v as f64)
                } else {
                    t.parse::<f64>().ok()
                }
            });
            let v = v.ok_or_else(|| {
                let t = String::from_utf8_lossy(tok).into_owned();
                self.error(at, format!("{}: `{t}` is not a number of its type", what()))
            })?;
            return Ok(v);
        }
        let size = s.size();
        let Some(raw) = self.bytes.get(self.at..self.at + size) else {
            return Err(self.error(self.at, format!("{}: the file ends early", what())));
        };
        self.at += size;
        Ok(s.decode(raw, self.encoding == Encoding::Big))
    }

    /// A list's length.
    fn count(&mut self, s: Scalar, element: &str, i: usize) -> Result<usize, SceneFileError> {
        let at = self.at;
        let n = self.scalar(s, element, i, "list length")?;
        if !(n >= 0.0 && n.fract() == 0.0) {
            return Err(self.error(at, format!("{element} {i}: list length {n} is not a count")));
        }
        // Every entry takes at least a byte: a longer list cannot fit in the file.
        if n as usize > self.bytes.len() - self.at.min(self.bytes.len()) {
            return Err(self.error(
                at,
                format!("{element} {i}: list length {n} is longer than the rest of the file"),
            ));
        }
        Ok(n as usize)
    }

    /// Reads past one property.
    fn skip(&mut self, p: &Property, element: &str, i: usize) -> Result<(), SceneFileError> {
        let n = match p.list {
            Some(c) => self.count(c, element, i)?,
            None => 1,
        };
        for _ in 0..n {
            self.scalar(p.scalar, element, i, &p.name)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment a quad\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 255 0 0\n1 1 0 255 0 0\n0 1 0 255 0 0\n4 0 1 2 3\n";

    #[test]
    fn ascii_quads_are_fanned_and_colours_kept() {
        let m = parse(ASCII.as_bytes(), "q.ply").unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.colours[2], Vec3::new(1.0, 0.0, 0.0));
    }

    /// The same quad in both binary byte orders reads as the ASCII one.
    #[test]
    fn binary_of_both_orders_reads_the_same() {
        for big in [false, true] {
            let head = ASCII.split("end_header\n").next().unwrap().replace(
                "format ascii",
                if big {
                    "format binary_big_endian"
                } else {
                    "format binary_little_endian"
                },
            ) + "end_header\n";
            let mut b = head.into_bytes();
            for (x, y) in [(0.0f32, 0.0f32), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                for v in [x, y, 0.0] {
                    b.extend(if big {
                        v.to_be_bytes()
                    } else {
                        v.to_le_bytes()
                    });
                }
                b.extend([255, 0, 0]);
            }
            b.push(4);
            for i in 0..4i32 {
                b.extend(if big {
                    i.to_be_bytes()
                } else {
                    i.to_le_bytes()
                });
            }
            let m = parse(&b, "q.ply").unwrap();
            assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
            assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 0.0));
            // Cut short: the byte offset of the missing value.
            let e = parse(&b[..b.len() - 2], "q.ply").unwrap_err();
            assert!(
                e.message.starts_with(&format!("byte {}", b.len() - 4)),
                "{e}"
            );
        }
    }

    /// A binary body read by the fast paths until a record has something to report: the
    /// general reader then names it at the same byte as it always did, and faces of more than
    /// four vertices are still fanned.
    #[test]
    fn binary_mistakes_are_found_after_fast_records() {
        let head = "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nproperty uchar flag\nelement face 3\nproperty list uchar uint vertex_indices\nend_header\n";
        let body = |x4: f32, faces: &[&[u32]]| {
            let mut b = head.as_bytes().to_vec();
            for p in [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ] {
                b.extend(p.iter().flat_map(|v: &f32| v.to_le_bytes()));
                b.push(7);
            }
            b.extend([x4, 2.0, 0.0].iter().flat_map(|v| v.to_le_bytes()));
            b.push(7);
            for f in faces {
                b.push(f.len() as u8);
                b.extend(f.iter().flat_map(|v| v.to_le_bytes()));
            }
            b
        };
        let good: [&[u32]; 3] = [&[0, 1, 2], &[0, 2, 3], &[0, 1, 2, 4, 3]];
        let m = parse(&body(0.5, &good), "f.ply").unwrap();
        assert_eq!(m.positions[4], Vec3::new(0.5, 2.0, 0.0));
        assert_eq!(
            m.triangles,
            vec![[0, 1, 2], [0, 2, 3], [0, 1, 2], [0, 2, 4], [0, 4, 3]]
        );
        let vertex_bytes = head.len() + 5 * 13;
        let e = parse(&body(f32::NAN, &good), "f.ply").unwrap_err();
        let at = head.len() + 4 * 13;
        assert!(
            e.message
                .starts_with(&format!("byte {at}: vertex 4: x = NaN is out of range")),
            "{e}"
        );
        let e = parse(&body(0.5, &[&[0, 1, 2], &[0, 2, 5], &[0, 1, 2]]), "f.ply").unwrap_err();
        let at = vertex_bytes + 13 + 1 + 8;
        assert!(
            e.message.starts_with(&format!(
                "byte {at}: face 1: vertex index 5 is out of range"
            )),
            "{e}"
        );
        let e = parse(&body(0.5, &[&[0, 1, 2], &[0, 2]]), "f.ply").unwrap_err();
        assert!(
            e.message.starts_with(&format!(
                "byte {}: face 1 has 2 vertices",
                vertex_bytes + 13
            )),
            "{e}"
        );
    }

    #[test]
    fn mistakes_are_positioned() {
        let e = parse(ASCII.replace("4 0 1 2 3", "4 0 1 2 7").as_bytes(), "q.ply").unwrap_err();
        assert_eq!((e.line, e.column), (18, 9), "{e}");
        assert!(e.message.contains("out of range"), "{e}");
        let e = parse(
            ASCII
                .replace("property uchar blue", "property colour blue")
                .as_bytes(),
            "q.ply",
        )
        .unwrap_err();
        assert_eq!(e.line, 10, "{e}");
        let e = parse(
            ASCII.replace("vertex 4", "vertex 4000000").as_bytes(),
            "q.ply",
        )
        .unwrap_err();
        assert!(e.message.contains("cut short"), "{e}");
        let e = parse(b"ply\nformat ascii 1.0\n", "q.ply").unwrap_err();
        assert!(e.message.contains("end_header"), "{e}");
        let e = parse(ASCII.replace("1 1 0 255", "1 x 0 255").as_bytes(), "q.ply").unwrap_err();
        assert_eq!((e.line, e.column), (16, 3), "{e}");
    }
}
