//! The portable path: the scalar test itself, one lane at a time (any target). It is what the
//! SIMD kernels are held to, so it has no `redo` lanes: the scalar test does its own `f64`
//! redo.

use super::{Hits, LANES, Tri4};
use crate::geometry::{Ray, intersect_watertight};

/// The hits of `ray` among `block`'s lanes.
#[inline(always)]
pub fn hits(block: &Tri4, ray: &Ray, t_max: f32) -> Hits {
    let mut out = Hits::NONE;
    for lane in 0..LANES {
        if let Some(h) = intersect_watertight(ray, &block.vertices(lane), t_max) {
            out.mask |= 1 << lane;
            out.t[lane] = h.t;
            for (b, w) in out.b.iter_mut().zip(h.b) {
                b[lane] = w;
            }
        }
    }
    out
}
