//! A scene: triangles with materials, lights (point, directional, spot, a constant environment,
//! emitting triangles), a starting camera and the effects it calls for. A scene that was built
//! is valid: every triangle has a finite unit normal, every light a finite position, a unit
//! direction and non-negative power, so rendering it cannot fail.

pub mod builtin;
pub mod cornell;
pub mod file;
pub mod model;
pub mod obj;
pub mod procedural;
pub mod texture;
pub mod vertex;

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

use std::f32::consts::FRAC_PI_2;

use glam::Vec3;
use rayon::prelude::*;

use crate::accel::{Accel, AccelKind, AccelStats, Hit, Isa, TileCache};
use crate::camera::Camera;
use crate::geometry::{Aabb, DegenerateTriangle, Ray, RayTile, Triangle};
use crate::image::ToneMap;
use crate::light::AreaLights;
use crate::sampler::Sampler;

pub use model::srgb_to_linear;
pub use texture::Texture;
pub use vertex::VertexData;

/// Largest absolute coordinate accepted anywhere a user gives one (scene files, OBJ vertices,
/// `--camera` and `--light`; box corners and transformed vertices too): far beyond any sensible
/// scene, far below where `f32` loses whole units. Exact in `f32` and `f64`.
pub const MAX_COORDINATE: f32 = 1e6;

/// A surface's material.
///
/// Its parts are layered, each taking a fraction of what the layers above it leave (see
/// [`crate::material::SurfaceBsdf`]): the seed's perfect mirror (`mirror`), a GGX metal of
/// colour `colour` (`metal`), glass (`transmission`, tinted by `colour`), and a Lambertian
/// base of colour `colour` under them. A surface may also emit (`emission`).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The base colour, linear RGB in `[0, 1]`: the diffuse reflectance ρ, a metal's
    /// reflectance at normal incidence, glass's transmittance. [`Scene::base_colour`] is the
    /// one place it is read for a hit.
    pub colour: Vec3,
    /// Mirror reflectance in `[0, 1]`: the fraction of light reflected specularly. 0 is a
    /// purely diffuse surface, for which no reflection ray is ever traced.
    pub mirror: f32,
    /// The fraction in `[0, 1]` that is a GGX conductor (of F0 = colour); 0 is none.
    pub metal: f32,
    /// Perceptual roughness in `[0, 1]` of the metal and the glass (GGX α = roughness²; 0 is
    /// smooth).
    pub roughness: f32,
    /// The glass's index of refraction, in `[1, MAX_IOR]` (1.5 by default).
    pub ior: f32,
    /// The fraction in `[0, 1]` of what the metal leaves that is glass (refracts).
    pub transmission: f32,
    /// What the surface emits from its front face ([`Triangle::front`]: the side its
    /// counter-clockwise winding faces),
    /// per channel, in the image's units: a camera sees an emitter of emission `e` as the
    /// pixel value `e` (radiance × π, the seed's units). Zero for a surface that does not
    /// emit.
    pub emission: Vec3,
}

/// The largest index of refraction a material may have (diamond's is 2.42).
pub const MAX_IOR: f32 = 4.0;

impl Material {
    /// A purely diffuse material.
    pub const fn diffuse(colour: Vec3) -> Material {
        Material {
            colour,
            mirror: 0.0,
            metal: 0.0,
            roughness: 0.0,
            ior: 1.5,
            transmission: 0.0,
            emission: Vec3::ZERO,
        }
    }

    /// Whether the surface only scatters diffusely: no mirror, metal or glass part.
    pub fn only_diffuse(&self) -> bool {
        self.mirror == 0.0 && self.metal == 0.0 && self.transmission == 0.0
    }

    /// Whether the surface emits light.
    pub fn emits(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// Whether every value is in its range (what [`SceneBuilder::build`] checks).
    fn is_valid(&self) -> bool {
        let unit = |x: f32| (0.0..=1.0).contains(&x);
        unit(self.mirror)
            && unit(self.metal)
            && unit(self.roughness)
            && unit(self.transmission)
            && (1.0..=MAX_IOR).contains(&self.ior)
            && self.emission.is_finite()
            && self.emission.min_element() >= 0.0
    }
}

/// A point light radiating `power` (per channel) equally in all directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Where the light is.
    pub position: Vec3,
    /// Radiant power per channel, the seed's P (14 for the Cornell box).
    pub power: Vec3,
}

/// A directional light: parallel light from far away (the sun), travelling along `direction`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// The way the light travels (unit length once built): a surface facing `-direction`
    /// receives all of it.
    pub direction: Vec3,
    /// Irradiance per channel on a surface facing the light, in the seed's units: a white
    /// diffuse surface facing it shows this value (glTF's lux).
    pub irradiance: Vec3,
}

