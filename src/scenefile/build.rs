//! From the parsed file to a [`Scene`]: every value checked against its limit, geometry
//! generated and transformed, every triangle checked with the line it came from.

use std::collections::HashMap;

use glam::Vec3;
use rayon::prelude::*;
use toml::Spanned;

use super::error::{SceneFileError, did_you_mean};
use super::spec::{INDIRECT_EXPECTED, IndirectSpec, NumberOrTriple, ObjectSpec, SceneSpec};
use super::*;
use crate::camera::Camera;
use crate::geometry::Triangle;
use crate::obj::parse_obj;
use crate::procedural::{displaced_icosphere, icosphere_triangles};
use crate::scene::{Effects, Indirect, Material, PointLight, SceneBuilder};

/// The object kinds and the keys each one takes besides `kind`, `material` and the transform.
const KINDS: [(&str, &[&str]); 4] = [
    ("triangles", &["triangles"]),
    ("box", &["min", "max", "centre", "size"]),
    ("obj", &["path"]),
    ("icosphere", &["subdivisions", "amplitude"]),
];

/// The keys every object takes.
const COMMON_KEYS: [&str; 5] = ["kind", "material", "translate", "rotate_y", "scale"];

/// How each required key is written, for "missing key" messages.
const KEY_FORMS: [(&str, &str); 6] = [
    ("position", "position = [x, y, z]"),
    ("power", "power = 14 (or [r, g, b])"),
    ("colour", "colour = [r, g, b] (each from 0 to 1)"),
    (
        "kind",
        "kind = \"triangles\", \"box\", \"obj\" or \"icosphere\"",
    ),
    ("material", "material = \"NAME\" (a [material.NAME] table)"),
    ("bounces", "bounces = n (0 to 16)"),
];

/// Where a triangle came from, for its error message.
enum Origin<'a> {
    /// A byte offset in the scene file.
    Scene(usize),
    /// A face in a mesh file.
    Mesh {
        file: &'a str,
        line: u32,
        column: u32,
    },
}

struct Ctx<'a> {
    source: &'a str,
    file: &'a str,
}

impl Ctx<'_> {
    fn err(&self, offset: usize, message: impl Into<String>) -> SceneFileError {
        SceneFileError::at(self.file, self.source, offset, message)
    }

    fn err_at<T>(&self, v: &Spanned<T>, message: impl Into<String>) -> SceneFileError {
        self.err(v.span().start, message)
    }

    /// `v` as an `f32` triple, each component finite and within ±[`MAX_COORDINATE`].
    fn point(&self, v: &Spanned<[f64; 3]>, what: &str) -> Result<Vec3, SceneFileError> {
        for c in v.get_ref() {
            if !c.is_finite() || c.abs() > MAX_COORDINATE {
                return Err(self.err_at(
                    v,
                    format!(
                        "{what} has the coordinate {c}: expected finite numbers within ±{MAX_COORDINATE:e}"
                    ),
                ));
            }
        }
        Ok(Vec3::from(v.get_ref().map(|c| c as f32)))
    }

    /// A number in `lo..=hi`.
    fn ranged(
        &self,
        v: &Spanned<f64>,
        lo: f64,
        hi: f64,
        what: &str,
    ) -> Result<f64, SceneFileError> {
        let x = *v.get_ref();
        if !(x >= lo && x <= hi) {
            return Err(self.err_at(
                v,
                format!("{what} is {x}: expected a number from {lo} to {hi}"),
            ));
        }
        Ok(x)
    }

    /// A whole number in `lo..=hi`.
    fn whole(&self, v: &Spanned<i64>, lo: i64, hi: i64, what: &str) -> Result<i64, SceneFileError> {
        let x = *v.get_ref();
        if !(lo..=hi).contains(&x) {
            return Err(self.err_at(
                v,
                format!("{what} is {x}: expected a whole number from {lo} to {hi}"),
            ));
        }
        Ok(x)
    }
}

