//! From the parsed file to a [`Scene`]: the camera, lights, materials and effects checked
//! value by value; the objects' geometry comes from [`super::objects`].

use std::collections::HashMap;

use glam::Vec3;

use super::check::{Ctx, toml_error};
use super::error::{SceneFileError, did_you_mean};
use super::objects::object_triangles;
use super::spec::{INDIRECT_EXPECTED, IndirectSpec, NumberOrTriple, SceneSpec};
use super::*;
use crate::camera::Camera;
use crate::scene::{Effects, Indirect, Material, PointLight, SceneBuilder};

/// Parses `source` and builds its scene.
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
        for c in &m.colour.get_ref().0 {
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
                colour: Vec3::from(m.colour.get_ref().0.map(|c| c as f32)),
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