/// A spot light: a point light seen only within a cone around `direction`, fading from full
/// within `inner` of the axis to nothing at `outer` by glTF's recommended falloff (see
/// [`SpotLight::falloff`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    /// Where the light is.
    pub position: Vec3,
    /// The cone's axis, where the light points (unit length once built).
    pub direction: Vec3,
    /// Per channel, the power of the point light it is cut from: along its axis it lights as a
    /// [`PointLight`] of this power would (intensity `power/4π`, glTF's candela × 4π).
    pub power: Vec3,
    /// The angle from the axis (radians) within which the light is full.
    pub inner: f32,
    /// The angle from the axis (radians) beyond which there is none; `inner ≤ outer ≤ π/2`.
    pub outer: f32,
}

impl SpotLight {
    /// The cone's two cosines and the falloff's scale: `(cos outer, scale)` with the falloff
    /// `t²`, `t = clamp((cos θ − cos outer)·scale, 0, 1)`, `scale = 1/(cos inner − cos
    /// outer)` (glTF `KHR_lights_punctual`'s recommended smooth falloff, square of a ramp linear
    /// in the cosine). Equal angles give a hard edge (the scale as large as an `f32` goes).
    pub fn cone(&self) -> (f32, f32) {
        let (ci, co) = (libm::cosf(self.inner), libm::cosf(self.outer));
        (co, 1.0 / (ci - co).max(f32::MIN_POSITIVE))
    }

    /// The falloff toward a direction at `cos_theta` from the axis, in `[0, 1]`.
    pub fn falloff(&self, cos_theta: f32) -> f32 {
        let (co, scale) = self.cone();
        let t = ((cos_theta - co) * scale).clamp(0.0, 1.0);
        t * t
    }
}

/// How indirect light is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Indirect {
    /// No indirect light: shadows are black.
    None,
    /// The seed's constant term N, added to the direct irradiance before multiplying by ρ.
    Constant(f32),
    /// Path-traced diffuse interreflection with next-event estimation.
    PathTraced {
        /// Maximum number of diffuse bounces after the primary hit.
        bounces: u32,
    },
}

/// What a frame computes. The scene says what it calls for; settings may change it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Effects {
    /// Trace shadow rays towards each light.
    pub shadows: bool,
    /// The indirect-light model.
    pub indirect: Indirect,
    /// Samples per pixel (stratified within the pixel; 1 = one ray through the centre).
    pub samples: u32,
    /// Where the samples' numbers come from.
    pub sampler: Sampler,
}

impl Effects {
    /// The seed's set: shadows, constant N = 0.5, one sample per pixel.
    pub const SEED: Effects = Effects {
        shadows: true,
        indirect: Indirect::Constant(0.5),
        samples: 1,
        sampler: Sampler::Sobol,
    };
}

impl Default for Effects {
    fn default() -> Effects {
        Effects::SEED
    }
}

/// A renderable scene.
#[derive(Clone, Debug)]
pub struct Scene {
    name: String,
    triangles: Vec<Triangle>,
    materials: Vec<Material>,
    lights: Vec<PointLight>,
    directional: Vec<DirectionalLight>,
    spots: Vec<SpotLight>,
    environment: Vec3,
    camera: Camera,
    effects: Effects,
    extent: f32,
    accel: Accel,
    /// The objects as added (ranges of `triangles`), for rebuilding the flat list.
    objects: Vec<Range<usize>>,
    has_mirrors: bool,
    /// The emitting triangles, picked by power; `None` when nothing emits.
    area_lights: Option<AreaLights>,
    default_lights: bool,
    step: f32,
    tone_map: ToneMap,
    centre: Vec3,
    /// The vertices' normals, texture coordinates, colours and textures; `None` for a scene
    /// that has none of them, which shades exactly as the seed's scenes do.
    vertex: Option<Box<VertexData>>,
    /// A big model's triangles, kept as its indexed mesh instead of in `triangles` (which is
    /// then empty): see [`Scene::triangle`].
    mesh: Option<Box<IndexedMesh>>,
}

/// Why a scene could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneError {
    /// A triangle is degenerate.
    Triangle {
        /// Index of the triangle in the order added.
        index: usize,
        /// What is wrong with it.
        problem: DegenerateTriangle,
    },
    /// A triangle names a material that does not exist.
    Material {
        /// Index of the triangle.
        index: usize,
    },
    /// A material has a value out of its range (see [`Material`]'s fields).
    MaterialValue {
        /// Index of the material.
        index: usize,
    },
    /// A light has a non-finite position or a negative or non-finite power.
    Light {
        /// Index of the light.
        index: usize,
    },
    /// A directional or spot light or the environment has a bad value.
    LightOfKind {
        /// "directional", "spot" or "environment".
        kind: &'static str,
        /// Index of the light among its kind.
        index: usize,
    },
    /// The vertex data does not fit the triangles or materials (see [`VertexData`]).
    VertexData {
        /// What does not fit.
        problem: String,
    },
}

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SceneError::Triangle { index, problem } => write!(f, "triangle {index}: {problem}"),
            SceneError::Material { index } => write!(f, "triangle {index}: unknown material"),
            SceneError::MaterialValue { index } => write!(
                f,
                "material {index}: a value is out of range (fractions and roughness from 0 to 1, ior from 1 to {MAX_IOR}, emission finite and non-negative)"
            ),
            SceneError::Light { index } => write!(
                f,
                "light {index}: position must be finite and power finite and non-negative"
            ),
            SceneError::LightOfKind { kind, index } => write!(
                f,
                "{kind} light {index}: positions must be finite, directions finite and not zero, power finite and non-negative, angles 0 <= inner <= outer <= 90 degrees"
            ),
            SceneError::VertexData { problem } => write!(f, "vertex data: {problem}"),
        }
    }
}

