//! OBJ models: the OBJ reader's indexed mesh ([`crate::scene::obj::parse_obj_model`]) with the
//! materials of the MTL libraries it names. A library that cannot be read is a note (the model
//! shows in the default material), as is a `usemtl` name no library defines; a mistake inside
//! a library is an error at its line and column.

use std::collections::HashMap;

use glam::Vec2;

use super::{FileReader, MAX_MODEL_TRIANGLES, Model, ModelMaterial, mtl};
use crate::scene::Texture;
use crate::scene::file::SceneFileError;
use crate::scene::obj::{ObjError, line_text, parse_obj_model};

/// Reads `bytes` as an OBJ model named `file`, its libraries through `read`.
pub fn parse(bytes: &[u8], file: &str, read: FileReader) -> Result<Model, SceneFileError> {
    let positioned = |name: &str, bytes: &[u8], e: ObjError| {
        SceneFileError::on_line(name, &line_text(bytes, e.line), e.line, e.column, e.message)
    };
    let obj = parse_obj_model(bytes, MAX_MODEL_TRIANGLES, 3 * MAX_MODEL_TRIANGLES)
        .map_err(|e| positioned(file, bytes, e))?;
    let mut model = Model {
        positions: obj.positions,
        normals: obj.normals,
        // OBJ's v runs up from the image's bottom, the model's down from its top (glTF's).
        uvs: obj
            .uvs
            .into_iter()
            .map(|t| Vec2::new(t.x, 1.0 - t.y))
            .collect(),
        triangles: obj.triangles,
        triangle_materials: obj.triangle_materials,
        ..Model::default()
    };
    let mut library: Vec<ModelMaterial> = Vec::new();
    for (name, _line, _column) in &obj.libraries {
        match read(name) {
            Ok((shown, bytes)) => {
                library.extend(mtl::parse_mtl(&bytes).map_err(|e| positioned(&shown, &bytes, e))?)
            }
            Err(e) => model.note(format!("material library: {e}; default materials used")),
        }
    }
    let mut decoded = HashMap::new();
    for name in &obj.material_names {
        let found = library.iter().rev().find(|m| &m.name == name);
        if found.is_none() && !name.is_empty() && !obj.libraries.is_empty() {
            model.note(format!(
                "material `{name}` is in no library: default material used"
            ));
        }
        let m = found.cloned().unwrap_or_else(|| ModelMaterial {
            name: name.clone(),
            ..ModelMaterial::default()
        });
        let mut m = m;
        if let Some(t) = m.base_colour_texture.clone() {
            m.texture = texture(&t, &m.name, read, &mut model, &mut decoded);
        }
        model.materials.push(m);
    }
    Ok(model)
}

/// The texture `map_Kd name` names (for material `material`), as an index into
/// `model.textures`, each file decoded once (`decoded`); one that cannot be read or decoded is
/// a warning and `None` (the material's `Kd` is drawn alone). Its options (`-clamp`, `-o`,
/// `-s` and the rest) are not read: the image repeats, filtered bilinearly.
fn texture(
    name: &str,
    material: &str,
    read: FileReader,
    model: &mut Model,
    decoded: &mut HashMap<String, Option<u32>>,
) -> Option<u32> {
    if let Some(&done) = decoded.get(name) {
        return done;
    }
    let out = match read(name)
        .and_then(|(shown, bytes)| Texture::decode(&bytes).map_err(|e| format!("{shown}: {e}")))
    {
        Ok(t) => {
            model.textures.push(t);
            Some(model.textures.len() as u32 - 1)
        }
        Err(why) => {
            model.note(format!(
                "warning: texture `{name}` (map_Kd of material `{material}`): {why}; the material's Kd is drawn instead"
            ));
            None
        }
    };
    decoded.insert(name.to_string(), out);
    out
}
