//! glTF 2.0, JSON (`.gltf`, buffers in files beside it or in `data:` URIs) and binary
//! (`.glb`), through the `gltf` crate's parser and validator: the default scene's node
//! hierarchy with its transforms, triangle meshes (lists, strips and fans; indexed or not) with
//! their normals, first UVs and `COLOR_0`, metallic-roughness materials (with the emissive
//! strength, IOR and transmission extensions), perspective cameras and `KHR_lights_punctual`
//! point, spot and directional lights.
//!
//! Accessors are read here, each range checked against its buffer first, so no file can make
//! a read go out of bounds. A required extension raytty does not read is an error naming it.
//! Errors give the JSON path of what is wrong (`/meshes/0/primitives/1`), or a JSON line and
//! column, or the GLB's byte layout.

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use ::gltf::{Gltf, Node, buffer};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use std::collections::HashMap;

use super::{
    FileReader, Model, ModelCamera, ModelLight, ModelLightKind, ModelMaterial, check_triangles,
};
use crate::scene::file::SceneFileError;
use crate::scene::texture::{Filter, Texture, Wrap};

/// The extensions a file may require: those read here, and those whose absence only loses
/// quality (`KHR_materials_volume`, `_specular`: parsed, for the materials to come).
pub const KNOWN_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_specular",
];

/// Deepest node hierarchy followed: deeper is taken for a cycle.
const MAX_DEPTH: usize = 256;
/// Most node instances visited (a node shared by many parents is visited once per parent).
const MAX_NODE_VISITS: usize = 1_000_000;

/// Bytes in a GLB's header: magic, version, length.
const GLB_HEADER: u32 = 12;

/// The length a GLB's header declares, if `bytes` start with one.
fn glb_length(bytes: &[u8]) -> Option<u32> {
    let length = bytes.strip_prefix(b"glTF")?.get(4..8)?;
    Some(u32::from_le_bytes(length.try_into().ok()?))
}