impl std::error::Error for SceneError {}

/// Collects objects (groups of triangles) and builds a [`Scene`].
///
/// Adding is cheap: triangles are validated, in parallel, when the scene is built.
#[derive(Clone, Debug, Default)]
pub struct SceneBuilder {
    /// Vertex triples with their material, in the order added.
    raw: Vec<([Vec3; 3], u32)>,
    /// A mesh given by vertex indices, after `raw` (see [`SceneBuilder::indexed_mesh`]).
    indexed: Option<IndexedMesh>,
    /// Tests: the size from which an indexed mesh is kept ([`MESH_SCENE`]).
    #[cfg(test)]
    mesh_from: Option<usize>,
    objects: Vec<Range<usize>>,
    materials: Vec<Material>,
    lights: Vec<PointLight>,
    directional: Vec<DirectionalLight>,
    spots: Vec<SpotLight>,
    environment: Vec3,
    accel: Option<AccelKind>,
    drop_degenerate: bool,
    default_lights: bool,
    step: Option<f32>,
    tone_map: ToneMap,
    vertex: Option<VertexData>,
}

/// A mesh as model files hold it: shared positions and each triangle's indices into them,
/// with one material for each triangle (or the last one for the rest).
#[derive(Clone, Debug, Default)]
struct IndexedMesh {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    materials: Vec<u32>,
}

/// A model of at least this many triangles (and nothing emitting: area lights read a list)
/// keeps its indexed mesh, about 18 bytes a triangle plus 4 for several materials, instead of
/// a list of [`Triangle`]s of 52 (with its BVH, about 48 bytes a triangle that holds the
/// vertices again for traversal, a 10M-triangle PLY then takes under 100 bytes a triangle),
/// and its BVH is built fast (`Bvh::build_fast`): a million-triangle model
/// shows its first frame sooner. Built-in scenes and scene files keep a list and the SAH tree.
pub const MESH_SCENE: usize = 1 << 19;

impl IndexedMesh {
    #[inline]
    fn material(&self, i: usize) -> u32 {
        self.materials[i.min(self.materials.len() - 1)]
    }

    /// Triangle `i`, as [`Triangle::new`] makes it (the scene checked that it can).
    fn triangle(&self, i: usize) -> Triangle {
        let [a, b, c] = crate::accel::Vertices::vertices(self, i);
        let t = Triangle::new(a, b, c, self.material(i));
        debug_assert!(t.is_ok(), "a mesh scene holds only valid triangles");
        t.unwrap_or(PLACEHOLDER)
    }

    /// Keeps the triangles for which `keep` holds (their materials with them).
    fn retain(&mut self, keep: &[bool]) {
        let mut i = 0;
        self.triangles.retain(|_| {
            i += 1;
            keep[i - 1]
        });
        if self.materials.len() == keep.len() {
            let mut i = 0;
            self.materials.retain(|_| {
                i += 1;
                keep[i - 1]
            });
        }
    }
}

impl crate::accel::Vertices for IndexedMesh {
    #[inline]
    fn count(&self) -> usize {
        self.triangles.len()
    }

    #[inline]
    fn vertices(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|v| self.positions[v as usize])
    }
}

/// Stands in for a degenerate triangle while validating; never part of a scene.
const PLACEHOLDER: Triangle = Triangle {
    v: [Vec3::ZERO; 3],
    normal: Vec3::Z,
    material: 0,
};

impl SceneBuilder {
    /// An empty builder.
    pub fn new() -> SceneBuilder {
        SceneBuilder::default()
    }

    /// Adds a material and returns its index.
    pub fn material(&mut self, m: Material) -> u32 {
        self.materials.push(m);
        (self.materials.len() - 1) as u32
    }

    /// Adds an object: triangles given as vertex triples, all of one material. Degenerate
    /// triangles are an error (the first one is reported by [`SceneBuilder::build`]).
    pub fn object(&mut self, triangles: impl IntoIterator<Item = [Vec3; 3]>, material: u32) {
        let start = self.raw.len();
        self.raw
            .extend(triangles.into_iter().map(|v| (v, material)));
        self.objects.push(start..self.raw.len());
    }

    /// Adds an object whose triangles each have their own material (a model's mesh).
    pub fn mesh(&mut self, triangles: impl IntoIterator<Item = ([Vec3; 3], u32)>) {
        let start = self.raw.len();
        self.raw.extend(triangles);
        self.objects.push(start..self.raw.len());
    }

