//! `Aabb`: axis-aligned bounding boxes.

use glam::Vec3;

use super::float::gamma;
use super::ray::Ray;
use super::triangle::Triangle;
use crate::simd::Lanes;

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

    /// The slab test: where `ray` enters the box within `[0, t_max]`, or `None` if it misses
    /// it there. The one-lane form of [`slab_lanes`], which every box test in the crate is.
    pub fn enter(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let (hit, t0) = slab_lanes::<f32>(
            self.min.to_array(),
            self.max.to_array(),
            &ray.origin.to_array(),
            &ray.inv_dir.to_array(),
            t_max,
        );
        hit.then_some(t0)
    }

    /// Whether `ray` meets the box within `[0, t_max]` ([`Aabb::enter`]).
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f32) -> bool {
        self.enter(ray, t_max).is_some()
    }
}

/// The slab test lane by lane, a box per lane (its corners `min`, `max` by axis): which boxes
/// the ray (`origin`, `inv_dir = 1/dir`) meets for some `t` in `[0, t_max]`, and where it
/// enters each. The far side of each slab is widened by pbrt-v4's 1 + 2γ₃ so that rounding
/// never culls a box the ray grazes; a NaN slab distance (a ray parallel to a slab whose origin
/// lies on its plane) constrains nothing, as `min`/`max` pick their second operand on NaN.
/// An empty box (min +∞, max −∞) is not rejected (the near/far swap makes it everything):
/// callers mask those lanes.
#[inline(always)]
pub(crate) fn slab_lanes<L: Lanes>(
    min: [L; 3],
    max: [L; 3],
    origin: &[f32; 3],
    inv_dir: &[f32; 3],
    t_max: f32,
) -> (L::Mask, L) {
    let widen = L::splat(1.0 + 2.0 * gamma(3));
    let mut t0 = L::splat(0.0);
    let mut t1 = L::splat(t_max);
    for axis in 0..3 {
        let (o, inv) = (L::splat(origin[axis]), L::splat(inv_dir[axis]));
        let a = min[axis].sub(o).mul(inv);
        let b = max[axis].sub(o).mul(inv);
        // near = a > b ? b : a; far = a > b ? a : b.
        let near = b.min(a);
        let far = a.max(b).mul(widen);
        t0 = near.max(t0);
        t1 = far.min(t1);
    }
    (t0.le(t1), t0)
}

/// [`slab_lanes`] for `W` boxes held slab by slab (`min[axis][box]`), `L::N` at a time: a bit
/// per box the ray meets, and where it enters each.
#[inline(always)]
pub(crate) fn enter_boxes<L: Lanes, const W: usize>(
    min: &[[f32; W]; 3],
    max: &[[f32; W]; 3],
    origin: &[f32; 3],
    inv_dir: &[f32; 3],
    t_max: f32,
) -> (u32, [f32; W]) {
    let mut mask = 0;
    let mut t = [0.0; W];
    for at in (0..W).step_by(L::N) {
        let lo = [
            L::load(&min[0][at..]),
            L::load(&min[1][at..]),
            L::load(&min[2][at..]),
        ];
        let hi = [
            L::load(&max[0][at..]),
            L::load(&max[1][at..]),
            L::load(&max[2][at..]),
        ];
        let (hit, t0) = slab_lanes::<L>(lo, hi, origin, inv_dir, t_max);
        mask |= L::bits(hit) << at;
        t0.store(&mut t[at..]);
    }
    (mask, t)
}
