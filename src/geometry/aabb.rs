//! `Aabb`: axis-aligned bounding boxes.

use glam::Vec3;

use super::float::gamma;
use super::ray::Ray;
use super::triangle::Triangle;

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (min = +∞, max = −∞), the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    /// The box around a triangle.
    pub fn of_triangle(t: &Triangle) -> Aabb {
        Aabb {
            min: t.v[0].min(t.v[1]).min(t.v[2]),
            max: t.v[0].max(t.v[1]).max(t.v[2]),
        }
    }

    /// The smallest box holding both.
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// The box's centre.
    pub fn centre(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// The slab test, the one every box test in the crate is held to bit for bit (the BVH's
    /// paired SSE2 and portable forms, in `accel::bvh`'s tests): where `ray` enters the box
    /// within `[0, t_max]`, or `None` if it misses it there. The far side of each slab is
    /// widened by pbrt-v4's 1 + 2γ₃ so that rounding never culls a box the ray grazes; a NaN
    /// slab distance (a ray parallel to a slab whose origin lies on its plane) leaves the
    /// interval unchanged.
    pub fn enter(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let mut t0 = 0.0f32;
        let mut t1 = t_max;
        for i in 0..3 {
            let inv = ray.inv_dir[i];
            let mut near = (self.min[i] - ray.origin[i]) * inv;
            let mut far = (self.max[i] - ray.origin[i]) * inv;
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            far *= 1.0 + 2.0 * gamma(3);
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
            if t0 > t1 {
                return None;
            }
        }
        Some(t0)
    }

    /// Whether `ray` meets the box within `[0, t_max]` ([`Aabb::enter`]).
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f32) -> bool {
        self.enter(ray, t_max).is_some()
    }
}
