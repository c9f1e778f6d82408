//! The geometry of one `[[object]]`: its kind's triangles, its transform, and a check of every
//! triangle that names the line it came from (in the scene file, or in the OBJ file).

use glam::Vec3;
use rayon::prelude::*;
use toml::Spanned;

use super::check::Ctx;
use super::error::{SceneFileError, did_you_mean};
use super::spec::{NumberOrTriple, ObjectSpec};
use super::*;
use crate::geometry::Triangle;
use crate::scene::MAX_COORDINATE;
use crate::scene::obj::{line_text, parse_obj};
use crate::scene::procedural::{displaced_icosphere, icosphere_triangles};

/// The object kinds and the keys each one takes besides `kind`, `material` and the transform.
const KINDS: [(&str, &[&str]); 4] = [
    ("triangles", &["triangles"]),
    ("box", &["min", "max", "centre", "size"]),
    ("obj", &["path"]),
    ("icosphere", &["subdivisions", "amplitude"]),
];

/// The keys every object takes.
const COMMON_KEYS: [&str; 5] = ["kind", "material", "translate", "rotate_y", "scale"];

/// Where an object's triangles came from, for their error messages.
enum Origins {
    /// Each triangle at its own byte offset in the scene file.
    Each(Vec<usize>),
    /// All of them made from the object at this byte offset.
    Object(usize),
    /// Faces of a mesh file: the file's name, and each triangle's (line, column).
    Mesh(String, Vec<(u32, u32)>),
}

/// The triangles of one object, transformed and checked. `before` triangles came earlier.
pub fn object_triangles(
    cx: &Ctx,
    object: &Spanned<ObjectSpec>,
    before: usize,
    read_mesh: MeshReader,
) -> Result<Vec<[Vec3; 3]>, SceneFileError> {
    let o = object.get_ref();
    let kind = o.kind.get_ref().as_str();
    check_keys(cx, o)?;
    let budget = MAX_TRIANGLES - before;
    let over = |n: u64| {
        cx.err_at(
            object,
            format!(
                "this object makes {n} triangles; with the {before} before it the scene is over {MAX_TRIANGLES} triangles, the limit"
            ),
        )
    };
    let at = object.span().start;
    let (mut tris, origins) = match kind {
        "triangles" => listed(cx, object, budget, over)?,
        "box" => (cuboid(cx, object)?, Origins::Object(at)),
        "obj" => mesh(cx, object, budget, read_mesh)?,
        _ => (icosphere(cx, object, budget, over)?, Origins::Object(at)),
    };
    // A triangle degenerate as given is the object's own fault; one that the transform makes
    // degenerate (a tiny object far from the origin, where f32 steps are coarse) is the
    // transform's.
    let report = |i: usize, problem: String, after: bool| {
        let why = if after {
            "after the transform of the object at"
        } else {
            "in the object at"
        };
        match &origins {
            Origins::Each(offsets) => cx.err(offsets[i], problem),
            Origins::Object(offset) => cx.err(*offset, problem),
            Origins::Mesh(file, faces) => SceneFileError::at_line(
                file,
                "",
                faces[i].0 as usize,
                faces[i].1 as usize,
                format!("{problem} ({why} {})", cx.place(at)),
            ),
        }
    };
    if let Some((i, problem)) = first_bad(&tris, false) {
        return Err(report(i, problem, false));
    }
    if o.scale.is_some() || o.rotate_y.is_some() || o.translate.is_some() {
        transform(cx, o, &mut tris)?;
        if let Some((i, problem)) = first_bad(&tris, true) {
            return Err(report(i, problem, true));
        }
    }
    Ok(tris)
}

/// The first triangle with a problem, in parallel (a procedural mesh has a million).
fn first_bad(tris: &[[Vec3; 3]], transformed: bool) -> Option<(usize, String)> {
    let i = tris
        .par_iter()
        .position_first(|&t| triangle_problem(t, transformed).is_some())?;
    Some((i, triangle_problem(tris[i], transformed)?))
}

