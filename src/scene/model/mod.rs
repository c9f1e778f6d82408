//! Models made by other tools: glTF 2.0 (`.gltf`, `.glb`), OBJ with MTL, PLY and STL. Each
//! format's reader fills one [`Model`] (positions, optional normals, UVs and vertex colours,
//! triangles with their materials, the file's cameras and lights); [`Model::into_scene`] turns
//! it into a [`Scene`] with a camera that finds the model ([`view`]) and, when nothing in the
//! file gives light (no light, no emitting material), the default rig.
//!
//! Materials keep every physically based value the file gives (metallic, roughness, emission,
//! index of refraction, transmission, opacity, the base colour texture's name);
//! [`scene_material`] maps them onto the scene's [`Material`] (metal, glass, emission). Vertex
//! colours, normals and base-colour textures go to the scene as its [`VertexData`], only when
//! the model has them.
//!
//! Every mistake is a [`SceneFileError`] naming the file and where: a line and column in text,
//! a JSON path in glTF, a byte offset in binary data.

pub mod gltf;
pub mod mtl;
pub mod obj;
pub mod ply;
pub mod progress;
pub mod stl;
pub mod view;

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::scene::file::{MAX_EMISSION, SceneFileError};
use crate::scene::{
    DirectionalLight, Effects, MAX_COORDINATE, MAX_IOR, Material, PointLight, Scene, SceneBuilder,
    SpotLight, Texture, VertexData,
};

pub use progress::{LoadProgress, LoadStep};
pub use view::{View, ViewError};

/// Most triangles a model file may have: some 115 bytes a triangle at the peak of its load
/// (measured on a 10M-triangle binary PLY: 1.1 GB), so 30 million need about 3.5 GB.
pub const MAX_MODEL_TRIANGLES: usize = 30_000_000;
/// Largest model file read (with the files it names: MTL, glTF buffers): a binary PLY of
/// 30 million triangles is about 0.6 GB, an OBJ of as many some 1.5 GB.
pub const MAX_MODEL_BYTES: u64 = 2 << 30;
/// Most lights taken from a file (as [`crate::scene::file::MAX_LIGHTS`] for scene files).
pub const MAX_MODEL_LIGHTS: usize = crate::scene::file::MAX_LIGHTS;

/// The file formats raytty reads models from, by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`).
    Gltf,
    /// Wavefront OBJ, with its MTL material libraries.
    Obj,
    /// PLY (Stanford), ASCII or binary.
    Ply,
    /// STL, ASCII or binary.
    Stl,
}

impl Format {
    /// The format of a file named `path`, by its extension (any case).
    pub fn of(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "gltf" | "glb" => Format::Gltf,
            "obj" => Format::Obj,
            "ply" => Format::Ply,
            "stl" => Format::Stl,
            _ => return None,
        })
    }
}

/// A material as a file describes it. Colours are linear RGB.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelMaterial {
    /// The file's name for it ("" if none).
    pub name: String,
    /// Base colour (diffuse albedo for dielectrics), linear RGB.
    pub base_colour: Vec3,
    /// Metalness in [0, 1].
    pub metallic: f32,
    /// Perceptual roughness in [0, 1].
    pub roughness: f32,
    /// Emitted radiance, linear RGB (glTF's emissive factor times its strength; MTL's `Ke`).
    pub emission: Vec3,
    /// Index of refraction.
    pub ior: f32,
    /// Fraction of light transmitted through the surface, [0, 1].
    pub transmission: f32,
    /// Opacity (glTF's base colour alpha, MTL's `d`), [0, 1].
    pub opacity: f32,
    /// The base colour texture's file or URI as the file names it, if any.
    pub base_colour_texture: Option<String>,
    /// The base colour texture as decoded, an index into [`Model::textures`]; `None` when
    /// there is none or it could not be read (a warning says why).
    pub texture: Option<u32>,
}

impl Default for ModelMaterial {
    /// A light grey dielectric: what a triangle without a material gets.
    fn default() -> ModelMaterial {
        ModelMaterial {
            name: String::new(),
            base_colour: Vec3::splat(0.8),
            metallic: 0.0,
            roughness: 1.0,
            emission: Vec3::ZERO,
            ior: 1.5,
            transmission: 0.0,
            opacity: 1.0,
            base_colour_texture: None,
            texture: None,
        }
    }
}

/// A camera a file places.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelCamera {
    /// Eye position.
    pub position: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit up direction on screen.
    pub up: Vec3,
    /// Vertical field of view in radians, if the file gives one.
    pub fov: Option<f32>,
}