pub fn build(
    source: &str,
    file: &str,
    name: &str,
    read_mesh: MeshReader,
) -> Result<Scene, SceneFileError> {
    let cx = Ctx { source, file };
    let spec: SceneSpec = toml::from_str(source).map_err(|e| toml_error(&cx, &e))?;

    let mut camera = Camera::default();
    if let Some(c) = &spec.camera {
        if let Some(p) = &c.position {
            camera.position = cx.point(p, "the camera position")?;
        }
        if let Some(y) = &c.yaw {
            camera.yaw = cx
                .ranged(y, -360.0, 360.0, "the camera yaw (degrees)")?
                .to_radians() as f32;
        }
        if let Some(p) = &c.pitch {
            camera.pitch = cx
                .ranged(p, -90.0, 90.0, "the camera pitch (degrees)")?
                .to_radians() as f32;
        }
    }

    let mut b = SceneBuilder::new();
    for (i, l) in spec.light.iter().enumerate() {
        if i == MAX_LIGHTS {
            return Err(cx.err_at(l, format!("too many lights: at most {MAX_LIGHTS}")));
        }
        let l = l.get_ref();
        let position = cx.point(&l.position, "the light position")?;
        let NumberOrTriple(p) = *l.power.get_ref();
        if let Some(bad) = p.iter().find(|c| !(**c >= 0.0 && **c <= MAX_POWER)) {
            return Err(cx.err_at(
                &l.power,
                format!(
                    "light power {bad} is not allowed: expected a number from 0 to {MAX_POWER:e}, or [r, g, b] of such numbers (the Cornell box's is 14)"
                ),
            ));
        }
        b.light(PointLight {
            position,
            power: Vec3::from(p.map(|c| c as f32)),
        });
    }

    let mut materials: HashMap<&str, Material> = HashMap::new();
    for (key, m) in &spec.material {
        let m = m.get_ref();
        for c in m.colour.get_ref() {
            if !(*c >= 0.0 && *c <= 1.0) {
                return Err(cx.err_at(
                    &m.colour,
                    format!("material `{key}`: colour component {c} is out of range: expected [r, g, b] with each from 0 to 1"),
                ));
            }
        }
        let mirror = match &m.mirror {
            Some(r) => cx.ranged(
                r,
                0.0,
                1.0,
                &format!("material `{key}`: the mirror reflectance"),
            )?,
            None => 0.0,
        };
        materials.insert(
            key.as_str(),
            Material {
                colour: Vec3::from(m.colour.get_ref().map(|c| c as f32)),
                mirror: mirror as f32,
            },
        );
    }
    let mut material_names: Vec<&str> = materials.keys().copied().collect();
    material_names.sort_unstable();

    // Materials enter the scene in the order objects first use them.
    let mut material_index: HashMap<&str, u32> = HashMap::new();
    let mut total = 0usize;
    for object in &spec.object {
        let o = object.get_ref();
        let mname = o.material.get_ref().as_str();
        let Some(material) = materials.get(mname) else {
            let known = if material_names.is_empty() {
                "no materials are defined: add a [material.NAME] table with colour = [r, g, b]"
                    .to_string()
            } else {
                format!("defined: {}", material_names.join(", "))
            };
            return Err(cx.err_at(
                &o.material,
                format!(
                    "unknown material `{mname}`{} ({known})",
                    did_you_mean(mname, &material_names)
                ),
            ));
        };
        let index = *material_index
            .entry(mname)
            .or_insert_with(|| b.material(material.clone()));
        let triangles = object_triangles(&cx, object, total, read_mesh)?;
        total += triangles.len();
        b.object(triangles, index);
    }

    let mut effects = Effects::SEED;
    if let Some(e) = &spec.effects {
        if let Some(s) = e.shadows {
            effects.shadows = s;
        }
        if let Some(i) = &e.indirect {
            effects.indirect = match *i.get_ref() {
                IndirectSpec::None => Indirect::None,
                IndirectSpec::Constant(n) => {
                    if !(0.0..=MAX_CONSTANT).contains(&n) {
                        return Err(cx.err_at(
                            i,
                            format!("indirect = {n}: a constant term must be from 0 to {MAX_CONSTANT}; indirect takes {INDIRECT_EXPECTED}"),
                        ));
                    }
                    Indirect::Constant(n as f32)
                }
                IndirectSpec::Bounces(n) => {
                    if !(0..=MAX_BOUNCES).contains(&n) {
                        return Err(cx.err_at(
                            i,
                            format!(
                                "bounces is {n}: expected a whole number from 0 to {MAX_BOUNCES}"
                            ),
                        ));
                    }
                    Indirect::PathTraced { bounces: n as u32 }
                }
            };
        }
        if let Some(s) = &e.samples {
            effects.samples = cx.whole(s, 1, MAX_SAMPLES, "samples (per pixel)")? as u32;
        }
    }

    if spec.object.is_empty() {
        return Err(cx.err(
            0,
            "the scene has no objects: add an [[object]] table (scenes/example.toml shows every kind)",
        ));
    }

    let name = spec.name.as_ref().map_or(name, |n| n.get_ref().as_str());
    // Everything the builder checks was checked above with a position; this is a safety net.
    b.build(name, camera, effects)
        .map_err(|e| SceneFileError::whole_file(file, e.to_string()))
}