    /// Adds a mesh given by `positions` and each triangle's indices into them (every index
    /// must be in range), with `materials[i]` the material of triangle `i` (the last one for
    /// triangles past its end; it must not be empty). Unlike [`SceneBuilder::mesh`], the
    /// vertex triples are never gathered into a list: a 10M-triangle model's load writes 400 MB
    /// less. Only one such mesh, added last.
    pub fn indexed_mesh(
        &mut self,
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        materials: Vec<u32>,
    ) {
        assert!(self.indexed.is_none(), "one indexed mesh a scene");
        assert!(!materials.is_empty(), "an indexed mesh needs a material");
        let start = self.raw.len();
        self.objects.push(start..start + triangles.len());
        self.indexed = Some(IndexedMesh {
            positions,
            triangles,
            materials,
        });
    }

    /// The number of triangles added.
    fn added(&self) -> usize {
        self.raw.len() + self.indexed.as_ref().map_or(0, |m| m.triangles.len())
    }

    /// Triangle `i` as added: its vertices and material.
    #[inline]
    fn raw(&self, i: usize) -> ([Vec3; 3], u32) {
        match self.raw.get(i) {
            Some(&r) => r,
            None => {
                let m = self.indexed.as_ref().expect("a triangle index in range");
                let k = i - self.raw.len();
                (
                    m.triangles[k].map(|v| m.positions[v as usize]),
                    m.materials[k.min(m.materials.len() - 1)],
                )
            }
        }
    }

    /// Degenerate triangles are dropped when the scene is built instead of failing it (models
    /// made by other tools often have some); [`Scene::triangles`] then has fewer than added.
    pub fn drop_degenerate(&mut self) {
        self.drop_degenerate = true;
    }

    /// Marks the lights as the default rig put in for a model without any (said in the
    /// status line and in `render --stats`).
    pub fn default_lights(&mut self, yes: bool) {
        self.default_lights = yes;
    }

    /// How far the app's keys move the camera and light, as a multiple of the Cornell box's
    /// steps (default 1).
    pub fn step(&mut self, scale: f32) {
        self.step = Some(scale);
    }

    /// How the scene's frames are shown (default [`ToneMap::Linear`], the seed's look).
    pub fn tone_map(&mut self, t: ToneMap) {
        self.tone_map = t;
    }

    /// Gives the triangles per-vertex data (normals, texture coordinates, colours, textures),
    /// for all the triangles added by the time the scene is built. Data that changes nothing
    /// ([`VertexData::calls_for_anything`]) is not kept.
    pub fn vertex_data(&mut self, data: VertexData) {
        self.vertex = Some(data);
    }

    /// Adds a light.
    pub fn light(&mut self, l: PointLight) {
        self.lights.push(l);
    }

    /// Adds a directional light.
    pub fn directional_light(&mut self, l: DirectionalLight) {
        self.directional.push(l);
    }

    /// Adds a spot light.
    pub fn spot_light(&mut self, l: SpotLight) {
        self.spots.push(l);
    }

    /// Adds a constant environment: what a ray that leaves the scene sees, per channel, in the
    /// image's units (a camera sees it as that pixel value; a white diffuse surface open to
    /// all of it shows the same). Environments add.
    pub fn environment(&mut self, emission: Vec3) {
        self.environment += emission;
    }

    /// Forces the acceleration structure (by default the faster one for the triangle count,
    /// [`AccelKind::for_triangles`]).
    pub fn accel(&mut self, kind: AccelKind) {
        self.accel = Some(kind);
    }