/// A light a file places.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelLight {
    /// Where it is (unused by a directional light).
    pub position: Vec3,
    /// Radiant intensity per channel (W/sr; glTF's colour times intensity: candela), or a
    /// directional light's irradiance (lux).
    pub intensity: Vec3,
    /// What kind of light.
    pub kind: ModelLightKind,
}

/// The kinds of a model's lights (glTF's `KHR_lights_punctual`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModelLightKind {
    /// Light in all directions.
    Point,
    /// Parallel light travelling along `direction`.
    Directional {
        /// The way the light travels.
        direction: Vec3,
    },
    /// A point light within a cone around `direction`, full within `inner` radians of it,
    /// none beyond `outer`.
    Spot {
        /// Where it points.
        direction: Vec3,
        /// The cone's angles (radians).
        inner: f32,
        /// See `inner`.
        outer: f32,
    },
}

/// A triangle mesh read from a file, before it becomes a [`Scene`].
#[derive(Clone, Debug, Default)]
pub struct Model {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals: empty, or one per position.
    pub normals: Vec<Vec3>,
    /// Texture coordinates: empty, or one per position.
    pub uvs: Vec<Vec2>,
    /// Vertex colours, linear RGB: empty, or one per position.
    pub colours: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's index into `materials`; empty when every triangle has material 0.
    pub triangle_materials: Vec<u32>,
    /// Materials (at least one once the model is read).
    pub materials: Vec<ModelMaterial>,
    /// The materials' decoded base-colour textures.
    pub textures: Vec<Texture>,
    /// The file's cameras, in its order.
    pub cameras: Vec<ModelCamera>,
    /// The file's point lights.
    pub lights: Vec<ModelLight>,
    /// What the file has that raytty read but does not use, one line each (for the user).
    pub notes: Vec<String>,
}

/// A loaded model scene and what the user should know about it.
#[derive(Debug)]
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// What the file has that is not used, and what was dropped (degenerate triangles).
    pub notes: Vec<String>,
}

impl Model {
    /// The material of triangle `i`.
    pub fn material_of(&self, i: usize) -> u32 {
        self.triangle_materials.get(i).copied().unwrap_or(0)
    }

    /// Adds a note (kept once: the same note twice is said once).
    pub fn note(&mut self, note: impl Into<String>) {
        let note = note.into();
        if !self.notes.contains(&note) {
            self.notes.push(note);
        }
    }

    /// The model as a scene named `name`, seen through `view` (the file's camera, or one
    /// framed on the model), with the file's lights or else the default rig. Degenerate
    /// triangles (zero area), which exporters leave in, are dropped and counted in a note.
    pub fn into_scene(
        mut self,
        file: &str,
        name: &str,
        view: &View,
    ) -> Result<Loaded, SceneFileError> {
        if self.materials.is_empty() {
            self.materials.push(ModelMaterial::default());
        }
        if self.triangles.is_empty() {
            return Err(SceneFileError::whole_file(
                file,
                "the file has no triangles: raytty shows triangle meshes (points and lines are not drawn)",
            ));
        }
        if let Some(p) = self
            .positions
            .iter()
            .find(|p| !p.is_finite() || p.abs().max_element() > MAX_COORDINATE)
        {
            return Err(SceneFileError::whole_file(
                file,
                format!(
                    "a vertex at {p} (after the file's transforms) is out of range: coordinates must be finite and within ±{MAX_COORDINATE:e}"
                ),
            ));
        }
        let bounds = self.bounds();
        let camera = view
            .camera(&self.cameras, bounds)
            .map_err(|e| SceneFileError::whole_file(file, e.to_string()))?;
        let mut b = SceneBuilder::new();
        b.drop_degenerate();
        let (materials, material_textures) = self.scene_materials(&mut b);
        // A point light of radiant intensity I emits 4π·I; a spot is the point light it is
        // cut from.
        let mut lights: Vec<PointLight> = Vec::new();
        for l in self.lights.iter().take(MAX_MODEL_LIGHTS) {
            let power = l.intensity * (4.0 * std::f32::consts::PI);
            match l.kind {
                ModelLightKind::Point => lights.push(PointLight {
                    position: l.position,
                    power,
                }),
                ModelLightKind::Directional { direction } => {
                    b.directional_light(DirectionalLight {
                        direction,
                        irradiance: l.intensity,
                    })
                }
                ModelLightKind::Spot {
                    direction,
                    inner,
                    outer,
                } => b.spot_light(SpotLight {
                    position: l.position,
                    direction,
                    power,
                    inner,
                    outer,
                }),
            }
        }
        if self.lights.len() > MAX_MODEL_LIGHTS {
            self.note(format!(
                "{} lights: the first {MAX_MODEL_LIGHTS} are used",
                self.lights.len()
            ));
        }
        // The default rig only where nothing in the file gives light: no punctual light and
        // no emitting material.
        let used: Vec<Material> = self.materials.iter().map(scene_material).collect();
        let emits = used.iter().any(|m| m.emission != Vec3::ZERO);
        let default_lights = self.lights.is_empty() && !emits;
        // Light from surfaces, metal and glass show only where light is path traced (as in the
        // built-in scenes that have them: 16 bounces); other models keep the seed's effects.
        let traced =
            |m: &Material| m.emission != Vec3::ZERO || m.metal > 0.0 || m.transmission > 0.0;
        let effects = if used.iter().any(traced) {
            Effects {
                indirect: crate::scene::Indirect::PathTraced { bounces: 16 },
                ..Effects::default()
            }
        } else {
            Effects::default()
        };
        if default_lights {
            lights = view::default_rig(&camera, bounds);
        }
        for l in lights {
            b.light(l);
        }
        b.default_lights(default_lights);
        b.tone_map(crate::image::ToneMap::Neutral);
        // The Cornell box's diagonal is 2·√3: the keys' steps are the box's, scaled.
        b.step((bounds.1 - bounds.0).length() / (2.0 * 3f32.sqrt()));
        let triangles = self.triangles.len();
        if let Some(v) = self.vertex_data(material_textures) {
            b.vertex_data(v);
        }
        let mut notes = self.notes;
        b.indexed_mesh(self.positions, self.triangles, materials);
        let scene = b
            .build(name, camera, effects)
            .map_err(|e| SceneFileError::whole_file(file, e.to_string()))?;
        let dropped = triangles - scene.triangle_count();
        if scene.triangle_count() == 0 {
            return Err(SceneFileError::whole_file(
                file,
                format!("all {triangles} triangles have zero area: nothing to show"),
            ));
        }
        if dropped > 0 {
            notes.push(format!(
                "{dropped} of {triangles} triangles have zero area and were dropped"
            ));
        }
        Ok(Loaded { scene, notes })
    }

