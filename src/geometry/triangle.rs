//! `Triangle`: validated vertices, the seed's normal, a material index.

use glam::Vec3;

use super::ray::Ray;
use super::watertight::{TriHit, intersect_watertight};

/// A triangle with its geometric normal and material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Vertices in the scene's winding order.
    pub v: [Vec3; 3],
    /// `normalize(cross(v2 − v0, v1 − v0))`, the seed's convention. Never NaN: a scene only holds
    /// triangles whose normal is finite and unit length (see [`Triangle::new`]).
    pub normal: Vec3,
    /// Index into the scene's material table.
    pub material: u32,
}

/// Why a triangle cannot be part of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DegenerateTriangle {
    /// A vertex coordinate is NaN or infinite.
    NonFinite,
    /// Zero area (repeated or collinear vertices): it has no normal and can never be hit.
    ZeroArea,
}

impl std::fmt::Display for DegenerateTriangle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DegenerateTriangle::NonFinite => f.write_str("a vertex coordinate is NaN or infinite"),
            DegenerateTriangle::ZeroArea => {
                f.write_str("the triangle has zero area (repeated or collinear vertices)")
            }
        }
    }
}

impl std::error::Error for DegenerateTriangle {}

impl Triangle {
    /// Builds a triangle, rejecting the degenerate ones: non-finite vertices, or an area so small
    /// that the normal cannot be computed (the cross product computed in `f64` to avoid
    /// underflow at tiny scales).
    pub fn new(
        v0: Vec3,
        v1: Vec3,
        v2: Vec3,
        material: u32,
    ) -> Result<Triangle, DegenerateTriangle> {
        if !(v0.is_finite() && v1.is_finite() && v2.is_finite()) {
            return Err(DegenerateTriangle::NonFinite);
        }
        let c = (v2.as_dvec3() - v0.as_dvec3()).cross(v1.as_dvec3() - v0.as_dvec3());
        let len = c.length();
        if !(len > 0.0) || !len.is_finite() {
            return Err(DegenerateTriangle::ZeroArea);
        }
        let normal = (c / len).as_vec3();
        if !normal.is_finite() || normal == Vec3::ZERO {
            return Err(DegenerateTriangle::ZeroArea);
        }
        Ok(Triangle {
            v: [v0, v1, v2],
            normal: normal.normalize(),
            material,
        })
    }

    /// The unit normal of the side the vertices' counter-clockwise winding faces in a
    /// right-handed frame, `−normal`: a closed mesh wound the usual way (and the `box` and
    /// `icosphere` objects) has it pointing out. An emitter emits on this side, and glass has
    /// air on it.
    #[inline]
    pub fn front(&self) -> Vec3 {
        -self.normal
    }

    /// Intersects `ray` with this triangle (both sides), returning a hit with `0 < t < t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<TriHit> {
        intersect_watertight(ray, &self.v, t_max)
    }
}
