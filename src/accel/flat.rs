//! The flat object list: every object's box, then its triangles. Fastest below
//! [`super::BVH_THRESHOLD`] triangles (the Cornell box).

use std::ops::Range;

use super::hit::{Hit, cull_bound, shrunk_t_max};
use crate::geometry::{Aabb, Ray, Triangle, intersect_watertight};

pub(super) fn flat_intersect(
    objects: &[(Aabb, Range<usize>)],
    triangles: &[Triangle],
    ray: &Ray,
    t_max: f32,
) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    let mut tri_t_max = t_max;
    let mut bound = cull_bound(t_max);
    for (aabb, range) in objects {
        if !aabb.hit(ray, bound) {
            continue;
        }
        for i in range.clone() {
            let Some(h) = intersect_watertight(ray, &triangles[i].v, tri_t_max) else {
                continue;
            };
            if best.is_none_or(|b| h.t < b.t || h.t == b.t && (i as u32) < b.triangle) {
                best = Some(Hit {
                    t: h.t,
                    b: h.b,
                    triangle: i as u32,
                });
                tri_t_max = shrunk_t_max(h.t, t_max);
                bound = cull_bound(h.t);
            }
        }
    }
    best
}

pub(super) fn flat_occluded(
    objects: &[(Aabb, Range<usize>)],
    triangles: &[Triangle],
    ray: &Ray,
    t_max: f32,
) -> bool {
    let bound = cull_bound(t_max);
    objects.iter().any(|(aabb, range)| {
        aabb.hit(ray, bound)
            && triangles[range.clone()]
                .iter()
                .any(|t| intersect_watertight(ray, &t.v, t_max).is_some())
    })
}
