//! From the parsed file to a [`Scene`]: the camera, lights, materials and effects checked
//! value by value (all of them before any geometry is generated, so a mistake there costs no
//! wait), then the objects, whose geometry comes from [`super::objects`].

use std::collections::HashMap;

use glam::Vec3;

use super::check::{Ctx, KEY_FORMS, toml_error};
use super::error::{SceneFileError, did_you_mean};
use super::objects::object_triangles;
use super::spec::{
    CameraSpec, EffectsSpec, INDIRECT_EXPECTED, IndirectSpec, LightSpec, MaterialSpec,
    NumberOrTriple, SceneSpec, Three,
};
use super::*;
use crate::camera::Camera;
use crate::sampler::Sampler;
use crate::scene::{
    DirectionalLight, Effects, Indirect, MAX_IOR, Material, PointLight, SceneBuilder, SpotLight,
};
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
    lights.point.into_iter().for_each(|l| b.light(l));
    lights
        .directional
        .into_iter()
        .for_each(|l| b.directional_light(l));
    lights.spot.into_iter().for_each(|l| b.spot_light(l));
    b.environment(lights.environment);
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

/// The lights of a file, by kind.
#[derive(Default)]
struct Lights {
    point: Vec<PointLight>,
    directional: Vec<DirectionalLight>,
    spot: Vec<SpotLight>,
    environment: Vec3,
}

/// The light kinds, the keys each one needs and the ones it may have (besides `kind`).
const LIGHT_KINDS: [(&str, &[&str], &[&str]); 4] = [
    ("point", &["position", "power"], &[]),
    ("directional", &["direction", "irradiance"], &[]),
    (
        "spot",
        &["position", "direction", "power"],
        &["inner_angle", "outer_angle"],
    ),
    ("environment", &["emission"], &[]),
];

/// A spot's cone when the file does not say (glTF's defaults): full on its axis, none past
/// 45 degrees.
const SPOT_ANGLES: (f64, f64) = (0.0, 45.0);