/// The triangles of one object, transformed and checked. `before` triangles came earlier.
fn object_triangles(
    cx: &Ctx,
    object: &Spanned<ObjectSpec>,
    before: usize,
    read_mesh: MeshReader,
) -> Result<Vec<[Vec3; 3]>, SceneFileError> {
    let o = object.get_ref();
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
    let given: [(&str, Option<usize>); 7] = [
        ("triangles", o.triangles.as_ref().map(|v| v.span().start)),
        ("min", o.min.as_ref().map(|v| v.span().start)),
        ("max", o.max.as_ref().map(|v| v.span().start)),
        ("centre", o.centre.as_ref().map(|v| v.span().start)),
        ("size", o.size.as_ref().map(|v| v.span().start)),
        ("path", o.path.as_ref().map(|v| v.span().start)),
        (
            "subdivisions",
            o.subdivisions.as_ref().map(|v| v.span().start),
        ),
    ];
    let amplitude = ("amplitude", o.amplitude.as_ref().map(|v| v.span().start));
    for (key, at) in given.into_iter().chain([amplitude]) {
        if let (Some(at), false) = (at, allowed.contains(&key)) {
            let mut keys: Vec<&str> = allowed.to_vec();
            keys.extend(COMMON_KEYS);
            return Err(cx.err(
                at,
                format!(
                    "`{key}` is not a key of kind = \"{kind}\" objects: they take {}",
                    keys.join(", ")
                ),
            ));
        }
    }
    let budget = MAX_TRIANGLES - before;
    let over = |n: u64| {
        cx.err_at(
            object,
            format!("this object makes {n} triangles; with the {before} before it the scene is over {MAX_TRIANGLES} triangles, the limit"),
        )
    };
    let mut mesh_file = String::new();
    let (mut tris, origins): (Vec<[Vec3; 3]>, Vec<(u32, u32)>) = match kind {
        "triangles" => {
            let Some(list) = &o.triangles else {
                return Err(cx.err_at(object, "a `triangles` object needs triangles = [[[x, y, z], [x, y, z], [x, y, z]], ...]"));
            };
            if list.get_ref().len() > budget {
                return Err(over(list.get_ref().len() as u64));
            }
            let mut out = Vec::with_capacity(list.get_ref().len());
            for t in list.get_ref() {
                let mut v = [Vec3::ZERO; 3];
                for (vi, p) in v.iter_mut().zip(t.get_ref()) {
                    let spanned = Spanned::new(t.span(), *p);
                    *vi = cx.point(&spanned, "a triangle vertex")?;
                }
                out.push(v);
            }
            let origins = list
                .get_ref()
                .iter()
                .map(|t| (t.span().start as u32, 0))
                .collect();
            (out, origins)
        }
        "box" => {
            let (lo, hi) = match (&o.min, &o.max, &o.centre, &o.size) {
                (Some(min), Some(max), None, None) => {
                    let (lo, hi) = (
                        cx.point(min, "the box's min")?,
                        cx.point(max, "the box's max")?,
                    );
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
                        return Err(
                            cx.err_at(size, "the box's size must be positive on every axis")
                        );
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
            let t = box_triangles(lo, hi);
            let n = t.len();
            (t, vec![(object.span().start as u32, 0); n])
        }
        "obj" => {
            let Some(path) = &o.path else {
                return Err(cx.err_at(
                    object,
                    "an `obj` object needs path = \"FILE.obj\" (relative to the scene file)",
                ));
            };
            let (shown, bytes) = read_mesh(path.get_ref()).map_err(|e| {
                cx.err_at(
                    path,
                    format!(
                        "{e}; give the path of an OBJ file, relative to the scene file's folder"
                    ),
                )
            })?;
            let mesh =
                parse_obj(&bytes, budget, MAX_MESH_VERTICES).map_err(|e| SceneFileError {
                    file: crate::frame::printable(&shown),
                    line: e.line,
                    column: e.column,
                    message: crate::frame::printable(&format!(
                        "{} (in the mesh named at {}:{})",
                        e.message,
                        cx.file,
                        {
                            let (l, c) = line_column(cx.source, path.span().start);
                            format!("{l}:{c}")
                        }
                    )),
                })?;
            if mesh.triangles.is_empty() {
                return Err(cx.err_at(
                    path,
                    format!("the mesh file {shown} has no faces (f lines): is it an OBJ file?"),
                ));
            }
            mesh_file = shown;
            (mesh.triangles, mesh.origins)
        }
        _ => {
            let k = match &o.subdivisions {
                Some(s) => cx.whole(s, 1, MAX_SUBDIVISIONS, "subdivisions")?,
                None => return Err(cx.err_at(object, format!("an icosphere needs subdivisions = k (1 to {MAX_SUBDIVISIONS}; it has 20·k² triangles)"))),
            };
            let amplitude = match &o.amplitude {
                Some(a) => cx.ranged(a, -MAX_AMPLITUDE, MAX_AMPLITUDE, "amplitude")?,
                None => 0.0,
            };
            let n = icosphere_triangles(k as u32);
            if n > budget as u64 {
                return Err(over(n));
            }
            let t = displaced_icosphere(k as u32, amplitude as f32);
            let n = t.len();
            (t, vec![(object.span().start as u32, 0); n])
        }
    };

    transform(cx, o, &mut tris)?;
    let origin = |i: usize| -> Origin {
        let (a, b) = origins[i];
        if kind == "obj" {
            Origin::Mesh {
                file: &mesh_file,
                line: a,
                column: b,
            }
        } else {
            Origin::Scene(a as usize)
        }
    };
    // In parallel (a procedural mesh has a million triangles); the first bad one is reported.
    let bad = tris
        .par_iter()
        .position_first(|&t| triangle_problem(t).is_some());
    if let Some(i) = bad {
        let problem = triangle_problem(tris[i]).unwrap_or_default();
        return Err(match origin(i) {
            Origin::Scene(offset) => cx.err(offset, problem),
            Origin::Mesh { file, line, column } => SceneFileError {
                file: crate::frame::printable(file),
                line: line as usize,
                column: column as usize,
                message: crate::frame::printable(&format!(
                    "{problem} (after the transform at {}:{})",
                    cx.file,
                    {
                        let (l, c) = line_column(cx.source, object.span().start);
                        format!("{l}:{c}")
                    }
                )),
            },
        });
    }
    Ok(tris)
}

/// What is wrong with a transformed triangle, if anything: a vertex beyond the coordinate
/// limit, or a degenerate shape the scene would reject.
fn triangle_problem([a, b, c]: [Vec3; 3]) -> Option<String> {
    if [a, b, c]
        .iter()
        .any(|v| !(v.abs().max_element() <= MAX_COORDINATE as f32))
    {
        return Some(format!(
            "a vertex is beyond ±{MAX_COORDINATE:e} after the object's transform: make the scale or translate smaller"
        ));
    }
    Triangle::new(a, b, c, 0).err().map(|e| {
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
        let (s, c) = (angle.sin() as f32, angle.cos() as f32);
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

/// A TOML or serde error as a positioned message; unknown keys get a suggestion.
fn toml_error(cx: &Ctx, e: &toml::de::Error) -> SceneFileError {
    let offset = e.span().map_or(0, |s| s.start);
    let message = e.message().trim().replace('\n', "; ");
    let message = if let Some(rest) = message.strip_prefix("unknown field `") {
        let key = rest.split('`').next().unwrap_or("");
        let known: Vec<&str> = rest
            .split('`')
            .skip(1)
            .collect::<Vec<_>>()
            .chunks(2)
            .filter_map(|c| c.get(1).copied())
            .collect();
        format!(
            "unknown key `{key}`{} (keys here: {})",
            did_you_mean(key, &known),
            if known.is_empty() {
                "none".to_string()
            } else {
                known.join(", ")
            }
        )
    } else if let Some(rest) = message.strip_prefix("missing field `") {
        let key = rest.split('`').next().unwrap_or("");
        let form = KEY_FORMS
            .iter()
            .find(|k| k.0 == key)
            .map_or(String::new(), |k| format!(": add {}", k.1));
        format!("missing key `{key}` in this table{form}")
    } else {
        message
            .replace("duplicate field", "duplicate key")
            .replace(" as i128", "")
            .replace(
                "expected an array of length 3",
                "expected three numbers [a, b, c]",
            )
            .replace("expected i64", "expected a whole number")
            .replace("expected f64", "expected a number")
            .replace("expected a boolean", "expected true or false")
    };
    cx.err(offset, message)
}