/// Reads `bytes` (a `.gltf` or `.glb`) as a model named `file`, its buffers through `read`.
pub fn parse(bytes: &[u8], file: &str, read: FileReader) -> Result<Model, SceneFileError> {
    let whole = |m: String| SceneFileError::whole_file(file, m);
    // gltf 1.4.1 subtracts the 12-byte header from a GLB's declared length unchecked (an
    // overflow panic where overflow is checked: found by the million-input fuzz run).
    if let Some(length) = glb_length(bytes).filter(|&l| l < GLB_HEADER) {
        return Err(whole(format!(
            "byte 8: the GLB's length is {length}, less than its own {GLB_HEADER}-byte header"
        )));
    }
    let gltf = match Gltf::from_slice_without_validation(bytes) {
        Ok(g) => g,
        Err(e) => return Err(parse_error(bytes, file, e)),
    };
    validate(gltf.document.as_json()).map_err(|e| parse_error(bytes, file, e))?;
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for b in gltf.buffers() {
        let at = format!("/buffers/{}", b.index());
        let data = match b.source() {
            buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                whole(format!(
                    "{at}: refers to the GLB's binary chunk, which the file does not have"
                ))
            })?,
            buffer::Source::Uri(uri) => {
                uri_bytes(uri, read).map_err(|m| whole(format!("{at}: {m}")))?
            }
        };
        if data.len() < b.length() {
            return Err(whole(format!(
                "{at}: byteLength is {} but the data has {} bytes",
                b.length(),
                data.len()
            )));
        }
        buffers.push(data);
    }
    let mut model = Model::default();
    // Material 0 is the default; glTF material i is i + 1.
    model.materials.push(ModelMaterial::default());
    let root = gltf.document.as_json();
    let mut decoded = HashMap::new();
    for m in gltf.materials() {
        let mut mm = material(&m, root);
        if let Some(i) = m.index() {
            let files = Files {
                buffers: &buffers,
                read,
            };
            mm.texture = base_colour_texture(i, root, &files, &mut model, &mut decoded);
        }
        model.materials.push(mm);
    }
    let roots: Vec<Node> = match gltf.default_scene().or_else(|| gltf.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => {
            // No scene: every node that is no other's child is a root.
            let mut child = vec![false; gltf.nodes().len()];
            for n in gltf.nodes() {
                for c in n.children() {
                    child[c.index()] = true;
                }
            }
            gltf.nodes().filter(|n| !child[n.index()]).collect()
        }
    };
    let mut stack: Vec<(Node, Mat4, usize)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY, 0))
        .collect();
    let mut visits = 0;
    while let Some((node, parent, depth)) = stack.pop() {
        let at = format!("/nodes/{}", node.index());
        visits += 1;
        if depth > MAX_DEPTH || visits > MAX_NODE_VISITS {
            return Err(whole(format!(
                "{at}: the node hierarchy is deeper than {MAX_DEPTH} or has more than {MAX_NODE_VISITS} node instances (a node that is its own ancestor?)"
            )));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            return Err(whole(format!("{at}: its transform is not finite")));
        }
        if let Some(mesh) = node.mesh() {
            for p in mesh.primitives() {
                let at = format!("/meshes/{}/primitives/{}", mesh.index(), p.index());
                primitive(&p, &world, &buffers, &mut model)
                    .map_err(|m| whole(format!("{at}: {m}")))?;
            }
        }
        if let Some(camera) = node.camera() {
            // Read from the JSON: the crate's `projection()` unwraps the object the type names,
            // which its validator does not require (a perspective camera with only an
            // orthographic object would panic).
            use ::gltf::json::camera::Type;
            use ::gltf::json::validation::Checked;
            let json = &root.cameras[camera.index()];
            match (&json.type_, &json.perspective) {
                (Checked::Valid(Type::Perspective), Some(p)) => model.cameras.push(ModelCamera {
                    position: world.transform_point3(Vec3::ZERO),
                    forward: world.transform_vector3(-Vec3::Z).normalize_or_zero(),
                    up: world.transform_vector3(Vec3::Y).normalize_or_zero(),
                    fov: Some(p.yfov),
                }),
                _ => model.note(format!(
                    "camera {}: only perspective cameras are used",
                    camera.index()
                )),
            }
        }
        if let Some(light) = node.light() {
            use ::gltf::khr_lights_punctual::Kind;
            let intensity = Vec3::from(light.color()) * light.intensity();
            let position = world.transform_point3(Vec3::ZERO);
            // Directional and spot lights point down their node's -z.
            let direction = world.transform_vector3(-Vec3::Z).normalize_or_zero();
            let kind = match light.kind() {
                Kind::Point => Some(ModelLightKind::Point),
                _ if direction == Vec3::ZERO => None,
                Kind::Directional => Some(ModelLightKind::Directional { direction }),
                Kind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => {
                    let ok = 0.0 <= inner_cone_angle
                        && inner_cone_angle <= outer_cone_angle
                        && outer_cone_angle <= std::f32::consts::FRAC_PI_2;
                    if !ok {
                        return Err(whole(format!(
                            "/extensions/KHR_lights_punctual/lights/{}/spot: cone angles {inner_cone_angle} and {outer_cone_angle}: expected 0 <= innerConeAngle <= outerConeAngle <= pi/2",
                            light.index()
                        )));
                    }
                    Some(ModelLightKind::Spot {
                        direction,
                        inner: inner_cone_angle,
                        outer: outer_cone_angle,
                    })
                }
            };
            match kind {
                Some(kind) => model.lights.push(ModelLight {
                    position,
                    intensity,
                    kind,
                }),
                None => model.note(format!(
                    "light {}: its node's transform is degenerate, so it has no direction; not used",
                    light.index()
                )),
            }
        }
        for c in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((c, world, depth + 1));
        }
    }
    if model
        .lights
        .iter()
        .any(|l| !l.intensity.is_finite() || l.intensity.min_element() < 0.0)
    {
        return Err(whole(
            "/extensions/KHR_lights_punctual/lights: a light's colour and intensity must be finite and non-negative".into(),
        ));
    }
    if model
        .cameras
        .iter()
        .any(|c| !c.position.is_finite() || c.forward == Vec3::ZERO)
    {
        return Err(whole(
            "/cameras: a camera's node transform is degenerate".into(),
        ));
    }
    Ok(model)
}

/// The `gltf` crate's validation, which `Gltf::from_slice` runs; first, what its validator
/// takes for granted and would panic on (found by fuzzing: gltf-json 1.4.1 indexes the
/// accessors with a primitive's POSITION index unchecked).
fn validate(root: &::gltf::json::Root) -> Result<(), ::gltf::Error> {
    use ::gltf::json::validation::{Error, Validate};
    use ::gltf::json::{Path, mesh::Semantic, validation::Checked};
    let mut errors: Vec<(Path, Error)> = Vec::new();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(Semantic::Positions));
            if position.is_some_and(|i| i.value() >= root.accessors.len()) {
                let path = Path::new()
                    .field("meshes")
                    .index(m)
                    .field("primitives")
                    .index(p)
                    .field("attributes")
                    .key("POSITION");
                errors.push((path, Error::IndexOutOfBounds));
            }
        }
    }
    if errors.is_empty() {
        root.validate(root, Path::new, &mut |path, error| {
            errors.push((path(), error))
        });
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(::gltf::Error::Validation(errors))
    }
}