    /// Validates and builds the scene. Triangles are checked in parallel; the error names the
    /// first bad one in the order added.
    pub fn build(
        mut self,
        name: &str,
        camera: Camera,
        effects: Effects,
    ) -> Result<Scene, SceneError> {
        // Validated in parallel straight into place (an indexed collect: no intermediate
        // lists); a failure only raises a flag, and then a sequential pass finds the first. A
        // small scene is checked on this thread: the pool is not even started for it.
        let mut objects = std::mem::take(&mut self.objects);
        let vertex = self.vertex.take();
        let added = self.added();
        let small = added < PAR_MIN_TRIANGLES;
        #[cfg(test)]
        let mesh_from = self.mesh_from.unwrap_or(MESH_SCENE);
        #[cfg(not(test))]
        let mesh_from = MESH_SCENE;
        let keep_mesh = self.raw.is_empty()
            && self.indexed.is_some()
            && added >= mesh_from
            && !self.materials.iter().any(Material::emits);
        let valid_raw = |i: usize| {
            let ([a, b, c], m) = self.raw(i);
            Triangle::new(a, b, c, m).is_ok()
        };
        let failed = AtomicBool::new(false);
        let validate = |i: usize| {
            let ([a, b, c], m) = self.raw(i);
            Triangle::new(a, b, c, m).unwrap_or_else(|_| {
                failed.store(true, Ordering::Relaxed);
                PLACEHOLDER
            })
        };
        let mut triangles = Vec::new();
        if keep_mesh {
            // No list: each triangle is rebuilt from the mesh where it is read.
            if !(0..added).into_par_iter().all(valid_raw) {
                failed.store(true, Ordering::Relaxed);
            }
        } else if small {
            triangles = (0..added).map(validate).collect();
        } else {
            (0..added)
                .into_par_iter()
                .map(validate)
                .collect_into_vec(&mut triangles);
        }
        let mut vertex = vertex.filter(VertexData::calls_for_anything);
        if let Some(v) = &mut vertex {
            if let Some(problem) = v.problem(added, self.materials.len()) {
                return Err(SceneError::VertexData { problem });
            }
            v.sanitise();
        }
        if failed.load(Ordering::Relaxed) && self.drop_degenerate && keep_mesh {
            let mut keep = Vec::new();
            (0..added)
                .into_par_iter()
                .map(valid_raw)
                .collect_into_vec(&mut keep);
            let mut kept = 0;
            let mut ranges = Vec::with_capacity(objects.len());
            for r in &objects {
                let start = kept;
                kept += keep[r.clone()].iter().filter(|&&k| k).count();
                ranges.push(start..kept);
            }
            ranges.retain(|r| !r.is_empty());
            if let Some(v) = &mut vertex {
                v.retain_triangles(|i| keep[i]);
            }
            if let Some(m) = &mut self.indexed {
                m.retain(&keep);
            }
            objects = ranges;
        } else if failed.load(Ordering::Relaxed) && self.drop_degenerate {
            // Keep the valid triangles in order (in place), each object's range shrunk to its
            // own. A placeholder marks each degenerate one: no valid triangle has its zero area.
            let valid = |t: &Triangle| t.v != PLACEHOLDER.v;
            let mut kept = 0;
            let mut ranges = Vec::with_capacity(objects.len());
            for r in &objects {
                let start = kept;
                kept += triangles[r.clone()].iter().filter(|t| valid(t)).count();
                ranges.push(start..kept);
            }
            ranges.retain(|r| !r.is_empty());
            if let Some(v) = &mut vertex {
                v.retain_triangles(|i| valid(&triangles[i]));
            }
            triangles.retain(valid);
            objects = ranges;
        } else if failed.into_inner() {
            let (index, problem) = (0..added)
                .find_map(|i| {
                    let ([a, b, c], m) = self.raw(i);
                    Triangle::new(a, b, c, m).err().map(|e| (i, e))
                })
                .expect("a triangle failed to validate");
            return Err(SceneError::Triangle { index, problem });
        }
        let materials = self.materials.len();
        let bad_material = |t: &Triangle| t.material as usize >= materials;
        let first_bad = if let (true, Some(m)) = (keep_mesh, &self.indexed) {
            m.materials.iter().position(|&k| k as usize >= materials)
        } else if small {
            triangles.iter().position(bad_material)
        } else {
            triangles.par_iter().position_first(bad_material)
        };
        if let Some(index) = first_bad {
            return Err(SceneError::Material { index });
        }
        if let Some(index) = self.materials.iter().position(|m| !m.is_valid()) {
            return Err(SceneError::MaterialValue { index });
        }
        if let Some(index) = self.lights.iter().position(|l| {
            !l.position.is_finite() || !l.power.is_finite() || l.power.min_element() < 0.0
        }) {
            return Err(SceneError::Light { index });
        }
        let power_ok = |p: Vec3| p.is_finite() && p.min_element() >= 0.0;
        let unit = |d: Vec3| d.is_finite() && d.length_squared() > 0.0;
        let mut directional = self.directional;
        for (index, l) in directional.iter_mut().enumerate() {
            if !unit(l.direction) || !power_ok(l.irradiance) || !unit(l.direction.normalize()) {
                let kind = "directional";
                return Err(SceneError::LightOfKind { kind, index });
            }
            l.direction = l.direction.normalize();
        }
        let mut spots = self.spots;
        for (index, l) in spots.iter_mut().enumerate() {
            let angles = 0.0 <= l.inner && l.inner <= l.outer && l.outer <= FRAC_PI_2;
            if !l.position.is_finite()
                || !unit(l.direction)
                || !unit(l.direction.normalize())
                || !power_ok(l.power)
                || !angles
            {
                return Err(SceneError::LightOfKind {
                    kind: "spot",
                    index,
                });
            }
            l.direction = l.direction.normalize();
        }
        if !power_ok(self.environment) {
            let kind = "environment";
            return Err(SceneError::LightOfKind { kind, index: 0 });
        }
        // The union of boxes is exact (min and max), so any order gives the same bounds.
        let count = match (keep_mesh, &self.indexed) {
            (true, Some(m)) => m.triangles.len(),
            _ => triangles.len(),
        };
        let bounds = if let (true, Some(m)) = (keep_mesh, &self.indexed) {
            (0..count)
                .into_par_iter()
                .map(|i| {
                    let v = crate::accel::Vertices::vertices(m, i);
                    Aabb {
                        min: v[0].min(v[1]).min(v[2]),
                        max: v[0].max(v[1]).max(v[2]),
                    }
                })
                .reduce(|| Aabb::EMPTY, Aabb::union)
        } else if small {
            triangles
                .iter()
                .map(Aabb::of_triangle)
                .fold(Aabb::EMPTY, Aabb::union)
        } else {
            triangles
                .par_iter()
                .map(Aabb::of_triangle)
                .reduce(|| Aabb::EMPTY, Aabb::union)
        };
        let extent = if count == 0 {
            1.0
        } else {
            (bounds.max - bounds.min).length()
        };
        let kind = self
            .accel
            .unwrap_or_else(|| AccelKind::for_triangles(count));
        drop(self.raw);
        let mesh = self.indexed.take().filter(|_| keep_mesh).map(Box::new);
        // (A kept mesh is big: a BVH whatever the kind asked for.)
        let accel = match &mesh {
            Some(m) => Accel::build_fast(&**m),
            None => Accel::build_kind(&triangles, &objects, kind),
        };
        let has_mirrors = self.materials.iter().any(|m| m.mirror > 0.0);
        // Only a scene with an emitting material looks for emitting triangles.
        let area_lights = if self.materials.iter().any(Material::emits) {
            let materials = &self.materials;
            AreaLights::new(&triangles, |t| materials[t.material as usize].emission)
        } else {
            None
        };
        Ok(Scene {
            name: name.to_string(),
            triangles,
            materials: self.materials,
            lights: self.lights,
            directional,
            spots,
            environment: self.environment,
            camera,
            effects,
            extent: if extent.is_finite() && extent > 0.0 {
                extent
            } else {
                1.0
            },
            accel,
            objects,
            has_mirrors,
            area_lights,
            default_lights: self.default_lights,
            step: self
                .step
                .filter(|s| s.is_finite() && *s > 0.0)
                .unwrap_or(1.0),
            tone_map: self.tone_map,
            centre: if bounds.min.is_finite() && bounds.max.is_finite() {
                (bounds.min + bounds.max) * 0.5
            } else {
                Vec3::ZERO
            },
            vertex: vertex.map(Box::new),
            mesh,
        })
    }
}

