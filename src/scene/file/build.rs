//! From the parsed file to a [`Scene`]: the camera, lights, materials and effects checked
//! value by value (all of them before any geometry is generated, so a mistake there costs no
//! wait), then the objects, whose geometry comes from [`super::objects`].

use std::collections::HashMap;

use glam::Vec3;

use super::check::{Ctx, toml_error};
use super::error::{SceneFileError, did_you_mean};
use super::objects::object_triangles;
use super::spec::{
    CameraSpec, EffectsSpec, INDIRECT_EXPECTED, IndirectSpec, LightSpec, MaterialSpec,
    NumberOrTriple, SceneSpec,
};
use super::*;
use crate::camera::Camera;
use crate::sampler::Sampler;
use crate::scene::{Effects, Indirect, MAX_IOR, Material, PointLight, SceneBuilder};
use toml::Spanned;

/// Parses `source` and builds its scene.
pub fn build(
    source: &str,
    file: &str,
    name: &str,
    read_mesh: MeshReader,
) -> Result<Scene, SceneFileError> {
    let cx = Ctx { source, file };
    let spec: SceneSpec = toml::from_str(source).map_err(|e| toml_error(&cx, &e))?;
    let camera = camera(&cx, spec.camera.as_ref())?;
    let lights = lights(&cx, &spec.light)?;
    let materials = materials(&cx, &spec.material)?;
    let effects = effects(&cx, spec.effects.as_ref())?;
    if spec.object.is_empty() {
        return Err(cx.err(
            0,
            "the scene has no objects: add an [[object]] table (scenes/example.toml shows every kind)",
        ));
    }

    let mut b = SceneBuilder::new();
    lights.into_iter().for_each(|l| b.light(l));
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

    let name = spec.name.as_ref().map_or(name, |n| n.get_ref().as_str());
    // Everything the builder checks was checked above with a position; this is a safety net.
    b.build(name, camera, effects)
        .map_err(|e| SceneFileError::whole_file(file, e.to_string()))
}

/// `[camera]`: the seed's camera, with the keys given. Angles are converted in `f32`, as the
/// command line's `--camera` does, so the same numbers give the same camera.
fn camera(cx: &Ctx, spec: Option<&CameraSpec>) -> Result<Camera, SceneFileError> {
    let mut camera = Camera::default();
    let Some(c) = spec else {
        return Ok(camera);
    };
    if let Some(p) = &c.position {
        camera.position = cx.point(p, "the camera position")?;
    }
    if let Some(y) = &c.yaw {
        camera.yaw = (cx.ranged(y, -360.0, 360.0, "the camera yaw (degrees)")? as f32).to_radians();
    }
    if let Some(p) = &c.pitch {
        camera.pitch =
            (cx.ranged(p, -90.0, 90.0, "the camera pitch (degrees)")? as f32).to_radians();
    }
    Ok(camera)
}

/// `[[light]]`: at most [`MAX_LIGHTS`], each power from 0 to [`MAX_POWER`] per channel.
fn lights(cx: &Ctx, specs: &[Spanned<LightSpec>]) -> Result<Vec<PointLight>, SceneFileError> {
    let mut out = Vec::with_capacity(specs.len());
    for (i, l) in specs.iter().enumerate() {
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
        out.push(PointLight {
            position,
            power: Vec3::from(p.map(|c| c as f32)),
        });
    }
    Ok(out)
}