/// A `gltf` crate error as a positioned message.
fn parse_error(bytes: &[u8], file: &str, e: ::gltf::Error) -> SceneFileError {
    let glb = bytes.starts_with(b"glTF");
    match e {
        ::gltf::Error::Deserialize(j) if !glb => {
            let text = String::from_utf8_lossy(bytes);
            SceneFileError::at_line(
                file,
                &text,
                j.line(),
                j.column().max(1),
                format!("JSON: {j}"),
            )
        }
        ::gltf::Error::Deserialize(j) => {
            SceneFileError::whole_file(file, format!("the GLB's JSON chunk: {j}"))
        }
        ::gltf::Error::Binary(b) => SceneFileError::whole_file(
            file,
            format!("not a readable GLB (12-byte header, then JSON and BIN chunks): {b}"),
        ),
        ::gltf::Error::Validation(list) => {
            // A required extension first: it is why the rest cannot be read.
            let required = Gltf::from_slice_without_validation(bytes)
                .ok()
                .and_then(|g| {
                    g.extensions_required()
                        .find(|x| !KNOWN_EXTENSIONS.contains(x))
                        .map(str::to_string)
                });
            if let Some(x) = required {
                return SceneFileError::whole_file(
                    file,
                    format!(
                        "/extensionsRequired: the file requires extension `{x}`, which raytty does not read (it reads {})",
                        KNOWN_EXTENSIONS.join(", ")
                    ),
                );
            }
            let shown: Vec<String> = list
                .iter()
                .take(3)
                .map(|(path, err)| format!("{}: {err}", pointer(&path.to_string())))
                .collect();
            let more = match list.len() {
                n if n > 3 => format!(" (and {} more)", n - 3),
                _ => String::new(),
            };
            SceneFileError::whole_file(
                file,
                format!("not valid glTF 2.0: {}{more}", shown.join("; ")),
            )
        }
        other => SceneFileError::whole_file(file, other.to_string()),
    }
}

/// The `gltf` crate's path (`meshes[0].primitives[1].attributes["POSITION"]`) as a JSON
/// pointer (`/meshes/0/primitives/1/attributes/POSITION`).
fn pointer(path: &str) -> String {
    let mut out = String::from("/");
    for c in path.chars() {
        match c {
            '.' | '[' => {
                if !out.ends_with('/') {
                    out.push('/')
                }
            }
            ']' | '"' => {}
            c => out.push(c),
        }
    }
    out
}

/// A buffer's bytes: a `data:` URI's base64 payload, or a file beside the model.
fn uri_bytes(uri: &str, read: FileReader) -> Result<Vec<u8>, String> {
    use base64::Engine;
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err("a data URI must be base64 (`data:...;base64,...`)".into());
        };
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("its data URI is not valid base64: {e}"));
    }
    read(&percent_decode(uri)).map(|(_, bytes)| bytes)
}

/// `%20` and the like in a relative URI, as the file name they stand for.
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && let (Some(h), Some(l)) = (
                b.get(i + 1).and_then(|&c| hex(c)),
                b.get(i + 2).and_then(|&c| hex(c)),
            )
        {
            out.push((h * 16 + l) as u8);
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn material(m: &::gltf::Material, root: &::gltf::json::Root) -> ModelMaterial {
    let pbr = m.pbr_metallic_roughness();
    let base = Vec4::from(pbr.base_color_factor());
    // The image's URI from the JSON: the crate's `Image::source()` unwraps fields its validator
    // does not require.
    let texture = pbr.base_color_texture().map(|t| {
        let image = root
            .textures
            .get(t.texture().index())
            .map_or(usize::MAX, |t| t.source.value());
        image_name(root, image)
    });
    let finite01 = |x: f32| {
        if x.is_finite() {
            x.clamp(0.0, 1.0)
        } else {
            0.0
        }
    };
    let emission = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
    ModelMaterial {
        name: m.name().unwrap_or_default().to_string(),
        base_colour: base.truncate().to_array().map(finite01).into(),
        metallic: finite01(pbr.metallic_factor()),
        roughness: finite01(pbr.roughness_factor()),
        emission: if emission.is_finite() {
            emission.max(Vec3::ZERO)
        } else {
            Vec3::ZERO
        },
        ior: m
            .ior()
            .filter(|x| x.is_finite() && *x >= 1.0)
            .unwrap_or(1.5),
        transmission: m
            .transmission()
            .map_or(0.0, |t| finite01(t.transmission_factor())),
        opacity: finite01(base.w),
        base_colour_texture: texture,
        texture: None,
    }
}

/// What a glTF's images are read from: its buffers, and the files beside it.
struct Files<'a> {
    buffers: &'a [Vec<u8>],
    read: FileReader<'a>,
}