impl Scene {
    /// A short name for display (e.g. "cornell").
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The same scene under another display name (names are shown through
    /// [`crate::printable`], so any string is safe).
    pub fn with_name(mut self, name: impl Into<String>) -> Scene {
        self.name = name.into();
        self
    }

    /// All triangles as a list, each finite with a unit normal; [`Hit::triangle`] indexes
    /// this. Empty for the scene of a big model (at least [`MESH_SCENE`] triangles, nothing
    /// emitting), which keeps its indexed mesh instead: [`Scene::triangle`] and
    /// [`Scene::triangle_count`] read any scene's.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// Triangle `triangle` (as [`Hit::triangle`] names it).
    #[inline]
    pub fn triangle(&self, triangle: u32) -> Triangle {
        // The bounds check of the list's index is the only test a scene with a list pays.
        match self.triangles.get(triangle as usize) {
            Some(t) => *t,
            None => self.mesh_triangle(triangle),
        }
    }

    #[cold]
    #[inline(never)]
    fn mesh_triangle(&self, triangle: u32) -> Triangle {
        let mesh = self.mesh.as_deref().expect("a triangle index in range");
        mesh.triangle(triangle as usize)
    }

    /// The material of triangle `triangle`.
    #[inline]
    pub fn material_of(&self, triangle: u32) -> u32 {
        match self.triangles.get(triangle as usize) {
            Some(t) => t.material,
            None => {
                let mesh = self.mesh.as_deref().expect("a triangle index in range");
                mesh.material(triangle as usize)
            }
        }
    }

    /// The number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len() + self.mesh.as_ref().map_or(0, |m| m.triangles.len())
    }

    /// Materials; [`Triangle::material`] indexes this.
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// The lights the scene starts with (finite positions, non-negative power).
    pub fn lights(&self) -> &[PointLight] {
        &self.lights
    }

    /// The directional lights (unit directions, non-negative irradiance).
    pub fn directional_lights(&self) -> &[DirectionalLight] {
        &self.directional
    }

    /// The spot lights (unit directions, non-negative power, `0 ≤ inner ≤ outer ≤ π/2`).
    pub fn spot_lights(&self) -> &[SpotLight] {
        &self.spots
    }

    /// The constant environment: what a ray that leaves the scene sees (zero: none).
    pub fn environment(&self) -> Vec3 {
        self.environment
    }

    /// How far the app's keys move the camera and light, as a multiple of the Cornell box's
    /// steps: 1 for the built-in scenes and scene files, a model's size over the box's.
    pub fn step(&self) -> f32 {
        self.step
    }

    /// How the scene's frames are shown on a screen (PNG, the terminal): linear and clamped
    /// for the built-in scenes and scene files, Khronos PBR Neutral and sRGB for models.
    pub fn tone_map(&self) -> ToneMap {
        self.tone_map
    }