/// `[material.NAME]`: colours and mirror reflectances from 0 to 1.
fn materials<'a>(
    cx: &Ctx,
    specs: &'a std::collections::BTreeMap<String, Spanned<MaterialSpec>>,
) -> Result<HashMap<&'a str, Material>, SceneFileError> {
    let mut out = HashMap::new();
    for (key, m) in specs {
        let m = m.get_ref();
        if let Some(c) = m
            .colour
            .get_ref()
            .0
            .iter()
            .find(|c| !(0.0..=1.0).contains(*c))
        {
            return Err(cx.err_at(
                &m.colour,
                format!(
                    "material `{key}`: colour component {c} is out of range: expected [r, g, b] with each from 0 to 1"
                ),
            ));
        }
        let fraction = |v: &Option<Spanned<f64>>, what: &str, default: f64| match v {
            Some(r) => cx.ranged(r, 0.0, 1.0, &format!("material `{key}`: {what}")),
            None => Ok(default),
        };
        let mirror = fraction(&m.mirror, "the mirror reflectance", 0.0)?;
        let metal = fraction(&m.metal, "metal (the fraction that is metal)", 0.0)?;
        let roughness = fraction(&m.roughness, "roughness", 0.0)?;
        let transmission = fraction(
            &m.transmission,
            "transmission (the fraction that is glass)",
            0.0,
        )?;
        let ior = match &m.ior {
            Some(r) => cx.ranged(
                r,
                1.0,
                f64::from(MAX_IOR),
                &format!("material `{key}`: ior (the index of refraction; glass is 1.5)"),
            )?,
            None => 1.5,
        };
        let emission = match &m.emission {
            Some(e) => {
                let NumberOrTriple(c) = *e.get_ref();
                if let Some(bad) = c.iter().find(|c| !(**c >= 0.0 && **c <= MAX_EMISSION)) {
                    return Err(cx.err_at(
                        e,
                        format!(
                            "material `{key}`: emission {bad} is not allowed: expected a number from 0 to {MAX_EMISSION:e}, or [r, g, b] of such numbers (what the camera sees on the emitting face; 1 is white)"
                        ),
                    ));
                }
                Vec3::from(c.map(|c| c as f32))
            }
            None => Vec3::ZERO,
        };
        let material = Material {
            colour: Vec3::from(m.colour.get_ref().0.map(|c| c as f32)),
            mirror: mirror as f32,
            metal: metal as f32,
            roughness: roughness as f32,
            ior: ior as f32,
            transmission: transmission as f32,
            emission,
        };
        out.insert(key.as_str(), material);
    }
    Ok(out)
}

/// `[effects]`: the seed's effects, with the keys given.
fn effects(cx: &Ctx, spec: Option<&EffectsSpec>) -> Result<Effects, SceneFileError> {
    let mut effects = Effects::SEED;
    let Some(e) = spec else {
        return Ok(effects);
    };
    if let Some(s) = e.shadows {
        effects.shadows = s;
    }
    if let Some(i) = &e.indirect {
        effects.indirect = match *i.get_ref() {
            IndirectSpec::None => Indirect::None,
            IndirectSpec::Constant(n) if (0.0..=MAX_CONSTANT).contains(&n) => {
                Indirect::Constant(n as f32)
            }
            IndirectSpec::Constant(n) => {
                return Err(cx.err_at(
                    i,
                    format!(
                        "indirect = {n}: a constant term must be from 0 to {MAX_CONSTANT}; indirect takes {INDIRECT_EXPECTED}"
                    ),
                ));
            }
            IndirectSpec::Bounces(n) if (0..=MAX_BOUNCES).contains(&n) => {
                Indirect::PathTraced { bounces: n as u32 }
            }
            IndirectSpec::Bounces(n) => {
                return Err(cx.err_at(
                    i,
                    format!("bounces is {n}: expected a whole number from 0 to {MAX_BOUNCES}"),
                ));
            }
        };
    }
    if let Some(s) = &e.samples {
        effects.samples = cx.whole(s, 1, MAX_SAMPLES, "samples (per pixel)")? as u32;
    }
    if let Some(s) = &e.sampler {
        let name = s.get_ref().as_str();
        effects.sampler = Sampler::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = Sampler::ALL.iter().map(|s| s.name()).collect();
            cx.err_at(
                s,
                format!("unknown sampler `{name}`: expected {}", names.join(" or ")),
            )
        })?;
    }
    Ok(effects)
}