/// Image `image` as messages name it: its URI, or its index when it is embedded.
fn image_name(root: &::gltf::json::Root, image: usize) -> String {
    match root.images.get(image).and_then(|i| i.uri.as_deref()) {
        Some(uri) if !uri.starts_with("data:") => format!("`{}`", percent_decode(uri)),
        _ => format!("image {image} (embedded)"),
    }
}

/// Material `i`'s base-colour texture as an index into `model.textures`, each image and
/// sampler decoded once (`decoded`). A texture that cannot be drawn (its image missing or not
/// a PNG or JPEG, or on a second set of texture coordinates) is a warning, and `None`: the
/// material's base colour factor is drawn alone.
fn base_colour_texture(
    i: usize,
    root: &::gltf::json::Root,
    files: &Files,
    model: &mut Model,
    decoded: &mut HashMap<(usize, Option<usize>), Option<u32>>,
) -> Option<u32> {
    use ::gltf::json::texture::{MagFilter, WrappingMode};
    use ::gltf::json::validation::Checked;
    let info = root
        .materials
        .get(i)?
        .pbr_metallic_roughness
        .base_color_texture
        .as_ref()?;
    let at = format!("/materials/{i}/pbrMetallicRoughness/baseColorTexture");
    let texture = root.textures.get(info.index.value())?;
    let image = texture.source.value();
    let name = image_name(root, image);
    let warn = |model: &mut Model, why: String| {
        model.note(format!(
            "warning: texture {name} ({at}): {why}; the base colour factor is drawn instead"
        ))
    };
    if info.tex_coord != 0 {
        warn(
            model,
            format!(
                "it uses TEXCOORD_{}, and raytty reads TEXCOORD_0 only",
                info.tex_coord
            ),
        );
        return None;
    }
    let sampler = texture.sampler.map(|s| s.value());
    if let Some(&done) = decoded.get(&(image, sampler)) {
        return done;
    }
    let result = image_bytes(root, image, files).and_then(|b| Texture::decode(&b));
    let out = match result {
        Ok(mut t) => {
            if let Some(s) = sampler.and_then(|s| root.samplers.get(s)) {
                let wrap = |w: &Checked<WrappingMode>| match w {
                    Checked::Valid(WrappingMode::ClampToEdge) => Wrap::Clamp,
                    Checked::Valid(WrappingMode::MirroredRepeat) => Wrap::Mirror,
                    _ => Wrap::Repeat,
                };
                t.wrap = [wrap(&s.wrap_s), wrap(&s.wrap_t)];
                if let Some(Checked::Valid(MagFilter::Nearest)) = s.mag_filter {
                    t.filter = Filter::Nearest;
                }
            }
            model.textures.push(t);
            Some(model.textures.len() as u32 - 1)
        }
        Err(why) => {
            warn(model, why);
            None
        }
    };
    decoded.insert((image, sampler), out);
    out
}

/// Image `image`'s bytes: a `data:` URI's, a file's beside the model, or a buffer view's.
fn image_bytes(root: &::gltf::json::Root, image: usize, files: &Files) -> Result<Vec<u8>, String> {
    let Some(img) = root.images.get(image) else {
        return Err(format!("image {image} does not exist"));
    };
    if let Some(uri) = &img.uri {
        return uri_bytes(uri, files.read);
    }
    let Some(v) = img.buffer_view else {
        return Err("the image has neither a uri nor a bufferView".into());
    };
    let view = root
        .buffer_views
        .get(v.value())
        .ok_or_else(|| format!("buffer view {} does not exist", v.value()))?;
    let data = files
        .buffers
        .get(view.buffer.value())
        .ok_or_else(|| format!("buffer {} does not exist", view.buffer.value()))?;
    let start = view.byte_offset.map_or(0, |o| o.0);
    let end = start.checked_add(view.byte_length.0);
    match end {
        Some(end) if end <= data.len() as u64 => Ok(data[start as usize..end as usize].to_vec()),
        _ => Err(format!(
            "buffer view {} (bytes {start} to {} of a buffer of {}) does not fit its buffer",
            v.value(),
            start.saturating_add(view.byte_length.0),
            data.len()
        )),
    }
}

