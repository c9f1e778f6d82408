//! What a model's vertices carry besides their positions: normals (for shading), texture
//! coordinates (for base-colour textures) and colours, with the textures themselves. A scene
//! holds this only when its model has something of it ([`VertexData::calls_for_anything`]):
//! the built-in scenes and a model of bare positions hold nothing, and shade as they always
//! did.

use glam::{Vec2, Vec3};

use super::texture::Texture;

/// Per-vertex data for a scene's triangles ([`super::SceneBuilder::vertex_data`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VertexData {
    /// Each triangle's vertices, in the order the triangles were added (one per triangle
    /// added), indexing the lists below.
    pub corners: Vec<[u32; 3]>,
    /// Unit vertex normals, empty or one per vertex; a zero normal is none (the triangle's
    /// own normal is used where one of its vertices has none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates (u right, v down from the image's top), empty or one per vertex.
    pub uvs: Vec<Vec2>,
    /// Linear RGB colours in [0, 1] multiplying the base colour, empty or one per vertex.
    pub colours: Vec<Vec3>,
    /// The textures.
    pub textures: Vec<Texture>,
    /// Each material's base-colour texture (an index into `textures`), by material index;
    /// materials past the end have none.
    pub material_textures: Vec<Option<u32>>,
}

impl VertexData {
    /// Whether any of it changes a frame: vertex colours, normals, or a texture some
    /// material uses.
    pub fn calls_for_anything(&self) -> bool {
        !self.colours.is_empty()
            || !self.normals.is_empty()
            || self.material_textures.iter().any(Option::is_some)
    }

    /// Whether colours or textures make a triangle's base colour change across it.
    pub fn colour_varies(&self) -> bool {
        !self.colours.is_empty() || self.material_textures.iter().any(Option::is_some)
    }

    /// What is wrong with it for `triangles` triangles and `materials` materials, if anything.
    pub(super) fn problem(&self, triangles: usize, materials: usize) -> Option<String> {
        if self.corners.len() != triangles {
            return Some(format!(
                "{} triangles' corners for {triangles} triangles",
                self.corners.len()
            ));
        }
        let vertices = self
            .normals
            .len()
            .max(self.uvs.len())
            .max(self.colours.len());
        for (list, what) in [
            (self.normals.len(), "normals"),
            (self.uvs.len(), "texture coordinates"),
            (self.colours.len(), "colours"),
        ] {
            if list != 0 && list != vertices {
                return Some(format!("{list} {what} for {vertices} vertices"));
            }
        }
        if let Some(c) = self
            .corners
            .iter()
            .flatten()
            .find(|&&c| c as usize >= vertices)
        {
            return Some(format!("vertex {c} of {vertices} vertices"));
        }
        if self.material_textures.len() > materials {
            return Some(format!(
                "textures for {} materials of {materials}",
                self.material_textures.len()
            ));
        }
        if let Some(t) = self
            .material_textures
            .iter()
            .flatten()
            .find(|&&t| t as usize >= self.textures.len())
        {
            return Some(format!("texture {t} of {}", self.textures.len()));
        }
        None
    }

    /// Values made safe to shade with: normals unit or zero, coordinates finite, colours in
    /// [0, 1].
    pub(super) fn sanitise(&mut self) {
        for n in &mut self.normals {
            *n = if n.is_finite() {
                n.normalize_or_zero()
            } else {
                Vec3::ZERO
            };
        }
        for t in &mut self.uvs {
            if !t.is_finite() {
                *t = Vec2::ZERO;
            }
        }
        for c in &mut self.colours {
            *c = c.map(|x| {
                if x.is_finite() {
                    x.clamp(0.0, 1.0)
                } else {
                    0.0
                }
            });
        }
    }

    /// Keeps the corners of the triangles `keep` says, in order.
    pub(super) fn retain_triangles(&mut self, mut keep: impl FnMut(usize) -> bool) {
        let mut i = 0;
        self.corners.retain(|_| {
            i += 1;
            keep(i - 1)
        });
    }

    /// `colour` (a material's) at barycentrics `b` of triangle `triangle` of material
    /// `material`: times the interpolated vertex colour, times the texture's colour at the
    /// interpolated texture coordinate.
    #[inline]
    pub(super) fn base_colour(
        &self,
        colour: Vec3,
        triangle: u32,
        material: u32,
        b: [f32; 3],
    ) -> Vec3 {
        let c = self.corners[triangle as usize].map(|c| c as usize);
        let mut out = colour;
        if !self.colours.is_empty() {
            out *= lerp(&self.colours, c, b);
        }
        if let Some(&Some(t)) = self.material_textures.get(material as usize) {
            let uv = if self.uvs.is_empty() {
                Vec2::ZERO
            } else {
                let [a, bb, cc] = c.map(|c| self.uvs[c]);
                a * b[0] + bb * b[1] + cc * b[2]
            };
            out *= self.textures[t as usize].sample(uv);
        }
        out
    }

    /// The interpolated vertex normal of triangle `triangle` at barycentrics `b`, unit length;
    /// `None` where the model has no normals, a vertex has none, or they cancel.
    #[inline]
    pub fn normal(&self, triangle: u32, b: [f32; 3]) -> Option<Vec3> {
        if self.normals.is_empty() {
            return None;
        }
        let c = self.corners[triangle as usize].map(|c| c as usize);
        let n = c.map(|c| self.normals[c]);
        if n.contains(&Vec3::ZERO) {
            return None;
        }
        let s = n[0] * b[0] + n[1] * b[1] + n[2] * b[2];
        let s = s.normalize_or_zero();
        (s != Vec3::ZERO).then_some(s)
    }
}

/// `v` at corners `c` weighed by `b`.
#[inline]
fn lerp(v: &[Vec3], c: [usize; 3], b: [f32; 3]) -> Vec3 {
    v[c[0]] * b[0] + v[c[1]] * b[1] + v[c[2]] * b[2]
}