    /// The box around the positions the triangles use (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in &self.positions {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        (lo, hi)
    }

    /// The scene's materials for the triangles, one index per triangle (or one for all), and
    /// for each scene material its texture: each file material as [`scene_material`] maps it.
    fn scene_materials(&self, b: &mut SceneBuilder) -> (Vec<u32>, Vec<Option<u32>>) {
        let ids: Vec<u32> = self
            .materials
            .iter()
            .map(|m| b.material(scene_material(m)))
            .collect();
        let textures = self.materials.iter().map(|m| m.texture).collect();
        if self.triangle_materials.is_empty() {
            return (vec![ids[0]], textures);
        }
        let per_triangle = self
            .triangle_materials
            .iter()
            .map(|&m| ids[(m as usize).min(ids.len() - 1)])
            .collect();
        (per_triangle, textures)
    }

    /// What the vertices carry that changes a frame, for the scene (`None` if nothing):
    /// colours, normals, and texture coordinates when a material has a texture.
    /// `material_textures` is each scene material's texture. Takes the lists it keeps (all but
    /// the triangles).
    fn vertex_data(&mut self, material_textures: Vec<Option<u32>>) -> Option<VertexData> {
        let textured = material_textures.iter().any(Option::is_some);
        if self.colours.is_empty() && self.normals.is_empty() && !textured {
            return None;
        }
        Some(VertexData {
            // (The scene's mesh keeps the triangles too.)
            corners: self.triangles.clone(),
            normals: std::mem::take(&mut self.normals),
            uvs: if textured {
                std::mem::take(&mut self.uvs)
            } else {
                Vec::new()
            },
            colours: std::mem::take(&mut self.colours),
            textures: std::mem::take(&mut self.textures),
            material_textures: if textured {
                material_textures
            } else {
                Vec::new()
            },
        })
    }
}

/// A file's material as a scene's: glTF's metallic-roughness
/// model (and MTL's `Pm`, `Pr`, `Ni`, `Ke` and glass `illum`, which the reader maps onto it)
/// as raytty's materials take it: the metallic fraction a GGX conductor of F0 = base colour,
/// the transmission fraction glass of the file's IOR, both of the file's roughness; the rest
/// Lambertian (glTF's dielectric specular coat over it is left out: raytty has no layered
/// material yet); emission as the camera sees it. Values are clamped into the ranges a scene
/// allows. A plain dielectric is exactly [`Material::diffuse`], so such models render as
/// before. Opacity (glTF's alpha, MTL's `d` without a glass `illum`) is not simulated.
fn scene_material(m: &ModelMaterial) -> Material {
    let unit = |v: f32| {
        if v.is_finite() {
            v.clamp(0.0, 1.0)
        } else {
            0.0
        }
    };
    let colour = m.base_colour.clamp(Vec3::ZERO, Vec3::ONE).map(unit);
    let mut out = Material::diffuse(colour);
    let e = m.emission.map(|c| {
        if c.is_finite() {
            c.clamp(0.0, MAX_EMISSION as f32)
        } else {
            0.0
        }
    });
    out.emission = e;
    let (metal, transmission) = (unit(m.metallic), unit(m.transmission));
    if metal > 0.0 || transmission > 0.0 {
        out.metal = metal;
        out.transmission = transmission;
        out.roughness = unit(m.roughness);
        out.ior = if m.ior.is_finite() {
            m.ior.clamp(1.0, MAX_IOR)
        } else {
            1.5
        };
    }
    out
}

