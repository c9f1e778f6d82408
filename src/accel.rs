//! Acceleration structure: which triangles a ray needs to be tested against.
//!
//! The scene's triangles are grouped into objects (the Cornell room, each block, a mesh), each
//! with a bounding box; a ray is tested only against the triangles of the objects whose box it
//! meets. Closest-hit queries shrink `t_max` as they go; shadow queries stop at the first hit.

use std::ops::Range;

use crate::geometry::{Aabb, Ray, Triangle};

/// A closest hit in a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (`> 0`).
    pub t: f32,
    /// Barycentric weights of the triangle's three vertices.
    pub b: [f32; 3],
    /// Index of the triangle in [`crate::Scene::triangles`].
    pub triangle: u32,
}

/// Objects (contiguous triangle ranges) with their bounding boxes.
#[derive(Clone, Debug, Default)]
pub struct Accel {
    objects: Vec<(Aabb, Range<usize>)>,
}

impl Accel {
    /// Builds the structure over `triangles`, one object per range in `objects`.
    pub fn build(triangles: &[Triangle], objects: &[Range<usize>]) -> Accel {
        let objects = objects
            .iter()
            .filter(|r| !r.is_empty())
            .map(|r| {
                let aabb = triangles[r.clone()]
                    .iter()
                    .fold(Aabb::EMPTY, |b, t| b.union(Aabb::of_triangle(t)));
                (aabb, r.clone())
            })
            .collect();
        Accel { objects }
    }

    /// The closest hit with `t < t_max`, or `None`.
    pub fn intersect(&self, triangles: &[Triangle], ray: &Ray, t_max: f32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_max = t_max;
        for (aabb, range) in &self.objects {
            if !aabb.hit(ray, t_max) {
                continue;
            }
            for i in range.clone() {
                if let Some(h) = triangles[i].intersect(ray, t_max) {
                    t_max = h.t;
                    best = Some(Hit {
                        t: h.t,
                        b: h.b,
                        triangle: i as u32,
                    });
                }
            }
        }
        best
    }

    /// Whether anything lies along the ray for `t < t_max` (any hit; stops at the first).
    pub fn occluded(&self, triangles: &[Triangle], ray: &Ray, t_max: f32) -> bool {
        self.objects.iter().any(|(aabb, range)| {
            aabb.hit(ray, t_max)
                && triangles[range.clone()]
                    .iter()
                    .any(|t| t.intersect(ray, t_max).is_some())
        })
    }
}