    /// Whether the lights are the default rig, put in because the model's file has none.
    pub fn lights_are_default(&self) -> bool {
        self.default_lights
    }

    /// The camera the scene starts with.
    pub fn camera(&self) -> Camera {
        self.camera
    }

    /// The same scene starting from another camera.
    pub fn with_camera(mut self, camera: Camera) -> Scene {
        self.camera = camera;
        self
    }

    /// The effects the scene calls for.
    pub fn effects(&self) -> Effects {
        self.effects
    }

    /// The same scene calling for other effects (the geometry, and so its validity, unchanged).
    pub fn with_effects(mut self, effects: Effects) -> Scene {
        self.effects = effects;
        self
    }

    /// The centre of the scene's bounding box (the origin for a scene without triangles).
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// Length of the bounding box's diagonal: the scene's scale.
    pub fn extent(&self) -> f32 {
        self.extent
    }

    /// The closest hit along `ray` with `t < t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.accel.intersect(ray, t_max)
    }

    /// The closest hits of `tile`'s rays into `hits` (as many), each as [`Scene::intersect`]
    /// gives it; a tile whose rays share their axes (a camera's) is tested eight rays at a
    /// time where the structure can, keeping what tiles of one camera share in `cache` (start
    /// with `TileCache::default()`).
    #[inline]
    pub fn intersect_tile(
        &self,
        tile: &RayTile,
        t_max: f32,
        hits: &mut [Option<Hit>],
        cache: &mut TileCache,
    ) {
        // Shading reads each hit's triangle, a cache miss in a big scene: ask for it while the
        // tile's other rays are traced.
        let triangles = &self.triangles;
        self.accel
            .intersect_tile_with(tile, t_max, hits, cache, |i| {
                if let Some(t) = triangles.get(i as usize) {
                    crate::accel::prefetch_value(t);
                }
            })
    }

    /// [`Scene::intersect_tile`], the hits as lanes ([`crate::accel::Accel::intersect_tile_best`]).
    #[inline]
    pub fn intersect_tile_best(
        &self,
        tile: &RayTile,
        t_max: f32,
        best: &mut [crate::accel::tri4::Best8; crate::accel::TILE_RAYS / 8],
        cache: &mut TileCache,
    ) {
        self.accel.intersect_tile_best(tile, t_max, best, cache)
    }

    /// [`Scene::occluded`] for each of `rays`, into `out` (as many).
    #[inline]
    pub fn occluded_each(&self, rays: &[Ray], t_max: f32, out: &mut [bool]) {
        self.accel.occluded_each(rays, t_max, out)
    }

    /// Whether anything blocks `ray` before `t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.accel.occluded(ray, t_max)
    }

    /// The same scene with its acceleration structure rebuilt as `kind`. Frames do not change:
    /// every kind finds the same hits (see [`crate::accel`]).
    pub fn with_accel(mut self, kind: AccelKind) -> Scene {
        let isa = self.accel.isa();
        self.accel = self
            .build_accel(kind)
            .with_isa(isa)
            .expect("the scene's path is available");
        self
    }

    /// The same scene, its queries on SIMD path `isa`; `None` if this CPU does not have it.
    /// Frames do not change: every path finds the same hits, bit for bit.
    pub fn with_isa(mut self, isa: Isa) -> Option<Scene> {
        self.accel = self.accel.with_isa(isa)?;
        Some(self)
    }

    /// The SIMD path the scene's queries take.
    pub fn isa(&self) -> Isa {
        self.accel.isa()
    }

    /// A new acceleration structure of `kind` over this scene's triangles (for timing builds;
    /// [`Scene::with_accel`] installs one).
    pub fn build_accel(&self, kind: AccelKind) -> Accel {
        match (&self.mesh, kind) {
            (Some(m), AccelKind::Bvh) => Accel::build_fast(&**m),
            (Some(m), AccelKind::Flat) => {
                let list: Vec<Triangle> = (0..m.triangles.len()).map(|i| m.triangle(i)).collect();
                Accel::build_kind(&list, &self.objects, kind)
            }
            (None, _) => Accel::build_kind(&self.triangles, &self.objects, kind),
        }
    }

    /// The acceleration structure's kind, size and build time.
    pub fn accel_stats(&self) -> AccelStats {
        self.accel.stats()
    }

    /// The object (in the order added) that triangle `triangle` belongs to.
    pub fn object_of(&self, triangle: u32) -> u32 {
        self.objects.partition_point(|r| r.end <= triangle as usize) as u32
    }

    /// The base colour at a hit on `triangle` at barycentrics `b`: the one place a hit's colour
    /// is looked up. The material's colour, times the interpolated vertex colour and the
    /// base-colour texture where the scene has them ([`VertexData::base_colour`]).
    #[inline(always)]
    pub fn base_colour(&self, triangle: u32, b: [f32; 3]) -> Vec3 {
        let material = self.material_of(triangle);
        let colour = self.materials[material as usize].colour;
        match &self.vertex {
            None => colour,
            Some(v) => v.base_colour(colour, triangle, material, b),
        }
    }

    /// Whether some triangle's base colour changes across it (vertex colours or a texture):
    /// if not, [`Scene::base_colour`] is the material's colour wherever a triangle is hit.
    #[inline]
    pub fn colour_varies(&self) -> bool {
        self.vertex.as_ref().is_some_and(|v| v.colour_varies())
    }

    /// Whether the scene has vertex normals (shading normals: [`Scene::shading_normal`]).
    #[inline]
    pub fn has_normals(&self) -> bool {
        self.vertex.as_ref().is_some_and(|v| !v.normals.is_empty())
    }

    /// The shading normal at a hit on `triangle` at barycentrics `b`: its vertex normals
    /// interpolated, unit length (facing as the file gives them); `None` where the scene has
    /// no vertex normals or this triangle's give none, where the triangle's own normal
    /// shades.
    #[inline]
    pub fn shading_normal(&self, triangle: u32, b: [f32; 3]) -> Option<Vec3> {
        self.vertex.as_ref()?.normal(triangle, b)
    }

    /// The scene's per-vertex data, if it has any that changes a frame.
    pub fn vertex_data(&self) -> Option<&VertexData> {
        self.vertex.as_deref()
    }

    /// The emitting triangles as lights, picked by power (`None` when nothing emits).
    pub fn area_lights(&self) -> Option<&AreaLights> {
        self.area_lights.as_ref()
    }

    /// Whether any material reflects specularly (if not, no reflection ray is ever traced).
    pub fn has_mirrors(&self) -> bool {
        self.has_mirrors
    }

    /// The closest distance at which a point light is evaluated, relative to the scene's scale:
    /// `r²` in the inverse-square law is clamped to at least this squared, so a light on a
    /// surface gives a large but finite irradiance (see [`crate::shading`]).
    pub fn min_light_distance(&self) -> f32 {
        self.extent * MIN_LIGHT_DISTANCE_FRACTION
    }
}

