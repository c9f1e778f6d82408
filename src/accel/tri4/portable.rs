//! The portable path: the scalar test itself, one lane at a time (any target). It is what the
//! SIMD kernels are held to, so it has no `redo` lanes: the scalar test does its own `f64`
//! redo.

use super::{LANES, LaneHits, Tri4};
use crate::geometry::{Ray, intersect_watertight};

/// The hits of `ray` among `block`'s lanes: `(mask, 0)`, each hit lane's `t` and barycentrics
/// into lane `half + lane` of `out`.
#[inline(always)]
pub fn hits(block: &Tri4, ray: &Ray, t_max: f32, out: &mut LaneHits, half: usize) -> (u32, u32) {
    let mut mask = 0;
    for lane in 0..LANES {
        if let Some(h) = intersect_watertight(ray, &block.vertices(lane), t_max) {
            mask |= 1 << lane;
            out.t[half + lane] = h.t;
            for (b, w) in out.b.iter_mut().zip(h.b) {
                b[half + lane] = w;
            }
        }
    }
    (mask, 0)
}