/// Reads the model file at `path` (its format by extension) with the files it names, and
/// builds its scene seen through `view`. The scene is named by the file's stem.
pub fn load(path: &Path, view: &View) -> Result<Loaded, SceneFileError> {
    load_with(path, view, &LoadProgress::new())
}

/// [`load`], telling `progress` how far it has got.
pub fn load_with(
    path: &Path,
    view: &View,
    progress: &LoadProgress,
) -> Result<Loaded, SceneFileError> {
    let shown = path.display().to_string();
    let Some(format) = Format::of(path) else {
        return Err(SceneFileError::whole_file(
            &shown,
            "not a model file raytty reads: give a .gltf, .glb, .obj, .ply or .stl file",
        ));
    };
    let bytes = read_capped(path).map_err(|e| SceneFileError::whole_file(&shown, e))?;
    let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let read = move |name: &str| {
        let full = base.join(name);
        read_capped(&full).map(|b| (full.display().to_string(), b))
    };
    progress.start(LoadStep::Parsing, 0);
    let model = parse_with(format, &bytes, &shown, &read, progress)?;
    drop(bytes);
    progress.start(LoadStep::Building, 0);
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| shown.clone());
    model.into_scene(&shown, &stem, view)
}

/// Reads a file a model names (an MTL library, a glTF buffer): given its name as written,
/// the name to show and its bytes, or why it cannot be read.
pub type FileReader<'a> = &'a dyn Fn(&str) -> Result<(String, Vec<u8>), String>;

/// Parses `bytes` as a model of `format`; `file` names it in messages and `read` reads the
/// files it names. The pure core the fuzzer drives.
pub fn parse(
    format: Format,
    bytes: &[u8],
    file: &str,
    read: FileReader,
) -> Result<Model, SceneFileError> {
    parse_with(format, bytes, file, read, &LoadProgress::new())
}

/// [`parse`], telling `progress` how far it has got (PLY counts its records; the other
/// formats say only their step).
pub fn parse_with(
    format: Format,
    bytes: &[u8],
    file: &str,
    read: FileReader,
    progress: &LoadProgress,
) -> Result<Model, SceneFileError> {
    let model = match format {
        Format::Gltf => gltf::parse(bytes, file, read)?,
        Format::Obj => obj::parse(bytes, file, read)?,
        Format::Ply => ply::parse_with(bytes, file, progress)?,
        Format::Stl => stl::parse(bytes, file)?,
    };
    debug_assert!(
        model
            .triangles
            .iter()
            .flatten()
            .all(|&v| (v as usize) < model.positions.len())
    );
    Ok(model)
}

/// A [`FileReader`] for models read from memory: every named file is missing.
pub fn no_files(name: &str) -> Result<(String, Vec<u8>), String> {
    Err(format!(
        "{name}: not read (the model was given without its folder)"
    ))
}

/// Reads at most [`MAX_MODEL_BYTES`] of `path`; the error says which file and why.
fn read_capped(path: &Path) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let unreadable = |e: std::io::Error| format!("{} cannot be read: {e}", path.display());
    let file = std::fs::File::open(path).map_err(unreadable)?;
    let mut bytes = Vec::new();
    file.take(MAX_MODEL_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(unreadable)?;
    if bytes.len() as u64 > MAX_MODEL_BYTES {
        return Err(format!(
            "{} is larger than {} GiB, the limit for model files",
            path.display(),
            MAX_MODEL_BYTES >> 30
        ));
    }
    Ok(bytes)
}

/// The linear value of an sRGB-encoded channel in [0, 1].
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Checks that a model may add `more` triangles to `have`; the message names the cap.
pub(crate) fn check_triangles(have: usize, more: usize) -> Result<(), String> {
    if have.saturating_add(more) > MAX_MODEL_TRIANGLES {
        return Err(format!(
            "the model has more than {MAX_MODEL_TRIANGLES} triangles, the limit for model files"
        ));
    }
    Ok(())
}