/// Adds one primitive, transformed by `world`. An error says what is wrong, with the JSON path
/// of the accessor at fault (the caller puts the primitive's path before it).
fn primitive(
    p: &::gltf::Primitive,
    world: &Mat4,
    buffers: &[Vec<u8>],
    model: &mut Model,
) -> Result<(), String> {
    let mode = p.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        model.note("points and lines are not drawn (only triangles)");
        return Ok(());
    }
    let Some(positions) = p.get(&::gltf::Semantic::Positions) else {
        return Err("attributes: no POSITION: a triangle primitive needs positions".into());
    };
    let positions = read_floats::<3>(&positions, buffers)?;
    let first = model.positions.len();
    let count = positions.len();
    let normal_matrix = Mat3::from_mat4(*world).inverse().transpose();
    model.positions.extend(
        positions
            .iter()
            .map(|&v| world.transform_point3(Vec3::from(v))),
    );
    // Attributes some primitives have and others lack: zero normals and UVs, white colours.
    if let Some(a) = p.get(&::gltf::Semantic::Normals) {
        let n = read_floats::<3>(&a, buffers)?;
        same_count(n.len(), count, "NORMAL")?;
        model.normals.resize(first, Vec3::ZERO);
        model.normals.extend(n.iter().map(|&v| {
            let v = (normal_matrix * Vec3::from(v)).normalize_or_zero();
            if v.is_finite() { v } else { Vec3::ZERO }
        }));
    }
    if let Some(a) = p.get(&::gltf::Semantic::TexCoords(0)) {
        let t = read_floats::<2>(&a, buffers)?;
        same_count(t.len(), count, "TEXCOORD_0")?;
        model.uvs.resize(first, Vec2::ZERO);
        model.uvs.extend(t.iter().map(|&v| Vec2::from(v)));
    }
    if let Some(a) = p.get(&::gltf::Semantic::Colors(0)) {
        let c: Vec<[f32; 4]> = match a.dimensions() {
            Dimensions::Vec3 => read_floats::<3>(&a, buffers)?
                .into_iter()
                .map(|[r, g, b]| [r, g, b, 1.0])
                .collect(),
            _ => read_floats::<4>(&a, buffers)?,
        };
        same_count(c.len(), count, "COLOR_0")?;
        model.colours.resize(first, Vec3::ONE);
        model.colours.extend(
            c.iter()
                .map(|&[r, g, b, _]| Vec3::new(r, g, b).clamp(Vec3::ZERO, Vec3::ONE)),
        );
    }
    for (list, fill) in [
        (&mut model.normals, Vec3::ZERO),
        (&mut model.colours, Vec3::ONE),
    ] {
        if !list.is_empty() {
            list.resize(model.positions.len(), fill);
        }
    }
    if !model.uvs.is_empty() {
        model.uvs.resize(model.positions.len(), Vec2::ZERO);
    }
    let indices: Vec<u32> = match p.indices() {
        Some(a) => {
            let at = format!(" (accessor /accessors/{})", a.index());
            let idx = read_indices(&a, buffers)?;
            if let Some(bad) = idx.iter().find(|&&i| i as usize >= count) {
                return Err(format!(
                    "indices: index {bad} is out of range: the primitive has {count} vertices{at}"
                ));
            }
            idx
        }
        None => (0..count as u32).collect(),
    };
    let n = indices.len();
    let triangles = match mode {
        Mode::Triangles => n / 3,
        _ => n.saturating_sub(2),
    };
    check_triangles(model.triangles.len(), triangles)?;
    let base = first as u32;
    let material = p.material().index().map_or(0, |i| i as u32 + 1);
    let start = model.triangles.len();
    for k in 0..triangles {
        let t = match mode {
            Mode::Triangles => [indices[3 * k], indices[3 * k + 1], indices[3 * k + 2]],
            // Every other strip triangle is flipped so that all keep the strip's winding.
            Mode::TriangleStrip if k % 2 == 1 => [indices[k + 1], indices[k], indices[k + 2]],
            Mode::TriangleStrip => [indices[k], indices[k + 1], indices[k + 2]],
            _ => [indices[0], indices[k + 1], indices[k + 2]],
        };
        model.triangles.push(t.map(|i| base + i));
    }
    // Materials are listed once any triangle has one but the default (0).
    if material != 0 || !model.triangle_materials.is_empty() {
        model.triangle_materials.resize(start, 0);
        model
            .triangle_materials
            .resize(model.triangles.len(), material);
    }
    Ok(())
}