/// `[[light]]`: at most [`MAX_LIGHTS`], each of a known kind with that kind's keys; powers and
/// irradiances from 0 to [`MAX_POWER`], an environment's emission from 0 to [`MAX_EMISSION`]
/// per channel; directions not zero; a spot's angles from 0 to 90 degrees, inner ≤ outer.
fn lights(cx: &Ctx, specs: &[Spanned<LightSpec>]) -> Result<Lights, SceneFileError> {
    let mut out = Lights::default();
    for (i, spanned) in specs.iter().enumerate() {
        if i == MAX_LIGHTS {
            return Err(cx.err_at(spanned, format!("too many lights: at most {MAX_LIGHTS}")));
        }
        let l = spanned.get_ref();
        let kind = l.kind.as_ref().map_or("point", |k| k.get_ref().as_str());
        let kinds: Vec<&str> = LIGHT_KINDS.iter().map(|k| k.0).collect();
        let Some(&(_, needs, may)) = LIGHT_KINDS.iter().find(|k| k.0 == kind) else {
            let at = l.kind.as_ref().expect("the default kind is known");
            return Err(cx.err_at(
                at,
                format!(
                    "unknown light kind `{kind}`{} (kinds: {})",
                    did_you_mean(kind, &kinds),
                    kinds.join(", ")
                ),
            ));
        };
        fn at<T>(v: &Option<Spanned<T>>) -> Option<usize> {
            v.as_ref().map(|v| v.span().start)
        }
        let given = [
            ("position", at(&l.position)),
            ("power", at(&l.power)),
            ("direction", at(&l.direction)),
            ("irradiance", at(&l.irradiance)),
            ("inner_angle", at(&l.inner_angle)),
            ("outer_angle", at(&l.outer_angle)),
            ("emission", at(&l.emission)),
        ];
        let takes = || {
            let mut keys: Vec<&str> = vec!["kind"];
            keys.extend(needs.iter().chain(may));
            keys.join(", ")
        };
        for (key, offset) in given {
            if let (Some(offset), false) = (offset, needs.contains(&key) || may.contains(&key)) {
                return Err(cx.err(
                    offset,
                    format!(
                        "`{key}` is not a key of kind = \"{kind}\" lights: they take {}",
                        takes()
                    ),
                ));
            }
        }
        if let Some((key, _)) = given
            .iter()
            .find(|(key, offset)| offset.is_none() && needs.contains(key))
        {
            let form = KEY_FORMS.iter().find(|k| k.0 == *key).map_or("", |k| k.1);
            return Err(cx.err_at(
                spanned,
                format!(
                    "missing key `{key}` in this kind = \"{kind}\" light: add {form} (they take {})",
                    takes()
                ),
            ));
        }
        fn need(v: &Option<Spanned<Three<f64>>>) -> &Spanned<Three<f64>> {
            v.as_ref().expect("checked above")
        }
        let amount = |v: &Option<Spanned<NumberOrTriple>>, what: &str, max: f64, example: &str| {
            let v = v.as_ref().expect("checked above");
            let NumberOrTriple(p) = *v.get_ref();
            match p.iter().find(|c| !(**c >= 0.0 && **c <= max)) {
                Some(bad) => Err(cx.err_at(
                    v,
                    format!(
                        "{what} {bad} is not allowed: expected a number from 0 to {max:e}, or [r, g, b] of such numbers ({example})"
                    ),
                )),
                None => Ok(Vec3::from(p.map(|c| c as f32))),
            }
        };
        let direction = |what: &str| -> Result<Vec3, SceneFileError> {
            let v = need(&l.direction);
            let d = cx.point(v, what)?;
            if d == Vec3::ZERO {
                return Err(cx.err_at(
                    v,
                    format!("{what} is [0, 0, 0]: expected a direction, not zero"),
                ));
            }
            Ok(d)
        };
        match kind {
            "point" => out.point.push(PointLight {
                position: cx.point(need(&l.position), "the light position")?,
                power: amount(
                    &l.power,
                    "light power",
                    MAX_POWER,
                    "the Cornell box's is 14",
                )?,
            }),
            "directional" => out.directional.push(DirectionalLight {
                direction: direction("the light direction")?,
                irradiance: amount(
                    &l.irradiance,
                    "light irradiance",
                    MAX_POWER,
                    "1 lights a white surface facing it as 1",
                )?,
            }),
            "spot" => {
                let angle = |v: &Option<Spanned<f64>>, default: f64, what: &str| {
                    v.as_ref()
                        .map_or(Ok(default), |v| cx.ranged(v, 0.0, 90.0, what))
                };
                let outer = angle(
                    &l.outer_angle,
                    SPOT_ANGLES.1,
                    "the spot's outer_angle (degrees)",
                )?;
                let inner = angle(
                    &l.inner_angle,
                    SPOT_ANGLES.0,
                    "the spot's inner_angle (degrees)",
                )?;
                if inner > outer {
                    let at = l
                        .inner_angle
                        .as_ref()
                        .map_or(spanned.span().start, |v| v.span().start);
                    return Err(cx.err(
                        at,
                        format!("the spot's inner_angle {inner} is wider than its outer_angle {outer}: expected inner_angle <= outer_angle"),
                    ));
                }
                out.spot.push(SpotLight {
                    position: cx.point(need(&l.position), "the light position")?,
                    direction: direction("the spot direction")?,
                    power: amount(
                        &l.power,
                        "light power",
                        MAX_POWER,
                        "the Cornell box's is 14",
                    )?,
                    inner: (inner as f32).to_radians(),
                    outer: (outer as f32).to_radians(),
                });
            }
            _ => {
                out.environment += amount(
                    &l.emission,
                    "environment emission",
                    MAX_EMISSION,
                    "a camera sees the sky as this value",
                )?;
            }
        }
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