/// Scenes with fewer triangles are built on the calling thread (validation, materials,
/// bounds: microseconds for them), without starting the thread pool or waking it three times
/// (0.1-0.3 ms for the Cornell box's 30); the render starts the pool when it needs it.
const PAR_MIN_TRIANGLES: usize = 4096;

/// The point light is treated as a sphere of this radius, as a fraction of the scene's
/// diagonal: 1e-3 of a 3.5-unit Cornell box is 3.5 mm of a 55 cm room, small enough to change
/// no pixel of the seed's views, large enough that `1/r²` stays far from overflow.
pub const MIN_LIGHT_DISTANCE_FRACTION: f32 = 1e-3;

#[cfg(test)]
mod tests {
    use super::*;

    /// A model's mesh kept as it is (a big model's storage, forced here at a small size) reads
    /// as the list it replaces: the same triangles (degenerate ones dropped), materials,
    /// bounds and frames, bit for bit.
    #[test]
    fn a_kept_mesh_reads_as_the_list() {
        let mut soup = procedural::displaced_icosphere(12, 0.2);
        soup.insert(5, [Vec3::ZERO, Vec3::X, Vec3::X]);
        let positions: Vec<Vec3> = soup.iter().flatten().copied().collect();
        let indices: Vec<[u32; 3]> = (0..soup.len() as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        let build = |mesh_from: usize| {
            let mut b = SceneBuilder::new();
            let grey = b.material(Material::diffuse(Vec3::splat(0.7)));
            let red = b.material(Material::diffuse(Vec3::new(0.8, 0.2, 0.1)));
            let materials = (0..indices.len()).map(|i| [grey, red][i % 2]).collect();
            b.indexed_mesh(positions.clone(), indices.clone(), materials);
            b.drop_degenerate();
            b.light(PointLight {
                position: Vec3::new(0.3, -0.8, -2.5),
                power: Vec3::splat(14.0),
            });
            b.mesh_from = Some(mesh_from);
            b.build("mesh", Camera::default(), Effects::SEED).unwrap()
        };
        let (list, mesh) = (build(usize::MAX), build(0));
        assert!(mesh.triangles().is_empty() && mesh.mesh.is_some());
        assert_eq!(list.triangle_count(), soup.len() - 1);
        assert_eq!(mesh.triangle_count(), list.triangle_count());
        for i in 0..list.triangle_count() as u32 {
            assert_eq!(mesh.triangle(i), list.triangle(i), "triangle {i}");
            assert_eq!(mesh.material_of(i), list.material_of(i), "triangle {i}");
        }
        assert_eq!(mesh.centre(), list.centre());
        let frame = |s: &Scene| {
            s.render(&crate::Options {
                width: 48,
                height: 32,
                ..crate::Options::default()
            })
            .image
            .pixels
            .iter()
            .map(|p| p.to_array().map(f32::to_bits))
            .collect::<Vec<_>>()
        };
        let f = frame(&list);
        assert!(f.iter().any(|p| p != &[0; 3]), "the frame shows the sphere");
        assert_eq!(frame(&mesh), f);
    }
}