fn same_count(n: usize, count: usize, what: &str) -> Result<(), String> {
    if n != count {
        return Err(format!(
            "attribute {what}: {n} values for {count} positions: every attribute has one per vertex"
        ));
    }
    Ok(())
}

/// The byte range of accessor `a`'s elements within its buffer, checked: (buffer, start,
/// stride, element size). `None` for an accessor without a view (all zeros).
fn layout(
    a: &::gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Option<(usize, usize, usize, usize)>, String> {
    let at = format!("/accessors/{}", a.index());
    if a.sparse().is_some() {
        return Err(format!("{at}: sparse accessors are not read yet"));
    }
    let Some(view) = a.view() else {
        // No data: zeros, as many as the accessor says, which must be a sensible number.
        if a.count() > 3 * super::MAX_MODEL_TRIANGLES {
            return Err(format!(
                "{at}: {} elements without data: too many",
                a.count()
            ));
        }
        return Ok(None);
    };
    let size = a.size();
    let stride = view.stride().unwrap_or(size).max(size);
    let start = view.offset().checked_add(a.offset());
    let count = a.count();
    let end = start.and_then(|s| {
        count.checked_sub(1).map_or(Some(s), |last| {
            last.checked_mul(stride)?.checked_add(s)?.checked_add(size)
        })
    });
    let view_end = view.offset().checked_add(view.length());
    let data = &buffers[view.buffer().index()];
    match (start, end, view_end) {
        (Some(s), Some(e), Some(ve)) if e <= ve && ve <= data.len() => {
            Ok(Some((view.buffer().index(), s, stride, size)))
        }
        _ => Err(format!(
            "{at}: {count} elements of {size} bytes every {stride}, from byte {} of buffer view {} (bytes {} to {} of buffer {}, which has {} bytes), do not fit",
            a.offset(),
            view.index(),
            view.offset(),
            view.offset().saturating_add(view.length()),
            view.buffer().index(),
            data.len()
        )),
    }
}

/// Accessor `a` as `N` floats an element (normalized integers scaled as glTF says).
fn read_floats<const N: usize>(
    a: &::gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<[f32; N]>, String> {
    let dims = match a.dimensions() {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 => 4,
        _ => 0,
    };
    if dims != N {
        return Err(format!(
            "/accessors/{}: has {dims} components an element where {N} are expected",
            a.index()
        ));
    }
    let Some((buffer, start, stride, _)) = layout(a, buffers)? else {
        return Ok(vec![[0.0; N]; a.count()]);
    };
    let data = &buffers[buffer];
    let ty = a.data_type();
    let norm = a.normalized();
    let comp = ty.size();
    let value = |o: usize| -> f32 {
        let b = &data[o..o + comp];
        match ty {
            DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            DataType::U8 if norm => b[0] as f32 / 255.0,
            DataType::U8 => b[0] as f32,
            DataType::I8 if norm => (b[0] as i8 as f32 / 127.0).max(-1.0),
            DataType::I8 => b[0] as i8 as f32,
            DataType::U16 if norm => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
            DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f32,
            DataType::I16 if norm => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
            DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f32,
            DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
        }
    };
    Ok((0..a.count())
        .map(|i| std::array::from_fn(|k| value(start + i * stride + k * comp)))
        .collect())
}

/// Index accessor `a` (unsigned bytes, shorts or ints).
fn read_indices(a: &::gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>, String> {
    if a.dimensions() != Dimensions::Scalar
        || !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
    {
        return Err(format!(
            "/accessors/{}: indices must be scalars of unsigned bytes, shorts or ints",
            a.index()
        ));
    }
    let Some((buffer, start, stride, size)) = layout(a, buffers)? else {
        return Ok(vec![0; a.count()]);
    };
    let data = &buffers[buffer];
    Ok((0..a.count())
        .map(|i| {
            let b = &data[start + i * stride..start + i * stride + size];
            match size {
                1 => b[0] as u32,
                2 => u16::from_le_bytes([b[0], b[1]]) as u32,
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            }
        })
        .collect())
}
