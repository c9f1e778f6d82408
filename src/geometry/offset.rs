//! Where a new ray starts: the hit point with its error bound, pushed off the surface.

use glam::Vec3;

use super::float::{gamma, next_float_down, next_float_up};

/// The hit point from barycentrics, and a conservative bound on its absolute error per axis.
///
/// The point is clamped into the triangle's bounding box: the exact point lies in it, so the
/// clamp only moves the computed one closer on each axis and the bound still holds. Without
/// it, a hit exactly on a crease (a ray along the line where a wall meets the floor) can round
/// to one ulp behind the neighbouring wall, and a shadow ray from there, offset along its own
/// normal only, is blocked by that wall.
#[inline]
pub fn hit_point(v: &[Vec3; 3], b: [f32; 3]) -> (Vec3, Vec3) {
    let p0 = v[0] * b[0];
    let p1 = v[1] * b[1];
    let p2 = v[2] * b[2];
    let lo = v[0].min(v[1]).min(v[2]);
    let hi = v[0].max(v[1]).max(v[2]);
    let p = (p0 + p1 + p2).max(lo).min(hi);
    let err = (p0.abs() + p1.abs() + p2.abs()) * gamma(7);
    (p, err)
}

/// Moves `p` (with per-axis error bound `err`) off its surface with normal `n`, to the side that
/// `w` points to, far enough that a ray from the result cannot re-hit that surface (pbrt-v4's
/// `OffsetRayOrigin`). The offset is rounded away from `p` so it survives the addition.
#[inline]
pub fn offset_ray_origin(p: Vec3, err: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(err);
    let mut offset = n * d;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_float_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_float_down(po[i]);
        }
    }
    po
}