/// The kind is known, and every key given belongs to it.
fn check_keys(cx: &Ctx, o: &ObjectSpec) -> Result<(), SceneFileError> {
    let kind = o.kind.get_ref().as_str();
    let kinds: Vec<&str> = KINDS.iter().map(|k| k.0).collect();
    let Some((_, allowed)) = KINDS.iter().find(|k| k.0 == kind) else {
        return Err(cx.err_at(
            &o.kind,
            format!(
                "unknown object kind `{kind}`{} (kinds: {})",
                did_you_mean(kind, &kinds),
                kinds.join(", ")
            ),
        ));
    };
    fn at<T>(v: &Option<Spanned<T>>) -> Option<usize> {
        v.as_ref().map(|v| v.span().start)
    }
    let given = [
        ("triangles", at(&o.triangles)),
        ("min", at(&o.min)),
        ("max", at(&o.max)),
        ("centre", at(&o.centre)),
        ("size", at(&o.size)),
        ("path", at(&o.path)),
        ("subdivisions", at(&o.subdivisions)),
        ("amplitude", at(&o.amplitude)),
    ];
    for (key, offset) in given {
        if let (Some(offset), false) = (offset, allowed.contains(&key)) {
            let mut keys: Vec<&str> = allowed.to_vec();
            keys.extend(COMMON_KEYS);
            return Err(cx.err(
                offset,
                format!(
                    "`{key}` is not a key of kind = \"{kind}\" objects: they take {}",
                    keys.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// `kind = "triangles"`: the listed triangles.
fn listed(
    cx: &Ctx,
    object: &Spanned<ObjectSpec>,
    budget: usize,
    over: impl Fn(u64) -> SceneFileError,
) -> Result<(Vec<[Vec3; 3]>, Origins), SceneFileError> {
    let Some(list) = &object.get_ref().triangles else {
        return Err(cx.err_at(
            object,
            "a `triangles` object needs triangles = [[[x, y, z], [x, y, z], [x, y, z]], ...]",
        ));
    };
    let list = list.get_ref();
    if list.len() > budget {
        return Err(over(list.len() as u64));
    }
    let mut out = Vec::with_capacity(list.len());
    for t in list {
        let mut v = [Vec3::ZERO; 3];
        for (vi, p) in v.iter_mut().zip(&t.get_ref().0) {
            *vi = cx.point(&Spanned::new(t.span(), *p), "a triangle vertex")?;
        }
        out.push(v);
    }
    let offsets = list.iter().map(|t| t.span().start).collect();
    Ok((out, Origins::Each(offsets)))
}

/// `kind = "box"`: 12 triangles from min and max, or from centre and size.
fn cuboid(cx: &Ctx, object: &Spanned<ObjectSpec>) -> Result<Vec<[Vec3; 3]>, SceneFileError> {
    let o = object.get_ref();
    let (lo, hi) = match (&o.min, &o.max, &o.centre, &o.size) {
        (Some(min), Some(max), None, None) => {
            let lo = cx.point(min, "the box's min")?;
            let hi = cx.point(max, "the box's max")?;
            if !lo.cmplt(hi).all() {
                return Err(cx.err_at(
                    max,
                    "the box's max must be greater than its min on every axis",
                ));
            }
            (lo, hi)
        }
        (None, None, Some(centre), Some(size)) => {
            let c = cx.point(centre, "the box's centre")?;
            let s = cx.point(size, "the box's size")?;
            if !s.cmpgt(Vec3::ZERO).all() {
                return Err(cx.err_at(size, "the box's size must be positive on every axis"));
            }
            (c - s * 0.5, c + s * 0.5)
        }
        _ => {
            return Err(cx.err_at(
                object,
                "a box needs either min and max, or centre and size (and not both)",
            ));
        }
    };
    Ok(box_triangles(lo, hi))
}

/// `kind = "obj"`: the faces of an OBJ file.
fn mesh(
    cx: &Ctx,
    object: &Spanned<ObjectSpec>,
    budget: usize,
    read_mesh: MeshReader,
) -> Result<(Vec<[Vec3; 3]>, Origins), SceneFileError> {
    let Some(path) = &object.get_ref().path else {
        return Err(cx.err_at(
            object,
            "an `obj` object needs path = \"FILE.obj\" (relative to the scene file)",
        ));
    };
    let (shown, bytes) = read_mesh(path.get_ref()).map_err(|e| {
        cx.err_at(
            path,
            format!("{e}; give the path of an OBJ file, relative to the scene file's folder"),
        )
    })?;
    let mesh = parse_obj(&bytes, budget, MAX_MESH_VERTICES).map_err(|e| {
        SceneFileError::on_line(
            &shown,
            &line_text(&bytes, e.line),
            e.line,
            e.column,
            format!(
                "{} (in the mesh named at {})",
                e.message,
                cx.place(path.span().start)
            ),
        )
    })?;
    if mesh.triangles.is_empty() {
        return Err(cx.err_at(
            path,
            format!("the mesh file {shown} has no faces (f lines): is it an OBJ file?"),
        ));
    }
    Ok((mesh.triangles, Origins::Mesh(shown, mesh.origins)))
}

/// `kind = "icosphere"`: the displaced icosphere, refused before it is generated if too big.
fn icosphere(
    cx: &Ctx,
    object: &Spanned<ObjectSpec>,
    budget: usize,
    over: impl Fn(u64) -> SceneFileError,
) -> Result<Vec<[Vec3; 3]>, SceneFileError> {
    let o = object.get_ref();
    let Some(k) = &o.subdivisions else {
        return Err(cx.err_at(
            object,
            format!(
                "an icosphere needs subdivisions = k (1 to {MAX_SUBDIVISIONS}; it has 20·k² triangles)"
            ),
        ));
    };
    let k = cx.whole(k, 1, MAX_SUBDIVISIONS, "subdivisions")? as u32;
    let amplitude = match &o.amplitude {
        Some(a) => cx.ranged(a, -MAX_AMPLITUDE, MAX_AMPLITUDE, "amplitude")?,
        None => 0.0,
    };
    let n = icosphere_triangles(k);
    if n > budget as u64 {
        return Err(over(n));
    }
    Ok(displaced_icosphere(k, amplitude as f32))
}

/// What is wrong with a triangle, if anything: a vertex beyond the coordinate limit, or a
/// degenerate shape the scene would reject. `transformed`: the object's transform was applied.
fn triangle_problem([a, b, c]: [Vec3; 3], transformed: bool) -> Option<String> {
    if [a, b, c]
        .iter()
        .any(|v| !(v.abs().max_element() <= MAX_COORDINATE))
    {
        return Some(if transformed {
            format!(
                "a vertex is beyond ±{MAX_COORDINATE:e} after the object's transform: make the scale or translate smaller"
            )
        } else {
            format!("a vertex of the object is beyond ±{MAX_COORDINATE:e}")
        });
    }
    let e = Triangle::new(a, b, c, 0).err()?;
    Some(if transformed {
        format!(
            "the transform makes a triangle degenerate ({e}): it is too small for its distance from the origin in single precision; scale it up or move it nearer the origin"
        )
    } else {
        format!(
            "degenerate triangle: {e}; every triangle needs three distinct vertices that are not on one line"
        )
    })
}

/// Applies the object's scale, then rotation about y, then translation, each only if given
/// (so an object with no transform keeps its coordinates bit for bit).
fn transform(cx: &Ctx, o: &ObjectSpec, tris: &mut [[Vec3; 3]]) -> Result<(), SceneFileError> {
    if let Some(s) = &o.scale {
        let NumberOrTriple(s3) = *s.get_ref();
        let (lo, hi) = SCALE_RANGE;
        if let Some(bad) = s3.iter().find(|c| !(**c >= lo && **c <= hi)) {
            return Err(cx.err_at(s, format!("scale {bad} is out of range: expected a number or [x, y, z] with each from {lo:e} to {hi:e}")));
        }
        let s = Vec3::from(s3.map(|c| c as f32));
        tris.iter_mut().flatten().for_each(|v| *v *= s);
    }
    if let Some(r) = &o.rotate_y {
        let angle = cx
            .ranged(r, -360.0, 360.0, "rotate_y (degrees)")?
            .to_radians();
        // The camera's convention: a positive angle turns +z towards +x.
        let (s, c) = (libm::sin(angle) as f32, libm::cos(angle) as f32);
        tris.iter_mut()
            .flatten()
            .for_each(|v| *v = Vec3::new(c * v.x + s * v.z, v.y, c * v.z - s * v.x));
    }
    if let Some(t) = &o.translate {
        let t = cx.point(t, "translate")?;
        tris.iter_mut().flatten().for_each(|v| *v += t);
    }
    Ok(())
}

/// The 12 triangles of the axis-aligned box from `lo` to `hi`.
fn box_triangles(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 3]> {
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    // Each face as a quad of corner indices (bit 0: x, bit 1: y, bit 2: z).
    const FACES: [[usize; 4]; 6] = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    FACES
        .iter()
        .flat_map(|&[a, b, c, d]| {
            [
                [corner(a), corner(b), corner(c)],
                [corner(a), corner(c), corner(d)],
            ]
        })
        .collect()
}
